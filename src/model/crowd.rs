//! What the street crowds measured (`people.motion = "boids"`), for the report.

use serde::{Deserialize, Serialize};

/// The order parameters of one street stretch's crowd over the clip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrowdStat {
    /// The stretch: `<street id>/<n>`, the n-th straight piece of the street's centreline.
    pub street: String,
    /// Its walkers per district ("" = none): a stretch may cross a district's border.
    pub districts: std::collections::BTreeMap<String, usize>,
    /// Walkers on it at time 0.
    pub agents: usize,
    /// lambda1 at time 0.
    pub lambda1: f64,
    /// lambda2 at time 0.
    pub lambda2: f64,
    /// lambda3 at time 0.
    pub lambda3: f64,
    /// The three averaged over the clip's keys (those with a walker on the stretch).
    pub mean: MeanLambdas,
    /// lambda1-3 every second of the clip (0 when nobody is on the stretch), three decimals:
    /// the viewer's chart of a clicked street.
    #[serde(default)]
    pub series: Vec<[f64; 3]>,
    /// The stretch's ends, map metres (east, north) in the layers' CRS: where the viewer
    /// finds the stretch of a clicked street.
    #[serde(default)]
    pub line: [[f64; 2]; 2],
}

/// One walker's looping clip (`people.motion = "boids"`): written to GLB as animation and to
/// `crowds/<tile>.csv`, in the tile it stands in at time 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Walk {
    /// The person's id (its billboard's).
    pub id: String,
    /// Its group: the id of the group's first member.
    pub group: String,
    /// The street stretch it is on at time 0 (`<street id>/<n>`).
    pub street: String,
    /// Seconds between keys.
    pub dt: f64,
    /// Where it is at each key, from time 0 to the clip's end (the same as time 0).
    pub keys: Vec<WalkKey>,
}

/// One key of a [`Walk`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WalkKey {
    /// East, north (map metres) and the ground's height there.
    pub at: [f64; 3],
    /// The way it faces, radians counter-clockwise from east.
    pub heading: f64,
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
