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
    /// Length of the looping clip the crowd walks, seconds.
    pub duration: f64,
    /// Time between the clip's keys, seconds (the simulation steps at most 0.1 s).
    pub dt: f64,
    /// Weights of separation, alignment and cohesion, per second.
    pub weights: [f64; 3],
    /// Largest random turn per second of a person with nobody near (radians).
    pub wander: f64,
    /// People set out in groups of a size drawn uniformly from [smallest, largest]: the
    /// members of a group (neighbours in the process's order) start out the way the first
    /// of them faces.
    pub group: [usize; 2],
    /// How strongly a walker at a junction prefers going on straight: each way on is drawn
    /// with weight `exp(straight * cos(turn))` (0: every way alike; 2: straight on 79 % of
    /// the time at a crossing).
    pub straight: f64,
}

/// The longest clip, seconds (a typo of 1e9 s would run for days).
pub const MAX_DURATION: f64 = 3600.0;
/// The most keys a clip has (`duration / dt`): each is a position per walker in the tiles.
pub const MAX_KEYS: usize = 20_000;

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

    /// The clip's keys after the first: the duration in steps of `dt` (at least one).
    pub fn keys(&self) -> usize {
        let k = (self.duration / self.dt).round();
        if k.is_finite() && k >= 1.0 {
            k.min(usize::MAX as f64 / 2.0) as usize
        } else {
            1
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
        if !(self.duration > 0.0 && self.duration <= MAX_DURATION) {
            return Err(format!(
                "`crowd.duration` must be more than 0 and at most {MAX_DURATION} s, got {} \
                 (it replaced `crowd.steps`: duration = steps x dt)",
                crate::model::number::Num(self.duration)
            ));
        }
        if self.dt.is_nan() || self.dt < 0.05 || self.keys() > MAX_KEYS {
            return Err(format!(
                "`crowd.dt` must be at least 0.05 s and `crowd.duration / crowd.dt` at most \
                 {MAX_KEYS} keys, got dt = {} for a clip of {} s",
                crate::model::number::Num(self.dt),
                crate::model::number::Num(self.duration)
            ));
        }
        if !(0.0..=20.0).contains(&self.straight) {
            return Err(format!(
                "`crowd.straight` must be from 0 to 20, got {}",
                crate::model::number::Num(self.straight)
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
        duration: Option<f64>,
        dt: Option<f64>,
        weights: Option<[f64; 3]>,
        wander: Option<f64>,
        group: Option<[usize; 2]>,
        straight: Option<f64>,
    }
}
