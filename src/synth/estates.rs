//! What the `kyoto` profile adds to the grid: quarters of samurai estates (buke yashiki 武家
//! 屋敷), each walled with a gate on its street and an omoya hall inside, and the repeated
//! ids of real cadastral tables.
//!
//! The shares come from a real Kyoto-like town of 30,676 lots (issue 59): 1,433 estates,
//! 7,170 wall segments (282 km) with 1,434 gates, 1,815 repeated ids.

use rand::RngExt;

use super::{rect, SynthLot, BLOCK};
use crate::rng::feature_rng;

/// Share of the 2 x 2-block quarters given to estates: with six estates to an estate block and
/// about 52 town lots to a town block, a third of the blocks make 4.7 % of the lots estates.
const ESTATE_QUARTERS: f64 = 0.34;
/// Share of records that repeat the id of the record before them (1,815 of 30,676).
const REPEATED_IDS: f64 = 0.059;

/// Whether block (`bx`, `by`) lies in an estate quarter. Estates cluster, as they did around
/// the castle and the palace, so a quarter of 2 x 2 blocks is drawn at once.
pub(super) fn quarter(seed: u64, bx: usize, by: usize) -> bool {
    let key = format!("{}_{}", bx / 2, by / 2);
    feature_rng(seed, "synth/quarter", &key).random::<f64>() < ESTATE_QUARTERS
}

/// Six estates of half a block by a third (60.6 m by 40.4 m, 202 m of wall each), every one
/// on a street with its gate there: four wall edges, one split by the gate, make five wall
/// segments an estate, as in the real town (7,170 for 1,433).
pub(super) fn estate_block(
    lots: &mut Vec<SynthLot>,
    wanted: usize,
    [x0, y0]: [f64; 2],
    district: &'static str,
) {
    let (w, h) = (BLOCK / 2.0, BLOCK / 3.0);
    for row in 0..3 {
        for col in 0..2 {
            if lots.len() >= wanted {
                return;
            }
            lots.push(SynthLot {
                id: lots.len() as u64 + 1,
                ring: rect(x0 + col as f64 * w, y0 + row as f64 * h, w, h),
                lot_use: "buke",
                mtype: "",
                district,
                gate: "1",
            });
        }
    }
}

/// Gives about one record in seventeen the id of the record before it, as real cadastral
/// tables repeat ids (a lot split and recorded twice); the build keeps the first and lists
/// the repeat as skipped.
pub(super) fn repeat_ids(lots: &mut [SynthLot], seed: u64) {
    for i in 1..lots.len() {
        let mut rng = feature_rng(seed, "synth/id", &i.to_string());
        if rng.random::<f64>() < REPEATED_IDS {
            lots[i].id = lots[i - 1].id;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed area (geo's), positive for a counter-clockwise ring.
    fn area(ring: &[[f64; 2]]) -> f64 {
        use geo::Area;
        let line: Vec<(f64, f64)> = ring.iter().map(|p| (p[0], p[1])).collect();
        geo::Polygon::new(line.into(), vec![]).signed_area()
    }

    #[test]
    fn an_estate_block_is_six_walled_estates_that_tile_it() {
        let mut lots = Vec::new();
        estate_block(&mut lots, 100, [0.0, 0.0], "");
        assert_eq!(lots.len(), 6);
        assert!(lots.iter().all(|l| l.lot_use == "buke" && l.gate == "1"));
        let total: f64 = lots.iter().map(|l| area(&l.ring)).sum();
        assert!((total - BLOCK * BLOCK).abs() < 1e-6, "{total}");
    }

    #[test]
    fn repeated_ids_repeat_the_record_before() {
        let mut lots: Vec<SynthLot> = (0..2000)
            .map(|i| SynthLot {
                id: i + 1,
                ring: vec![],
                lot_use: "machiya",
                mtype: "",
                district: "",
                gate: "",
            })
            .collect();
        repeat_ids(&mut lots, 1);
        let repeats = lots.windows(2).filter(|w| w[0].id == w[1].id).count();
        assert!((60..180).contains(&repeats), "{repeats}");
    }
}
