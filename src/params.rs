//! The parameter file: every constant of the method a user may change, in one TOML file.
//!
//! `params/default.toml` is the documented reference; it is compiled into the binary so that
//! `edo-city build` works from any directory. Unknown keys and wrong types are errors that
//! name the key, line and column (serde's `deny_unknown_fields` plus toml's spans).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

pub mod allowed;
mod billboards;
pub mod catalogue;
mod crowd;
mod garden;
mod halls;
mod input;
mod landmarks;
mod layers;
pub mod output;
mod partial;
mod resolve;
mod validate;
pub use billboards::{PeopleParams, PointsLayer, TreesParams};
pub use crowd::CrowdParams;
pub use garden::GardenParams;
pub use halls::{GroundParams, HallParams};
pub use input::InputParams;
pub use landmarks::{LandmarkParams, LandmarksLayer, MAX_OFFSET, MAX_SIZE, MIN_SIZE};
pub use layers::*;
pub use output::OutputParams;
use resolve::resolved_table;

/// The default parameter file, shipped inside the binary.
pub const DEFAULT_TOML: &str = include_str!("../params/default.toml");

/// Why a parameter file cannot be used; each names the file (and the line and key where
/// there is one).
#[derive(Debug, Error)]
pub enum ParamsError {
    /// The file cannot be read.
    #[error("cannot read parameter file {path}: {cause}")]
    Io {
        /// The parameter file.
        path: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
    /// The file is not TOML, or a key is unknown or of the wrong type.
    #[error("parameter file {path}: {message}")]
    Parse {
        /// The parameter file.
        path: String,
        /// The key, line and column, and what is wrong.
        message: String,
    },
    /// A value is out of its range, or values contradict each other.
    #[error("parameter file {path}: {message}")]
    Invalid {
        /// The parameter file.
        path: String,
        /// The key and what it must be.
        message: String,
    },
}

/// A parameter file, resolved: the defaults of `params/default.toml` with every file of
/// the `extends` chain overlaid, and checked (every key known, every number in range).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Seed of every random choice; same seed, same city.
    pub seed: u64,
    /// A seed of its own for one section's draws (`[seeds] trees = 7`): kept when `seed`
    /// changes, so a liked draw of trees stays while the rest is drawn again (the
    /// workbench's seed lock). Left out of a manifest when empty.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub seeds: BTreeMap<String, u64>,
    /// Edge of a square tile, metres.
    pub tile_size: f64,
    /// A point of the tile grid, metres. Tile `c_r` spans
    /// `[origin + c*size, origin + (c+1)*size)` in x and the same in y with `r`.
    pub tile_origin: [f64; 2],
    /// Output coordinates are relative to this point. Empty: the south-west corner of the data
    /// rounded down to a whole kilometre (stated in the manifest and every OBJ header).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<[f64; 2]>,
    /// Output CRS (`EPSG:6674`, a proj string or WKT); also assumed for layers without a
    /// `.prj`. Empty: the lots layer's own CRS when projected, else the UTM zone of its centre.
    #[serde(default)]
    pub crs: String,
    /// Where each layer is and which fields hold what.
    pub layers: Layers,
    /// The input's extra files: the per-lot overrides. Left out of a manifest when unset.
    #[serde(default, skip_serializing_if = "InputParams::is_empty")]
    pub input: InputParams,
    /// The constants of Fig.4.
    pub frontage: FrontageParams,
    /// The machiya: depth, minimum depth, type templates.
    pub machiya: MachiyaParams,
    /// Kura, section 4.2.
    pub kura: KuraParams,
    /// Vertex generalisation, section 2.2.
    pub simplify: SimplifyParams,
    /// Fences and gates, section 4.3.
    pub fence: FenceParams,
    /// People, section 4.4.
    pub people: PeopleParams,
    /// Trees, section 4.4.
    pub trees: TreesParams,
    /// Street crowds (`people.motion = "boids"`, seed 004).
    pub crowd: CrowdParams,
    /// The rock gardens of temple lots (seed 000).
    pub garden: GardenParams,
    /// The halls of estates and temples.
    pub halls: HallParams,
    /// The ground of every tile: streets, lot and estate ground, water.
    pub ground: GroundParams,
    /// Landmarks placed from their own models (`layers.landmarks`).
    pub landmarks: LandmarkParams,
    /// The output formats.
    pub output: OutputParams,
    /// Where the output origin stands on the globe, `[longitude, latitude, height]`: for the
    /// tileset's placement when the CRS is local or unknown (else computed from the CRS).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin_lonlat: Option<[f64; 3]>,
    /// Relative weights of the machiya types drawn for lots of unknown type.
    pub type_mix: BTreeMap<String, f64>,
    /// Directory of textures that replace the shipped ones by file name (a texture set, as
    /// the paper compared texture libraries); "" = the shipped set. Relative to the working
    /// directory.
    #[serde(default)]
    pub textures: String,
    /// Write the DEM's terrain as a textured mesh `terrain_<tile>` in each tile.
    #[serde(default)]
    pub terrain: bool,
    /// Template parameter values: `[template.<name>] <param> = <number>`.
    #[serde(default)]
    pub template: BTreeMap<String, BTreeMap<String, f64>>,
    /// Settings per district id: `[district.<id>.template.<name>]`.
    #[serde(default)]
    pub district: BTreeMap<String, DistrictParams>,
}

/// What a district may change.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistrictParams {
    /// The type mix drawn from for this district's lots of unknown type, replacing
    /// `type_mix` there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub type_mix: Option<BTreeMap<String, f64>>,
    /// Template parameter values in this district, on top of `[template.<name>]`.
    #[serde(default)]
    pub template: BTreeMap<String, BTreeMap<String, f64>>,
    /// Billboard densities in this district, replacing `people.per_100m`, `trees.per_ha`
    /// and `trees.per_ha_machiya` there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub people_per_100m: Option<f64>,
    /// Trees per hectare of walled lots in this district, replacing `trees.per_ha`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trees_per_ha: Option<f64>,
    /// Trees per hectare of open town-lot backs here, replacing `trees.per_ha_machiya`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trees_per_ha_machiya: Option<f64>,
    /// How this district's people move, replacing `people.motion` there (`scatter` or
    /// `boids`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub people_motion: Option<String>,
    /// How this district's trees are made, replacing `trees.style` there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trees_style: Option<String>,
    /// Species weights per lot use here, replacing `trees.species` there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tree_species: Option<BTreeMap<String, BTreeMap<String, f64>>>,
}

impl Params {
    /// The type mix of a district: its own, else `type_mix`.
    pub fn type_mix_of(&self, district: Option<&str>) -> &BTreeMap<String, f64> {
        district
            .and_then(|d| self.district.get(d))
            .and_then(|d| d.type_mix.as_ref())
            .unwrap_or(&self.type_mix)
    }

    /// A district's own value of a billboard density (`pick` chooses which), else `default`.
    pub fn district_density(
        &self,
        district: Option<&str>,
        pick: fn(&DistrictParams) -> Option<f64>,
        default: f64,
    ) -> f64 {
        district
            .and_then(|d| self.district.get(d))
            .and_then(pick)
            .unwrap_or(default)
    }

    /// Whether the people of `district` walk as a crowd (`people.motion`, or the district's
    /// `people_motion`).
    pub fn crowd_walks(&self, district: Option<&str>) -> bool {
        district
            .and_then(|d| self.district.get(d))
            .and_then(|d| d.people_motion.as_deref())
            .unwrap_or(&self.people.motion)
            == "boids"
    }

    /// How the trees of `district` are made (`trees.style`, or the district's `trees_style`).
    pub fn trees_style(&self, district: Option<&str>) -> &str {
        district
            .and_then(|d| self.district.get(d))
            .and_then(|d| d.trees_style.as_deref())
            .unwrap_or(&self.trees.style)
    }

    /// The species weights of a lot use in `district`: the district's table, else
    /// `trees.species`; the use's own row, else its `default` row.
    pub fn tree_species(
        &self,
        district: Option<&str>,
        lot_use: &str,
    ) -> Option<&BTreeMap<String, f64>> {
        let table = district
            .and_then(|d| self.district.get(d))
            .and_then(|d| d.tree_species.as_ref())
            .unwrap_or(&self.trees.species);
        table.get(lot_use).or_else(|| table.get("default"))
    }

    /// `[district.<id>.template...]` of every district, as the catalog takes them.
    pub fn district_templates(&self) -> BTreeMap<String, BTreeMap<String, BTreeMap<String, f64>>> {
        self.district
            .iter()
            .map(|(k, d)| (k.clone(), d.template.clone()))
            .collect()
    }
}

/// The constants of Fig.4.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrontageParams {
    /// Largest angle at the lot centroid between the two frontage vertices, degrees.
    pub max_angle_deg: f64,
    /// Shortest frontage, metres.
    pub min_length: f64,
}

/// The machiya (町家) built on town lots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachiyaParams {
    /// Depth of the main building (omoya 主屋) from the frontage into the lot, metres;
    /// a shallower lot is filled to its back.
    pub depth: f64,
    /// Lots whose house would be shallower than this are skipped and reported, metres.
    pub min_depth: f64,
    /// Directory of machiya type files; empty = the ones shipped inside the binary.
    #[serde(default)]
    pub templates: String,
}

/// Fences and gates, section 4.3 of the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FenceParams {
    /// Wall walled lots and fence lines at all.
    pub enabled: bool,
    /// Lot uses walled along their whole outline.
    pub uses: Vec<String>,
    /// Fence template per lot use.
    pub types: BTreeMap<String, String>,
    /// Fence template of a walled lot whose use is not in `types`.
    pub default_type: String,
    /// Template of the gates.
    pub gate_template: String,
    /// Width of a gate, whatever the edge's length: 1 jo.
    pub gate_width: f64,
    /// Lot attributes: the fence template, the gate (1 = the edge facing the street, eN =
    /// edge N, 0 = none) and the wall height (metres, given to the template as `height`).
    pub type_field: String,
    /// The gate attribute (see `type_field`).
    pub gate_field: String,
    /// The wall height attribute (see `type_field`).
    pub height_field: String,
}

/// Vertex generalisation before analysis (section 2.2 of the paper).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimplifyParams {
    /// A vertex within this distance (metres) of the line through its neighbours is removed
    /// from outlines and lines; 0 = keep every vertex.
    pub tolerance: f64,
    /// A lot, footprint or fence line with more vertices than this after simplification is
    /// skipped with a reason (it would cost a wall segment and mesh edges per vertex).
    pub max_vertices: usize,
}

/// Kura (蔵) storehouses behind wide, deep machiya, section 4.2 of the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KuraParams {
    /// Build kura at all.
    pub enabled: bool,
    /// Template of the kura.
    pub template: String,
    /// Candidates: frontage at least this (3 ken = 5.454 m: the paper's sign of wealth) ...
    pub min_frontage: f64,
    /// ... and a lot at least this many times as deep as its frontage is wide.
    pub depth_ratio: f64,
    /// Size of a kura along the street, metres ...
    pub width: f64,
    /// ... and into the lot.
    pub depth: f64,
    /// A narrow or short lot shrinks its kura down to these, along the street ...
    pub min_width: f64,
    /// ... and into the lot; below them it gets none.
    pub min_depth: f64,
    /// Open ground between the back of the house and the kura (a courtyard).
    pub gap: f64,
    /// Distance of the kura from the back of the lot ...
    pub back_margin: f64,
    /// ... and from its sides.
    pub side_margin: f64,
    /// Collision avoidance of Fig.7: a kura whose provisional plot overlaps another plot is
    /// not built. false = the paper's "without avoidance" column.
    pub collision: bool,
    /// Plots overlapping by less than this area (m2) do not collide (touching plots never do).
    pub overlap_tolerance: f64,
}

impl Default for Params {
    fn default() -> Self {
        // The shipped file is the single source of the defaults; a unit test parses it.
        Params::from_toml_str(DEFAULT_TOML, "params/default.toml")
            .expect("shipped params/default.toml is valid")
    }
}

/// The largest parameter file read (the defaults, with every comment, are 20 KB).
pub const MAX_PARAMS_BYTES: u64 = 16 << 20;

/// The text of a parameter file, through `bounded` (a FIFO or device named instead is
/// refused, never waited on).
fn read_file(path: &Path) -> std::io::Result<String> {
    use crate::bounded::Refusal;
    crate::bounded::read_text(path, MAX_PARAMS_BYTES).map_err(|e| match e {
        Refusal::Io(e) => e,
        e => std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string()),
    })
}

/// The sections that may draw from a seed of their own (`[seeds]`): the machiya's types and
/// forms (and their kura), the trees, the people and crowds, the rock gardens.
pub const SEED_SECTIONS: [&str; 4] = ["machiya", "trees", "people", "gardens"];

impl Params {
    /// The seed `section`'s draws come from: its own in `[seeds]`, else `seed`.
    pub fn seed_for(&self, section: &str) -> u64 {
        self.seeds.get(section).copied().unwrap_or(self.seed)
    }

    /// Reads a parameter file. Keys it leaves out keep their default values.
    pub fn from_path(path: &Path) -> Result<Params, ParamsError> {
        let text = read_file(path).map_err(|cause| ParamsError::Io {
            path: path.display().to_string(),
            cause,
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Params::from_toml_in(&text, &path.display().to_string(), base, &mut Vec::new())
    }

    /// Reads `text` as the parameter file `path` would be read if it held it (its `extends`
    /// and the files it names found beside it): the workbench's unsaved edits, resolved as
    /// `build --params` will resolve them once saved.
    pub fn from_text_at(text: &str, path: &Path) -> Result<Params, ParamsError> {
        let base = path.parent().unwrap_or(Path::new("."));
        Params::from_toml_in(text, &path.display().to_string(), base, &mut Vec::new())
    }

    /// Parses parameter text over the defaults: a user file may give only the keys it changes.
    /// `extends` paths are relative to the current directory.
    pub fn from_toml_str(text: &str, path: &str) -> Result<Params, ParamsError> {
        Params::from_toml_in(text, path, Path::new("."), &mut Vec::new())
    }

    fn from_toml_in(
        text: &str,
        path: &str,
        base_dir: &Path,
        chain: &mut Vec<String>,
    ) -> Result<Params, ParamsError> {
        let merged = resolved_table(text, path, base_dir, chain)?;
        let merged_text = toml::to_string(&merged).map_err(|e| ParamsError::Parse {
            path: path.to_string(),
            message: e.to_string(),
        })?;
        // Lines of the merged text would mislead: the message alone.
        let params: Params = toml::from_str(&merged_text).map_err(|e| ParamsError::Parse {
            path: path.to_string(),
            message: crate::model::source::message(&e),
        })?;
        params.validate(path)?;
        Ok(params)
    }
}

#[cfg(test)]
mod tests;
