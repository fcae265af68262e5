//! Street crowds (`people.motion = "boids"`): the people the Poisson process put on a street
//! start there and walk as a crowd (the boids of seed 004, `growers::boids`) before they are
//! placed, each facing the way it walks.
//!
//! Each straight stretch of a street's centreline (between two of its vertices) is simulated
//! on its own, in street coordinates: distance along the centreline, offset across it, in a
//! rectangle as long as the stretch and as wide as the street less `people.edge_margin` on
//! each side. Its sides are the street's edges and its ends the junctions, and all four
//! reflect (walkers do not pass from one stretch to the next: a choice, so each stretch's
//! crowd, and its order parameters, stay its own). A walker who ends up in a building, kura
//! or fence is dropped, and the crowd is thinned to `people.min_spacing` again in the order
//! of the process's random keys, so the density of section 4.4 holds on average.

use std::collections::BTreeMap;

use geo_types::Coord;
use rand::RngExt;
use rayon::prelude::*;

use crate::growers::boids::{Boid, Flock, Lambdas};
use crate::model::tile::tile_id;
use crate::model::{CrowdStat, Dataset, MeanLambdas, PlannedBillboard};
use crate::params::Params;

/// One straight stretch of street: from `a`, unit direction `u`, `len` long, walkable
/// `half` either side of the centreline.
struct Stretch {
    a: Coord<f64>,
    u: Coord<f64>,
    len: f64,
    half: f64,
}

impl Stretch {
    /// The left normal, into the street's left half.
    fn v(&self) -> Coord<f64> {
        Coord {
            x: -self.u.y,
            y: self.u.x,
        }
    }
}

/// The id of the `k`-th (from 0) straight stretch of a street: `<street id>/<k + 1>`. The
/// people drawn on it have ids that begin so (`billboards::street_sources`).
pub(super) fn stretch_id(street: &str, k: usize) -> String {
    format!("{street}/{}", k + 1)
}

/// Every stretch of every street, by [`stretch_id`].
fn stretches(data: &Dataset, p: &Params) -> BTreeMap<String, Stretch> {
    let mut out = BTreeMap::new();
    for s in &data.streets {
        for (k, line) in s.line.lines().enumerate() {
            let d = line.end - line.start;
            let len = d.x.hypot(d.y);
            if len > 0.0 && len.is_finite() {
                out.insert(
                    stretch_id(&s.id, k),
                    Stretch {
                        a: line.start,
                        u: d / len,
                        len,
                        half: (s.width / 2.0 - p.people.edge_margin).max(0.0),
                    },
                );
            }
        }
    }
    out
}

/// The stretch a generated person's id names (`<street>/<n>/<piece>/<i>`).
fn stretch_of(id: &str) -> Option<String> {
    let mut parts = id.splitn(3, '/');
    Some(format!("{}/{}", parts.next()?, parts.next()?))
}

/// Walks the people of every stretch; returns them where they ended, facing the way they
/// walk (in their input order), with each stretch's order parameters. `ground_at` gives the
/// ground under a point, `blocked` whether a point is inside a building, kura or fence.
pub fn walk(
    people: Vec<PlannedBillboard>,
    data: &Dataset,
    p: &Params,
    ground_at: &(dyn Fn(Coord<f64>) -> f64 + Sync),
    blocked: &(dyn Fn(Coord<f64>) -> bool + Sync),
) -> (Vec<PlannedBillboard>, Vec<CrowdStat>) {
    let streets = stretches(data, p);
    let mut groups: BTreeMap<String, Vec<PlannedBillboard>> = BTreeMap::new();
    let mut order: Vec<(String, usize)> = Vec::with_capacity(people.len());
    let mut alone = Vec::new();
    for b in people {
        // A district that scatters its people keeps them where they stand.
        let walking = p.crowd_walks(b.district.as_deref());
        match stretch_of(&b.id).filter(|s| walking && streets.contains_key(s)) {
            Some(s) => {
                let g = groups.entry(s.clone()).or_default();
                order.push((s, g.len()));
                g.push(b);
            }
            None => alone.push(b),
        }
    }
    let walked: Vec<(String, Vec<PlannedBillboard>, Option<CrowdStat>)> = groups
        .into_par_iter()
        .map(|(id, group)| {
            let s = &streets[&id];
            let (moved, stat) = walk_stretch(&id, s, group, p, ground_at);
            (id, moved, stat)
        })
        .collect();
    let mut by_stretch: BTreeMap<String, Vec<Option<PlannedBillboard>>> = BTreeMap::new();
    let mut stats = Vec::new();
    for (id, moved, stat) in walked {
        by_stretch.insert(id, moved.into_iter().map(Some).collect());
        stats.extend(stat);
    }
    // Back in the input order (the process's key order), blocked walkers left out.
    let mut out = Vec::with_capacity(order.len() + alone.len());
    for (s, i) in order {
        if let Some(b) = by_stretch.get_mut(&s).and_then(|v| v[i].take()) {
            if !blocked(b.at) {
                out.push(b);
            }
        }
    }
    out.extend(alone);
    (out, stats)
}

/// One stretch's crowd: simulated in street coordinates, mapped back.
fn walk_stretch(
    id: &str,
    s: &Stretch,
    group: Vec<PlannedBillboard>,
    p: &Params,
    ground_at: &(dyn Fn(Coord<f64>) -> f64 + Sync),
) -> (Vec<PlannedBillboard>, Option<CrowdStat>) {
    if s.half <= 0.0 || group.is_empty() {
        return (group, None);
    }
    let v = s.v();
    let model = p.crowd.model();
    let boids: Vec<Boid> = group
        .iter()
        .map(|b| {
            let d = b.at - s.a;
            let (du, dv) = (d.x * s.u.x + d.y * s.u.y, d.x * v.x + d.y * v.y);
            let h = Coord {
                x: b.facing.cos(),
                y: b.facing.sin(),
            };
            Boid {
                pos: [du.clamp(0.0, s.len), (dv + s.half).clamp(0.0, 2.0 * s.half)],
                heading: [h.x * s.u.x + h.y * s.u.y, h.x * v.x + h.y * v.y],
                speed: model.min_speed,
            }
        })
        .collect();
    let mut rng = crate::rng::feature_rng(p.seed, "crowd", id);
    let seed = rng.random::<u64>();
    let mut boids = boids;
    set_out_in_groups(&mut boids, p.crowd.group, &mut rng);
    let mut flock = Flock::from_boids(boids, s.len, 2.0 * s.half, model, true, seed);
    let steps = p.crowd.steps;
    let last = p.crowd.last_steps.min(steps);
    let mut mean = MeanLambdas::default();
    for step in 0..steps {
        flock.step();
        if step + last >= steps && last > 0 {
            let l = flock.lambdas();
            mean.lambda1 += l.lambda1 / last as f64;
            mean.lambda2 += l.lambda2 / last as f64;
            mean.lambda3 += l.lambda3 / last as f64;
        }
    }
    let Lambdas {
        lambda1,
        lambda2,
        lambda3,
    } = flock.lambdas();
    let stat = CrowdStat {
        street: id.to_string(),
        districts: group.iter().fold(BTreeMap::new(), |mut m, b| {
            *m.entry(b.district.clone().unwrap_or_default()).or_default() += 1;
            m
        }),
        agents: group.len(),
        lambda1,
        lambda2,
        lambda3,
        mean,
    };
    let moved = group
        .into_iter()
        .zip(&flock.boids)
        .map(|(b, w)| {
            let at = s.a + s.u * w.pos[0] + v * (w.pos[1] - s.half);
            let h = s.u * w.heading[0] + v * w.heading[1];
            PlannedBillboard {
                at,
                facing: h.y.atan2(h.x),
                ground: ground_at(at),
                tile: tile_id(at, p.tile_size, p.tile_origin),
                ..b
            }
        })
        .collect();
    (moved, Some(stat))
}

/// Groups of a size drawn from `[smallest, largest]`, neighbours in the process's order,
/// each member turned the way the group's first faces.
fn set_out_in_groups(boids: &mut [Boid], size: [usize; 2], rng: &mut impl rand::Rng) {
    let mut i = 0;
    while i < boids.len() {
        let n = rng.random_range(size[0]..=size[1]).max(1);
        let heading = boids[i].heading;
        for b in boids.iter_mut().skip(i).take(n) {
            b.heading = heading;
        }
        i += n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_person_belongs_to_the_stretch_its_id_begins_with() {
        assert_eq!(stretch_of("12/3/4/5").as_deref(), Some("12/3"));
        assert_eq!(stretch_of("12"), None);
    }

    #[test]
    fn groups_set_out_the_way_their_first_member_faces() {
        let b = |a: f64| Boid {
            pos: [0.0, 0.0],
            heading: [a.cos(), a.sin()],
            speed: 1.0,
        };
        let mut boids: Vec<Boid> = (0..10).map(|i| b(i as f64)).collect();
        let mut rng = crate::rng::feature_rng(1, "t", "groups");
        set_out_in_groups(&mut boids, [3, 3], &mut rng);
        for g in boids.chunks(3) {
            assert!(g.iter().all(|x| x.heading == g[0].heading));
        }
        assert_ne!(boids[0].heading, boids[3].heading);
    }
}
