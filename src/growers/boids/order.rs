//! The order parameters of Oyama et al. (seed 004, eqs. 1-5), as printed: over all ordered
//! pairs i != j of the N agents,
//!
//! - lambda1 = mean cos(theta_ij), theta_ij the angle between the headings of i and j;
//! - lambda2 = mean D_ij, with D_ij = 1 when r_ij <= r1, else r1 / r_ij;
//! - lambda3 = mean D_ij cos(theta_ij).
//!
//! The seed names its third definition "lambda1" again (Definition 2.3, eq. 4); it is lambda3
//! here. lambda1 is exact for any N through |sum of headings|^2 - N = sum over i != j of
//! cos(theta_ij). lambda2 and lambda3 are exact (all pairs) up to [`MAX_EXACT`] agents; above,
//! they are taken over the pairs of [`MAX_EXACT`] agents chosen at an even stride of the index
//! order, a fixed sample (so the result is still deterministic). With fewer than two agents
//! there is no pair and every parameter is 0.

use super::Boid;

/// The most agents whose pairs are all counted (16 million ordered pairs, a few tens of ms).
pub const MAX_EXACT: usize = 4000;

/// lambda1-3 of one moment.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Lambdas {
    /// Mean cos of the angle between headings (eq. 1).
    pub lambda1: f64,
    /// Mean closeness D (eqs. 2-3).
    pub lambda2: f64,
    /// Mean closeness times cos (eqs. 4-5).
    pub lambda3: f64,
}

/// The order parameters of `boids` with the alignment radius `r1`.
///
/// ```
/// use edo_city::growers::boids::{order_parameters, Boid};
/// let b = |x: f64, h: [f64; 2]| Boid { pos: [x, 0.0], heading: h, speed: 1.0 };
/// // Two agents 160 apart facing opposite ways, r1 = 80: cos = -1, D = 1/2.
/// let l = order_parameters(&[b(0.0, [1.0, 0.0]), b(160.0, [-1.0, 0.0])], 80.0);
/// assert_eq!((l.lambda1, l.lambda2, l.lambda3), (-1.0, 0.5, -0.5));
/// ```
pub fn order_parameters(boids: &[Boid], r1: f64) -> Lambdas {
    let n = boids.len();
    if n < 2 {
        return Lambdas::default();
    }
    let sum = boids.iter().fold([0.0, 0.0], |s, b| {
        [s[0] + b.heading[0], s[1] + b.heading[1]]
    });
    let lambda1 = ((sum[0] * sum[0] + sum[1] * sum[1]) - n as f64) / (n as f64 * (n as f64 - 1.0));
    let sample: Vec<&Boid> = match n <= MAX_EXACT {
        true => boids.iter().collect(),
        false => (0..MAX_EXACT).map(|k| &boids[k * n / MAX_EXACT]).collect(),
    };
    let m = sample.len();
    let (mut d_sum, mut dc_sum) = (0.0, 0.0);
    for i in 0..m {
        for j in (i + 1)..m {
            let (a, b) = (sample[i], sample[j]);
            let r = ((a.pos[0] - b.pos[0]).powi(2) + (a.pos[1] - b.pos[1]).powi(2)).sqrt();
            let d = if r <= r1 { 1.0 } else { r1 / r };
            let cos = a.heading[0] * b.heading[0] + a.heading[1] * b.heading[1];
            d_sum += d;
            dc_sum += d * cos;
        }
    }
    // Each unordered pair stands for its two ordered ones.
    let pairs = (m * (m - 1)) as f64 / 2.0;
    Lambdas {
        lambda1: lambda1.clamp(-1.0, 1.0),
        lambda2: d_sum / pairs,
        lambda3: dc_sum / pairs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    fn at(x: f64, y: f64, angle: f64) -> Boid {
        Boid {
            pos: [x, y],
            heading: [angle.cos(), angle.sin()],
            speed: 1.0,
        }
    }

    #[test]
    fn equal_headings_give_lambda1_one_and_a_tight_group_lambda2_one() {
        let flock: Vec<Boid> = (0..7).map(|i| at(i as f64 * 5.0, 0.0, 0.7)).collect();
        let l = order_parameters(&flock, 80.0);
        assert!((l.lambda1 - 1.0).abs() < 1e-12);
        assert_eq!(l.lambda2, 1.0, "every pair within r1");
        assert!((l.lambda3 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn two_agents_facing_opposite_ways_give_minus_one() {
        let l = order_parameters(
            &[at(0.0, 0.0, 0.0), at(1.0, 0.0, std::f64::consts::PI)],
            80.0,
        );
        assert!((l.lambda1 + 1.0).abs() < 1e-12);
        assert!((l.lambda3 + 1.0).abs() < 1e-12);
    }

    #[test]
    fn lambda1_by_the_sum_of_headings_equals_the_pairwise_mean() {
        let mut r = crate::rng::feature_rng(5, "t", "t");
        let flock: Vec<Boid> = (0..40)
            .map(|_| {
                at(
                    r.random_range(0.0..500.0),
                    r.random_range(0.0..300.0),
                    r.random_range(0.0..6.3),
                )
            })
            .collect();
        let mut s = 0.0;
        for (i, a) in flock.iter().enumerate() {
            for (j, b) in flock.iter().enumerate() {
                if i != j {
                    s += a.heading[0] * b.heading[0] + a.heading[1] * b.heading[1];
                }
            }
        }
        let pairwise = s / (40.0 * 39.0);
        assert!((order_parameters(&flock, 80.0).lambda1 - pairwise).abs() < 1e-12);
    }

    #[test]
    fn no_pair_gives_zeros_not_nan() {
        assert_eq!(order_parameters(&[], 80.0), Lambdas::default());
        assert_eq!(
            order_parameters(&[at(1.0, 1.0, 0.0)], 80.0),
            Lambdas::default()
        );
        // Coincident agents: D = 1.
        let l = order_parameters(&[at(1.0, 1.0, 0.0), at(1.0, 1.0, 0.0)], 80.0);
        assert_eq!((l.lambda1, l.lambda2, l.lambda3), (1.0, 1.0, 1.0));
    }

    /// E[D] for two points uniform in 500 x 300 and r1 = 80, by Monte Carlo over independent
    /// pairs (1e6 of them: standard error 3e-4).
    fn expected_d() -> f64 {
        let mut r = crate::rng::feature_rng(17, "mc", "pairs");
        let n = 1_000_000;
        let mut s = 0.0;
        for _ in 0..n {
            let (x1, y1): (f64, f64) = (r.random_range(0.0..500.0), r.random_range(0.0..300.0));
            let (x2, y2): (f64, f64) = (r.random_range(0.0..500.0), r.random_range(0.0..300.0));
            let d: f64 = ((x1 - x2) * (x1 - x2) + (y1 - y2) * (y1 - y2)).sqrt();
            s += if d <= 80.0 { 1.0 } else { 80.0 / d };
        }
        s / n as f64
    }

    #[test]
    fn random_layouts_match_the_monte_carlo_baseline_not_the_seeds_figures() {
        // What the printed formulas give for the seed's random system; the seed reports
        // R-lambda1 ~ 0.6 and R-lambda2,3 ~ 0.13-0.15 (docs/crowds.md).
        let e_d = expected_d();
        assert!((e_d - 0.483).abs() < 0.003, "E[D] = {e_d}");
        let mut r = crate::rng::feature_rng(18, "mc", "layouts");
        let (mut l1, mut l2, mut l3) = (0.0, 0.0, 0.0);
        let layouts = 4000;
        for _ in 0..layouts {
            let flock: Vec<Boid> = (0..10)
                .map(|_| {
                    at(
                        r.random_range(0.0..500.0),
                        r.random_range(0.0..300.0),
                        r.random_range(0.0..std::f64::consts::TAU),
                    )
                })
                .collect();
            let l = order_parameters(&flock, 80.0);
            l1 += l.lambda1 / layouts as f64;
            l2 += l.lambda2 / layouts as f64;
            l3 += l.lambda3 / layouts as f64;
        }
        assert!(l1.abs() < 0.02, "lambda1 {l1}");
        assert!((l2 - e_d).abs() < 0.02, "lambda2 {l2} against {e_d}");
        assert!(l3.abs() < 0.02, "lambda3 {l3}");
    }

    #[test]
    fn above_the_exact_limit_a_fixed_sample_is_used_and_lambda1_stays_exact() {
        let mut r = crate::rng::feature_rng(19, "t", "big");
        let flock: Vec<Boid> = (0..MAX_EXACT + 500)
            .map(|_| at(r.random_range(0.0..50.0), r.random_range(0.0..50.0), 0.3))
            .collect();
        let l = order_parameters(&flock, 80.0);
        assert!((l.lambda1 - 1.0).abs() < 1e-9);
        assert_eq!(l.lambda2, 1.0, "every sampled pair within r1");
        assert_eq!(l, order_parameters(&flock, 80.0), "the sample is fixed");
    }
}
