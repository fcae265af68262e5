//! `[crowd]`: the street crowds of `people.motion = "boids"` (seed 004), in metres and
//! seconds, scaled to people: a person keeps about an arm's length (r0), walks with those
//! within a few steps (r1) and toward those a little farther (r2), at a walking pace.

use serde::{Deserialize, Serialize};

/// The crowd model's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrowdParams {
    /// Separation zone, metres.
    pub r0: f64,
    /// Alignment zone, metres (also the distance scale of lambda2 and lambda3).
    pub r1: f64,
    /// Cohesion zone, metres; beyond it a person walks on at random.
    pub r2: f64,
    /// Walking speeds, metres per second: [slowest, fastest].
    pub speed: [f64; 2],
    /// Steps simulated before the people are placed where the crowd has walked to.
    pub steps: usize,
    /// Length of a step, seconds.
    pub dt: f64,
    /// The order parameters reported are also averaged over this many last steps.
    pub last_steps: usize,
    /// Weights of separation, alignment and cohesion, per second.
    pub weights: [f64; 3],
    /// Largest random turn per second of a person with nobody near (radians).
    pub wander: f64,
    /// People set out in groups of a size drawn uniformly from [smallest, largest]: the
    /// members of a group (neighbours in the process's order) start out the way the first
    /// of them faces.
    pub group: [usize; 2],
}

/// The most steps a build simulates per street (a typo of 1e9 steps would run for days).
pub const MAX_STEPS: usize = 100_000;

impl CrowdParams {
    /// The boids model of these settings.
    pub fn model(&self) -> crate::growers::boids::BoidParams {
        crate::growers::boids::BoidParams {
            r0: self.r0,
            r1: self.r1,
            r2: self.r2,
            min_speed: self.speed[0],
            max_speed: self.speed[1],
            dt: self.dt,
            separation: self.weights[0],
            alignment: self.weights[1],
            cohesion: self.weights[2],
            wander: self.wander,
        }
    }

    pub(super) fn validate(&self) -> Result<(), String> {
        if let Some(why) = self.model().problem() {
            return Err(format!("`[crowd]`: {why}"));
        }
        if self.r2 > 100.0 || self.speed[1] > 20.0 || self.dt > 60.0 {
            return Err("`[crowd]`: r2 up to 100 m, speeds up to 20 m/s and dt up to 60 s".into());
        }
        if self.group[0] == 0 || self.group[0] > self.group[1] || self.group[1] > 100 {
            return Err(format!(
                "`crowd.group` must be [smallest, largest] with 1 <= smallest <= largest <= \
                 100, got [{}, {}]",
                self.group[0], self.group[1]
            ));
        }
        if self.steps > MAX_STEPS || self.last_steps > self.steps.max(1) {
            return Err(format!(
                "`crowd.steps` must be at most {MAX_STEPS} and `crowd.last_steps` at most \
                 `crowd.steps`, got {} and {}",
                self.steps, self.last_steps
            ));
        }
        Ok(())
    }
}

/// The same table with every field optional, for checking a user's partial file.
pub(super) mod partial {
    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Crowd {
        r0: Option<f64>,
        r1: Option<f64>,
        r2: Option<f64>,
        speed: Option<[f64; 2]>,
        steps: Option<usize>,
        dt: Option<f64>,
        last_steps: Option<usize>,
        weights: Option<[f64; 3]>,
        wander: Option<f64>,
        group: Option<[usize; 2]>,
    }
}
