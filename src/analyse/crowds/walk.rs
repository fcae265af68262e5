//! The crowd's walk: every walker of the city follows its errand ([`super::route`]) while the
//! seed's three zones (separation within `r0`, alignment within `r1`, cohesion within `r2`,
//! the latter two with those walking its way) push it off its line, inside its street.
//!
//! A walker steers toward where its errand puts it (a point `lane` metres left of the route,
//! moving at its pace), with the zones' steering added, as a second-order system: velocity
//! relaxes toward the wanted one in `1 / RELAX` seconds, position toward the route point in
//! `1 / PULL` seconds; and it walks no faster toward the person ahead in its line than the
//! gap allows (`(gap - BODY) / TIME_GAP`, the collision-free speed model's rule: without it
//! the crowd did not slow as it thickened, docs/crowds.md). Steps of [`STEP`] seconds or less, synchronous (all walkers from the
//! same old state) and each walker's neighbours visited in a fixed order, so the result is
//! the same for any thread count. The walk starts [`WARM_UP`] seconds before the clip, so
//! the clip begins with a crowd that has already sorted itself out.
//!
//! The clip loops without a jump: each errand is periodic by construction (out and back once
//! per clip), and what the zones add to it (the walker's offset from its errand point) is
//! made periodic by spreading its mismatch between the clip's end and start linearly over
//! the clip (`offset(t) + t / duration * (offset(0) - offset(duration))`): a drift of a few
//! centimetres a second at most, measured by `tests/crowds.rs`.

use std::collections::HashMap;

use geo_types::Coord;
use rayon::prelude::*;

use super::network::Network;
use super::route::Route;
use crate::growers::boids::BoidParams;

/// The longest simulation step, seconds (a clip's `dt` is cut into steps this long or less).
pub const STEP: f64 = 0.1;
/// Seconds walked before the clip starts.
pub const WARM_UP: f64 = 10.0;
/// How fast a walker's velocity follows the one it wants, per second.
const RELAX: f64 = 2.0;
/// How fast a walker closes on its errand's point, per second.
const PULL: f64 = 1.0;
/// A walker's width, metres: two closer than this side by side would touch, and a walker
/// keeps this much more than its time gap's worth of room ahead.
const BODY: f64 = 0.4;
/// Seconds of walking a walker keeps between itself and the one ahead (JuPedSim's
/// collision-free speed model's default time gap).
const TIME_GAP: f64 = 1.0;
/// How much faster than its pace a walker may go to catch up.
const CATCH_UP: f64 = 1.15;

/// One walker's errand and place on it.
#[derive(Debug, Clone)]
pub struct Walker {
    /// The way it walks, out and back.
    pub route: Route,
    /// Where on its loop (`2 * route.len` metres: out, then back) it is at time 0.
    pub phase: f64,
    /// How far left of its route's way out it walks, metres (kept inside each street's
    /// walkable half).
    pub lane: f64,
}

/// Where a walker's errand puts it at a time.
#[derive(Debug, Clone, Copy)]
pub struct Target {
    /// The point.
    pub at: Coord<f64>,
    /// The velocity there.
    pub vel: Coord<f64>,
    /// The link it is on.
    pub link: usize,
}

impl Walker {
    /// Where its errand puts it `t` seconds into a clip of `duration` seconds.
    pub fn target(&self, net: &Network, t: f64, duration: f64) -> Target {
        let len = self.route.len;
        let speed = 2.0 * len / duration;
        let q = (self.phase + speed * t).rem_euclid((2.0 * len).max(f64::MIN_POSITIVE));
        let (dist, sign) = if q <= len {
            (q, 1.0)
        } else {
            (2.0 * len - q, -1.0)
        };
        let on = self.route.at(net, dist);
        let way = on.dir * sign;
        // Left of the route's way out, on the way back too: a group that turns round keeps
        // its places across the street (its members do not walk through each other).
        let left = Coord {
            x: -on.dir.y,
            y: on.dir.x,
        };
        let half = net.links[on.link].half;
        Target {
            at: on.at + left * self.lane.clamp(-half, half),
            vel: way * speed,
            link: on.link,
        }
    }
}

/// A walker's clip: where it is at each key (every `dt` from 0 to the duration, the last the
/// same as the first) and the way it faces (radians from east).
#[derive(Debug, Clone, Default)]
pub struct Track {
    /// Positions, map metres.
    pub at: Vec<Coord<f64>>,
    /// Headings.
    pub heading: Vec<f64>,
    /// The link of its errand point at each key (for measuring each stretch's crowd).
    pub link: Vec<usize>,
}

/// Walks `walkers` for `keys` keys of `dt` seconds, a clip that loops; returns their tracks,
/// in order.
pub fn simulate(
    net: &Network,
    walkers: &[Walker],
    model: &BoidParams,
    dt: f64,
    keys: usize,
) -> Vec<Track> {
    let at = run(net, walkers, model, dt, keys, dt * keys as f64, WARM_UP);
    walkers
        .iter()
        .zip(at)
        .map(|(w, at)| {
            let mut tr = Track {
                at,
                ..Track::default()
            };
            close_loop(w, &mut tr, net, dt, keys);
            tr
        })
        .collect()
}

/// The walk itself: each walker's place at keys 0 to `keys` (every `dt` seconds) on errands
/// of `period` seconds, after `warm_up` seconds walked before the first key; not looped
/// (`examples/crowd_corridor.rs` measures a crowd setting out with it).
pub fn run(
    net: &Network,
    walkers: &[Walker],
    model: &BoidParams,
    dt: f64,
    keys: usize,
    period: f64,
    warm_up: f64,
) -> Vec<Vec<Coord<f64>>> {
    let sub = (dt / STEP).ceil().max(1.0) as usize;
    let h = dt / sub as f64;
    let warm = (warm_up.max(0.0) / h).ceil() as usize;
    let mut state: Vec<(Coord<f64>, Coord<f64>)> = walkers
        .iter()
        .map(|w| {
            let t = w.target(net, -(warm as f64) * h, period);
            (t.at, t.vel)
        })
        .collect();
    let mut out = vec![Vec::with_capacity(keys + 1); walkers.len()];
    let total = warm + keys * sub;
    for step in 0..=total {
        if step >= warm && (step - warm).is_multiple_of(sub) {
            for (tr, s) in out.iter_mut().zip(&state) {
                tr.push(s.0);
            }
        }
        if step == total {
            break;
        }
        let t_next = (step as f64 + 1.0 - warm as f64) * h;
        let grid = Grid::new(&state, model.r2);
        state = (0..walkers.len())
            .into_par_iter()
            .map(|i| {
                let aim = walkers[i].target(net, t_next, period);
                step_one(&state, &grid, i, aim, net, model, h)
            })
            .collect();
    }
    out
}

/// A walker's errand alone, on the centreline (lane 0, nobody else): the track of a walker
/// the crowd pushed into a building. Periodic as the errand is.
pub fn centreline(w: &Walker, net: &Network, dt: f64, keys: usize) -> Track {
    let alone = Walker {
        lane: 0.0,
        ..w.clone()
    };
    let duration = dt * keys as f64;
    let mut tr = Track {
        at: (0..=keys)
            .map(|k| alone.target(net, k as f64 * dt, duration).at)
            .collect(),
        ..Track::default()
    };
    close_loop(&alone, &mut tr, net, dt, keys);
    tr
}

/// One walker's next position and velocity.
fn step_one(
    state: &[(Coord<f64>, Coord<f64>)],
    grid: &Grid,
    i: usize,
    aim: Target,
    net: &Network,
    m: &BoidParams,
    h: f64,
) -> (Coord<f64>, Coord<f64>) {
    let (x, v) = state[i];
    let pace = aim.vel.x.hypot(aim.vel.y);
    let top = pace * CATCH_UP;
    let want = limit(aim.vel + (aim.at - x) * PULL, top);
    let way = unit(want);
    let (push, ahead) = zones(state, grid, i, way, m);
    let a = (want - v) * RELAX + push;
    let mut v = limit(v + a * h, top);
    // No faster toward someone ahead than the gap allows (the collision-free speed model's
    // rule); sideways it may still step round them.
    let room = ((ahead - BODY) / TIME_GAP).max(0.0);
    let along = v.x * way.x + v.y * way.y;
    if along > room {
        v = v - way * (along - room);
    }
    (inside(x + v * h, &net.links[aim.link]), v)
}

/// The seed's steering of walker `i`: away from those within `r0`, toward the heading of
/// those walking its way within `r1`, toward their centre within `r2`; and one rule of
/// people the seed has no need of: someone coming the other way within `r1` ahead makes a
/// walker step to its left (both do, so they pass keeping left; without it two walkers on
/// one line met head-on and pushed through each other). Also how far ahead along `way`
/// the nearest walker within a body's width of the walker's line is (infinite when none is
/// within the grid's reach): one pass over the neighbours for both.
fn zones(
    state: &[(Coord<f64>, Coord<f64>)],
    grid: &Grid,
    i: usize,
    way: Coord<f64>,
    m: &BoidParams,
) -> (Coord<f64>, f64) {
    let (x, v) = state[i];
    let mut ahead = f64::INFINITY;
    let zero = Coord { x: 0.0, y: 0.0 };
    let (mut sep, mut ali, mut coh) = (zero, zero, zero);
    let (mut n_ali, mut n_coh) = (0usize, 0usize);
    let mut evade = 0.0;
    grid.near(x, |j| {
        if j == i {
            return;
        }
        let (y, w) = state[j];
        let d = y - x;
        let along = d.x * way.x + d.y * way.y;
        if along > 0.0 && along < ahead && (d.x * way.y - d.y * way.x).abs() < BODY {
            ahead = along;
        }
        let r = d.x.hypot(d.y);
        if r > m.r2 {
            return;
        }
        let oncoming = v.x * w.x + v.y * w.y < 0.0;
        if oncoming && r <= m.r1 && d.x * v.x + d.y * v.y > 0.0 {
            evade += (m.r1 - r) / m.r1;
        }
        if r <= m.r0 {
            if r > 0.0 {
                sep = sep - d * ((m.r0 - r) / (r * m.r0));
            }
        } else if !oncoming {
            if r <= m.r1 {
                ali = ali + unit(w);
                n_ali += 1;
            } else {
                coh = coh + d;
                n_coh += 1;
            }
        }
    });
    let mut a = sep * (m.separation * m.max_speed);
    let going = unit(v);
    a = a + Coord {
        x: -going.y,
        y: going.x,
    } * (evade * m.separation * m.max_speed * 0.5);
    if n_ali > 0 {
        let speed = v.x.hypot(v.y);
        a = a + (unit(ali) * speed - v) * m.alignment;
    }
    if n_coh > 0 {
        a = a + coh * (m.cohesion / n_coh as f64);
    }
    (a, ahead)
}

/// `v`, shortened to `top` if longer.
fn limit(v: Coord<f64>, top: f64) -> Coord<f64> {
    let n = v.x.hypot(v.y);
    if n > top && n > 0.0 {
        v * (top / n)
    } else {
        v
    }
}

/// The unit vector of `v` (zero for a zero vector).
fn unit(v: Coord<f64>) -> Coord<f64> {
    let n = v.x.hypot(v.y);
    if n > 1e-12 {
        v / n
    } else {
        Coord { x: 0.0, y: 0.0 }
    }
}

/// `x` kept within the walkable half-width of `link` where it is beside the link (past its
/// ends a walker is in a junction, whose crossing street holds it).
fn inside(x: Coord<f64>, link: &super::network::Link) -> Coord<f64> {
    let u = link.dir();
    let left = Coord { x: -u.y, y: u.x };
    let rel = x - link.a;
    let s = rel.x * u.x + rel.y * u.y;
    let d = rel.x * left.x + rel.y * left.y;
    if (0.0..=link.len).contains(&s) && d.abs() > link.half {
        link.a + u * s + left * d.clamp(-link.half, link.half)
    } else {
        x
    }
}

/// Makes a track loop: its offset from the errand point is bent linearly so that the last
/// key is the first, then headings from the looped positions.
fn close_loop(w: &Walker, tr: &mut Track, net: &Network, dt: f64, keys: usize) {
    let duration = dt * keys as f64;
    let targets: Vec<Target> = (0..=keys)
        .map(|k| w.target(net, k as f64 * dt, duration))
        .collect();
    let off = |k: usize, at: &[Coord<f64>]| at[k] - targets[k].at;
    let gap = off(0, &tr.at) - off(keys, &tr.at);
    for (k, p) in tr.at.iter_mut().enumerate() {
        *p = *p + gap * (k as f64 / keys as f64);
    }
    tr.at[keys] = tr.at[0];
    tr.link = targets.iter().map(|t| t.link).collect();
    tr.heading = (0..=keys)
        .map(|k| {
            let (prev, next) = (if k == 0 { keys - 1 } else { k - 1 }, (k + 1) % keys.max(1));
            let d = tr.at[next] - tr.at[prev];
            let d = if d.x.hypot(d.y) > 1e-6 {
                d
            } else {
                targets[k].vel
            };
            d.y.atan2(d.x)
        })
        .collect();
    let last = tr.heading[0];
    tr.heading[keys] = last;
}

/// The walkers in cells of `r2`, each cell's in index order.
struct Grid {
    cell: f64,
    // Looked up, never iterated: the hasher changes no result (foldhash: 18 lookups a walker
    // a step).
    cells: HashMap<(i64, i64), Vec<usize>, foldhash::fast::FixedState>,
}

impl Grid {
    fn new(state: &[(Coord<f64>, Coord<f64>)], r2: f64) -> Grid {
        let cell = r2.max(0.1);
        let mut cells: HashMap<(i64, i64), Vec<usize>, foldhash::fast::FixedState> =
            HashMap::default();
        for (i, (x, _)) in state.iter().enumerate() {
            cells.entry(Grid::key(*x, cell)).or_default().push(i);
        }
        Grid { cell, cells }
    }

    fn key(x: Coord<f64>, cell: f64) -> (i64, i64) {
        ((x.x / cell).floor() as i64, (x.y / cell).floor() as i64)
    }

    /// Calls `f` with every walker in the 3 x 3 cells around `x`, in a fixed order.
    fn near(&self, x: Coord<f64>, mut f: impl FnMut(usize)) {
        let (cx, cy) = Grid::key(x, self.cell);
        for gx in cx - 1..=cx + 1 {
            for gy in cy - 1..=cy + 1 {
                for &j in self.cells.get(&(gx, gy)).into_iter().flatten() {
                    f(j);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyse::crowds::network::network;
    use crate::model::{Dataset, Street};
    use geo_types::LineString;

    fn corridor(width: f64) -> Network {
        let data = Dataset {
            streets: vec![Street {
                id: "s".into(),
                line: LineString::from(vec![[0.0, 0.0], [200.0, 0.0]]),
                width,
            }],
            ..Dataset::default()
        };
        network(&data, 0.5)
    }

    fn model() -> BoidParams {
        crate::params::Params::default().crowd.model()
    }

    #[test]
    fn a_lone_walker_walks_its_errand_at_its_pace_and_comes_back() {
        let net = corridor(8.0);
        let w = Walker {
            route: Route::along(&net, 0),
            phase: 20.0,
            lane: 1.0,
        };
        // 200 m out and back in 300 s: 1.333 m/s.
        let tr = &simulate(&net, std::slice::from_ref(&w), &model(), 0.5, 600)[0];
        assert_eq!(tr.at.len(), 601);
        assert_eq!(tr.at[0], tr.at[600]);
        for k in 10..590 {
            let d = tr.at[k + 1] - tr.at[k];
            let speed = d.x.hypot(d.y) / 0.5;
            assert!(speed < 1.6, "key {k}: {speed} m/s");
        }
        // Mid-way out it walks at the pace, a metre left of the centreline.
        let d = tr.at[101] - tr.at[100];
        assert!((d.x / 0.5 - 4.0 / 3.0).abs() < 0.02, "{d:?}");
        assert!((tr.at[100].y - 1.0).abs() < 0.05, "{:?}", tr.at[100]);
        assert!(tr.heading[100].abs() < 0.05);
    }

    #[test]
    fn walkers_meeting_head_on_keep_apart_and_inside_the_street() {
        let net = corridor(4.0);
        let walkers: Vec<Walker> = (0..20)
            .map(|k| Walker {
                route: Route::along(&net, 0),
                phase: k as f64 * 20.0,
                lane: 0.0,
            })
            .collect();
        let m = model();
        // 400 m out and back in 300 s: 1.33 m/s.
        let tracks = simulate(&net, &walkers, &m, 0.5, 600);
        let mut closest = f64::INFINITY;
        for k in 0..=600 {
            for (i, a) in tracks.iter().enumerate() {
                assert!(a.at[k].y.abs() <= 1.5 + 0.05, "{:?}", a.at[k]);
                for b in &tracks[i + 1..] {
                    let d = a.at[k] - b.at[k];
                    closest = closest.min(d.x.hypot(d.y));
                }
            }
        }
        assert!(closest > 0.5, "two walkers came {closest} m near");
    }

    #[test]
    fn the_same_walk_on_any_thread_count() {
        let net = corridor(6.0);
        let walkers: Vec<Walker> = (0..30)
            .map(|k| Walker {
                route: Route::along(&net, 0),
                phase: k as f64 * 13.0,
                lane: (k % 3) as f64 - 1.0,
            })
            .collect();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| simulate(&net, &walkers, &model(), 0.5, 60))
        };
        let (a, b) = (run(1), run(3));
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.at, y.at);
            assert_eq!(x.heading, y.heading);
        }
    }
}
