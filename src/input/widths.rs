//! Street widths from a separate line layer (Chino keeps widths on short split lines across
//! the road): each straight piece of centreline takes the width of the nearest width line.

use geo_types::LineString;
use rstar::{PointDistance, RTree};

use crate::geom::segment::Segment;
use crate::model::Street;

/// Splits streets into straight pieces and gives each the width of the nearest width line
/// within `max_distance` of its midpoint. Returns the pieces and how many got a width.
pub fn apply_widths(
    streets: Vec<Street>,
    width_lines: &[(LineString<f64>, f64)],
    max_distance: f64,
) -> (Vec<Street>, usize) {
    let tree = RTree::bulk_load(
        width_lines
            .iter()
            .flat_map(|(line, w)| {
                line.lines().map(move |l| Segment {
                    a: [l.start.x, l.start.y],
                    b: [l.end.x, l.end.y],
                    value: *w,
                })
            })
            .collect(),
    );
    let mut out = Vec::new();
    let mut matched = 0;
    for street in streets {
        for (k, seg) in street.line.lines().enumerate() {
            let mid = [
                (seg.start.x + seg.end.x) / 2.0,
                (seg.start.y + seg.end.y) / 2.0,
            ];
            let width = match tree.nearest_neighbor(&mid) {
                Some(w) if w.distance_2(&mid) <= max_distance * max_distance => {
                    matched += 1;
                    w.value
                }
                _ => street.width,
            };
            out.push(Street {
                id: format!("{}:{k}", street.id),
                line: LineString::from(vec![seg.start, seg.end]),
                width,
            });
        }
    }
    (out, matched)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_piece_takes_the_nearest_width() {
        let street = Street {
            id: "s".into(),
            line: LineString::from(vec![(0.0, 0.0), (100.0, 0.0), (200.0, 0.0)]),
            width: 6.0,
        };
        // A split line across the first piece, none near the second.
        let widths = vec![(LineString::from(vec![(50.0, -5.0), (50.0, 5.0)]), 11.0)];
        let (pieces, matched) = apply_widths(vec![street], &widths, 25.0);
        assert_eq!(pieces.len(), 2);
        assert_eq!(matched, 1);
        assert_eq!(pieces[0].width, 11.0);
        assert_eq!(pieces[1].width, 6.0);
    }
}
