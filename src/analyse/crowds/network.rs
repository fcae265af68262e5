//! The street network the crowds walk on: every street centreline cut where another street
//! crosses it or ends on it, into links between junctions (nodes).
//!
//! Streets in GIS layers seldom share vertices where they meet: the synthetic towns and most
//! hand-drawn maps run each street as one long line across the others, OSM splits some and
//! not others, and a street drawn to meet another often stops a little short or long of it.
//! So the junctions are found, not read: two centrelines that cross are cut at the crossing,
//! a line that ends within [`SNAP`] of another's middle cuts it there (a T junction), and cut
//! points within [`SNAP`] of each other are one node. A zero-length street (or piece) gives
//! no link; a street that touches no other is a network of its own, walked end to end.

use std::collections::HashMap;

use geo::line_intersection::{line_intersection, LineIntersection};
use geo_types::{Coord, Line};
use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use crate::model::Dataset;

/// How near (metres) a street's end must come to another street to meet it, and how near two
/// junction points must be to be one junction.
pub const SNAP: f64 = 1.0;

/// A piece of street between two nodes, straight.
#[derive(Debug, Clone)]
pub struct Link {
    /// The stretch it is part of (`<street>/<n>`, see [`super::stretch_id`]).
    pub stretch: String,
    /// Its ends, the positions of its nodes.
    pub a: Coord<f64>,
    /// The other end.
    pub b: Coord<f64>,
    /// The nodes at `a` and `b`.
    pub ends: [usize; 2],
    /// Its length, metres (> 0).
    pub len: f64,
    /// How far either side of the centreline people walk: half the street's width less
    /// `people.edge_margin` (0 or more).
    pub half: f64,
}

impl Link {
    /// The unit direction from `a` to `b`.
    pub fn dir(&self) -> Coord<f64> {
        (self.b - self.a) / self.len
    }
}

/// A junction (or a street's free end): where links meet.
#[derive(Debug, Clone)]
pub struct Node {
    /// Where it is.
    pub at: Coord<f64>,
    /// The links that start or end here, in link order.
    pub links: Vec<usize>,
}

/// The links and nodes of a dataset's streets.
#[derive(Debug, Clone, Default)]
pub struct Network {
    /// Links, street by street, piece by piece along each.
    pub links: Vec<Link>,
    /// Nodes, in the order first met.
    pub nodes: Vec<Node>,
}

impl Network {
    /// Takes the links whose centreline `blocked` anywhere (every half metre) out of their
    /// junctions: no errand turns into them (a street drawn through a building, as real
    /// layers have, would take every walker that went that way into it). A walker set out
    /// on one still walks it, from where it stands.
    pub fn close_blocked(&mut self, blocked: &(dyn Fn(Coord<f64>) -> bool + Sync)) {
        let open: Vec<bool> = self
            .links
            .par_iter()
            .map(|l| {
                let steps = (l.len / 0.5).ceil().max(1.0) as usize;
                (0..=steps).all(|k| !blocked(l.a + l.dir() * (l.len * k as f64 / steps as f64)))
            })
            .collect();
        for n in &mut self.nodes {
            n.links.retain(|&l| open[l]);
        }
    }
}

/// One straight piece of a centreline before it is cut.
struct Piece {
    stretch: String,
    line: Line<f64>,
    half: f64,
}

/// The network of `data`'s streets; `edge_margin` is kept from each street's edges.
pub fn network(data: &Dataset, edge_margin: f64) -> Network {
    let mut pieces = Vec::new();
    for s in &data.streets {
        for (k, line) in s.line.lines().enumerate() {
            let d = line.end - line.start;
            let len = d.x.hypot(d.y);
            if len > 0.0 && len.is_finite() {
                pieces.push(Piece {
                    stretch: super::stretch_id(&s.id, k),
                    line,
                    half: (s.width / 2.0 - edge_margin).max(0.0),
                });
            }
        }
    }
    let index = RTree::bulk_load(
        pieces
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let (a, b) = (p.line.start, p.line.end);
                let lo = [a.x.min(b.x) - SNAP, a.y.min(b.y) - SNAP];
                let hi = [a.x.max(b.x) + SNAP, a.y.max(b.y) + SNAP];
                GeomWithData::new(Rectangle::from_corners(lo, hi), i)
            })
            .collect(),
    );
    let cuts: Vec<Vec<f64>> = pieces
        .par_iter()
        .enumerate()
        .map(|(i, p)| cuts_of(i, p, &pieces, &index))
        .collect();
    let mut nodes = Nodes::default();
    let mut links = Vec::new();
    for (p, cuts) in pieces.iter().zip(cuts) {
        let d = p.line.end - p.line.start;
        let ends: Vec<usize> = cuts
            .iter()
            .map(|&t| nodes.at(p.line.start + d * t))
            .collect();
        for w in ends.windows(2) {
            let (a, b) = (nodes.list[w[0]].at, nodes.list[w[1]].at);
            let len = (b - a).x.hypot((b - a).y);
            if w[0] == w[1] || len <= 0.0 {
                continue;
            }
            for &n in &[w[0], w[1]] {
                nodes.list[n].links.push(links.len());
            }
            links.push(Link {
                stretch: p.stretch.clone(),
                a,
                b,
                ends: [w[0], w[1]],
                len,
                half: p.half,
            });
        }
    }
    Network {
        links,
        nodes: nodes.list,
    }
}

/// Where piece `i` is cut (fractions of its length, 0 and 1 included, ascending): where
/// another piece crosses or overlaps it, and where another ends within [`SNAP`] of it.
fn cuts_of(
    i: usize,
    p: &Piece,
    pieces: &[Piece],
    index: &RTree<GeomWithData<Rectangle<[f64; 2]>, usize>>,
) -> Vec<f64> {
    let (a, d) = (p.line.start, p.line.end - p.line.start);
    let len2 = d.x * d.x + d.y * d.y;
    let along = |c: Coord<f64>| ((c - a).x * d.x + (c - a).y * d.y) / len2;
    let mut out = vec![0.0, 1.0];
    let env = AABB::from_corners(
        [a.x.min(a.x + d.x), a.y.min(a.y + d.y)],
        [a.x.max(a.x + d.x), a.y.max(a.y + d.y)],
    );
    for o in index.locate_in_envelope_intersecting(&env) {
        let j = o.data;
        if j == i {
            continue;
        }
        let q = &pieces[j].line;
        match line_intersection(p.line, *q) {
            Some(LineIntersection::SinglePoint { intersection, .. }) => {
                out.push(along(intersection))
            }
            Some(LineIntersection::Collinear { intersection }) => {
                out.extend([along(intersection.start), along(intersection.end)])
            }
            None => {}
        }
        // A street that stops short of this one (or runs a little past it) meets it.
        for e in [q.start, q.end] {
            let t = along(e);
            let foot = a + d * t.clamp(0.0, 1.0);
            if (e - foot).x.hypot((e - foot).y) <= SNAP {
                out.push(t);
            }
        }
    }
    out.retain(|t| t.is_finite());
    for t in &mut out {
        *t = t.clamp(0.0, 1.0);
    }
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

/// Nodes found so far, on a grid of [`SNAP`] cells for finding the one near a point.
#[derive(Default)]
struct Nodes {
    list: Vec<Node>,
    grid: HashMap<(i64, i64), Vec<usize>, foldhash::fast::FixedState>,
}

impl Nodes {
    /// The node within [`SNAP`] of `c` (the first made, of several), or a new one there.
    fn at(&mut self, c: Coord<f64>) -> usize {
        let cell = |v: f64| (v / SNAP).floor() as i64;
        let (cx, cy) = (cell(c.x), cell(c.y));
        let mut best: Option<usize> = None;
        for gx in cx - 1..=cx + 1 {
            for gy in cy - 1..=cy + 1 {
                for &n in self.grid.get(&(gx, gy)).into_iter().flatten() {
                    let o = self.list[n].at - c;
                    if o.x.hypot(o.y) <= SNAP && best.is_none_or(|b| n < b) {
                        best = Some(n);
                    }
                }
            }
        }
        best.unwrap_or_else(|| {
            self.list.push(Node {
                at: c,
                links: Vec::new(),
            });
            let n = self.list.len() - 1;
            self.grid.entry((cx, cy)).or_default().push(n);
            n
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Street;
    use geo_types::LineString;

    fn street(id: &str, pts: &[[f64; 2]]) -> Street {
        Street {
            id: id.into(),
            line: LineString::from(pts.to_vec()),
            width: 6.0,
        }
    }

    fn net(streets: Vec<Street>) -> Network {
        let data = Dataset {
            streets,
            ..Dataset::default()
        };
        network(&data, 0.5)
    }

    #[test]
    fn crossing_streets_meet_at_one_node_of_four_links() {
        let n = net(vec![
            street("a", &[[0.0, 50.0], [100.0, 50.0]]),
            street("b", &[[50.0, 0.0], [50.0, 100.0]]),
        ]);
        assert_eq!(n.links.len(), 4);
        let hub = n.nodes.iter().find(|x| x.links.len() == 4).unwrap();
        assert!((hub.at.x - 50.0).abs() < 1e-9 && (hub.at.y - 50.0).abs() < 1e-9);
        assert!(n.links.iter().all(|l| (l.len - 50.0).abs() < 1e-9));
        assert!(n.links.iter().all(|l| l.half == 2.5));
    }

    #[test]
    fn a_street_that_stops_short_of_another_meets_it() {
        let n = net(vec![
            street("a", &[[0.0, 0.0], [100.0, 0.0]]),
            street("b", &[[40.0, 0.8], [40.0, 60.0]]),
        ]);
        // a is cut at 40; b's end snaps onto that node: a T of three links.
        assert_eq!(n.links.len(), 3);
        assert_eq!(n.nodes.iter().filter(|x| x.links.len() == 3).count(), 1);
    }

    #[test]
    fn zero_length_and_isolated_streets() {
        let n = net(vec![
            street("z", &[[5.0, 5.0], [5.0, 5.0]]),
            street("i", &[[200.0, 0.0], [210.0, 0.0]]),
        ]);
        assert_eq!(n.links.len(), 1);
        assert_eq!(n.links[0].stretch, "i/1");
        assert!(n.nodes.iter().all(|x| x.links.len() == 1));
    }

    #[test]
    fn a_street_through_a_building_is_closed_to_errands() {
        let mut n = net(vec![
            street("a", &[[0.0, 50.0], [100.0, 50.0]]),
            street("b", &[[50.0, 0.0], [50.0, 100.0]]),
        ]);
        // A building across b's northern half.
        n.close_blocked(&|c| c.x > 45.0 && c.x < 55.0 && c.y > 70.0 && c.y < 80.0);
        let hub = n.nodes.iter().find(|x| x.links.len() == 3).unwrap();
        assert!(hub.links.iter().all(|&l| n.links[l].stretch != "b/1"
            || n.links[l].a.y < 50.0
            || n.links[l].b.y < 50.0));
    }

    #[test]
    fn many_streets_through_one_point_make_one_junction() {
        let streets: Vec<Street> = (0..6)
            .map(|k| {
                let a = k as f64 * std::f64::consts::PI / 6.0;
                let (s, c) = a.sin_cos();
                street(
                    &k.to_string(),
                    &[[-50.0 * c, -50.0 * s], [50.0 * c, 50.0 * s]],
                )
            })
            .collect();
        let n = net(streets);
        assert_eq!(n.links.len(), 12);
        assert_eq!(n.nodes.iter().map(|x| x.links.len()).max(), Some(12));
    }
}
