//! The skeleton both tree growers return and the tree mesher takes: nodes joined to their
//! parents (a forest of rooted trees, parents before children), each with a radius, plus
//! leaf polygons. The L-system turtle and space colonization grow different shapes into the
//! same form, so one mesher makes every level of detail of either.

use super::v3::{self, V3};

/// One node: a point of a branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Where it is, metres; the tree stands at the origin, z up.
    pub at: V3,
    /// The node it grew from; `None` for a root (the base, or where the turtle moved
    /// without drawing). Always a smaller index than this node's.
    pub parent: Option<u32>,
    /// The branch's radius here, metres.
    pub radius: f64,
    /// The material index (`'` of the turtle): 0 bark; others as the species says.
    pub material: u8,
}

/// A leaf polygon drawn by the turtle (`{ . . . }`), corners in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    /// Its corners, metres.
    pub corners: Vec<V3>,
    /// The material index it was drawn with.
    pub material: u8,
}

/// A grown plant.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Skeleton {
    /// The nodes, parents before children.
    pub nodes: Vec<Node>,
    /// Leaf polygons.
    pub polygons: Vec<Polygon>,
    /// Marked points (`@`), e.g. the seeds of a phyllotaxis disc.
    pub dots: Vec<V3>,
}

impl Skeleton {
    /// How many children each node has.
    pub fn child_counts(&self) -> Vec<u32> {
        let mut n = vec![0u32; self.nodes.len()];
        for node in &self.nodes {
            if let Some(p) = node.parent {
                n[p as usize] += 1;
            }
        }
        n
    }

    /// The nodes that have a parent and no child: the tips of the branches.
    pub fn tips(&self) -> Vec<usize> {
        let kids = self.child_counts();
        (0..self.nodes.len())
            .filter(|&i| self.nodes[i].parent.is_some() && kids[i] == 0)
            .collect()
    }

    /// The number of edges (nodes with a parent).
    pub fn edges(&self) -> usize {
        self.nodes.iter().filter(|n| n.parent.is_some()).count()
    }

    /// The box around every node, polygon corner and dot: (min, max); zeros when empty.
    pub fn bounds(&self) -> (V3, V3) {
        let pts = self
            .nodes
            .iter()
            .map(|n| n.at)
            .chain(self.polygons.iter().flat_map(|p| p.corners.iter().copied()))
            .chain(self.dots.iter().copied());
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut any = false;
        for p in pts {
            any = true;
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if any {
            (lo, hi)
        } else {
            ([0.0; 3], [0.0; 3])
        }
    }

    /// The farthest point from the trunk's axis (the z axis) and the top, each plus `margin`
    /// (the leaves' reach): the extent a billboard of the tree is framed by.
    pub fn extent(&self, margin: f64) -> (f64, f64) {
        let (_, hi) = self.bounds();
        let radial = self
            .nodes
            .iter()
            .map(|n| n.at)
            .chain(self.polygons.iter().flat_map(|p| p.corners.iter().copied()))
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0, f64::max);
        (radial + margin, hi[2].max(0.0) + margin * 0.5)
    }

    /// Scales every point and radius by `s` about the origin.
    pub fn scale(&mut self, s: f64) {
        for n in &mut self.nodes {
            n.at = v3::scale(n.at, s);
            n.radius *= s;
        }
        for p in &mut self.polygons {
            for c in &mut p.corners {
                *c = v3::scale(*c, s);
            }
        }
        for d in &mut self.dots {
            *d = v3::scale(*d, s);
        }
    }

    /// Roots as a visitor sees them: the nodes below ground within `reach` of the trunk's
    /// axis are raised to lie along the surface (sunk by a third of their radius), the
    /// others dropped with everything that grows from them.
    pub fn expose_roots(&mut self, reach: f64) {
        let mut map: Vec<Option<u32>> = vec![None; self.nodes.len()];
        let mut kept = Vec::with_capacity(self.nodes.len());
        for (i, n) in self.nodes.iter().enumerate() {
            let parent_kept = n.parent.is_none_or(|p| map[p as usize].is_some());
            let below = n.at[2] < 0.0;
            if !parent_kept || (below && n.at[0].hypot(n.at[1]) > reach) {
                continue;
            }
            let mut node = *n;
            node.parent = n.parent.and_then(|p| map[p as usize]);
            if below {
                node.at[2] = -node.radius / 3.0;
            }
            map[i] = Some(kept.len() as u32);
            kept.push(node);
        }
        self.nodes = kept;
    }

    /// Narrows the plant horizontally by `s` about its axis (x and y only).
    pub fn squeeze(&mut self, s: f64) {
        let xy = |p: &mut V3| {
            p[0] *= s;
            p[1] *= s;
        };
        self.nodes.iter_mut().for_each(|n| xy(&mut n.at));
        self.polygons
            .iter_mut()
            .for_each(|p| p.corners.iter_mut().for_each(xy));
        self.dots.iter_mut().for_each(xy);
    }

    /// Radii by the pipe model (da Vinci's rule, Shinozaki et al.): at every node
    /// `r^e = sum of r_child^e`, tips getting `tip`. `e` is 2 for area-preserving pipes, up to
    /// 3 for stiffer wood.
    pub fn pipe_radii(&mut self, tip: f64, e: f64) {
        let kids = self.child_counts();
        let mut sum = vec![0.0f64; self.nodes.len()];
        // Children come after their parents, so one backward pass sees every child first.
        for i in (0..self.nodes.len()).rev() {
            let r = if kids[i] == 0 {
                tip
            } else {
                sum[i].powf(1.0 / e)
            };
            self.nodes[i].radius = r;
            if let Some(p) = self.nodes[i].parent {
                sum[p as usize] += r.powf(e);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(at: V3, parent: Option<u32>) -> Node {
        Node {
            at,
            parent,
            radius: 0.0,
            material: 0,
        }
    }

    #[test]
    fn pipe_radii_keep_the_sum_of_powers_at_a_fork() {
        let mut s = Skeleton {
            nodes: vec![
                node([0.0; 3], None),
                node([0.0, 0.0, 1.0], Some(0)),
                node([1.0, 0.0, 2.0], Some(1)),
                node([-1.0, 0.0, 2.0], Some(1)),
                node([-1.0, 0.0, 3.0], Some(3)),
            ],
            ..Skeleton::default()
        };
        s.pipe_radii(0.1, 2.5);
        let r = |i: usize| s.nodes[i].radius;
        assert!((r(1).powf(2.5) - r(2).powf(2.5) - r(3).powf(2.5)).abs() < 1e-12);
        assert!((r(3) - r(4)).abs() < 1e-12);
        assert_eq!(s.tips(), vec![2, 4]);
        assert_eq!(s.edges(), 4);
    }
}
