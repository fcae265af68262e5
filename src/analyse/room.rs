//! How deep a wall may reach into its lot.
//!
//! A wall stands inside its lot on the band behind one edge, its ends mitred: at depth `t`
//! its inner corners are `t * start_mitre` and `width - t * end_mitre` along the edge. A
//! sliver or a spike of a lot can be narrower than the wall is thick; the wall's template
//! then gets the room there is (its `lot_depth` input) and is built no thicker, instead of
//! reaching through the lot into the street or the neighbour.

use geo_types::{Coord, Polygon};
use rstar::primitives::{GeomWithData, Line};
use rstar::{RTree, AABB};

/// The most room a wall is ever given, metres: no wall is this thick.
pub const MAX_ROOM: f64 = 5.0;

/// Below this many edges a lot's edges are scanned, above it looked up in an R-tree.
const SCAN_EDGES: usize = 64;

/// The edges of one lot (every ring), for [`LotEdges::room`].
pub struct LotEdges {
    /// `(a, b, ring, edge)`: the ring's index (0 = exterior) and the edge's index in it.
    edges: Vec<([f64; 2], [f64; 2], usize, usize)>,
    tree: Option<RTree<GeomWithData<Line<[f64; 2]>, usize>>>,
}

impl LotEdges {
    /// The edges of `lot`'s outline (holes included), indexed for room queries.
    pub fn new(lot: &Polygon<f64>) -> LotEdges {
        let mut edges = Vec::new();
        for (r, ring) in std::iter::once(lot.exterior())
            .chain(lot.interiors())
            .enumerate()
        {
            for (i, l) in ring.lines().enumerate() {
                edges.push(([l.start.x, l.start.y], [l.end.x, l.end.y], r, i));
            }
        }
        let tree = (edges.len() > SCAN_EDGES).then(|| {
            RTree::bulk_load(
                edges
                    .iter()
                    .enumerate()
                    .map(|(k, e)| GeomWithData::new(Line::new(e.0, e.1), k))
                    .collect(),
            )
        });
        LotEdges { edges, tree }
    }

    /// The depth a wall on exterior edge `edge`, from `a` to `b` (the lot on its left), with
    /// the given end mitres, can have and stay inside the lot; at most [`MAX_ROOM`].
    pub fn room(&self, edge: usize, a: Coord<f64>, b: Coord<f64>, mitres: [f64; 2]) -> f64 {
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let len = dx.hypot(dy);
        if len.is_nan() || len <= 1e-9 {
            return 0.0;
        }
        let u = [dx / len, dy / len];
        let v = [-u[1], u[0]];
        let local = |p: [f64; 2]| {
            let (px, py) = (p[0] - a.x, p[1] - a.y);
            [px * u[0] + py * u[1], px * v[0] + py * v[1]]
        };
        // The band is bounded by v >= 0 and its two mitre lines; where they meet (two sharp
        // corners on a short edge) it ends.
        let [c0, c1] = mitres;
        let deepest = if c0 + c1 > 0.0 {
            MAX_ROOM.min(len / (c0 + c1))
        } else {
            MAX_ROOM
        };
        let corner = |t: f64, s: f64| Coord {
            x: a.x + s * u[0] + t * v[0],
            y: a.y + s * u[1] + t * v[1],
        };
        let mut room = deepest;
        let mut test = |k: usize| {
            let (p, q, ring, i) = self.edges[k];
            if ring == 0 && i == edge {
                return;
            }
            if let Some(t) = entry_depth(local(p), local(q), len, c0, c1, room) {
                room = room.min(t);
            }
        };
        match &self.tree {
            None => (0..self.edges.len()).for_each(&mut test),
            Some(tree) => {
                let pts = [
                    corner(0.0, 0.0),
                    corner(0.0, len),
                    corner(deepest, deepest * c0),
                    corner(deepest, len - deepest * c1),
                ];
                let lo = pts
                    .iter()
                    .fold([f64::MAX; 2], |m, p| [m[0].min(p.x), m[1].min(p.y)]);
                let hi = pts
                    .iter()
                    .fold([f64::MIN; 2], |m, p| [m[0].max(p.x), m[1].max(p.y)]);
                for line in tree.locate_in_envelope_intersecting(&AABB::from_corners(lo, hi)) {
                    test(line.data);
                }
            }
        }
        room
    }
}

/// Where the segment p-q (in the edge's frame: u along it, v into the lot) first enters the
/// band `v in [EPS, deepest]`, `u >= c0 v`, `u <= len - c1 v` (strictly, by EPS): its least
/// depth there, if it enters it. A neighbouring edge touches the band only at its corner or
/// along a side (a gate's square end on a right-angled corner), so it does not count.
fn entry_depth(p: [f64; 2], q: [f64; 2], len: f64, c0: f64, c1: f64, deepest: f64) -> Option<f64> {
    const EPS: f64 = 1e-6;
    // Each bound as f(s) = f0 + s (f1 - f0) >= 0 along the segment, s in [0, 1].
    let f = |w: [f64; 2]| {
        [
            w[1] - EPS,
            deepest - w[1],
            w[0] - c0 * w[1] - EPS,
            len - c1 * w[1] - w[0] - EPS,
        ]
    };
    let (fp, fq) = (f(p), f(q));
    let (mut s0, mut s1) = (0.0f64, 1.0f64);
    for k in 0..4 {
        let (f0, d) = (fp[k], fq[k] - fp[k]);
        if d.abs() < 1e-15 {
            if f0 < 0.0 {
                return None;
            }
        } else {
            let s = -f0 / d;
            if d > 0.0 {
                s0 = s0.max(s);
            } else {
                s1 = s1.min(s);
            }
        }
    }
    (s0 <= s1).then(|| {
        let at = |s: f64| p[1] + s * (q[1] - p[1]);
        at(s0).min(at(s1)).max(0.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo_types::LineString;

    fn poly(pts: &[(f64, f64)], holes: Vec<Vec<(f64, f64)>>) -> Polygon<f64> {
        Polygon::new(
            LineString::from(pts.to_vec()),
            holes.into_iter().map(LineString::from).collect(),
        )
    }

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn a_wide_lot_gives_all_the_room_and_a_narrow_one_its_width() {
        let wide = LotEdges::new(&poly(&[(0., 0.), (40., 0.), (40., 30.), (0., 30.)], vec![]));
        assert_eq!(wide.room(0, c(0., 0.), c(40., 0.), [1.0, 1.0]), MAX_ROOM);
        // A strip 0.4 m deep: a wall along its long side has 0.4 m.
        let strip = LotEdges::new(&poly(&[(0., 0.), (40., 0.), (40., 0.4), (0., 0.4)], vec![]));
        let r = strip.room(0, c(0., 0.), c(40., 0.), [1.0, 1.0]);
        assert!((r - 0.4).abs() < 1e-9, "{r}");
        // Along its short side the mitres meet at half the width.
        let r = strip.room(1, c(40., 0.), c(40., 0.4), [1.0, 1.0]);
        assert!((r - 0.2).abs() < 1e-9, "{r}");
    }

    #[test]
    fn a_courtyard_and_a_spike_across_the_band_limit_it() {
        let lot = poly(
            &[(0., 0.), (40., 0.), (40., 30.), (0., 30.)],
            vec![vec![(10., 1.), (10., 5.), (20., 5.), (20., 1.)]],
        );
        let r = LotEdges::new(&lot).room(0, c(0., 0.), c(40., 0.), [1.0, 1.0]);
        assert!((r - 1.0).abs() < 1e-9, "{r}");
        // A notch cut into the lot from its right side, 0.3 m above the bottom edge.
        let notched = poly(
            &[
                (0., 0.),
                (40., 0.),
                (40., 0.3),
                (30., 0.3),
                (30., 0.5),
                (40., 0.5),
                (40., 30.),
                (0., 30.),
            ],
            vec![],
        );
        let r = LotEdges::new(&notched).room(0, c(0., 0.), c(40., 0.), [1.0, 1.0]);
        assert!((r - 0.3).abs() < 1e-9, "{r}");
    }

    #[test]
    fn a_reflex_corner_does_not_limit_the_band() {
        // An L: the bottom edge's right end meets a reflex corner's wall.
        let l = poly(
            &[
                (0., 0.),
                (10., 0.),
                (10., 10.),
                (20., 10.),
                (20., 20.),
                (0., 20.),
            ],
            vec![],
        );
        let edges = LotEdges::new(&l);
        let reflex = crate::analyse::fences::mitre(c(10., 0.), c(10., 10.), c(20., 10.));
        assert!(reflex < 0.0);
        let r = edges.room(2, c(10., 10.), c(20., 10.), [reflex, 1.0]);
        assert_eq!(r, MAX_ROOM);
    }

    #[test]
    fn many_edges_are_looked_up_and_give_the_same_room() {
        // A zigzag back edge of 200 vertices 1 m behind the front.
        let mut pts = vec![(0., 0.), (10., 0.)];
        for i in 0..=200 {
            let x = 10.0 - 10.0 * i as f64 / 200.0;
            pts.push((x, 1.0 + 0.01 * (i % 2) as f64));
        }
        let lot = poly(&pts, vec![]);
        let edges = LotEdges::new(&lot);
        assert!(edges.tree.is_some());
        let r = edges.room(0, c(0., 0.), c(10., 0.), [1.0, 1.0]);
        assert!((r - 1.0).abs() < 1e-9, "{r}");
    }
}
