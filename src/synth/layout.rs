//! The town's layout: a grid of blocks with streets between them, each block cut into town
//! lots along its faces or given whole (or in estates) to samurai and temples.

use std::ops::Range;

use rand::RngExt;
use rand_pcg::Pcg64;

use super::{estates, rect, Profile, SynthLot, Town, BASE, BLOCK, KEN};
use crate::rng::feature_rng;

const STREET: f64 = 7.0;
const AVENUE: f64 = 12.0;

/// Machiya types written into the data (kanji, as in the machiya database), with weights.
const GIVEN_TYPES: &[(&str, f64)] = &[
    ("平屋", 30.0),
    ("中二階", 30.0),
    ("総二階", 15.0),
    ("仕舞屋", 8.0),
    ("塀付", 6.0),
    ("三階", 5.0),
    ("看板建", 6.0),
];
const DISTRICTS: [&str; 3] = ["上京", "中京", "下京"];

/// How a profile cuts a block's faces into town lots.
struct Cut {
    /// Frontage widths drawn, in ken.
    frontage_ken: Range<f64>,
    /// Depth of the lots on the east and west faces (they hold the corners), metres.
    side_depth: Range<f64>,
    /// Share of the side lines between deep strips that are slanted (by up to 1 %), as
    /// cadastral lines are; a slanted line makes the two lots' kura plots overlap.
    slanted: f64,
    /// A block drawn below the first is one samurai lot, below the second one temple.
    whole_blocks: (f64, f64),
}

impl Profile {
    fn cut(self) -> Cut {
        match self {
            Profile::Grid => Cut {
                frontage_ken: 1.5..5.0,
                side_depth: 14.0..22.0,
                slanted: 1.0,
                whole_blocks: (0.05, 0.08),
            },
            // Wider and deeper lots with mostly square side lines: a kura behind about half
            // the houses after collision avoidance, as the real towns users build hold.
            Profile::Kyoto => Cut {
                frontage_ken: 2.0..6.0,
                side_depth: 22.0..30.0,
                slanted: 0.35,
                whole_blocks: (0.01, 0.03),
            },
        }
    }

    /// Lots a block holds on average, to size the grid.
    fn lots_per_block(self) -> usize {
        match self {
            Profile::Grid => 60,
            Profile::Kyoto => 36,
        }
    }
}

fn pick<'a>(rng: &mut Pcg64, items: &'a [(&'a str, f64)]) -> &'a str {
    let total: f64 = items.iter().map(|i| i.1).sum();
    let mut r = rng.random::<f64>() * total;
    for (name, w) in items {
        if r < *w {
            return name;
        }
        r -= w;
    }
    items[items.len() - 1].0
}

fn street_width(i: usize) -> f64 {
    if i.is_multiple_of(4) {
        AVENUE
    } else {
        STREET
    }
}

/// Street centreline positions along one axis for `n` blocks.
fn street_lines(n: usize) -> Vec<f64> {
    let mut pos = vec![0.0];
    for i in 0..n {
        let next = pos[i] + street_width(i) / 2.0 + BLOCK + street_width(i + 1) / 2.0;
        pos.push(next);
    }
    pos
}

/// Makes the town in memory: lots, block outlines and street centrelines (with widths).
pub fn make_town(lots_wanted: usize, seed: u64, profile: Profile) -> Town {
    // Lay the blocks out in a near-square grid; rows are added should the town need more.
    let blocks_needed = lots_wanted.div_ceil(profile.lots_per_block()).max(1);
    let nx = (blocks_needed as f64).sqrt().ceil() as usize;
    let ny_planned = blocks_needed.div_ceil(nx);
    let xs = street_lines(nx);
    let cut = profile.cut();

    let mut lots = Vec::with_capacity(lots_wanted);
    let mut blocks = Vec::new();
    let mut by = 0;
    let mut ys = street_lines(ny_planned);
    while lots.len() < lots_wanted {
        if by + 1 >= ys.len() {
            ys = street_lines(by + 1);
        }
        for (bx, x) in xs[..nx].iter().enumerate() {
            if lots.len() >= lots_wanted {
                break;
            }
            let x0 = BASE[0] + x + street_width(bx) / 2.0;
            let y0 = BASE[1] + ys[by] + street_width(by) / 2.0;
            blocks.push(rect(x0, y0, BLOCK, BLOCK));
            let district = DISTRICTS[(2 - (by * 3 / ny_planned).min(2)).min(2)];
            let block_id = (by * nx + bx) as u64;
            let mut rng = feature_rng(seed, "synth/block", &block_id.to_string());
            if profile == Profile::Kyoto && estates::quarter(seed, bx, by) {
                estates::estate_block(&mut lots, lots_wanted, [x0, y0], district);
                continue;
            }
            let roll = rng.random::<f64>();
            let (buke, jisha) = cut.whole_blocks;
            if roll < buke || (roll < jisha && lots_wanted - lots.len() > 1) {
                lots.push(SynthLot {
                    id: lots.len() as u64 + 1,
                    ring: rect(x0, y0, BLOCK, BLOCK),
                    lot_use: if roll < buke { "buke" } else { "jisha" },
                    mtype: "",
                    district,
                    gate: profile.gate(),
                });
                continue;
            }
            block_lots(&mut lots, lots_wanted, &mut rng, &cut, [x0, y0], district);
        }
        by += 1;
    }
    // `ys` reaches the last row built, or the planned grid's last.
    let ny = by.max(ny_planned);
    let mut streets = Vec::new();
    let (x_end, y_end) = (xs[nx], ys[ny]);
    for (i, x) in xs.iter().enumerate() {
        streets.push((
            vec![[BASE[0] + x, BASE[1]], [BASE[0] + x, BASE[1] + y_end]],
            street_width(i),
        ));
    }
    for (j, y) in ys.iter().enumerate() {
        streets.push((
            vec![[BASE[0], BASE[1] + y], [BASE[0] + x_end, BASE[1] + y]],
            street_width(j),
        ));
    }
    if profile == Profile::Kyoto {
        estates::repeat_ids(&mut lots, seed);
    }
    Town {
        lots,
        blocks,
        streets,
    }
}

/// Frontage widths that fill `length` exactly, each within `ken` (in ken).
fn frontages(rng: &mut Pcg64, length: f64, ken: &Range<f64>) -> Vec<f64> {
    let (lo, hi) = (ken.start * KEN, ken.end * KEN);
    let mut out = Vec::new();
    let mut left = length;
    while left > 0.0 {
        let w = rng.random_range(ken.clone()) * KEN;
        if left - w < lo {
            if left > hi {
                out.push(left / 2.0);
                out.push(left / 2.0);
            } else {
                out.push(left);
            }
            break;
        }
        out.push(w);
        left -= w;
    }
    out
}

/// Lots along the four faces of one block whose south-west corner is `at`.
fn block_lots(
    lots: &mut Vec<SynthLot>,
    wanted: usize,
    rng: &mut Pcg64,
    cut: &Cut,
    [x0, y0]: [f64; 2],
    district: &'static str,
) {
    let side_depth = rng.random_range(cut.side_depth.clone());
    let push = |lots: &mut Vec<SynthLot>, rng: &mut Pcg64, ring: Vec<[f64; 2]>| {
        if lots.len() >= wanted {
            return;
        }
        let mtype = if rng.random::<f64>() < 0.25 {
            pick(rng, GIVEN_TYPES)
        } else {
            ""
        };
        lots.push(SynthLot {
            id: lots.len() as u64 + 1,
            ring,
            lot_use: "machiya",
            mtype,
            district,
            gate: "",
        });
    };
    // West and east faces: full height of the block, they hold the corners.
    for east in [false, true] {
        let mut y = y0;
        for w in frontages(rng, BLOCK, &cut.frontage_ken) {
            let ring = if east {
                let x = x0 + BLOCK;
                vec![
                    [x - side_depth, y],
                    [x, y],
                    [x, y + w],
                    [x - side_depth, y + w],
                ]
            } else {
                vec![
                    [x0, y],
                    [x0 + side_depth, y],
                    [x0 + side_depth, y + w],
                    [x0, y + w],
                ]
            };
            push(lots, rng, ring);
            y += w;
        }
    }
    // South and north faces between the side lots: deep strips whose side lines may be
    // slanted, as cadastral lots are; neighbours share their side lines, so lots never overlap.
    let inner = BLOCK - 2.0 * side_depth;
    for north in [false, true] {
        let widths = frontages(rng, inner, &cut.frontage_ken);
        let mut bounds = vec![(x0 + side_depth, 0.0)];
        let mut x = x0 + side_depth;
        for (k, w) in widths.iter().enumerate() {
            x += w;
            let slant = if k + 1 == widths.len() {
                0.0
            } else if cut.slanted >= 1.0 || rng.random::<f64>() < cut.slanted {
                rng.random_range(-0.01..0.01)
            } else {
                0.0
            };
            bounds.push((x, slant));
        }
        for k in 0..widths.len() {
            let depth = BLOCK / 2.0 * rng.random_range(0.55..1.0);
            let (xa, sa) = bounds[k];
            let (xb, sb) = bounds[k + 1];
            let ring = if north {
                let yf = y0 + BLOCK;
                vec![
                    [xa + sa * depth, yf - depth],
                    [xb + sb * depth, yf - depth],
                    [xb, yf],
                    [xa, yf],
                ]
            } else {
                vec![
                    [xa, y0],
                    [xb, y0],
                    [xb + sb * depth, y0 + depth],
                    [xa + sa * depth, y0 + depth],
                ]
            };
            push(lots, rng, ring);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frontages_fill_the_face_within_the_ken_range() {
        let mut rng = feature_rng(1, "t", "t");
        for ken in [1.5..5.0, 2.0..6.0] {
            for _ in 0..200 {
                let ws = frontages(&mut rng, 80.0, &ken);
                assert!((ws.iter().sum::<f64>() - 80.0).abs() < 1e-9);
                assert!(
                    ws.iter()
                        .all(|w| *w >= ken.start * KEN - 1e-9 && *w <= ken.end * KEN + 1e-9),
                    "{ws:?}"
                );
            }
        }
    }
}
