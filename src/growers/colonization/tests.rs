//! The closed-form checks of issue 21 on the grower alone.

use rand::SeedableRng;
use rand_pcg::Pcg64;

use super::*;

fn crown() -> Vec<Group> {
    vec![
        Group {
            name: "trunk".into(),
            envelope: Envelope::Cylinder {
                base: 0.5,
                top: 4.0,
                radius: 0.3,
            },
            points: 60,
            attach: Attach::Base,
            weight: Some(0.0),
        },
        Group {
            name: "branches".into(),
            envelope: Envelope::Ellipsoid {
                center: [0.0, 0.0, 7.0],
                radii: [4.0, 4.0, 3.0],
            },
            points: 2000,
            attach: Attach::Stem(0.6, 1.0),
            weight: None,
        },
        Group {
            name: "roots".into(),
            envelope: Envelope::BelowGround {
                radii: [3.0, 3.0, 1.0],
            },
            points: 300,
            attach: Attach::Base,
            weight: Some(0.0),
        },
    ]
}

fn run(p: &Params, groups: &[Group], seed: u64) -> (Skeleton, Vec<GroupReport>) {
    grow(p, groups, &mut Pcg64::seed_from_u64(seed)).unwrap()
}

#[test]
fn every_edge_is_one_step_and_every_group_is_a_tree() {
    let p = Params::with_step(0.25);
    let (sk, reports) = run(&p, &crown(), 1);
    for (i, n) in sk.nodes.iter().enumerate() {
        if let Some(q) = n.parent {
            assert!((q as usize) < i, "parents precede children");
            let len = v3::dist(n.at, sk.nodes[q as usize].at);
            assert!((len - 0.25).abs() < 1e-9, "edge {i}: {len}");
        }
    }
    for r in &reports {
        assert_eq!(r.nodes, r.edges + 1, "{}", r.name);
        assert_eq!(r.members.len(), r.nodes, "{}", r.name);
        let inside = r.members[1..]
            .iter()
            .filter(|&&m| {
                sk.nodes[m as usize]
                    .parent
                    .is_some_and(|q| r.members.contains(&q))
            })
            .count();
        assert_eq!(inside, r.edges, "{}: every edge joins two members", r.name);
        assert!(["all_killed", "none_in_range", "stalled", "max_iter"].contains(&r.stop.as_str()));
    }
    assert!(
        reports[2].members[1..]
            .iter()
            .all(|&m| sk.nodes[m as usize].at[2] < 0.1),
        "roots grow below ground"
    );
}

#[test]
fn no_surviving_point_lies_within_kill_of_a_node() {
    let p = Params::with_step(0.3);
    let env = Envelope::Ellipsoid {
        center: [0.0, 0.0, 5.0],
        radii: [3.0, 3.0, 2.0],
    };
    let points = env.sample(800, &mut Pcg64::seed_from_u64(4)).unwrap();
    let mut g = Graph::default();
    g.push([0.0; 3], None);
    let r = colonize(&mut g, &[0], &points, &env, &p);
    assert!(r.points_left < 800);
    // Recount the survivors by brute force: none within d_k of any node.
    let survivors: Vec<&V3> = points
        .iter()
        .filter(|q| g.at.iter().all(|n| v3::dist(*n, **q) >= p.kill))
        .collect();
    assert_eq!(survivors.len(), r.points_left);
    if r.points_left == 0 {
        assert_eq!(r.stop, Stop::AllKilled);
    }
}

#[test]
fn zero_weight_is_plain_colonization_to_the_byte() {
    let plain = Params::with_step(0.25);
    let windy = Params {
        field: Field::Constant([1.0, 0.0, 0.0]),
        weight: 0.0,
        twist: 0.7,
        ..plain
    };
    let a = run(&plain, &crown(), 7).0;
    let b = run(&windy, &crown(), 7).0;
    assert_eq!(a, b);
}

#[test]
fn a_strong_constant_field_points_the_tips_its_way() {
    let wind = v3::unit([1.0, 0.0, 0.3]).unwrap();
    let p = Params {
        field: Field::Constant(wind),
        weight: 8.0,
        ..Params::with_step(0.25)
    };
    let (sk, reports) = run(&p, &crown()[..2], 3);
    let branches: std::collections::HashSet<u32> = reports[1].members.iter().copied().collect();
    let mut mean = [0.0; 3];
    for t in sk.tips() {
        if !branches.contains(&(t as u32)) {
            continue;
        }
        let q = sk.nodes[t].parent.unwrap() as usize;
        mean = v3::add(
            mean,
            v3::unit(v3::sub(sk.nodes[t].at, sk.nodes[q].at)).unwrap(),
        );
    }
    let mean = v3::unit(mean).unwrap();
    let angle = v3::dot(mean, wind).clamp(-1.0, 1.0).acos().to_degrees();
    assert!(
        angle < 15.0,
        "mean tip direction {angle} degrees from the field"
    );
}

#[test]
fn radii_keep_the_pipe_rule_at_every_node() {
    let (mut sk, _) = run(&Params::with_step(0.3), &crown(), 2);
    let e = 2.5;
    sk.pipe_radii(0.01, e);
    let mut sum = vec![0.0; sk.nodes.len()];
    for n in &sk.nodes {
        if let Some(q) = n.parent {
            sum[q as usize] += n.radius.powf(e);
        }
    }
    for (i, n) in sk.nodes.iter().enumerate() {
        if sum[i] > 0.0 {
            assert!(
                (n.radius.powf(e) - sum[i]).abs() < 1e-9 * sum[i].max(1.0),
                "node {i}"
            );
        }
    }
}

#[test]
fn the_same_seed_grows_the_same_tree() {
    let p = Params::with_step(0.3);
    assert_eq!(run(&p, &crown(), 5).0, run(&p, &crown(), 5).0);
    assert_ne!(run(&p, &crown(), 5).0, run(&p, &crown(), 6).0);
}

#[test]
fn a_max_iter_stop_is_reported() {
    let p = Params {
        max_iter: 3,
        ..Params::with_step(0.2)
    };
    let (_, r) = run(&p, &crown()[1..2], 1);
    assert_eq!(r[0].stop, Stop::MaxIter);
    assert_eq!(r[0].iterations, 3);
}

#[test]
fn two_points_either_side_do_not_make_a_node_oscillate() {
    // One node between two points at equal distance across: the pull sums to zero, so it
    // keeps its heading (up); it never grows back onto its parent.
    let env = Envelope::Cylinder {
        base: 0.0,
        top: 1.0,
        radius: 1.0,
    };
    let mut g = Graph::default();
    g.push([0.0; 3], None);
    let points = vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]];
    let p = Params {
        max_iter: 50,
        ..Params::with_step(0.1)
    };
    let r = colonize(&mut g, &[0], &points, &env, &p);
    for (i, at) in g.at.iter().enumerate().skip(1) {
        let q = g.parent[i].unwrap() as usize;
        assert!(v3::dist(*at, g.at[q]) > 0.099);
    }
    assert!(matches!(
        r.stop,
        Stop::AllKilled | Stop::NoneInRange | Stop::Stalled | Stop::MaxIter
    ));
}
