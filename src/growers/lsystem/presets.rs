//! The seed's examples as presets of `edo-city lsystem --preset`: its branching tree FFFA, the
//! Koch curve, the Sierpinski gasket, and a phyllotaxis disc (r = c sqrt(n), phi = n x the
//! golden angle) written as a parametric L-system.

/// The golden angle, degrees: 360 (1 - 1/phi), phi = (1 + sqrt 5) / 2.
pub const GOLDEN_ANGLE: f64 = 137.507_764_050_037_85;

/// One of the seed's examples.
#[derive(Debug, Clone, PartialEq)]
pub struct Preset {
    /// Its name (`fffa`, `koch`, `sierpinski`, `phyllotaxis`).
    pub name: &'static str,
    /// The axiom.
    pub axiom: &'static str,
    /// The rules.
    pub rules: &'static [&'static str],
    /// The turning angle, degrees.
    pub angle: f64,
    /// The generations the seed draws (or a readable number).
    pub generations: usize,
    /// Whether it draws in a plane (an SVG shows it whole).
    pub planar: bool,
}

/// The presets, by name.
pub const PRESETS: &[Preset] = &[
    // The seed's tree: "premise: FFFA A=[&FFFA]////[&FFFA]///[&FFFA]", bent by 30 degrees.
    // Its rolls are 4 x 30 = 120 and 3 x 30 = 90 degrees, so the three branches stand at
    // azimuths 0, 120 and 210 degrees, not an even 120: we follow the formula.
    Preset {
        name: "fffa",
        axiom: "FFFA",
        rules: &["A=[&FFFA]////[&FFFA]///[&FFFA]"],
        angle: 30.0,
        generations: 3,
        planar: false,
    },
    Preset {
        name: "koch",
        axiom: "F",
        rules: &["F=F-F++F-F"],
        angle: 60.0,
        generations: 4,
        planar: true,
    },
    Preset {
        name: "sierpinski",
        axiom: "F-F-F",
        rules: &["F=F-F+F+F-F"],
        angle: 120.0,
        generations: 5,
        planar: true,
    },
    // One seed per generation: the n-th at angle n x 137.5078 degrees and radius sqrt(n)
    // steps (c = the step).
    Preset {
        name: "phyllotaxis",
        axiom: "A(0)",
        rules: &["A(n)=[+(n*137.50776405003785)f(sqrt(n))@]A(n+1)"],
        angle: GOLDEN_ANGLE,
        generations: 500,
        planar: true,
    },
];

/// The preset called `name`.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::growers::lsystem::{LSystem, TurtleParams, DEFAULT_MAX_SYMBOLS};
    use crate::growers::skeleton::Skeleton;
    use crate::growers::v3;
    use rand::SeedableRng;
    use rand_pcg::Pcg64;

    fn run(name: &str, n: usize) -> (String, Skeleton) {
        let p = preset(name).unwrap();
        let rules: Vec<String> = p.rules.iter().map(|r| r.to_string()).collect();
        let sys = LSystem::parse(p.axiom, &rules, n, DEFAULT_MAX_SYMBOLS).unwrap();
        let mut rng = Pcg64::seed_from_u64(0);
        let word = sys.expand(&mut rng).unwrap();
        let turtle = TurtleParams {
            angle: p.angle,
            ..TurtleParams::default()
        };
        (
            word.to_text(),
            crate::growers::lsystem::turtle::interpret(&word, &turtle),
        )
    }

    fn count_f(s: &str) -> usize {
        s.chars().filter(|&c| c == 'F').count()
    }

    #[test]
    fn fffa_grows_4_plus_27_halves_of_3n_minus_1_symbols_and_3n_tips() {
        for n in 1..=5u32 {
            let (s, sk) = run("fffa", n as usize);
            let want = 4 + 27 * (3usize.pow(n) - 1) / 2;
            assert_eq!(s.chars().count(), want, "n = {n}");
            assert_eq!(sk.tips().len(), 3usize.pow(n), "n = {n}");
        }
        assert_eq!(run("fffa", 1).0.len(), 31);
        assert_eq!(run("fffa", 2).0.len(), 112);
        assert_eq!(run("fffa", 3).0.len(), 355);
    }

    #[test]
    fn fffa_branches_stand_at_azimuths_0_120_and_210_degrees() {
        let (_, sk) = run("fffa", 1);
        let fork = sk.nodes[3].at;
        let mut az: Vec<f64> = sk
            .tips()
            .iter()
            .map(|&t| {
                let d = v3::sub(sk.nodes[t].at, fork);
                d[1].atan2(d[0]).to_degrees()
            })
            .collect();
        let first = az[0];
        for a in &mut az {
            *a = (*a - first).rem_euclid(360.0);
        }
        // The rolls turn the frame clockwise seen from above (`/` is roll right).
        let want = [0.0, 360.0 - 120.0, 360.0 - 210.0];
        for (a, w) in az.iter().zip(want) {
            assert!((a - w).abs() < 1e-9, "{az:?}");
        }
    }

    #[test]
    fn koch_has_4n_segments_and_ends_3n_steps_away() {
        for n in 0..=6u32 {
            let (s, sk) = run("koch", n as usize);
            assert_eq!(count_f(&s), 4usize.pow(n));
            let end = sk.nodes.last().unwrap().at;
            assert!(
                (v3::norm(end) - 3f64.powi(n as i32)).abs() < 1e-9,
                "n = {n}"
            );
        }
    }

    #[test]
    fn sierpinski_has_3_times_5n_segments_and_closes() {
        for n in 0..=5u32 {
            let (s, sk) = run("sierpinski", n as usize);
            assert_eq!(count_f(&s), 3 * 5usize.pow(n));
            let end = sk.nodes.last().unwrap().at;
            assert!(v3::norm(end) < 1e-9, "n = {n}: {end:?}");
        }
    }

    fn disc(n: usize) -> Vec<[f64; 2]> {
        let (_, sk) = run("phyllotaxis", n);
        // Planar: the disc is drawn in the x-z plane.
        sk.dots.iter().map(|d| [d[0], d[2]]).collect()
    }

    #[test]
    fn phyllotaxis_puts_r_squared_seeds_within_radius_r() {
        let pts = disc(2000);
        assert_eq!(pts.len(), 2000);
        for r in [20.0f64, 30.0, 40.0] {
            let inside = pts.iter().filter(|p| p[0].hypot(p[1]) <= r).count() as f64;
            assert!((inside / (r * r) - 1.0).abs() < 0.01, "R = {r}: {inside}");
        }
        // The golden angle between successive seeds.
        let a = |k: usize| pts[k][1].atan2(pts[k][0]);
        let turn = (a(101) - a(100)).to_degrees().rem_euclid(360.0);
        assert!((turn - GOLDEN_ANGLE).abs() < 1e-6, "{turn}");
    }

    #[test]
    fn phyllotaxis_spirals_count_successive_fibonacci_numbers() {
        // A seed's nearest neighbour is n seeds away along one family of spirals
        // (parastichies): the number of spirals of that family. Going outward the count climbs
        // the Fibonacci sequence one step at a time.
        let pts = disc(2000);
        let fib = [1usize, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144];
        let mut seen = Vec::new();
        for k in (20..2000).step_by(7) {
            let best = (0..pts.len())
                .filter(|&j| j != k)
                .min_by(|&i, &j| {
                    let d = |x: usize| (pts[x][0] - pts[k][0]).hypot(pts[x][1] - pts[k][1]);
                    d(i).total_cmp(&d(j))
                })
                .unwrap();
            let gap = best.abs_diff(k);
            assert!(fib.contains(&gap), "seed {k}: nearest is {gap} away");
            if seen.last() != Some(&gap) {
                seen.push(gap);
            }
        }
        // Successive counts are successive Fibonacci numbers, rising outward (the
        // neighbourhood flips between two families near a transition, so keep the maxima).
        let mut rising: Vec<usize> = Vec::new();
        for g in seen {
            if rising.last().is_none_or(|&l| g > l) {
                rising.push(g);
            }
        }
        assert!(rising.len() >= 4, "{rising:?}");
        for w in rising.windows(2) {
            let i = fib.iter().position(|&f| f == w[0]).unwrap();
            assert_eq!(fib[i + 1], w[1], "{rising:?}");
        }
    }
}
