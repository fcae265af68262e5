//! A walker's errand (yōji 用事): a path through the street network, walked out and back once
//! in each clip, so that where it is at the clip's end is where it was at its start.
//!
//! A route is built from the walker's starting point both ways: behind it (the part already
//! walked at time 0) and ahead. At the end of a link the walker goes on into another street
//! of the junction, drawn by its own RNG with weights `exp(straight * cos(turn))` (a walker
//! goes on straight more often than it turns; `straight = 0` makes every street alike), and
//! turns round at a dead end. Why out and back: a clip of 60 s cannot close a loop round a
//! Kyoto block (400 m and more at 1.3 m/s), and an errand walked there and back is what people
//! in a street do; each walker turns at its own moment, so the street never turns at once.

use geo_types::Coord;
use rand::RngExt;

use super::network::Network;

/// The most links a route passes (a network of tiny links cannot make one long).
pub const MAX_LEGS: usize = 4096;

/// A route's passage along one link.
#[derive(Debug, Clone, Copy)]
struct Leg {
    link: usize,
    /// Distances along the link from its `a` end where the leg starts and ends.
    from: f64,
    to: f64,
}

/// A path through the network, from its start to its far end.
#[derive(Debug, Clone, Default)]
pub struct Route {
    legs: Vec<Leg>,
    /// Where each leg starts, metres along the route.
    starts: Vec<f64>,
    /// Its length, metres.
    pub len: f64,
}

/// Where on a route a walker is.
#[derive(Debug, Clone, Copy)]
pub struct OnRoute {
    /// The point on the centreline.
    pub at: Coord<f64>,
    /// The unit direction of the route there (from its start toward its end).
    pub dir: Coord<f64>,
    /// The link.
    pub link: usize,
}

impl Route {
    /// The point `q` metres along the route (clamped to it).
    pub fn at(&self, net: &Network, q: f64) -> OnRoute {
        let q = q.clamp(0.0, self.len);
        let k = self.starts.partition_point(|&s| s <= q).saturating_sub(1);
        let leg = self.legs[k];
        let l = &net.links[leg.link];
        let sign = if leg.to >= leg.from { 1.0 } else { -1.0 };
        let s = leg.from + sign * (q - self.starts[k]);
        OnRoute {
            at: l.a + l.dir() * s.clamp(0.0, l.len),
            dir: l.dir() * sign,
            link: leg.link,
        }
    }

    /// A route of one leg, for a walker whose link is its whole world (tests).
    #[cfg(test)]
    pub fn along(net: &Network, link: usize) -> Route {
        Route::of(vec![Leg {
            link,
            from: 0.0,
            to: net.links[link].len,
        }])
    }

    fn of(legs: Vec<Leg>) -> Route {
        let mut starts = Vec::with_capacity(legs.len());
        let mut len = 0.0;
        for l in &legs {
            starts.push(len);
            len += (l.to - l.from).abs();
        }
        Route { legs, starts, len }
    }
}

/// The route through (`link`, `s` metres from its `a` end): `behind` metres walked backward
/// from there against `forward` (true: toward `b`), then `ahead` metres on; junction choices
/// from `rng`.
pub fn route(
    net: &Network,
    link: usize,
    s: f64,
    forward: bool,
    [behind, ahead]: [f64; 2],
    straight: f64,
    rng: &mut impl rand::Rng,
) -> Route {
    let mut back = walk(net, link, s, !forward, behind, straight, rng);
    back.reverse();
    for l in &mut back {
        std::mem::swap(&mut l.from, &mut l.to);
    }
    let on = walk(net, link, s, forward, ahead, straight, rng);
    let legs: Vec<Leg> = back.into_iter().chain(on).collect();
    if legs.is_empty() {
        return Route::of(vec![Leg {
            link,
            from: s,
            to: s,
        }]);
    }
    Route::of(legs)
}

/// The legs of walking `len` metres from (`link`, `s`), toward `b` when `forward`.
fn walk(
    net: &Network,
    mut link: usize,
    mut s: f64,
    mut forward: bool,
    len: f64,
    straight: f64,
    rng: &mut impl rand::Rng,
) -> Vec<Leg> {
    let mut legs = Vec::new();
    let mut left = len.max(0.0);
    while left > 0.0 && legs.len() < MAX_LEGS {
        let l = &net.links[link];
        let end = if forward { l.len } else { 0.0 };
        let room = (end - s).abs();
        if room >= left {
            let to = if forward { s + left } else { s - left };
            legs.push(Leg { link, from: s, to });
            break;
        }
        legs.push(Leg {
            link,
            from: s,
            to: end,
        });
        left -= room;
        let node = l.ends[usize::from(forward)];
        let heading = if forward { l.dir() } else { -l.dir() };
        match next_link(net, node, link, heading, straight, rng) {
            Some(n) => {
                link = n;
                forward = net.links[n].ends[0] == node;
                s = if forward { 0.0 } else { net.links[n].len };
            }
            // A dead end: turn round.
            None => {
                forward = !forward;
                s = end;
            }
        }
    }
    legs
}

/// The link a walker arriving at `node` along `from`, walking `heading`, goes on into:
/// another of the node's links, weighted by `exp(straight * cos(turn))`; `None` at a dead end.
fn next_link(
    net: &Network,
    node: usize,
    from: usize,
    heading: Coord<f64>,
    straight: f64,
    rng: &mut impl rand::Rng,
) -> Option<usize> {
    let choices: Vec<(usize, f64)> = net.nodes[node]
        .links
        .iter()
        .filter(|&&l| l != from)
        .map(|&l| {
            let link = &net.links[l];
            let out = if link.ends[0] == node {
                link.dir()
            } else {
                -link.dir()
            };
            let cos = (out.x * heading.x + out.y * heading.y).clamp(-1.0, 1.0);
            (l, (straight * cos).exp())
        })
        .collect();
    let total: f64 = choices.iter().map(|c| c.1).sum();
    if choices.is_empty() || !(total > 0.0 && total.is_finite()) {
        return choices.first().map(|c| c.0);
    }
    let mut r = rng.random::<f64>() * total;
    for &(l, w) in &choices {
        if r < w {
            return Some(l);
        }
        r -= w;
    }
    choices.last().map(|c| c.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyse::crowds::network::network;
    use crate::model::{Dataset, Street};
    use geo_types::LineString;

    fn cross() -> Network {
        let street = |id: &str, pts: Vec<[f64; 2]>| Street {
            id: id.into(),
            line: LineString::from(pts),
            width: 6.0,
        };
        let data = Dataset {
            streets: vec![
                street("a", vec![[0.0, 50.0], [100.0, 50.0]]),
                street("b", vec![[50.0, 0.0], [50.0, 100.0]]),
            ],
            ..Dataset::default()
        };
        network(&data, 0.5)
    }

    #[test]
    fn a_route_is_as_long_as_asked_and_continuous() {
        let net = cross();
        for seed in 0..20 {
            let mut rng = crate::rng::feature_rng(seed, "t", "route");
            let r = route(&net, 0, 10.0, true, [5.0, 120.0], 2.0, &mut rng);
            assert!((r.len - 125.0).abs() < 1e-9, "{}", r.len);
            // The walker at time 0 stands 5 m along it, at (10, 50).
            let p = r.at(&net, 5.0).at;
            assert!((p.x - 10.0).abs() < 1e-9 && (p.y - 50.0).abs() < 1e-9);
            let mut last = r.at(&net, 0.0).at;
            for k in 1..=250 {
                let p = r.at(&net, k as f64 * 0.5).at;
                assert!(
                    (p - last).x.hypot((p - last).y) <= 0.5 + 1e-9,
                    "jump at {k}"
                );
                last = p;
            }
        }
    }

    #[test]
    fn walkers_go_on_straight_more_often_than_they_turn() {
        let net = cross();
        let hub = net.nodes.iter().position(|n| n.links.len() == 4).unwrap();
        let from = net.nodes[hub].links[0];
        let l = &net.links[from];
        let heading = if l.ends[1] == hub { l.dir() } else { -l.dir() };
        let mut rng = crate::rng::feature_rng(1, "t", "turns");
        let mut straight_on = 0;
        for _ in 0..1000 {
            let n = next_link(&net, hub, from, heading, 2.0, &mut rng).unwrap();
            let o = &net.links[n];
            let out = if o.ends[0] == hub { o.dir() } else { -o.dir() };
            if out.x * heading.x + out.y * heading.y > 0.9 {
                straight_on += 1;
            }
        }
        // exp(2) / (exp(2) + 2): 79 %.
        assert!((740..840).contains(&straight_on), "{straight_on}");
        // A dead end has no way on.
        let end = net.nodes.iter().position(|n| n.links.len() == 1).unwrap();
        let only = net.nodes[end].links[0];
        assert_eq!(next_link(&net, end, only, heading, 2.0, &mut rng), None);
    }

    #[test]
    fn a_walker_turns_round_at_a_dead_end() {
        let net = cross();
        let end = net.nodes.iter().position(|n| n.links.len() == 1).unwrap();
        let link = net.nodes[end].links[0];
        let l = &net.links[link];
        let toward_end = l.ends[1] == end;
        let s = if toward_end { l.len - 10.0 } else { 10.0 };
        let mut rng = crate::rng::feature_rng(1, "t", "dead end");
        let r = route(&net, link, s, toward_end, [0.0, 30.0], 2.0, &mut rng);
        let p = r.at(&net, 30.0).at;
        let start = r.at(&net, 0.0).at;
        // 10 m to the end and 20 back: 10 m behind where it started.
        assert!(((p - start).x.hypot((p - start).y) - 10.0).abs() < 1e-9);
    }
}
