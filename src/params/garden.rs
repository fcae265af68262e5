//! `[garden]`: the dry rock gardens (karesansui 枯山水) of temple lots, designed per lot by
//! the GA of seed 000 (docs/garden.md).

use serde::{Deserialize, Serialize};

/// The gardens' settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GardenParams {
    /// Whether lots of `uses` get a garden.
    pub enabled: bool,
    /// The lot uses that get one.
    pub uses: Vec<String>,
    /// The shorter side of the smallest garden placed, metres; a lot with no open rectangle
    /// this deep is skipped with the reason.
    pub min_size: f64,
    /// The largest garden, metres along its viewing side (depth: 0.4 of it, Ryoanji's).
    pub max_width: f64,
    /// Distance kept from buildings, walls and the lot's edge, metres.
    pub clearance: f64,
    /// GA generations per garden.
    pub generations: usize,
    /// Layouts per generation.
    pub population: usize,
    /// The designs file a person kept in the browser (`model::design`), "" for none;
    /// resolved against the directory of the parameter file that names it when read.
    #[serde(default)]
    pub designs: String,
}

/// The most generations or layouts a garden of the city may ask for.
pub const MAX_GA: usize = 10_000;

impl GardenParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        for (key, v, lo, hi) in [
            (
                "min_size",
                self.min_size,
                crate::growers::garden::MIN_SIDE,
                1000.0,
            ),
            ("max_width", self.max_width, 1.0, 1000.0),
            ("clearance", self.clearance, 0.0, 100.0),
        ] {
            if !(v.is_finite() && v >= lo && v <= hi) {
                let v = crate::model::number::Num(v);
                return Err(format!("`garden.{key}` must be from {lo} to {hi}, got {v}"));
            }
        }
        if self.min_size > self.max_width {
            return Err("`garden.min_size` must be at most `garden.max_width`".into());
        }
        if self.generations > MAX_GA || self.population == 0 || self.population > MAX_GA {
            return Err(format!(
                "`garden.generations` must be at most {MAX_GA} and `garden.population` from 1 to {MAX_GA}"
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
    pub struct Garden {
        enabled: Option<bool>,
        uses: Option<Vec<String>>,
        min_size: Option<f64>,
        max_width: Option<f64>,
        clearance: Option<f64>,
        generations: Option<usize>,
        population: Option<usize>,
        designs: Option<String>,
    }
}
