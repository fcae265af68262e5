//! `[people]`, `[trees]` and their point layers: the billboards of section 4.4 of the paper.
//!
//! The paper had no GIS data for people and trees and drew their points from an assumed
//! spatial probability distribution; these are that distribution's parameters, per district
//! where `[district.<id>]` gives its own density.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::allowed;
pub use super::allowed::{MAX_PER_100M, MAX_PER_HA, TREE_STYLES};

/// A point layer of people or trees (`people.shp`, `trees.shp`). When it is present its
/// points are used and none are generated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointsLayer {
    /// The point layer's file (`people.shp`, `trees.shp`); "" for none.
    pub file: String,
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
    /// Its text encoding, when the `.cpg` is wrong or missing.
    #[serde(default)]
    pub encoding: String,
    /// Its id field.
    pub id_field: String,
    /// Height of the billboard, metres; empty or missing = drawn from the height range.
    pub height_field: String,
    /// Texture (library material name, or its number in `textures`); else drawn.
    pub texture_field: String,
    /// Tree species (a file of templates/trees/); else drawn from `[trees.species]`.
    #[serde(default)]
    pub species_field: String,
}

/// People (hito 人): one alpha-textured quad each, standing in the street.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeopleParams {
    /// Whether people are placed at all.
    pub enabled: bool,
    /// The person template.
    pub template: String,
    /// Expected people per 100 m of street centreline (`[district.<id>] people_per_100m`).
    pub per_100m: f64,
    /// Heights are drawn uniformly from this range, metres.
    pub height: [f64; 2],
    /// A person faces along the street, turned by a random angle of at most this.
    pub max_turn_deg: f64,
    /// People stand at least this far inside the street's edges.
    pub edge_margin: f64,
    /// No two people closer than this (the hard core of the Poisson-disk process).
    pub min_spacing: f64,
    /// Distance kept from buildings, kura and fences.
    pub clearance: f64,
    /// Library materials drawn from, one per person.
    pub textures: Vec<String>,
    /// More points than this in one tile are thinned to it, with a warning.
    pub max_points_per_tile: usize,
    /// `scatter`: people stand where the Poisson process put them (section 4.4); `boids`:
    /// they start there and walk as a crowd for `crowd.steps` (seed 004, `[crowd]`).
    pub motion: String,
}

/// Trees (ki 木): two crossed alpha-textured quads each, in estates and back gardens.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TreesParams {
    /// Whether trees are placed at all.
    pub enabled: bool,
    /// The tree template.
    pub template: String,
    /// Lot uses planted at `per_ha` over the whole lot (estates, temples).
    pub uses: Vec<String>,
    /// Expected trees per hectare in lots of `uses` (`[district.<id>] trees_per_ha`).
    pub per_ha: f64,
    /// Expected trees per hectare of the open back part of a town lot: behind the house,
    /// outside its kura (`[district.<id>] trees_per_ha_machiya`).
    pub per_ha_machiya: f64,
    /// [low, high] metres, a tree's height drawn uniformly between.
    pub height: [f64; 2],
    /// No two trees nearer than this, metres (Poisson-disk thinning).
    pub min_spacing: f64,
    /// Distance of a trunk from buildings, kura, fences and the lot's edge.
    pub clearance: f64,
    /// Library materials drawn from, one per tree.
    pub textures: Vec<String>,
    /// The most trees one tile may hold; a denser tile is scaled down, with a warning.
    pub max_points_per_tile: usize,
    /// `billboard`: crossed pictures (section 4.4); `lsystem` / `colonization`: trees grown
    /// by that method (seeds 003, 001) from the species of `species`
    /// (`[district.<id>] trees_style`).
    pub style: String,
    /// The leaves shown: spring, summer, autumn or winter (each species says what it wears).
    pub season: String,
    /// Bytes of grown-tree geometry one tile may hold: the tallest trees get meshes, the rest
    /// of the tile's trees billboards of their species.
    pub max_tile_bytes: u64,
    /// Grown trees of a species come in this many variants, each grown once from its own
    /// RNG key and every tree of the species one of them, scaled to its height (growth is
    /// then per variant, not per tree); 0: every tree grown from its own skeleton.
    pub variants: u32,
    /// Species weights per lot use (`machiya`, `buke`, ... or `default` for any other), the
    /// species drawn per tree (`[district.<id>.tree_species]`).
    pub species: BTreeMap<String, BTreeMap<String, f64>>,
}

/// The most billboards one tile may hold (`max_points_per_tile`).
pub const MAX_POINTS_PER_TILE: usize = 1_000_000;

impl PeopleParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        common(
            "people",
            &[
                ("per_100m", self.per_100m),
                ("edge_margin", self.edge_margin),
                ("min_spacing", self.min_spacing),
                ("clearance", self.clearance),
            ],
            self.height,
            &self.textures,
            self.max_points_per_tile,
        )?;
        allowed::check_word("people.motion", &self.motion)?;
        allowed::check_number("people.max_turn_deg", self.max_turn_deg)
    }
}

/// The largest `trees.max_tile_bytes`: 1 GB.
pub const MAX_TILE_BYTES: u64 = 1_000_000_000;

/// The most tree variants per species (`trees.variants`).
pub const MAX_VARIANTS: u32 = 1024;

/// A tree style is one of [`TREE_STYLES`].
pub fn check_style(key: &str, style: &str) -> Result<(), String> {
    if TREE_STYLES.contains(&style) {
        Ok(())
    } else {
        Err(format!(
            "`{key}` must be \"billboard\", \"lsystem\" or \"colonization\", got \"{style}\""
        ))
    }
}

/// Species weights are finite, from 0 to 1e9, and some weight of each use is above 0.
pub fn check_species(
    key: &str,
    table: &BTreeMap<String, BTreeMap<String, f64>>,
) -> Result<(), String> {
    for (usage, mix) in table {
        for (name, w) in mix {
            if !(w.is_finite() && (0.0..=1e9).contains(w)) {
                return Err(format!(
                    "`{key}.{usage}.{name}` must be a weight from 0 to 1e9, got {}",
                    crate::model::number::Num(*w)
                ));
            }
        }
        if mix.values().sum::<f64>() <= 0.0 {
            return Err(format!("`{key}.{usage}` weights add up to 0"));
        }
    }
    Ok(())
}

impl TreesParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        check_style("trees.style", &self.style)?;
        allowed::check_word("trees.season", &self.season)?;
        if self.max_tile_bytes > MAX_TILE_BYTES {
            return Err(format!(
                "`trees.max_tile_bytes` must be at most {MAX_TILE_BYTES}, got {}",
                self.max_tile_bytes
            ));
        }
        if self.variants > MAX_VARIANTS {
            return Err(format!(
                "`trees.variants` must be from 0 to {MAX_VARIANTS}, got {}",
                self.variants
            ));
        }
        check_species("trees.species", &self.species)?;
        common(
            "trees",
            &[
                ("per_ha", self.per_ha),
                ("per_ha_machiya", self.per_ha_machiya),
                ("min_spacing", self.min_spacing),
                ("clearance", self.clearance),
            ],
            self.height,
            &self.textures,
            self.max_points_per_tile,
        )
    }
}

/// Densities and distances are within their ranges (`params::allowed`), the height range is positive, ordered
/// and under 100 m, the per-tile cap bounded, and there is a texture to draw from.
fn common(
    table: &str,
    bounded: &[(&str, f64)],
    height: [f64; 2],
    textures: &[String],
    max_points_per_tile: usize,
) -> Result<(), String> {
    for (key, v) in bounded {
        super::allowed::check_number(&format!("{table}.{key}"), *v)?;
    }
    let [lo, hi] = height;
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi && hi <= 100.0) {
        return Err(format!(
            "`{table}.height` must be [low, high] with 0 < low <= high <= 100, got [{lo}, {hi}]"
        ));
    }
    if max_points_per_tile > MAX_POINTS_PER_TILE {
        return Err(format!(
            "`{table}.max_points_per_tile` must be at most {MAX_POINTS_PER_TILE}, got \
             {max_points_per_tile}"
        ));
    }
    if textures.is_empty() {
        return Err(format!("`{table}.textures` lists no texture"));
    }
    Ok(())
}

/// The same tables with every field optional, for checking a user's partial file.
pub(super) mod partial {
    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct PointsLayer {
        file: Option<String>,
        layer: Option<String>,
        encoding: Option<String>,
        id_field: Option<String>,
        height_field: Option<String>,
        texture_field: Option<String>,
        species_field: Option<String>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct People {
        enabled: Option<bool>,
        template: Option<String>,
        per_100m: Option<f64>,
        height: Option<[f64; 2]>,
        max_turn_deg: Option<f64>,
        motion: Option<String>,
        edge_margin: Option<f64>,
        min_spacing: Option<f64>,
        clearance: Option<f64>,
        textures: Option<Vec<String>>,
        max_points_per_tile: Option<usize>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Trees {
        enabled: Option<bool>,
        template: Option<String>,
        uses: Option<Vec<String>>,
        per_ha: Option<f64>,
        per_ha_machiya: Option<f64>,
        height: Option<[f64; 2]>,
        min_spacing: Option<f64>,
        clearance: Option<f64>,
        textures: Option<Vec<String>>,
        max_points_per_tile: Option<usize>,
        style: Option<String>,
        season: Option<String>,
        max_tile_bytes: Option<u64>,
        variants: Option<u32>,
        species:
            Option<std::collections::BTreeMap<String, std::collections::BTreeMap<String, f64>>>,
    }
}
