//! Dry rock gardens (karesansui 枯山水) designed by a genetic algorithm with the rules of
//! seed 000 (Namba, Kobe & Cai, *Designing Japanese Garden using Interactive GA*): the
//! conventional rules of the old garden manuals and the shape properties of Ryoanji's
//! garden, the seed's fitness and weights ([`rules`]), the medial-axis rule ([`medial`]),
//! stone sizes by a Zipf-like rank-size law, and the GA ([`ga`]): population 100, uniform
//! crossover at stone and group level (0.8), mutation 0.01, tournament selection with
//! elitism, or the user's picks (the interactive GA of the seed).
//!
//! Garden coordinates: x along the viewing side (0..width), y away from it (0..depth); the
//! viewpoint (the veranda) is at `viewpoint`, by default the middle of the viewing side a
//! little outside the garden. Units are the garden's (metres in the city).

pub mod ga;
pub mod medial;
pub mod rules;

use rand::RngExt;
use rand_pcg::Pcg64;

/// A stone's part in its group (yaku-ishi 役石): shin 真 (the largest, the master), soe 副
/// (the second), tai 対 (the third), or another of a larger group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The largest stone of a group.
    Shin,
    /// The second.
    Soe,
    /// The third.
    Tai,
    /// A fourth or later stone.
    Other,
}

impl Role {
    /// The role of the k-th stone of a group (largest first).
    pub fn of(k: usize) -> Role {
        [Role::Shin, Role::Soe, Role::Tai]
            .get(k)
            .copied()
            .unwrap_or(Role::Other)
    }

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Role::Shin => "shin",
            Role::Soe => "soe",
            Role::Tai => "tai",
            Role::Other => "other",
        }
    }
}

/// One stone: its place, its size (its diameter in plan) and its group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stone {
    /// Along the viewing side.
    pub x: f64,
    /// Away from the viewing side.
    pub y: f64,
    /// Diameter in plan.
    pub size: f64,
    /// Its group's index.
    pub group: usize,
    /// Its role in the group.
    pub role: Role,
}

/// A garden's stones, group by group, each group largest first.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The stones.
    pub stones: Vec<Stone>,
}

impl Layout {
    /// A layout from (x, y, size, group) rows, each group largest first: roles by order.
    pub fn from_rows(rows: &[[f64; 4]]) -> Layout {
        let mut seen: Vec<usize> = Vec::new();
        let stones = rows
            .iter()
            .map(|r| {
                let group = r[3].max(0.0) as usize;
                if seen.len() <= group {
                    seen.resize(group + 1, 0);
                }
                let role = Role::of(seen[group]);
                seen[group] += 1;
                Stone {
                    x: r[0],
                    y: r[1],
                    size: r[2],
                    group,
                    role,
                }
            })
            .collect();
        Layout { stones }
    }

    /// The stones as (x, y, size, group) rows.
    pub fn to_rows(&self) -> Vec<[f64; 4]> {
        self.stones
            .iter()
            .map(|st| [st.x, st.y, st.size, st.group as f64])
            .collect()
    }

    /// The stone indices of each group, in order.
    pub fn groups(&self) -> Vec<Vec<usize>> {
        let n = self.stones.iter().map(|s| s.group + 1).max().unwrap_or(0);
        let mut g = vec![Vec::new(); n];
        for (i, s) in self.stones.iter().enumerate() {
            g[s.group].push(i);
        }
        g.retain(|v| !v.is_empty());
        g
    }
}

/// The garden and the rules' parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Garden width (along the viewing side).
    pub width: f64,
    /// Garden depth.
    pub depth: f64,
    /// Stones per group (Ryoanji: 5, 2, 3, 2, 3).
    pub groups: Vec<usize>,
    /// The viewpoint.
    pub viewpoint: [f64; 2],
    /// The largest stone's diameter.
    pub max_size: f64,
    /// The Zipf exponent of the sizes by rank (size = max_size x rank^-zipf).
    pub zipf: f64,
    /// Radius of the centre zone stones avoid.
    pub centre_radius: f64,
    /// Group shins nearer than this break the opposition rule.
    pub opposition: f64,
    /// A stone farther than this x (its size + its shin's) from its shin breaks adjacency.
    pub adjacent: f64,
    /// The medial axis's sampling step.
    pub cell: f64,
}

/// The shortest side a garden may have, metres: `garden.min_size`'s own lower bound, so every
/// garden a build places can be designed, and the repair's stone sizes stay above their floor.
pub const MIN_SIDE: f64 = 1.0;

impl Settings {
    /// The seed's garden: 25 x 25, Ryoanji's 15 stones in five groups.
    pub fn seed() -> Settings {
        Settings::sized(25.0, 25.0)
    }

    /// A `width` x `depth` garden with the rules' distances scaled to it.
    pub fn sized(width: f64, depth: f64) -> Settings {
        let small = width.min(depth);
        Settings {
            width,
            depth,
            groups: vec![5, 2, 3, 2, 3],
            viewpoint: [width / 2.0, -0.1 * depth],
            max_size: 0.07 * width.max(depth).min(2.5 * small),
            zipf: 0.9,
            centre_radius: 0.15 * small,
            opposition: 0.2 * width.max(depth),
            adjacent: 1.2,
            cell: (small / 20.0).max(1e-3),
        }
    }

    /// What is wrong with the numbers, if anything.
    pub fn problem(&self) -> Option<String> {
        let pos = |v: f64| v.is_finite() && v > 0.0 && v <= 1e4;
        let side = |v: f64| v.is_finite() && (MIN_SIDE..=1e4).contains(&v);
        if !(side(self.width) && side(self.depth)) {
            return Some(format!(
                "width and depth must be from {MIN_SIDE} to 10,000 metres (a garden's stones \
                 are centimetres at least, and the build places none under a metre), got {} x {}",
                self.width, self.depth
            ));
        }
        if !(pos(self.max_size) && pos(self.cell)) {
            return Some("the stone size must be a positive number up to 10,000".into());
        }
        let stones: usize = self.groups.iter().sum();
        if self.groups.is_empty() || self.groups.contains(&0) || stones > 200 {
            return Some("groups must each hold a stone, 200 stones at most".into());
        }
        if !(self.zipf.is_finite() && (0.0..=3.0).contains(&self.zipf)) {
            return Some("zipf must be from 0 to 3".into());
        }
        None
    }

    /// The Zipf sizes by rank: size of the r-th largest stone = max_size x r^-zipf.
    pub fn zipf_sizes(&self) -> Vec<f64> {
        let n: usize = self.groups.iter().sum();
        (1..=n)
            .map(|r| self.max_size * (r as f64).powf(-self.zipf))
            .collect()
    }
}

/// A random layout: Zipf sizes dealt to the groups (each group's largest first), places
/// uniform in the garden (the seed's first generation), then made legal ([`repair`]).
pub fn random_layout(s: &Settings, rng: &mut Pcg64) -> Layout {
    scattered(s, rng, false)
}

/// A random layout whose groups start gathered: each group's stones within adjacency of a
/// shin placed uniformly. Short runs (the city's) converge much sooner from it.
pub fn clustered_layout(s: &Settings, rng: &mut Pcg64) -> Layout {
    scattered(s, rng, true)
}

fn scattered(s: &Settings, rng: &mut Pcg64, gathered: bool) -> Layout {
    let mut sizes = s.zipf_sizes();
    // Deal the sizes: the largest stones go to the groups' shin places in turn.
    let mut slots: Vec<(usize, usize)> = Vec::new();
    for k in 0..s.groups.iter().copied().max().unwrap_or(0) {
        for (g, &n) in s.groups.iter().enumerate() {
            if k < n {
                slots.push((g, k));
            }
        }
    }
    let mut stones: Vec<Stone> = Vec::new();
    for (g, &n) in s.groups.iter().enumerate() {
        let first = stones.len();
        for k in 0..n {
            let rank = slots.iter().position(|&q| q == (g, k)).unwrap_or(0);
            let jitter = 0.85 + 0.3 * rng.random::<f64>();
            let size = sizes[rank] * jitter;
            let (x, y) = match (gathered, stones.get(first)) {
                (true, Some(shin)) if k > 0 => {
                    let reach = s.adjacent * (size + shin.size) * (0.6 + 0.4 * rng.random::<f64>());
                    let a = rng.random::<f64>() * std::f64::consts::TAU;
                    (shin.x + reach * a.cos(), shin.y + reach * a.sin())
                }
                _ => (rng.random::<f64>() * s.width, rng.random::<f64>() * s.depth),
            };
            stones.push(Stone {
                x,
                y,
                size,
                group: g,
                role: Role::of(k),
            });
        }
    }
    sizes.clear();
    let mut l = Layout { stones };
    repair(&mut l, s);
    l
}

/// Makes a layout legal: each group's stones sorted largest first (so the roles hold),
/// every stone inside the garden, no two overlapping (pushed apart, a few passes, then
/// shrunk if the garden is too full).
pub fn repair(l: &mut Layout, s: &Settings) {
    for g in l.groups() {
        let mut sizes: Vec<f64> = g.iter().map(|&i| l.stones[i].size).collect();
        sizes.sort_by(|a, b| b.total_cmp(a));
        for (k, &i) in g.iter().enumerate() {
            l.stones[i].size = sizes[k].clamp(1e-3, s.max_size * 1.5);
            l.stones[i].role = Role::of(k);
        }
    }
    let n = l.stones.len();
    for pass in 0..60 {
        let mut moved = false;
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (l.stones[i], l.stones[j]);
                let need = (a.size + b.size) / 2.0 * 1.05;
                let (dx, dy) = (b.x - a.x, b.y - a.y);
                let d = dx.hypot(dy);
                if d < need {
                    let (ux, uy) = if d > 1e-9 {
                        (dx / d, dy / d)
                    } else {
                        let t = (i * 7 + j * 13) as f64;
                        (t.cos(), t.sin())
                    };
                    let push = (need - d) / 2.0 + 1e-6;
                    l.stones[i].x -= ux * push;
                    l.stones[i].y -= uy * push;
                    l.stones[j].x += ux * push;
                    l.stones[j].y += uy * push;
                    moved = true;
                }
            }
        }
        for st in &mut l.stones {
            let r = st.size / 2.0;
            st.x = st.x.clamp(r, (s.width - r).max(r));
            st.y = st.y.clamp(r, (s.depth - r).max(r));
        }
        if !moved {
            return;
        }
        if pass >= 40 {
            // A crowded garden: smaller stones until they fit.
            for st in &mut l.stones {
                st.size *= 0.95;
            }
        }
    }
}

/// Whether every stone is inside the garden and no two overlap.
pub fn is_legal(l: &Layout, s: &Settings) -> bool {
    let inside = l.stones.iter().all(|st| {
        let r = st.size / 2.0 - 1e-9;
        st.x >= r && st.x <= s.width - r && st.y >= r && st.y <= s.depth - r
    });
    let apart = (0..l.stones.len()).all(|i| {
        (i + 1..l.stones.len()).all(|j| {
            let (a, b) = (l.stones[i], l.stones[j]);
            (a.x - b.x).hypot(a.y - b.y) >= (a.size + b.size) / 2.0 - 1e-9
        })
    });
    inside && apart
}

/// The least-squares line of log(size) on log(rank): (slope, r^2). Zipf's law is a straight
/// line.
pub fn zipf_fit(l: &Layout) -> (f64, f64) {
    let mut sizes: Vec<f64> = l.stones.iter().map(|s| s.size).collect();
    sizes.sort_by(|a, b| b.total_cmp(a));
    let pts: Vec<(f64, f64)> = sizes
        .iter()
        .enumerate()
        .map(|(k, &v)| (((k + 1) as f64).ln(), v.max(1e-12).ln()))
        .collect();
    let n = pts.len() as f64;
    if pts.len() < 2 {
        return (0.0, 1.0);
    }
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = pts.iter().map(|p| (p.1 - my).powi(2)).sum();
    let slope = sxy / sxx.max(1e-12);
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    (slope, r2)
}

/// Ryoanji's garden, 25 x 10 m (the hojo's veranda on the viewing side): its fifteen
/// stones in five groups of 5, 2, 3, 2, 3 seen from the veranda left to right, their places
/// and plan sizes read by eye (to about half a metre) off the plan in Van Tonder, Lyons &
/// Ejima, *Visual structure of a Japanese Zen garden*, Nature 419 (2002), fig. 1, which is
/// drawn from the survey the seed cites. Not survey coordinates.
pub fn ryoanji() -> (Layout, Settings) {
    let s = Settings::sized(25.0, 10.0);
    let groups: [&[(f64, f64, f64)]; 5] = [
        &[
            (3.5, 4.0, 1.6),
            (2.3, 3.2, 0.9),
            (5.0, 3.0, 0.7),
            (2.6, 5.4, 0.5),
            (4.4, 5.3, 0.4),
        ],
        &[(8.6, 6.6, 1.0), (9.6, 7.3, 0.5)],
        &[(12.6, 3.3, 1.2), (11.4, 2.6, 0.6), (14.0, 2.5, 0.5)],
        &[(17.0, 7.6, 0.8), (18.0, 8.2, 0.4)],
        &[(21.5, 4.6, 1.3), (20.4, 3.8, 0.7), (23.0, 3.4, 0.5)],
    ];
    let mut stones = Vec::new();
    for (g, list) in groups.iter().enumerate() {
        for (k, &(x, y, size)) in list.iter().enumerate() {
            stones.push(Stone {
                x,
                y,
                size,
                group: g,
                role: Role::of(k),
            });
        }
    }
    (Layout { stones }, s)
}

#[cfg(test)]
mod tests;
