//! Thinning of the drawn points: the hard-core (Poisson-disk) spacing in key order, and the
//! per-tile cap.

use std::collections::{BTreeMap, HashMap};

use geo_types::Coord;

use super::kind::Kind;
use super::Candidate;
use crate::model::PlannedBillboard;

/// Hard-core thinning: in the order of the points' random keys, a point is kept when no kept
/// point lies within `spacing`. The result is in key order, so it does not depend on the
/// order the points were made in.
pub(super) fn thin(mut points: Vec<Candidate>, spacing: f64) -> Vec<PlannedBillboard> {
    points.sort_by(|a, b| a.key.cmp(&b.key).then_with(|| a.b.id.cmp(&b.b.id)));
    keep_spaced(points.into_iter().map(|c| c.b).collect(), spacing)
}

/// The points in the order given, each kept when no kept point is nearer than `spacing`.
pub(super) fn keep_spaced(points: Vec<PlannedBillboard>, spacing: f64) -> Vec<PlannedBillboard> {
    if spacing <= 0.0 {
        return points;
    }
    let cell = |c: Coord<f64>| {
        (
            (c.x / spacing).floor() as i64,
            (c.y / spacing).floor() as i64,
        )
    };
    // Looked up, never iterated: the hasher changes no result (foldhash: SipHash showed up).
    let mut grid: HashMap<(i64, i64), Vec<Coord<f64>>, foldhash::fast::FixedState> =
        HashMap::default();
    let mut kept = Vec::new();
    for b in points {
        let (i, j) = cell(b.at);
        // A spacing of 1e-300 m puts every point in a cell at the ends of i64: saturate.
        let crowded = (i.saturating_sub(1)..=i.saturating_add(1)).any(|x| {
            (j.saturating_sub(1)..=j.saturating_add(1)).any(|y| {
                grid.get(&(x, y)).is_some_and(|v| {
                    v.iter()
                        .any(|q| (q.x - b.at.x).hypot(q.y - b.at.y) < spacing)
                })
            })
        });
        if !crowded {
            grid.entry((i, j)).or_default().push(b.at);
            kept.push(b);
        }
    }
    kept
}

/// At most `max_points_per_tile` per tile (the densities were scaled to that, but a Poisson
/// draw can exceed it): the first in key order stay. Each tile's points are then put in id
/// order.
pub(super) fn cap_tiles(
    points: Vec<PlannedBillboard>,
    k: &Kind,
    warnings: &mut Vec<crate::model::Warning>,
) -> Vec<PlannedBillboard> {
    let mut per_tile: BTreeMap<String, Vec<PlannedBillboard>> = BTreeMap::new();
    for b in points {
        per_tile.entry(b.tile.clone()).or_default().push(b);
    }
    let mut out = Vec::new();
    for (tile, mut v) in per_tile {
        if v.len() > k.max_per_tile {
            warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Billboards,
                    format!(
                "{}: tile {tile} has {} points, more than max_points_per_tile = {}; the first \
                 {} were kept",
                k.layer,
                v.len(),
                k.max_per_tile,
                k.max_per_tile
            ),
                )
                .for_key(&format!("{}.max_points_per_tile", k.layer)),
            );
            v.truncate(k.max_per_tile);
        }
        v.sort_by(|a, b| a.id.cmp(&b.id));
        out.extend(v);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BillboardKind;

    fn candidate(key: u64, x: f64) -> Candidate {
        Candidate {
            key,
            b: PlannedBillboard {
                kind: BillboardKind::Tree,
                id: format!("{key}"),
                at: Coord { x, y: 0.0 },
                facing: 0.0,
                height: 5.0,
                texture: "tree_01".into(),
                ground: 0.0,
                district: None,
                tile: "0_0".into(),
                tree: None,
            },
        }
    }

    #[test]
    fn thinning_keeps_the_lowest_key_of_close_points_whatever_their_order() {
        let make = || {
            vec![
                candidate(9, 0.0),
                candidate(3, 1.0),
                candidate(5, 2.5),
                candidate(1, 10.0),
            ]
        };
        let kept: Vec<String> = thin(make(), 2.0).into_iter().map(|b| b.id).collect();
        // 1 (alone), 3 (beats 9 at 1 m), 5 is 1.5 m from 3: dropped; 9 is 1 m from 3: dropped.
        assert_eq!(kept, ["1", "3"]);
        let mut reversed = make();
        reversed.reverse();
        let again: Vec<String> = thin(reversed, 2.0).into_iter().map(|b| b.id).collect();
        assert_eq!(kept, again);
        assert_eq!(thin(make(), 0.0).len(), 4);
    }
}
