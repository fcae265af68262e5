//! The union of many polygons in near-linear time: a cascaded union.
//!
//! geo's `unary_union` sweeps every ring at once; its cost grows with the crossings between
//! all of them. Polygons that overlap many others (one 480 m street drawn as 10,000 pieces,
//! each buffered to its width: every piece overlaps a hundred others) made one tile's ground
//! take 1.1 GiB and 16 s, and 20,000 pieces 3 GB (issue 57). Here the polygons are put in
//! order along a space-filling curve and unioned in groups of [`LEAF`] neighbours, then the
//! groups' unions two by two, level by level: each sweep meets only the crossings of a few
//! neighbours, and the merged shapes stay the size of what they cover. A few polygons (at
//! most `LEAF`, a tile's streets as real data draws them) are one sweep in their own order,
//! exactly as `unary_union` makes it.

use geo::BooleanOps;
use geo::BoundingRect;
use geo_types::{MultiPolygon, Polygon};

/// Polygons unioned in one sweep.
pub const LEAF: usize = 32;

/// The union of `polys`.
///
/// ```
/// use geo_types::polygon;
/// let a = polygon![(x: 0.0, y: 0.0), (x: 2.0, y: 0.0), (x: 2.0, y: 1.0), (x: 0.0, y: 1.0)];
/// let b = polygon![(x: 1.0, y: 0.0), (x: 3.0, y: 0.0), (x: 3.0, y: 1.0), (x: 1.0, y: 1.0)];
/// let u = edo_city::geom::union::cascaded(&[a, b]);
/// use geo::Area;
/// assert!((u.unsigned_area() - 3.0).abs() < 1e-9);
/// ```
pub fn cascaded<'a>(polys: impl IntoIterator<Item = &'a Polygon<f64>>) -> MultiPolygon<f64> {
    let polys: Vec<&Polygon<f64>> = polys.into_iter().collect();
    if polys.len() <= LEAF {
        return geo::unary_union(polys);
    }
    // Keys relative to the polygons' own box: neighbours on the map are near in the order
    // (ties by their place in `polys`).
    let bounds = bounds(&polys);
    let mut keyed: Vec<(u64, usize)> = polys
        .iter()
        .enumerate()
        .map(|(i, p)| {
            (
                p.bounding_rect().map_or(0, |r| morton(r.center(), bounds)),
                i,
            )
        })
        .collect();
    keyed.sort_unstable();
    let mut level: Vec<MultiPolygon<f64>> = keyed
        .chunks(LEAF)
        .map(|group| geo::unary_union(group.iter().map(|&(_, i)| polys[i])))
        .collect();
    while level.len() > 1 {
        level = level
            .chunks(2)
            .map(|pair| match pair {
                [a, b] => a.union(b),
                [a] => a.clone(),
                _ => unreachable!("chunks of two"),
            })
            .collect();
    }
    level.pop().unwrap_or_else(|| MultiPolygon(Vec::new()))
}

/// The box around every polygon: [xmin, ymin, xmax, ymax].
fn bounds(polys: &[&Polygon<f64>]) -> [f64; 4] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for r in polys.iter().filter_map(|p| p.bounding_rect()) {
        b = [
            b[0].min(r.min().x),
            b[1].min(r.min().y),
            b[2].max(r.max().x),
            b[3].max(r.max().y),
        ];
    }
    b
}

/// The Morton (Z-order) code of `c` on a 2^16 grid over `b`: points near on the map are
/// mostly near in the code.
fn morton(c: geo_types::Coord<f64>, b: [f64; 4]) -> u64 {
    let cell = |v: f64, lo: f64, hi: f64| -> u64 {
        let t = if hi > lo { (v - lo) / (hi - lo) } else { 0.0 };
        (t.clamp(0.0, 1.0) * 65535.0) as u64
    };
    let spread = |mut v: u64| {
        v &= 0xffff;
        v = (v | (v << 8)) & 0x00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333;
        (v | (v << 1)) & 0x5555_5555
    };
    spread(cell(c.x, b[0], b[2])) | (spread(cell(c.y, b[1], b[3])) << 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::Area;
    use geo_types::polygon;

    fn square(x: f64, y: f64, s: f64) -> Polygon<f64> {
        polygon![(x: x, y: y), (x: x + s, y: y), (x: x + s, y: y + s), (x: x, y: y + s)]
    }

    #[test]
    fn many_overlapping_pieces_union_to_what_they_cover() {
        // A strip 0..100 x 0..10 drawn as 5,000 squares of 10 m, each 2 cm after the last.
        let pieces: Vec<Polygon<f64>> = (0..5000)
            .map(|i| square(i as f64 * 0.018, 0.0, 10.0))
            .collect();
        let u = cascaded(&pieces);
        let want = 89.982 + 10.0;
        assert!(
            (u.unsigned_area() - want * 10.0).abs() < 1e-3,
            "{}",
            u.unsigned_area()
        );
        assert_eq!(u.0.len(), 1, "one strip");
        // In any order.
        let mut shuffled = pieces.clone();
        shuffled.reverse();
        shuffled.swap(7, 4000);
        assert!((cascaded(&shuffled).unsigned_area() - want * 10.0).abs() < 1e-3);
    }

    #[test]
    fn few_polygons_are_one_sweep_as_unary_union_makes_it() {
        let few: Vec<Polygon<f64>> = (0..LEAF)
            .map(|i| square(i as f64 * 3.0, 0.0, 4.0))
            .collect();
        assert_eq!(cascaded(&few), geo::unary_union(&few));
        // Disjoint pieces stay apart.
        let apart: Vec<Polygon<f64>> = (0..100)
            .map(|i| square(i as f64 * 10.0, 0.0, 1.0))
            .collect();
        let u = cascaded(&apart);
        assert_eq!(u.0.len(), 100);
        assert!((u.unsigned_area() - 100.0).abs() < 1e-9);
    }
}
