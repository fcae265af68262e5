//! Space colonization (Runions, Lane & Prusinkiewicz 2007) extended with vector-field control
//! as in seed 001 (Tanaka, Ito, Kikuchi): a directed tree grown toward attraction points.
//!
//! Each iteration: every live attraction point finds its nearest growing node; within `kill`
//! (d_k) the point dies, within `influence` (d_i) it pulls that node. Each pulled node grows
//! one child at distance `step` (D) along n = sum of unit vectors to its points (eq. 6-7); a
//! node whose sum is ~0 keeps its own direction. With a vector field of weight w the direction
//! is normalize(n/|n| + w f), f the mean of the field's vectors at the node's points, each
//! turned about its point's normal by `twist` (eq. 13-15, see [`field`]). The seed's eq. 16
//! adds the field vector to the position without normalising, so edges would drift from D;
//! we normalise, so every edge is D long. w = 0 is plain colonization, to the byte.
//!
//! A child is never made twice at one place, and the known oscillation (a node pulled back
//! and forth between two points, its child landing on its own parent) is detected and not
//! grown. Termination has a reason: [`Stop`]. Nearest-node queries use a uniform grid of
//! cell `influence`, so an iteration costs O(points).
//!
//! Groups (trunk, branches, roots) grow one after another, each from its own points and from
//! a starting range of the nodes before it: "nodes divided into two or more groups, connected
//! from a starting node within a range" (section 3.3 and 3.7.1 of the seed).

pub mod envelope;
pub mod field;
pub mod hull;

use std::collections::HashMap;

use rand_pcg::Pcg64;

pub use envelope::Envelope;
pub use field::Field;
pub use hull::MAX_HULL_TRIANGLES;

use super::skeleton::{Node, Skeleton};
use super::v3::{self, V3};

/// The most attraction points one group may sample.
pub const MAX_POINTS: usize = 1_000_000;
/// The most iterations one group may run.
pub const MAX_ITER: usize = 100_000;

/// The growth parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// D: the length of every new edge.
    pub step: f64,
    /// d_i: how far a point reaches for its nearest node (default 10 D).
    pub influence: f64,
    /// d_k: a point this near a node dies (default 2 D).
    pub kill: f64,
    /// The most iterations.
    pub max_iter: usize,
    /// The vector field.
    pub field: Field,
    /// w: the field's weight against the points' pull; 0 for plain colonization.
    pub weight: f64,
    /// theta: the turn of each point's field vector about its normal, radians.
    pub twist: f64,
}

impl Params {
    /// D with the seed's defaults d_i = 10 D, d_k = 2 D, no field.
    pub fn with_step(step: f64) -> Params {
        Params {
            step,
            influence: 10.0 * step,
            kill: 2.0 * step,
            max_iter: 1000,
            field: Field::None,
            weight: 0.0,
            twist: 0.0,
        }
    }

    /// What is wrong with the numbers, if anything.
    pub fn problem(&self) -> Option<String> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(self.step) && ok(self.influence) && ok(self.kill)) {
            return Some("step, influence and kill must be positive numbers".into());
        }
        if self.kill >= self.influence {
            return Some(format!(
                "kill ({}) must be less than influence ({})",
                self.kill, self.influence
            ));
        }
        if self.influence / self.step > 1e4 {
            return Some("influence must be at most 10,000 steps".into());
        }
        if self.max_iter > MAX_ITER {
            return Some(format!("max_iter must be at most {MAX_ITER}"));
        }
        if !(self.weight.is_finite() && self.twist.is_finite()) {
            return Some("weight and twist must be numbers".into());
        }
        None
    }
}

/// Why a group stopped growing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// Every point died.
    AllKilled,
    /// Points are left, but none is within `influence` of a node.
    NoneInRange,
    /// Points pull nodes, but no new node could be made (duplicates, oscillation).
    Stalled,
    /// `max_iter` iterations ran.
    MaxIter,
}

impl Stop {
    /// The reason as the report spells it.
    pub fn as_str(self) -> &'static str {
        match self {
            Stop::AllKilled => "all_killed",
            Stop::NoneInRange => "none_in_range",
            Stop::Stalled => "stalled",
            Stop::MaxIter => "max_iter",
        }
    }
}

/// What one group did.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupReport {
    /// The group's name.
    pub name: String,
    /// Why it stopped.
    pub stop: Stop,
    /// Iterations run (the approach to the points included).
    pub iterations: usize,
    /// Nodes of the group: its starting range and the nodes it grew.
    pub nodes: usize,
    /// Edges within the group (nodes - 1: the group is a tree).
    pub edges: usize,
    /// Points alive at the end.
    pub points_left: usize,
    /// Growths refused as the two-point oscillation.
    pub oscillations: usize,
    /// The group's node indices in the skeleton: the starting range, then the grown.
    pub members: Vec<u32>,
}

/// Where a group starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Attach {
    /// At the origin (the first group) or at the base node of the tree (roots).
    Base,
    /// On the main stem of the first group, between these shares of its height.
    Stem(f64, f64),
}

/// One group of a tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// Its name (`trunk`, `branches`, `roots`).
    pub name: String,
    /// Where its points are.
    pub envelope: Envelope,
    /// How many points.
    pub points: usize,
    /// Where it starts.
    pub attach: Attach,
    /// Its own field weight, else the tree's.
    pub weight: Option<f64>,
}

/// Grows the groups in order into one skeleton (radii zero; see
/// [`Skeleton::pipe_radii`]).
pub fn grow(
    params: &Params,
    groups: &[Group],
    rng: &mut Pcg64,
) -> Result<(Skeleton, Vec<GroupReport>), String> {
    if let Some(p) = params.problem() {
        return Err(p);
    }
    let mut g = Graph::default();
    g.push([0.0; 3], None);
    let mut reports: Vec<GroupReport> = Vec::new();
    for group in groups {
        if group.points > MAX_POINTS {
            return Err(format!(
                "group `{}`: at most {MAX_POINTS} points, got {}",
                group.name, group.points
            ));
        }
        let points = group
            .envelope
            .sample(group.points, rng)
            .map_err(|e| format!("group `{}`: {e}", group.name))?;
        let seeds = match (group.attach, reports.first()) {
            (Attach::Base, _) | (_, None) => vec![0],
            (Attach::Stem(lo, hi), Some(first)) => g.stem(&first.members, lo, hi),
        };
        let p = Params {
            weight: group.weight.unwrap_or(params.weight),
            ..*params
        };
        let mut r = colonize(&mut g, &seeds, &points, &group.envelope, &p);
        r.name = group.name.clone();
        reports.push(r);
    }
    let sk = Skeleton {
        nodes: g
            .at
            .iter()
            .zip(&g.parent)
            .map(|(&at, &parent)| Node {
                at,
                parent,
                radius: 0.0,
                material: 0,
            })
            .collect(),
        ..Skeleton::default()
    };
    Ok((sk, reports))
}

/// The growing graph: positions, parents and children.
#[derive(Debug, Default)]
struct Graph {
    at: Vec<V3>,
    parent: Vec<Option<u32>>,
    children: Vec<Vec<u32>>,
}

impl Graph {
    fn push(&mut self, at: V3, parent: Option<u32>) -> u32 {
        let i = self.at.len() as u32;
        self.at.push(at);
        self.parent.push(parent);
        self.children.push(Vec::new());
        if let Some(p) = parent {
            self.children[p as usize].push(i);
        }
        i
    }

    /// The direction a node grew in (its own heading), +z for a root.
    fn heading(&self, i: u32) -> V3 {
        self.parent[i as usize]
            .and_then(|p| v3::unit(v3::sub(self.at[i as usize], self.at[p as usize])))
            .unwrap_or([0.0, 0.0, 1.0])
    }

    /// The main stem of a group (the path from its highest member down to its first), cut to
    /// the contiguous part between `lo` and `hi` of its height.
    fn stem(&self, members: &[u32], lo: f64, hi: f64) -> Vec<u32> {
        let Some(&first) = members.first() else {
            return vec![0];
        };
        let top = members
            .iter()
            .copied()
            .max_by(|&a, &b| {
                self.at[a as usize][2]
                    .total_cmp(&self.at[b as usize][2])
                    .then(b.cmp(&a))
            })
            .unwrap_or(first);
        let mut chain = vec![top];
        let mut i = top;
        while i != first {
            match self.parent[i as usize] {
                Some(p) => {
                    chain.push(p);
                    i = p;
                }
                None => break,
            }
        }
        chain.reverse();
        let base = self.at[first as usize][2];
        let height = self.at[top as usize][2] - base;
        let z = |i: u32| (self.at[i as usize][2] - base) / height.max(1e-12);
        let start = chain
            .iter()
            .position(|&i| z(i) >= lo)
            .unwrap_or(chain.len() - 1);
        let end = chain
            .iter()
            .rposition(|&i| z(i) <= hi)
            .unwrap_or(start)
            .max(start);
        chain[start..=end].to_vec()
    }
}

/// A uniform grid of points (attraction points or nodes), cell size `influence`.
struct Grid {
    cell: f64,
    cells: HashMap<[i64; 3], Vec<u32>, foldhash::fast::FixedState>,
}

impl Grid {
    fn new(cell: f64) -> Grid {
        Grid {
            cell,
            cells: HashMap::default(),
        }
    }

    fn key(&self, p: V3) -> [i64; 3] {
        [
            (p[0] / self.cell).floor() as i64,
            (p[1] / self.cell).floor() as i64,
            (p[2] / self.cell).floor() as i64,
        ]
    }

    fn insert(&mut self, p: V3, i: u32) {
        let k = self.key(p);
        self.cells.entry(k).or_default().push(i);
    }
}

/// Each attraction point's nearest growing node within `influence`, kept up to date as
/// nodes are added (only the points around a new node are looked at).
struct Nearest<'a> {
    points: &'a [V3],
    grid: Grid,
    best: Vec<Option<(u32, f64)>>,
    alive: Vec<bool>,
}

impl<'a> Nearest<'a> {
    fn new(points: &'a [V3], influence: f64) -> Nearest<'a> {
        let mut grid = Grid::new(influence);
        for (i, &p) in points.iter().enumerate() {
            grid.insert(p, i as u32);
        }
        Nearest {
            points,
            grid,
            best: vec![None; points.len()],
            alive: vec![true; points.len()],
        }
    }

    /// Node `n` at `at` now grows: the points within `influence` that it is nearer to take
    /// it (ties keep the lower index, which is the older node).
    fn add(&mut self, n: u32, at: V3) {
        let k = self.grid.key(at);
        let cell = self.grid.cell;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = self.grid.cells.get_mut(&[k[0] + dx, k[1] + dy, k[2] + dz])
                    else {
                        continue;
                    };
                    // Dead points leave the grid as they are met, so the crown's filled
                    // parts cost nothing.
                    list.retain(|&a| self.alive[a as usize]);
                    for &a in list.iter() {
                        let a = a as usize;
                        let d = v3::dist(self.points[a], at);
                        if d < cell && self.best[a].is_none_or(|(_, bd)| d < bd) {
                            self.best[a] = Some((n, d));
                        }
                    }
                }
            }
        }
    }

    /// Points within `kill` of their nearest node die.
    fn kill(&mut self, kill: f64) {
        for a in 0..self.points.len() {
            if self.alive[a] && self.best[a].is_some_and(|(_, d)| d < kill) {
                self.alive[a] = false;
            }
        }
    }

    fn live(&self) -> usize {
        self.alive.iter().filter(|&&a| a).count()
    }

    fn any_in_range(&self) -> bool {
        (0..self.points.len()).any(|a| self.alive[a] && self.best[a].is_some())
    }
}

/// One group's growth from `seeds` toward `points`.
fn colonize(
    g: &mut Graph,
    seeds: &[u32],
    points: &[V3],
    env: &Envelope,
    p: &Params,
) -> GroupReport {
    let mut near = Nearest::new(points, p.influence);
    for &s in seeds {
        near.add(s, g.at[s as usize]);
    }
    let first_new = g.at.len();
    let normals: Vec<V3> = points.iter().map(|&q| env.normal(q)).collect();
    let mut iterations = 0;
    let mut oscillations = 0;
    // The approach: the first seed walks toward the points' centre until one is in range.
    if !points.is_empty() && !near.any_in_range() {
        let centre = v3::scale(
            points.iter().fold([0.0; 3], |s, &q| v3::add(s, q)),
            1.0 / points.len() as f64,
        );
        let mut tip = seeds[0];
        while iterations < p.max_iter && !near.any_in_range() {
            let Some(d) = v3::unit(v3::sub(centre, g.at[tip as usize])) else {
                break;
            };
            let at = v3::add(g.at[tip as usize], v3::scale(d, p.step));
            tip = g.push(at, Some(tip));
            near.add(tip, at);
            iterations += 1;
        }
    }
    let stop = loop {
        near.kill(p.kill);
        // Each pulled node and its points, in node order.
        let mut pulls: Vec<(u32, usize)> = (0..points.len())
            .filter(|&a| near.alive[a])
            .filter_map(|a| near.best[a].map(|(n, _)| (n, a)))
            .collect();
        if near.live() == 0 {
            break Stop::AllKilled;
        }
        if iterations >= p.max_iter {
            break Stop::MaxIter;
        }
        if pulls.is_empty() {
            break Stop::NoneInRange;
        }
        iterations += 1;
        pulls.sort_unstable();
        let mut grew = 0;
        let mut k = 0;
        while k < pulls.len() {
            let n = pulls[k].0;
            let end = k + pulls[k..].iter().take_while(|q| q.0 == n).count();
            let mine = &pulls[k..end];
            k = end;
            let here = g.at[n as usize];
            let sum = mine.iter().fold([0.0; 3], |s, &(_, a)| {
                v3::add(s, v3::unit(v3::sub(points[a], here)).unwrap_or([0.0; 3]))
            });
            let mut dir = v3::unit(sum).unwrap_or_else(|| g.heading(n));
            if p.weight != 0.0 {
                let f = mine.iter().fold([0.0; 3], |s, &(_, a)| {
                    let v = field::rotate_about(p.field.at(points[a]), normals[a], p.twist);
                    v3::add(s, v3::unit(v).unwrap_or([0.0; 3]))
                });
                if let Some(f) = v3::unit(f) {
                    dir = v3::unit(v3::add(dir, v3::scale(f, p.weight))).unwrap_or(dir);
                }
            }
            let at = v3::add(here, v3::scale(dir, p.step));
            let twice = g.children[n as usize]
                .iter()
                .any(|&c| v3::dist(g.at[c as usize], at) < 1e-6 * p.step);
            if twice {
                continue;
            }
            let back =
                g.parent[n as usize].is_some_and(|q| v3::dist(g.at[q as usize], at) < 0.1 * p.step);
            if back {
                oscillations += 1;
                continue;
            }
            let i = g.push(at, Some(n));
            near.add(i, at);
            grew += 1;
        }
        if grew == 0 {
            break Stop::Stalled;
        }
    };
    // The last growth may have come within d_k of live points: they die too.
    near.kill(p.kill);
    let left = near.live();
    let stop = if left == 0 { Stop::AllKilled } else { stop };
    let grown = g.at.len() - first_new;
    let mut members: Vec<u32> = seeds.to_vec();
    members.extend(first_new as u32..g.at.len() as u32);
    GroupReport {
        name: String::new(),
        stop,
        iterations,
        nodes: seeds.len() + grown,
        edges: seeds.len() - 1 + grown,
        points_left: left,
        oscillations,
        members,
    }
}

#[cfg(test)]
mod tests;
