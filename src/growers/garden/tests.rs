//! The closed-form checks of issue 23 on the designer alone.

use rand::SeedableRng;
use rand_pcg::Pcg64;

use super::ga::{self, GaParams, Population};
use super::rules::{self, WEIGHTS};
use super::*;

#[test]
fn the_weights_are_the_seeds() {
    assert_eq!(
        WEIGHTS,
        [
            ("centre", 1.54),
            ("triangles", 1.32),
            ("opposition", 0.53),
            ("adjacency", 2.0),
            ("axis", 1.22)
        ]
    );
}

/// Three stones, obtuse and scalene, far from the centre, shin between the others so the
/// axis of the open space runs through the garden toward the viewpoint.
fn good() -> (Layout, Settings) {
    let mut s = Settings::sized(20.0, 20.0);
    s.groups = vec![3];
    let st = |x: f64, y: f64, size: f64, k: usize| Stone {
        x,
        y,
        size,
        group: 0,
        role: Role::of(k),
    };
    let l = Layout {
        stones: vec![
            st(3.0, 4.0, 1.0, 0),
            st(2.0, 3.5, 0.6, 1),
            st(4.5, 3.3, 0.5, 2),
        ],
    };
    (l, s)
}

#[test]
fn a_layout_meeting_every_rule_scores_no_violation() {
    let (l, mut s) = good();
    // The open space's axis then points at a viewpoint set on it.
    let (c, d) = medial::main_axis(&medial::ridge(&l, &s)).unwrap();
    s.viewpoint = [c[0] + 30.0 * d[0], c[1] + 30.0 * d[1]];
    let scores = rules::scores(&l, &s);
    assert_eq!(scores[..4], [0.0; 4], "{scores:?}");
    assert!(scores[4] < 1e-9, "{scores:?}");
    assert!(rules::fitness(&scores) >= 1e8);
}

#[test]
fn a_stone_moved_d_into_the_centre_zone_adds_exactly_1_54_d() {
    let (mut l, s) = good();
    let base = rules::scores(&l, &s)[0];
    // Put the tai on the zone's edge, then move it d toward the centre.
    let c = [s.width / 2.0, s.depth / 2.0];
    l.stones[2].x = c[0] + s.centre_radius;
    l.stones[2].y = c[1];
    let edge = rules::scores(&l, &s);
    for d in [0.1, 0.5, 1.2] {
        let mut m = l.clone();
        m.stones[2].x -= d;
        let moved = rules::scores(&m, &s);
        let added = 1.54 * (moved[0] - edge[0]);
        assert!((added - 1.54 * d).abs() < 1e-12, "d = {d}: {added}");
        assert!(
            (rules::violation(&moved) - rules::violation(&edge) - 1.54 * d).abs() < 1e-9
                || moved[1..] != edge[1..]
        );
    }
    assert_eq!(base, 0.0);
}

#[test]
fn the_best_fitness_never_decreases_and_stones_stay_legal() {
    let s = Settings::seed();
    let p = GaParams::default();
    let (pop, history) = ga::run(&s, &p, 40, &mut Pcg64::seed_from_u64(1));
    for w in history.windows(2) {
        assert!(w[1] >= w[0], "{history:?}");
    }
    assert!(history.last() > history.first());
    for c in &pop.members {
        assert!(is_legal(&c.layout, &s));
    }
}

#[test]
fn the_best_after_a_long_run_has_obtuse_scalene_triangles() {
    let s = Settings::seed();
    let (pop, _) = ga::run(&s, &GaParams::default(), 150, &mut Pcg64::seed_from_u64(2));
    let best = &pop.best().layout;
    // Each group's triangle (shin, soe, tai); the triangle of the groups' shins is scored
    // too, but trades off against opposition and the axis.
    let groups = best.groups();
    for t in groups
        .iter()
        .filter(|g| g.len() >= 3)
        .map(|g| [g[0], g[1], g[2]])
    {
        assert!(
            rules::angle_at(best, t[0], t[1], t[2]) > std::f64::consts::FRAC_PI_2,
            "{t:?}"
        );
        assert!(
            rules::triangle_degree(best, t) < 0.05,
            "{t:?}: {}",
            rules::triangle_degree(best, t)
        );
    }
}

#[test]
fn ryoanji_beats_nearly_every_random_layout() {
    let (l, s) = ryoanji();
    assert!(is_legal(&l, &s));
    let ours = rules::fitness(&rules::scores(&l, &s));
    let mut rng = Pcg64::seed_from_u64(9);
    let worse = (0..400)
        .filter(|_| rules::fitness(&rules::scores(&random_layout(&s, &mut rng), &s)) < ours)
        .count();
    assert!(worse >= 380, "Ryoanji beats {worse} of 400 random layouts");
}

#[test]
fn the_same_seed_designs_the_same_garden() {
    let s = Settings::seed();
    let p = GaParams {
        population: 30,
        ..GaParams::default()
    };
    let a = ga::run(&s, &p, 10, &mut Pcg64::seed_from_u64(4))
        .0
        .best()
        .clone();
    let b = ga::run(&s, &p, 10, &mut Pcg64::seed_from_u64(4))
        .0
        .best()
        .clone();
    assert_eq!(a, b);
}

#[test]
fn picks_are_kept_and_bred_from() {
    let s = Settings::seed();
    let p = GaParams {
        population: 20,
        ..GaParams::default()
    };
    let mut rng = Pcg64::seed_from_u64(5);
    let pop = Population::random(&s, &p, &mut rng);
    let picked = pop.members[7].layout.clone();
    let next = pop.next_from(&[7], &s, &p, &mut rng);
    assert!(next.members.iter().any(|c| c.layout == picked));
    // With one parent, every child is a mutant of it: most stones stay where they were.
    let same = next
        .members
        .iter()
        .filter(|c| {
            c.layout
                .stones
                .iter()
                .zip(&picked.stones)
                .filter(|(a, b)| a == b)
                .count()
                >= 10
        })
        .count();
    assert!(same >= 10, "{same}");
}

#[test]
fn sizes_follow_zipf() {
    let s = Settings::seed();
    let (slope, r2) = zipf_fit(&random_layout(&s, &mut Pcg64::seed_from_u64(3)));
    assert!((slope + s.zipf).abs() < 0.25, "{slope}");
    assert!(r2 > 0.9, "{r2}");
}

/// A child copied from a parent takes the parent's scores instead of being scored again: over
/// generations of the city's GA every layout's scores are still exactly what scoring it gives,
/// and copies did happen (or the shortcut was never tried).
#[test]
fn scores_carried_from_a_parent_are_the_layouts_own() {
    let s = Settings::sized(12.0, 8.0);
    let p = GaParams {
        population: 30,
        gathered: true,
        ..GaParams::default()
    };
    let mut rng = Pcg64::seed_from_u64(7);
    let mut pop = Population::random(&s, &p, &mut rng);
    let mut copies = 0;
    for _ in 0..15 {
        let next = pop.next(&s, &p, &mut rng);
        for c in &next.members {
            let fresh = rules::scores(&c.layout, &s);
            assert_eq!(c.scores.map(f64::to_bits), fresh.map(f64::to_bits));
            assert_eq!(c.fitness.to_bits(), rules::fitness(&fresh).to_bits());
        }
        // The elites are carried over; any other layout of the last generation is a copy.
        let carried = (next.members.iter())
            .filter(|c| pop.members.iter().any(|m| m.layout == c.layout))
            .count();
        copies += carried.saturating_sub(p.elite);
        pop = next;
    }
    assert!(
        copies > 0,
        "no child was a copy of a parent in 15 generations"
    );
}
