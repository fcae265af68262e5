//! Frontage (maguchi 間口) of a lot: the paper's Fig.4.
//!
//! Take the two lot vertices nearest the street (1 and 2). If the angle between them seen from
//! the lot centroid is at most 120 degrees and they are at least 1.2 m apart, 1-2 is the
//! frontage. Otherwise try the next-nearest vertex 3 with 1, then the lot's edges in order of
//! their distance to the street, until one passes. A lot where nothing passes gets the edge
//! nearest the street, flagged as a fallback and counted in the report.

use geo_types::Coord;

use crate::model::Frontage;

/// The rule's two constants (see `[frontage]` in the parameter file).
#[derive(Debug, Clone, Copy)]
pub struct FrontageRule {
    /// Largest angle at the lot's centroid between the two frontage vertices, degrees (Fig.4).
    pub max_angle_deg: f64,
    /// Shortest frontage, metres: shorter candidates are passed over.
    pub min_length: f64,
}

/// Finds the frontage of a lot.
///
/// `ring` is the exterior ring, counter-clockwise, without the closing repeat; `dist` holds
/// each vertex's distance to the street edge.
///
/// ```
/// use edo_city::analyse::frontage::{find_frontage, FrontageRule};
/// use geo_types::Coord;
/// // A 4 m x 20 m strip whose south edge (y = 0) faces the street.
/// let ring = [Coord { x: 0., y: 0. }, Coord { x: 4., y: 0. }, Coord { x: 4., y: 20. }, Coord { x: 0., y: 20. }];
/// let dist = [0.0, 0.0, 20.0, 20.0];
/// let rule = FrontageRule { max_angle_deg: 120.0, min_length: 1.2 };
/// let f = find_frontage(&ring, &dist, Coord { x: 2., y: 10. }, rule);
/// assert_eq!((f.a, f.b), (ring[0], ring[1]));
/// assert!(!f.fallback);
/// ```
pub fn find_frontage(
    ring: &[Coord<f64>],
    dist: &[f64],
    centroid: Coord<f64>,
    rule: FrontageRule,
) -> Frontage {
    let n = ring.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| dist[i].total_cmp(&dist[j]).then(i.cmp(&j)));

    let mut candidates: Vec<(usize, usize)> = Vec::with_capacity(n + 2);
    if n >= 2 {
        candidates.push((order[0], order[1]));
    }
    if n >= 3 {
        candidates.push((order[0], order[2]));
    }
    let mut edges: Vec<(usize, usize)> = (0..n).map(|i| (i, (i + 1) % n)).collect();
    edges.sort_by(|&(a, b), &(c, d)| {
        (dist[a] + dist[b])
            .total_cmp(&(dist[c] + dist[d]))
            .then(a.cmp(&c))
    });
    candidates.extend(edges.iter().copied());

    let max_angle = rule.max_angle_deg.to_radians();
    for &(i, j) in &candidates {
        let (p, q) = (ring[i], ring[j]);
        if length(p, q) >= rule.min_length && angle_at(centroid, p, q) <= max_angle + 1e-12 {
            return oriented(p, q, centroid, false);
        }
    }
    let (i, j) = edges[0];
    oriented(ring[i], ring[j], centroid, true)
}

fn length(p: Coord<f64>, q: Coord<f64>) -> f64 {
    (q.x - p.x).hypot(q.y - p.y)
}

/// Angle p-c-q in radians, in [0, pi].
fn angle_at(c: Coord<f64>, p: Coord<f64>, q: Coord<f64>) -> f64 {
    let (ax, ay) = (p.x - c.x, p.y - c.y);
    let (bx, by) = (q.x - c.x, q.y - c.y);
    let cross = ax * by - ay * bx;
    let dot = ax * bx + ay * by;
    cross.abs().atan2(dot)
}

/// Orders the pair so that the lot (its centroid) lies on the left of a -> b.
fn oriented(p: Coord<f64>, q: Coord<f64>, c: Coord<f64>, fallback: bool) -> Frontage {
    let cross = (q.x - p.x) * (c.y - p.y) - (q.y - p.y) * (c.x - p.x);
    let (a, b) = if cross >= 0.0 { (p, q) } else { (q, p) };
    Frontage { a, b, fallback }
}

/// Extent of the lot behind the frontage line, metres (the lot's depth along v).
pub fn lot_depth(ring: &[Coord<f64>], f: &Frontage) -> f64 {
    let v = f.v_axis();
    ring.iter()
        .map(|p| (p.x - f.a.x) * v.x + (p.y - f.a.y) * v.y)
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    const RULE: FrontageRule = FrontageRule {
        max_angle_deg: 120.0,
        min_length: 1.2,
    };

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn nearest_pair_is_oriented_with_the_lot_on_the_left() {
        // Street to the north (y = 20); ring counter-clockwise.
        let ring = [c(0., 0.), c(4., 0.), c(4., 20.), c(0., 20.)];
        let dist = [20., 20., 0., 0.];
        let f = find_frontage(&ring, &dist, c(2., 10.), RULE);
        assert_eq!((f.a, f.b), (c(4., 20.), c(0., 20.)));
        assert!(
            f.v_axis().y < 0.0,
            "v points into the lot, away from the street"
        );
        assert!((lot_depth(&ring, &f) - 20.0).abs() < 1e-9);
    }

    #[test]
    fn diagonal_nearest_pair_fails_the_angle_test() {
        let ring = [c(0., 0.), c(6., 0.), c(6., 6.), c(0., 6.)];
        let dist = [0.0, 0.5, 0.1, 3.0];
        // Nearest: 0 then 2 (diagonal, 180 degrees): fails; then 0 with 1: passes.
        let f = find_frontage(&ring, &dist, c(3., 3.), RULE);
        assert_eq!((f.a, f.b), (c(0., 0.), c(6., 0.)));
        assert!(!f.fallback);
    }

    #[test]
    fn a_short_nearest_pair_fails_the_length_test() {
        // A notch: vertices 0 and 1 are 0.5 m apart.
        let ring = [c(0., 0.), c(0.5, 0.), c(5., 0.2), c(5., 20.), c(0., 20.)];
        let dist = [0.0, 0.0, 0.2, 20., 20.];
        let f = find_frontage(&ring, &dist, c(2.5, 10.), RULE);
        assert!(f.width() >= 1.2);
        assert!(!f.fallback);
    }

    #[test]
    fn nothing_passes_gives_the_nearest_edge_as_fallback() {
        let ring = [c(0., 0.), c(1., 0.), c(1., 1.), c(0., 1.)];
        let dist = [0.0, 0.0, 1.0, 1.0];
        let f = find_frontage(&ring, &dist, c(0.5, 0.5), RULE);
        assert!(f.fallback);
        assert_eq!((f.a, f.b), (c(0., 0.), c(1., 0.)));
    }
}
