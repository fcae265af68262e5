//! Street crowds (`people.motion = "boids"`): the people the Poisson process put on a street
//! walk through the street network (seed 004's boids on errands), in a clip of
//! `crowd.duration` seconds that loops without a jump. docs/crowds.md tells the model.
//!
//! - [`network`]: the streets cut into links at their junctions.
//! - [`route`]: each group's errand, out and back once a clip, its turns drawn at junctions.
//! - [`walk`]: every walker of the city at once, pushed by the seed's three zones.
//!
//! Groups of `crowd.group` people (neighbours in the process's order on a stretch) walk one
//! errand, abreast where the street is wide enough, else one behind another. The whole city
//! is walked together, in the analysis (which `--tiles` and `--shard` share), so a walker's
//! neighbours are the same whichever tiles are written; a walker is written in the tile it
//! stands in at time 0 (its clip may take it into the next). A walker whose clip ever takes
//! it into a building, kura or fence walks its errand's centreline instead, or if that too
//! crosses one is left out (with a warning); a stretch asked for more walkers than
//! [`MAX_DENSITY`] allows is thinned (with a warning).

pub mod network;
pub mod route;
pub mod walk;

use std::collections::BTreeMap;

use geo_types::Coord;
use rand::RngExt;
use rayon::prelude::*;

use crate::growers::boids::{order_parameters, Boid};
use crate::model::tile::tile_id;
use crate::model::{CrowdStat, Dataset, MeanLambdas, PlannedBillboard, Walk, WalkKey};
use crate::params::Params;
use network::Network;
use walk::{Track, Walker};

/// The most walkers a square metre of street holds: above 1 person/m2 our crowd no longer
/// slows as people do (docs/crowds.md, the fundamental diagram), so no street is given more.
pub const MAX_DENSITY: f64 = 1.0;

/// The id of the `k`-th (from 0) straight stretch of a street: `<street id>/<k + 1>`. The
/// people drawn on it have ids that begin so (`billboards::street_sources`).
pub(super) fn stretch_id(street: &str, k: usize) -> String {
    format!("{street}/{}", k + 1)
}

/// The stretch a generated person's id names (`<street>/<n>/<piece>/<i>`).
fn stretch_of(id: &str) -> Option<String> {
    let mut parts = id.splitn(3, '/');
    Some(format!("{}/{}", parts.next()?, parts.next()?))
}

/// What walking did.
#[derive(Debug, Default)]
pub struct Walked {
    /// Every person, the walkers where they are at time 0 facing their way (in their input
    /// order; walkers left out are gone).
    pub people: Vec<PlannedBillboard>,
    /// The order parameters of each stretch over the clip.
    pub stats: Vec<CrowdStat>,
    /// Each walker's clip, by person id.
    pub walks: BTreeMap<String, Walk>,
    /// What was thinned or left out, for the report.
    pub warnings: Vec<crate::model::Warning>,
}

/// One walker before the walk: its person and its errand.
struct Setting {
    person: PlannedBillboard,
    group: String,
    walker: Walker,
}

/// Walks the people of every street. `ground_at` gives the ground under a point, `blocked`
/// whether a point is inside a building, kura or fence.
pub fn walk(
    people: Vec<PlannedBillboard>,
    data: &Dataset,
    p: &Params,
    ground_at: &(dyn Fn(Coord<f64>) -> f64 + Sync),
    blocked: &(dyn Fn(Coord<f64>) -> bool + Sync),
) -> Walked {
    let mut net = network::network(data, p.people.edge_margin);
    net.close_blocked(blocked);
    let mut by_stretch: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (i, l) in net.links.iter().enumerate() {
        by_stretch.entry(&l.stretch).or_default().push(i);
    }
    let mut groups: BTreeMap<String, Vec<PlannedBillboard>> = BTreeMap::new();
    let mut out = Walked::default();
    for b in people {
        let walking = p.crowd_walks(b.district.as_deref());
        match stretch_of(&b.id).filter(|s| walking && by_stretch.contains_key(s.as_str())) {
            Some(s) => groups.entry(s).or_default().push(b),
            None => out.people.push(b),
        }
    }
    let mut thinned = 0;
    for (s, people) in groups.iter_mut() {
        let room: f64 = by_stretch[s.as_str()]
            .iter()
            .map(|&l| net.links[l].len * (2.0 * net.links[l].half).max(1.0))
            .sum();
        let most = (room * MAX_DENSITY).floor() as usize;
        if people.len() > most {
            thinned += people.len() - most;
            // Evenly along the process's order, so the thinning keeps the spread.
            let n = people.len();
            let keep: Vec<usize> = (0..most).map(|k| k * n / most.max(1)).collect();
            let mut k = 0;
            people.retain(|_| {
                k += 1;
                keep.binary_search(&(k - 1)).is_ok()
            });
        }
    }
    if thinned > 0 {
        out.warnings.push(
            crate::model::Warning::new(
                crate::model::WarningClass::Billboards,
                format!(
                    "people: {thinned} walkers thinned: a street holds at most {MAX_DENSITY} \
                     person per m2 of its walkable width (lower people.per_100m)"
                ),
            )
            .for_key("people.per_100m"),
        );
    }
    let settings: Vec<Setting> = groups
        .into_par_iter()
        .flat_map_iter(|(s, people)| set_out(&s, people, &by_stretch[s.as_str()], &net, p))
        .collect();
    let keys = p.crowd.keys();
    let settings = bounded(settings, keys, &mut out.warnings);
    let walkers: Vec<Walker> = settings.iter().map(|s| s.walker.clone()).collect();
    let mut tracks = walk::simulate(&net, &walkers, &p.crowd.model(), p.crowd.dt, keys);
    let inside = |t: &Track| !t.at.iter().any(|&c| blocked(c));
    // A walker pushed into a building (mostly cutting a corner at a junction, or off a lane
    // of a street narrower than its lots leave it) walks its errand's centreline instead;
    // one whose centreline crosses a building too is left out.
    let mut ok: Vec<bool> = tracks.par_iter().map(inside).collect();
    let fixed: Vec<(usize, Track)> = (ok.iter().enumerate())
        .filter(|(_, ok)| !**ok)
        .map(|(i, _)| i)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|i| (i, walk::centreline(&walkers[i], &net, p.crowd.dt, keys)))
        .filter(|(_, t)| inside(t))
        .collect();
    for (i, t) in fixed {
        tracks[i] = t;
        ok[i] = true;
    }
    let left_out = ok.iter().filter(|k| !**k).count();
    if left_out > 0 {
        out.warnings.push(
            crate::model::Warning::new(
                crate::model::WarningClass::Billboards,
                format!(
                    "people: {left_out} walkers left out: their walk crossed a building, kura \
                     or fence (a street narrower than its lots leave it; widen the street or \
                     raise people.edge_margin)"
                ),
            )
            .for_key("people.edge_margin"),
        );
    }
    out.stats = measure(&net, &settings, &tracks, &ok, p);
    let placed: Vec<(PlannedBillboard, Walk)> = settings
        .into_par_iter()
        .zip(tracks)
        .zip(ok)
        .filter(|(_, ok)| *ok)
        .map(|((s, t), _)| place(s, &t, &net, p, ground_at))
        .collect();
    for (b, w) in placed {
        out.walks.insert(b.id.clone(), w);
        out.people.push(b);
    }
    out
}

/// The most walker-keys a build holds (walkers x keys): each is a position in memory, in the
/// GLB and a row of `crowds/*.csv` (about 60 bytes); 10 million is 5,000 walkers on a clip of
/// 2,000 keys (the default clip has 121).
pub const MAX_WALKER_KEYS: usize = 10_000_000;

/// `settings`, thinned evenly (with a warning) when their walkers times the clip's `keys`
/// would pass [`MAX_WALKER_KEYS`].
fn bounded<T>(settings: Vec<T>, keys: usize, warnings: &mut Vec<crate::model::Warning>) -> Vec<T> {
    let most = MAX_WALKER_KEYS / (keys + 1);
    let n = settings.len();
    if n <= most {
        return settings;
    }
    warnings.push(
        crate::model::Warning::new(
            crate::model::WarningClass::Billboards,
            format!(
                "people: {n} walkers on a clip of {} keys would be more than {MAX_WALKER_KEYS} \
                 positions; {most} walkers kept (shorten crowd.duration or lengthen crowd.dt)",
                keys + 1
            ),
        )
        .for_key("crowd.duration"),
    );
    let keep: std::collections::BTreeSet<usize> = (0..most).map(|k| k * n / most).collect();
    settings
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep.contains(i))
        .map(|(_, s)| s)
        .collect()
}

/// The errands of one stretch's people, in groups.
fn set_out(
    stretch: &str,
    people: Vec<PlannedBillboard>,
    links: &[usize],
    net: &Network,
    p: &Params,
) -> Vec<Setting> {
    let mut rng = crate::rng::feature_rng(p.seed_for("people"), "crowd", stretch);
    let c = &p.crowd;
    let gap = (p.people.min_spacing + 0.2).max(c.r0);
    let mut out = Vec::with_capacity(people.len());
    let mut people = people.into_iter().peekable();
    while people.peek().is_some() {
        let n = rng.random_range(c.group[0]..=c.group[1]).max(1);
        let members: Vec<PlannedBillboard> = people.by_ref().take(n).collect();
        let lead = &members[0];
        let (link, s) = nearest(net, links, lead.at);
        let l = &net.links[link];
        let facing = Coord {
            x: lead.facing.cos(),
            y: lead.facing.sin(),
        };
        let ahead = facing.x * l.dir().x + facing.y * l.dir().y >= 0.0;
        // Groups walk 4 % slower a member (pedestrians.md: 10-20 % for two to four).
        let pace =
            rng.random_range(c.speed[0]..=c.speed[1]) * (1.0 - 0.04 * (members.len() - 1) as f64);
        let len = pace * c.duration / 2.0;
        let u = rng.random_range(0.0..2.0 * len.max(f64::MIN_POSITIVE));
        // Going out at time 0 (u < len), or coming back (then out is the other way).
        let (forward, behind) = if u < len {
            (ahead, u)
        } else {
            (!ahead, 2.0 * len - u)
        };
        let route = route::route(
            net,
            link,
            s,
            forward,
            [behind, len - behind],
            c.straight,
            &mut rng,
        );
        let phase = if u < len {
            behind
        } else {
            2.0 * route.len - behind
        };
        let abreast = (members.len() - 1) as f64 * gap <= 2.0 * l.half;
        let width = if abreast {
            (members.len() - 1) as f64 * gap
        } else {
            0.0
        };
        let room = (l.half - width / 2.0).max(0.0);
        let centre = rng.random_range(-room..=room);
        let group = lead.id.clone();
        for (k, person) in members.into_iter().enumerate() {
            let (lane, back) = match abreast {
                true => (centre - width / 2.0 + k as f64 * gap, 0.0),
                false => (centre, k as f64 * gap),
            };
            out.push(Setting {
                person,
                group: group.clone(),
                walker: Walker {
                    route: route.clone(),
                    phase: (phase - back).rem_euclid((2.0 * route.len).max(f64::MIN_POSITIVE)),
                    lane,
                },
            });
        }
    }
    out
}

/// The link of `links` nearest `at`, and how far along it `at`'s foot is.
fn nearest(net: &Network, links: &[usize], at: Coord<f64>) -> (usize, f64) {
    let mut best = (links[0], 0.0, f64::INFINITY);
    for &i in links {
        let l = &net.links[i];
        let rel = at - l.a;
        let s = (rel.x * l.dir().x + rel.y * l.dir().y).clamp(0.0, l.len);
        let foot = l.a + l.dir() * s;
        let d = (at - foot).x.hypot((at - foot).y);
        if d < best.2 {
            best = (i, s, d);
        }
    }
    (best.0, best.1)
}

/// A walker's person at time 0 and its clip.
fn place(
    s: Setting,
    t: &Track,
    net: &Network,
    p: &Params,
    ground_at: &(dyn Fn(Coord<f64>) -> f64 + Sync),
) -> (PlannedBillboard, Walk) {
    let keys: Vec<WalkKey> =
        t.at.iter()
            .zip(&t.heading)
            .map(|(c, h)| WalkKey {
                at: [c.x, c.y, ground_at(*c)],
                heading: *h,
            })
            .collect();
    let at = t.at[0];
    let b = PlannedBillboard {
        at,
        facing: t.heading[0],
        ground: keys[0].at[2],
        tile: tile_id(at, p.tile_size, p.tile_origin),
        ..s.person
    };
    let walk = Walk {
        id: b.id.clone(),
        group: s.group,
        street: net.links[t.link[0]].stretch.clone(),
        dt: p.crowd.dt,
        keys,
    };
    (b, walk)
}

/// lambda1-3 of each stretch's crowd at each key: of the walkers whose errand point is on
/// the stretch then (left-out walkers not counted).
fn measure(
    net: &Network,
    settings: &[Setting],
    tracks: &[Track],
    ok: &[bool],
    p: &Params,
) -> Vec<CrowdStat> {
    let keys = p.crowd.keys();
    let dt = p.crowd.dt;
    let every = ((1.0 / dt).round() as usize).max(1);
    // Who is on each stretch at time 0, by district.
    let mut at_start: BTreeMap<&str, BTreeMap<String, usize>> = BTreeMap::new();
    for ((s, t), _) in settings.iter().zip(tracks).zip(ok).filter(|(_, ok)| **ok) {
        *at_start
            .entry(net.links[t.link[0]].stretch.as_str())
            .or_default()
            .entry(s.person.district.clone().unwrap_or_default())
            .or_default() += 1;
    }
    // Per key, the walkers on each stretch.
    let frames: Vec<BTreeMap<&str, Vec<Boid>>> = (0..=keys)
        .into_par_iter()
        .map(|k| {
            let mut on: BTreeMap<&str, Vec<Boid>> = BTreeMap::new();
            for (t, _) in tracks.iter().zip(ok).filter(|(_, ok)| **ok) {
                let next = t.at[(k + 1).min(keys)] - t.at[k];
                let (sin, cos) = t.heading[k].sin_cos();
                on.entry(net.links[t.link[k]].stretch.as_str())
                    .or_default()
                    .push(Boid {
                        pos: [t.at[k].x, t.at[k].y],
                        heading: [cos, sin],
                        speed: next.x.hypot(next.y) / dt,
                    });
            }
            on
        })
        .collect();
    let mut names: Vec<&str> = frames.iter().flat_map(|f| f.keys().copied()).collect();
    names.sort_unstable();
    names.dedup();
    let r1 = p.crowd.r1;
    // Each stretch's ends: its first link's start, its last link's end.
    let mut ends: BTreeMap<&str, [[f64; 2]; 2]> = BTreeMap::new();
    for l in &net.links {
        let r = |v: f64| (v * 1000.0).round() / 1000.0;
        ends.entry(l.stretch.as_str())
            .or_insert([[r(l.a.x), r(l.a.y)]; 2])[1] = [r(l.b.x), r(l.b.y)];
    }
    names
        .par_iter()
        .map(|&name| {
            let mut mean = MeanLambdas::default();
            let mut frames_on = 0usize;
            let mut series = Vec::new();
            let mut first = None;
            for (k, f) in frames.iter().enumerate().take(keys) {
                let l = f.get(name).map(|b| order_parameters(b, r1));
                if k == 0 {
                    first = l;
                }
                if let Some(l) = l {
                    mean.lambda1 += l.lambda1;
                    mean.lambda2 += l.lambda2;
                    mean.lambda3 += l.lambda3;
                    frames_on += 1;
                }
                if k % every == 0 {
                    let l = l.unwrap_or_default();
                    let r = |v: f64| (v * 1000.0).round() / 1000.0;
                    series.push([r(l.lambda1), r(l.lambda2), r(l.lambda3)]);
                }
            }
            if frames_on > 0 {
                let n = frames_on as f64;
                mean = MeanLambdas {
                    lambda1: mean.lambda1 / n,
                    lambda2: mean.lambda2 / n,
                    lambda3: mean.lambda3 / n,
                };
            }
            let districts = at_start.get(name).cloned().unwrap_or_default();
            let first = first.unwrap_or_default();
            CrowdStat {
                street: name.to_string(),
                agents: districts.values().sum(),
                districts,
                lambda1: first.lambda1,
                lambda2: first.lambda2,
                lambda3: first.lambda3,
                mean,
                series,
                line: ends.get(name).copied().unwrap_or_default(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walkers_past_the_bound_of_positions_are_thinned_evenly_with_a_warning() {
        let mut w = Vec::new();
        let kept = bounded((0..100).collect::<Vec<usize>>(), 99, &mut w);
        assert_eq!(kept.len(), 100);
        assert!(w.is_empty());
        // 20,000 keys a walker: 499 walkers fit in 10 million positions.
        let kept = bounded((0..1000).collect::<Vec<usize>>(), 20_000, &mut w);
        assert_eq!(kept.len(), MAX_WALKER_KEYS / 20_001);
        assert_eq!((kept[0], kept[1]), (0, 2));
        assert!(w[0].message.contains("crowd.duration"), "{:?}", w[0]);
    }

    #[test]
    fn a_person_belongs_to_the_stretch_its_id_begins_with() {
        assert_eq!(stretch_of("12/3/4/5").as_deref(), Some("12/3"));
        assert_eq!(stretch_of("12"), None);
    }
}
