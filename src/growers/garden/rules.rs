//! The five rules of seed 000 (Namba, Kobe & Cai, Table 1) as degrees of violation, and the
//! seed's fitness 1 / sum(weight x degree). The seed leaves the units open; ours:
//!
//! | rule | weight | degree |
//! |---|---|---|
//! | `centre` | 1.54 | for each stone inside the centre zone (a disc of `centre_radius` about the garden's centre), how far inside it is, in garden units |
//! | `triangles` | 1.32 | for each triangle (shin, soe, tai of every group of three or more, and the shin stones of the three largest groups): how far the angle at its largest stone falls short of 100 degrees, in radians, plus for each pair of sides how far their difference falls short of 10 % of the longest, as a share of it |
//! | `opposition` | 0.53 | for each pair of groups, how far their shin stones are nearer than `opposition` units |
//! | `adjacency` | 2.0 | for each stone, how far it lies farther than `adjacent` x (its size + its shin's size) from its group's shin, in units |
//! | `axis` | 1.22 | the angle, in radians, between the main branch of the medial axis of the open space and the line from it to the viewpoint ([`super::medial`]) |

use super::{medial, Layout, Settings};

/// The seed's weights, by rule name, in Table 1's order.
pub const WEIGHTS: [(&str, f64); 5] = [
    ("centre", 1.54),
    ("triangles", 1.32),
    ("opposition", 0.53),
    ("adjacency", 2.0),
    ("axis", 1.22),
];

/// A layout's five degrees of violation, in [`WEIGHTS`]' order.
pub fn scores(l: &Layout, s: &Settings) -> [f64; 5] {
    [
        centre(l, s),
        triangles(l),
        opposition(l, s),
        adjacency(l, s),
        medial::axis_violation(l, s),
    ]
}

/// sum(weight x degree).
pub fn violation(scores: &[f64; 5]) -> f64 {
    scores.iter().zip(WEIGHTS).map(|(d, (_, w))| d * w).sum()
}

/// The seed's eq. 1, fitness = 1 / sum(weight x degree); a layout that breaks no rule
/// (violation 0) gets 1e9, the largest fitness reported.
pub fn fitness(scores: &[f64; 5]) -> f64 {
    1.0 / violation(scores).max(1e-9)
}

fn centre(l: &Layout, s: &Settings) -> f64 {
    let c = [s.width / 2.0, s.depth / 2.0];
    l.stones
        .iter()
        .map(|st| (s.centre_radius - (st.x - c[0]).hypot(st.y - c[1])).max(0.0))
        .sum()
}

/// The triangles the rule looks at: each group's first three stones (shin, soe, tai) and
/// the shin stones of the three largest groups.
pub fn rule_triangles(l: &Layout) -> Vec<[usize; 3]> {
    let mut out = Vec::new();
    for g in l.groups() {
        if g.len() >= 3 {
            out.push([g[0], g[1], g[2]]);
        }
    }
    let mut shins: Vec<usize> = l.groups().iter().map(|g| g[0]).collect();
    shins.sort_by(|&a, &b| {
        l.stones[b]
            .size
            .total_cmp(&l.stones[a].size)
            .then(a.cmp(&b))
    });
    if shins.len() >= 3 {
        out.push([shins[0], shins[1], shins[2]]);
    }
    out
}

/// Angle at `a` of the triangle `a b c`, radians.
pub fn angle_at(l: &Layout, a: usize, b: usize, c: usize) -> f64 {
    let p = |i: usize| [l.stones[i].x, l.stones[i].y];
    let (pa, pb, pc) = (p(a), p(b), p(c));
    let u = [pb[0] - pa[0], pb[1] - pa[1]];
    let v = [pc[0] - pa[0], pc[1] - pa[1]];
    let n = (u[0].hypot(u[1]) * v[0].hypot(v[1])).max(1e-12);
    ((u[0] * v[0] + u[1] * v[1]) / n).clamp(-1.0, 1.0).acos()
}

/// The smallest angle the obtuse rule accepts at the largest stone, radians (100 degrees).
pub const OBTUSE: f64 = 100.0 * std::f64::consts::PI / 180.0;
/// Two sides of a scalene triangle differ by at least this share of the longest.
pub const SCALENE: f64 = 0.1;

/// The degree of one triangle: obtuse at its first (largest) stone, and scalene.
pub fn triangle_degree(l: &Layout, t: [usize; 3]) -> f64 {
    let obtuse = (OBTUSE - angle_at(l, t[0], t[1], t[2])).max(0.0);
    let d =
        |i: usize, j: usize| (l.stones[i].x - l.stones[j].x).hypot(l.stones[i].y - l.stones[j].y);
    let sides = [d(t[0], t[1]), d(t[1], t[2]), d(t[0], t[2])];
    let longest = sides.iter().copied().fold(1e-12, f64::max);
    let mut scalene = 0.0;
    for (a, b) in [(0, 1), (1, 2), (0, 2)] {
        scalene += (SCALENE - (sides[a] - sides[b]).abs() / longest).max(0.0);
    }
    obtuse + scalene
}

fn triangles(l: &Layout) -> f64 {
    rule_triangles(l)
        .into_iter()
        .map(|t| triangle_degree(l, t))
        .sum()
}

fn opposition(l: &Layout, s: &Settings) -> f64 {
    let shins: Vec<usize> = l.groups().iter().map(|g| g[0]).collect();
    let mut sum = 0.0;
    for (k, &a) in shins.iter().enumerate() {
        for &b in &shins[k + 1..] {
            let d = (l.stones[a].x - l.stones[b].x).hypot(l.stones[a].y - l.stones[b].y);
            sum += (s.opposition - d).max(0.0);
        }
    }
    sum
}

fn adjacency(l: &Layout, s: &Settings) -> f64 {
    let mut sum = 0.0;
    for g in l.groups() {
        let shin = &l.stones[g[0]];
        for &i in &g[1..] {
            let st = &l.stones[i];
            let d = (st.x - shin.x).hypot(st.y - shin.y);
            sum += (d - s.adjacent * (st.size + shin.size)).max(0.0);
        }
    }
    sum
}
