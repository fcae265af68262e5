//! Boids (Reynolds 1987) with the three zones of Oyama et al. (seed 004): separation within
//! `r0`, alignment of headings within `r1`, cohesion toward the neighbours' centre within
//! `r2`, and random motion where no other agent is within `r2`; in a rectangle whose walls
//! reflect (the seed's Neumann boundary).
//!
//! Deterministic and order-free: every agent has its own RNG from (seed, agent index), all
//! agents are updated from the same old state (a synchronous step), and neighbours come from
//! a uniform grid whose cells are visited in a fixed order, so the result depends on neither
//! thread count nor agent order. Headings are unit vectors at every step.

mod grid;
pub mod order;

use rand::RngExt;
use rand_pcg::Pcg64;

use grid::Grid;
pub use order::{order_parameters, Lambdas};

/// The model's parameters, in the units of the space (the seed's: pixels and steps; the
/// city's: metres and seconds).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoidParams {
    /// Separation zone: other agents this near push an agent away.
    pub r0: f64,
    /// Alignment zone (r0, r1]: an agent turns toward its neighbours' mean heading.
    pub r1: f64,
    /// Cohesion zone (r1, r2]: an agent steers toward its neighbours' centre.
    pub r2: f64,
    /// Speed limits, units per unit time.
    pub min_speed: f64,
    /// The upper speed limit.
    pub max_speed: f64,
    /// The time step.
    pub dt: f64,
    /// Weights of the three rules (per unit time).
    pub separation: f64,
    /// Weight of alignment.
    pub alignment: f64,
    /// Weight of cohesion.
    pub cohesion: f64,
    /// Largest random turn per unit time of an agent with nobody within `r2` (radians):
    /// the seed's random motion.
    pub wander: f64,
}

impl BoidParams {
    /// The seed's setting (Table 1): r0 = 20, r1 = 80, r2 = 100 in a 500 x 300 space, with
    /// speeds and weights chosen so that ten agents flock within a few hundred steps.
    pub fn seed() -> BoidParams {
        BoidParams {
            r0: 20.0,
            r1: 80.0,
            r2: 100.0,
            min_speed: 1.0,
            max_speed: 3.0,
            dt: 1.0,
            separation: 0.05,
            alignment: 0.08,
            cohesion: 0.004,
            wander: 0.3,
        }
    }

    /// Why the parameters cannot be simulated, if they cannot: zones ordered and positive,
    /// speeds and step positive and finite, weights finite and not negative.
    pub fn problem(&self) -> Option<String> {
        let p = self;
        let finite = [
            p.r0,
            p.r1,
            p.r2,
            p.min_speed,
            p.max_speed,
            p.dt,
            p.separation,
            p.alignment,
            p.cohesion,
            p.wander,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !finite {
            return Some("every boids parameter must be a finite number".into());
        }
        if !(p.r0 > 0.0 && p.r0 <= p.r1 && p.r1 <= p.r2) {
            return Some(format!(
                "the zones must satisfy 0 < r0 <= r1 <= r2, got r0 = {}, r1 = {}, r2 = {}",
                p.r0, p.r1, p.r2
            ));
        }
        if !(p.min_speed >= 0.0 && p.min_speed <= p.max_speed && p.max_speed > 0.0 && p.dt > 0.0) {
            return Some(format!(
                "speeds must satisfy 0 <= min <= max, max > 0, and the step > 0: got {} .. {}, \
                 dt {}",
                p.min_speed, p.max_speed, p.dt
            ));
        }
        if [p.separation, p.alignment, p.cohesion, p.wander]
            .iter()
            .any(|w| *w < 0.0)
        {
            return Some("the rule weights and the wander must be 0 or more".into());
        }
        // Past these a step's arithmetic leaves the floats (weights of 1e308 made the
        // headings NaN and the grid's index panic); no crowd of people comes near them.
        if [p.separation, p.alignment, p.cohesion, p.wander]
            .iter()
            .any(|w| *w > MAX_WEIGHT)
        {
            return Some(format!(
                "the rule weights and the wander must be at most {MAX_WEIGHT} (per second), \
                 got [{}, {}, {}] and {}",
                p.separation, p.alignment, p.cohesion, p.wander
            ));
        }
        if p.r2 > MAX_ZONE || p.max_speed > MAX_SPEED || p.dt > MAX_DT {
            return Some(format!(
                "r2 may be at most {MAX_ZONE}, the fastest speed {MAX_SPEED} and the step \
                 {MAX_DT}: got r2 = {}, speed {}, dt {}",
                p.r2, p.max_speed, p.dt
            ));
        }
        None
    }
}

/// The largest rule weight or wander (per second).
pub const MAX_WEIGHT: f64 = 1000.0;
/// The largest cohesion zone `r2`.
pub const MAX_ZONE: f64 = 10_000.0;
/// The largest speed.
pub const MAX_SPEED: f64 = 1000.0;
/// The longest step.
pub const MAX_DT: f64 = 3600.0;

/// One agent: where it is, its heading (a unit vector) and its speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Boid {
    /// Position, in `[0, width] x [0, height]`.
    pub pos: [f64; 2],
    /// Heading, a unit vector.
    pub heading: [f64; 2],
    /// Speed, within the limits.
    pub speed: f64,
}

/// A crowd of boids in a `width` x `height` rectangle with reflecting walls.
#[derive(Debug, Clone)]
pub struct Flock {
    /// The agents, in index order.
    pub boids: Vec<Boid>,
    /// The rectangle's size.
    pub width: f64,
    /// The rectangle's height.
    pub height: f64,
    /// The model.
    pub params: BoidParams,
    /// Whether the three rules apply (false: the seed's random system).
    pub rules: bool,
    rngs: Vec<Pcg64>,
}

impl Flock {
    /// `n` agents at uniformly random places with random headings and speeds; each agent's
    /// RNG comes from (seed, its index).
    pub fn random(
        n: usize,
        width: f64,
        height: f64,
        params: BoidParams,
        rules: bool,
        seed: u64,
    ) -> Flock {
        let mut rngs: Vec<Pcg64> = (0..n)
            .map(|i| crate::rng::feature_rng(seed, "boid", &i.to_string()))
            .collect();
        let boids = rngs
            .iter_mut()
            .map(|r| {
                let a = r.random_range(0.0..std::f64::consts::TAU);
                Boid {
                    pos: [r.random_range(0.0..=width), r.random_range(0.0..=height)],
                    heading: [a.cos(), a.sin()],
                    speed: r.random_range(params.min_speed..=params.max_speed),
                }
            })
            .collect();
        Flock::from_boids(boids, width, height, params, rules, seed)
    }

    /// A flock of given agents (headings normalised; a zero heading becomes +x).
    pub fn from_boids(
        boids: Vec<Boid>,
        width: f64,
        height: f64,
        params: BoidParams,
        rules: bool,
        seed: u64,
    ) -> Flock {
        let rngs = (0..boids.len())
            .map(|i| crate::rng::feature_rng(seed, "boid-step", &i.to_string()))
            .collect();
        let boids = boids
            .into_iter()
            .map(|b| Boid {
                heading: unit(b.heading).unwrap_or([1.0, 0.0]),
                ..b
            })
            .collect();
        Flock {
            boids,
            width,
            height,
            params,
            rules,
            rngs,
        }
    }

    /// One time step: every agent's new velocity from the old state, then every move.
    pub fn step(&mut self) {
        let p = self.params;
        let grid = Grid::new(&self.boids, p.r2);
        let old = self.boids.clone();
        for (i, (b, rng)) in self.boids.iter_mut().zip(&mut self.rngs).enumerate() {
            let mut v = [b.heading[0] * b.speed, b.heading[1] * b.speed];
            let steer = if self.rules {
                rules(&old, &grid, i, &p)
            } else {
                None
            };
            match steer {
                Some(a) => {
                    v[0] += a[0] * p.dt;
                    v[1] += a[1] * p.dt;
                }
                None => {
                    // Random motion: a random turn, and a random change of pace.
                    let turn = rng.random_range(-1.0..=1.0) * p.wander * p.dt;
                    let (s, c) = turn.sin_cos();
                    v = [v[0] * c - v[1] * s, v[0] * s + v[1] * c];
                    let pace = 1.0 + 0.1 * rng.random_range(-1.0..=1.0);
                    v = [v[0] * pace, v[1] * pace];
                }
            }
            let speed = (v[0] * v[0] + v[1] * v[1]).sqrt();
            b.heading = unit(v).unwrap_or(b.heading);
            b.speed = speed.clamp(p.min_speed, p.max_speed);
            b.pos[0] += b.heading[0] * b.speed * p.dt;
            b.pos[1] += b.heading[1] * b.speed * p.dt;
            reflect(&mut b.pos[0], &mut b.heading[0], self.width);
            reflect(&mut b.pos[1], &mut b.heading[1], self.height);
        }
    }

    /// The order parameters of the flock now.
    pub fn lambdas(&self) -> Lambdas {
        order_parameters(&self.boids, self.params.r1)
    }
}

/// The steering of agent `i` by the three zones, or `None` when nobody is within `r2`
/// (the agent then moves at random).
fn rules(boids: &[Boid], grid: &Grid, i: usize, p: &BoidParams) -> Option<[f64; 2]> {
    let me = boids[i];
    let (mut sep, mut ali, mut coh) = ([0.0; 2], [0.0; 2], [0.0; 2]);
    let (mut n_ali, mut n_coh, mut any) = (0usize, 0usize, false);
    grid.near(me.pos, |j| {
        if j == i {
            return;
        }
        let o = boids[j];
        let d = [o.pos[0] - me.pos[0], o.pos[1] - me.pos[1]];
        let r = (d[0] * d[0] + d[1] * d[1]).sqrt();
        if r > p.r2 {
            return;
        }
        any = true;
        if r <= p.r0 {
            // Away from the other, harder the nearer (coincident agents: no direction).
            if r > 0.0 {
                let k = (p.r0 - r) / (r * p.r0);
                sep[0] -= d[0] * k;
                sep[1] -= d[1] * k;
            }
        } else if r <= p.r1 {
            ali[0] += o.heading[0];
            ali[1] += o.heading[1];
            n_ali += 1;
        } else {
            coh[0] += d[0];
            coh[1] += d[1];
            n_coh += 1;
        }
    });
    if !any {
        return None;
    }
    let v = [me.heading[0] * me.speed, me.heading[1] * me.speed];
    let mut a = [
        sep[0] * p.separation * p.max_speed,
        sep[1] * p.separation * p.max_speed,
    ];
    if n_ali > 0 {
        // Toward the neighbours' mean heading at the agent's own speed.
        let m = unit(ali).unwrap_or(me.heading);
        a[0] += p.alignment * (m[0] * me.speed - v[0]);
        a[1] += p.alignment * (m[1] * me.speed - v[1]);
    }
    if n_coh > 0 {
        a[0] += p.cohesion * coh[0] / n_coh as f64;
        a[1] += p.cohesion * coh[1] / n_coh as f64;
    }
    Some(a)
}

/// The unit vector of `v`, or `None` for a zero (or non-finite) vector.
fn unit(v: [f64; 2]) -> Option<[f64; 2]> {
    let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
    (n > 1e-12 && n.is_finite()).then(|| [v[0] / n, v[1] / n])
}

/// A coordinate past a wall at 0 or `size` is mirrored back inside and its heading turned
/// (the seed's reflecting boundary). A step longer than the space is folded repeatedly.
fn reflect(x: &mut f64, heading: &mut f64, size: f64) {
    for _ in 0..8 {
        if *x < 0.0 {
            *x = -*x;
            *heading = heading.abs();
        } else if *x > size {
            *x = 2.0 * size - *x;
            *heading = -heading.abs();
        } else {
            return;
        }
    }
    *x = x.clamp(0.0, size);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_stay_unit_and_agents_inside_for_any_seed() {
        for rules in [true, false] {
            for seed in 0..5 {
                let mut f = Flock::random(30, 500.0, 300.0, BoidParams::seed(), rules, seed);
                for _ in 0..300 {
                    f.step();
                    for b in &f.boids {
                        let n = (b.heading[0].powi(2) + b.heading[1].powi(2)).sqrt();
                        assert!((n - 1.0).abs() < 1e-9, "{b:?}");
                        assert!((0.0..=500.0).contains(&b.pos[0]), "{b:?}");
                        assert!((0.0..=300.0).contains(&b.pos[1]), "{b:?}");
                        assert!(b.speed >= 1.0 && b.speed <= 3.0);
                    }
                }
            }
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_flock_and_another_seed_another() {
        let run = |seed| {
            let mut f = Flock::random(10, 500.0, 300.0, BoidParams::seed(), true, seed);
            for _ in 0..200 {
                f.step();
            }
            f.boids
        };
        assert_eq!(run(3), run(3));
        assert_ne!(run(3), run(4));
    }

    #[test]
    fn coincident_agents_and_tiny_flocks_give_no_nan() {
        let b = Boid {
            pos: [10.0, 10.0],
            heading: [0.0, 0.0],
            speed: 2.0,
        };
        for n in 0..4 {
            let mut f = Flock::from_boids(vec![b; n], 50.0, 50.0, BoidParams::seed(), true, 1);
            for _ in 0..50 {
                f.step();
            }
            assert!(f.boids.iter().all(|b| b.pos.iter().all(|v| v.is_finite())));
            let l = f.lambdas();
            assert!([l.lambda1, l.lambda2, l.lambda3]
                .iter()
                .all(|v| v.is_finite()));
        }
    }

    #[test]
    fn a_wall_reflects_the_heading() {
        let (mut x, mut h) = (-2.0, -0.5);
        reflect(&mut x, &mut h, 10.0);
        assert_eq!((x, h), (2.0, 0.5));
        let (mut x, mut h) = (13.0, 1.0);
        reflect(&mut x, &mut h, 10.0);
        assert_eq!((x, h), (7.0, -1.0));
    }

    #[test]
    fn bad_parameters_are_named() {
        let mut p = BoidParams::seed();
        assert!(p.problem().is_none());
        p.r1 = 10.0;
        assert!(p.problem().unwrap().contains("r0 <= r1"));
        p = BoidParams::seed();
        p.dt = f64::NAN;
        assert!(p.problem().is_some());
        p = BoidParams::seed();
        (p.separation, p.alignment, p.cohesion) = (1e308, 1e308, 1e308);
        assert!(p.problem().unwrap().contains("at most 1000"));
        p = BoidParams::seed();
        p.dt = 1e9;
        assert!(p.problem().unwrap().contains("dt 1000000000"));
        // At the bounds a flock still steps to finite positions.
        p = BoidParams::seed();
        (p.separation, p.alignment, p.cohesion, p.wander) = (1000.0, 1000.0, 1000.0, 1000.0);
        assert!(p.problem().is_none());
        let mut f = Flock::random(40, 50.0, 30.0, p, true, 3);
        for _ in 0..50 {
            f.step();
        }
        assert!(f
            .boids
            .iter()
            .all(|b| b.pos.iter().chain(&b.heading).all(|v| v.is_finite())));
    }
}

#[cfg(test)]
mod flocking {
    use super::*;

    /// Mean of lambda3 over the last `last` of `steps` steps.
    fn tail_lambda3(rules: bool, seed: u64, steps: usize, last: usize) -> f64 {
        let mut f = Flock::random(10, 500.0, 300.0, BoidParams::seed(), rules, seed);
        let mut sum = 0.0;
        for s in 0..steps {
            f.step();
            if s >= steps - last {
                sum += f.lambdas().lambda3;
            }
        }
        sum / last as f64
    }

    #[test]
    fn a_flock_of_the_seeds_ten_agents_clusters_and_the_random_system_does_not() {
        // The seed's Table 1 and fig. 8: from random starts, the BOID system settles into a
        // cluster (lambda3 near 1), the random system stays near 0.
        let (mut boids, mut random) = (0.0, 0.0);
        for seed in 0..10 {
            let b = tail_lambda3(true, seed, 2000, 100);
            let r = tail_lambda3(false, seed, 2000, 100);
            assert!(b > 0.5, "seed {seed}: the flock's lambda3 {b}");
            assert!(
                r.abs() < 0.2,
                "seed {seed}: the random system's lambda3 {r}"
            );
            boids += b / 10.0;
            random += r / 10.0;
        }
        assert!(boids - random > 0.6, "{boids} against {random}");
    }
}
