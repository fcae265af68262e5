//! What the street crowds measured (`people.motion = "boids"`), for the report.

use serde::{Deserialize, Serialize};

/// The order parameters of one street stretch's crowd after its walk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrowdStat {
    /// The stretch: `<street id>/<n>`, the n-th straight piece of the street's centreline.
    pub street: String,
    /// Its walkers per district ("" = none): a stretch may cross a district's border.
    pub districts: std::collections::BTreeMap<String, usize>,
    /// Walkers simulated.
    pub agents: usize,
    /// lambda1 after the last step.
    pub lambda1: f64,
    /// lambda2 after the last step.
    pub lambda2: f64,
    /// lambda3 after the last step.
    pub lambda3: f64,
    /// The three averaged over the last `crowd.last_steps` steps.
    pub mean: MeanLambdas,
}

/// lambda1-3 averaged over steps.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MeanLambdas {
    /// Mean lambda1.
    pub lambda1: f64,
    /// Mean lambda2.
    pub lambda2: f64,
    /// Mean lambda3.
    pub lambda3: f64,
}
