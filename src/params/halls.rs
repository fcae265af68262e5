//! `[halls]`: the buildings of estates and temples (a temple's main hall, gate and pagoda,
//! a samurai's main house, a court noble's residence), templates of kind `hall` placed in a
//! lot's open ground behind its gate; and `[ground]`: the surfaces of a tile (streets, lot
//! and estate ground, water).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The halls' settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HallParams {
    /// Whether estates and temples get their halls.
    pub enabled: bool,
    /// Distance a hall keeps from the lot's edge, walls, houses and the halls placed before
    /// it, metres.
    pub clearance: f64,
    /// Per lot use, the hall templates placed in each lot of that use, in order (the first
    /// gets the most room); a use not listed, or listed with none, stays open ground.
    pub uses: BTreeMap<String, Vec<String>>,
}

impl HallParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        let c = self.clearance;
        if !(c.is_finite() && (0.0..=100.0).contains(&c)) {
            let c = crate::model::number::Num(c);
            return Err(format!("`halls.clearance` must be from 0 to 100, got {c}"));
        }
        for (u, names) in &self.uses {
            if names.len() > 16 {
                return Err(format!(
                    "`halls.uses.{u}` lists {} halls; at most 16 a lot",
                    names.len()
                ));
            }
        }
        Ok(())
    }
}

/// The ground's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundParams {
    /// Whether every tile gets its ground (objects `ground` and `streets`).
    pub enabled: bool,
    /// The material of the ground under lots of each use; others, and the open ground
    /// between lots, get `default`.
    pub materials: BTreeMap<String, String>,
    /// One texture repeat per this many metres.
    pub texture_size: f64,
    /// Where the street surface comes from: "centrelines" (the streets layer buffered by
    /// half its widths), "blocks" (the ground between the city blocks), or "auto" (the
    /// centrelines when there are any, else the blocks).
    pub streets: String,
}

impl GroundParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        let s = self.texture_size;
        if !(s.is_finite() && (0.1..=1000.0).contains(&s)) {
            return Err(format!(
                "`ground.texture_size` must be from 0.1 to 1000, got {}",
                crate::model::number::Num(s)
            ));
        }
        if !matches!(self.streets.as_str(), "auto" | "centrelines" | "blocks") {
            return Err(format!(
                "`ground.streets` must be \"auto\", \"centrelines\" or \"blocks\", got \"{}\"",
                self.streets
            ));
        }
        // The material names are checked against the library by `build` (params know no
        // materials).
        Ok(())
    }
}

/// The same tables with every field optional, for checking a user's partial file.
pub(super) mod partial {
    use std::collections::BTreeMap;

    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Halls {
        enabled: Option<bool>,
        clearance: Option<f64>,
        uses: Option<BTreeMap<String, Vec<String>>>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Ground {
        enabled: Option<bool>,
        materials: Option<BTreeMap<String, String>>,
        texture_size: Option<f64>,
        streets: Option<String>,
    }
}
