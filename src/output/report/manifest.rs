//! The manifest: what a build wrote (every file of every tile with its size and sha256),
//! what it read (`InputSummary`) and with which parameters, written last; and how its paths
//! and parameters are published (a published manifest names nothing outside the input).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::TileStats;
use crate::model::{LayerInfo, Skipped, TableJoin};
use crate::params::Params;

/// The part of the report that comes from reading and analysis, the same for every tile.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct InputSummary {
    /// The input directory: absolute while a build runs and in a shard's manifest (which
    /// `merge` reads and removes); in the published manifest and report its name only.
    pub input: String,
    /// A fingerprint of the input directory's absolute path, so that a later build into the
    /// same output can tell whether it reads the same input without the path published.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub input_id: String,
    /// The `--templates` directory of the build, as typed, so that `edo-city plan` can load
    /// the same types again.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub templates: Option<String>,
    /// The output CRS (proj string).
    pub crs: String,
    /// Every layer read.
    pub layers: Vec<LayerInfo>,
    /// Lots read (parts of multipart lots split).
    pub lots: usize,
    /// Lots per use.
    pub lots_by_use: BTreeMap<String, usize>,
    /// Footprints read.
    pub footprints_read: usize,
    /// Lots where Fig.4 fell back to the nearest edge.
    pub frontage_fallback: usize,
    /// Features reading and analysis left out.
    pub skipped: Vec<Skipped>,
    /// How each attribute table matched its layer.
    pub tables: Vec<TableJoin>,
    /// What reading and analysis noticed.
    pub warnings: Vec<crate::model::Warning>,
    /// What each layer's records became in reading and analysis, closed in the report.
    #[serde(default)]
    pub ledgers: Vec<crate::output::accounting::Ledger>,
    /// The street crowds' order parameters (`people.motion = "boids"`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub crowds: Vec<crate::model::CrowdStat>,
    /// Every lot that could have had a rock garden: placed or skipped with why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub gardens: Vec<crate::model::GardenStat>,
    /// Every hall a lot's use asked for: placed or not with why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub halls: Vec<crate::model::HallStat>,
    /// What became of the landmarks layer (its `placed` is left empty here: the tiles list
    /// what they hold).
    #[serde(default, skip_serializing_if = "landmarks_empty")]
    pub landmarks: crate::model::LandmarkReport,
}

/// The fingerprint of an input directory (see [`InputSummary::input_id`]).
pub fn input_id(absolute: &std::path::Path) -> String {
    let hex = crate::output::sha256_hex(absolute.as_os_str().as_encoded_bytes());
    hex[..16].to_string()
}

/// The fingerprint of a build's parameters as they are published (paths outside the input
/// by their fingerprints): the hypothesis a city model names, the same for a full build,
/// its shards and its merge, on any machine.
pub fn params_id(params: &Params) -> String {
    let bytes = serde_json::to_vec(&published_params(params)).expect("parameters serialise");
    crate::output::sha256_hex(&bytes)[..16].to_string()
}

/// What stands in a published manifest for a parameter's path outside the input.
pub const UNPUBLISHED: &str = "(not published) ";

/// The parameters as a published manifest carries them: a path that names a place outside
/// the input directory (absolute, from `~`, or climbing out with `..`: `models_dir =
/// "/home/alice/models"`) by its last name and a fingerprint of the whole path, after
/// [`UNPUBLISHED`]. Paths inside the input (`lots.shp`) stay; applied twice, the same.
pub fn publish_paths(params: &mut serde_json::Value) {
    use serde_json::Value as V;
    match params {
        V::Object(map) => map.values_mut().for_each(publish_paths),
        V::Array(items) => items.iter_mut().for_each(publish_paths),
        V::String(s) if leaves_the_input(s) => {
            let name = std::path::Path::new(s.as_str())
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            let hex = crate::output::sha256_hex(s.as_bytes());
            *s = format!("{UNPUBLISHED}{name}#{}", &hex[..16]);
        }
        _ => {}
    }
}

/// Whether a parameter's string is a path to a place outside the input directory.
fn leaves_the_input(s: &str) -> bool {
    let path = std::path::Path::new(s);
    !s.starts_with(UNPUBLISHED)
        && (path.is_absolute()
            || s.starts_with('~')
            || s.starts_with('\\')
            || s.get(1..3).is_some_and(|d| d == ":\\" || d == ":/")
            || path
                .components()
                .any(|c| c == std::path::Component::ParentDir))
}

/// The keys of published parameters whose paths were left out (see [`publish_paths`]).
pub fn unpublished_keys(params: &serde_json::Value, at: &str, out: &mut Vec<String>) {
    use serde_json::Value as V;
    let key = |k: &str| match at {
        "" => k.to_string(),
        _ => format!("{at}.{k}"),
    };
    match params {
        V::Object(map) => map
            .iter()
            .for_each(|(k, v)| unpublished_keys(v, &key(k), out)),
        V::Array(items) => items
            .iter()
            .enumerate()
            .for_each(|(i, v)| unpublished_keys(v, &key(&i.to_string()), out)),
        V::String(s) if s.starts_with(UNPUBLISHED) => out.push(at.to_string()),
        _ => {}
    }
}

/// [`publish_paths`] of typed parameters (strings stay strings, so they read back).
pub fn published_params(params: &Params) -> Params {
    let mut v = serde_json::to_value(params).expect("parameters serialise");
    publish_paths(&mut v);
    serde_json::from_value(v).unwrap_or_else(|_| params.clone())
}

impl InputSummary {
    /// The summary as a published manifest carries it: the input directory and the
    /// `--templates` directory by their names alone.
    pub fn published(&self) -> InputSummary {
        let name = |p: &str| {
            std::path::Path::new(p)
                .file_name()
                .map_or_else(|| ".".to_string(), |n| n.to_string_lossy().into_owned())
        };
        InputSummary {
            input: name(&self.input),
            templates: self.templates.as_deref().map(name),
            ..self.clone()
        }
    }
}

/// Whether a build had no landmarks at all (the report then leaves the key out).
pub(super) fn landmarks_empty(l: &crate::model::LandmarkReport) -> bool {
    l.placed.is_empty() && l.displaced.is_empty() && l.skipped.is_empty()
}

/// manifest.json, written last: what the build is (tool, parameters, input, frame) and
/// every file it wrote with its size and sha256.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// `edo-city`.
    pub tool: String,
    /// The tool's version.
    pub version: String,
    /// Set on a shard's manifest: [index, count], index from 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<[usize; 2]>,
    /// Output coordinates are relative to this point, in the input's projected metres.
    pub origin: [f64; 2],
    /// The output frame, in words (axes and units).
    pub frame: String,
    /// The output CRS as a proj string; empty when no layer had a `.prj`.
    pub crs: String,
    /// The lots (else footprints) layer's `.prj`, if it had one.
    pub crs_wkt: Option<String>,
    /// Tile edge, metres.
    pub tile_size: f64,
    /// The resolved parameters of the build.
    pub params: Params,
    /// What reading and analysis found, the same for every tile.
    pub input: InputSummary,
    /// Every tile written, with its files and statistics.
    pub tiles: Vec<ManifestTile>,
    /// The formats written (`obj`, `glb`).
    #[serde(default)]
    pub formats: Vec<String>,
    /// The files that describe the whole build (`tileset.json`).
    #[serde(default)]
    pub files: Vec<ManifestFile>,
    /// The texture files.
    pub textures: Vec<ManifestFile>,
    /// `species/`: each planted species' LOD0 and `placements.csv` (empty when no tree has a
    /// species).
    #[serde(default)]
    pub species: Vec<ManifestFile>,
}

/// One tile of the manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestTile {
    /// The tile's id.
    pub id: String,
    /// Its OBJ file (format `obj`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obj: Option<ManifestFile>,
    /// Its MTL file (format `obj`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mtl: Option<ManifestFile>,
    /// Its GLB file (format `glb`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glb: Option<ManifestFile>,
    /// Its walkers' clips, `crowds/<id>.csv` (`people.motion = "boids"`, any format).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crowds: Option<ManifestFile>,
    /// Its CityJSON features, `tiles/<id>.city.jsonl` (format `cityjson`): the lines
    /// `city.city.jsonl` is made of.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cityjson: Option<ManifestFile>,
    /// The shared files its files draw: the GLB's grown trees' variants
    /// (`tiles/models/<species>_<k>.bin`) and CityJSON's geometry templates of them
    /// (`tiles/templates/<species>_<k>.json`); other tiles list the same files.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub models: Vec<ManifestFile>,
    /// The extent of its content, metres relative to the origin: `[east_min, north_min,
    /// up_min, east_max, north_max, up_max]` (for the tileset's bounding boxes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bounds: Option<[f64; 6]>,
    /// The point its GLB's coordinates are taken around, metres relative to the origin:
    /// `[east, north]`.
    #[serde(default)]
    pub centre: [f64; 2],
    /// What generation found in it.
    pub stats: TileStats,
}

impl ManifestTile {
    /// Every file of the tile, whatever the format, in a fixed order: its own, then the
    /// shared models it draws.
    pub fn files(&self) -> impl Iterator<Item = &ManifestFile> {
        self.own_files().chain(&self.models)
    }

    /// The files of the tile alone (not the shared models).
    fn own_files(&self) -> impl Iterator<Item = &ManifestFile> {
        [
            &self.obj,
            &self.mtl,
            &self.glb,
            &self.crowds,
            &self.cityjson,
        ]
        .into_iter()
        .flatten()
    }

    /// Files a sink wrote, each put in its slot by its extension.
    pub fn add_files(&mut self, files: Vec<ManifestFile>) {
        for f in files {
            let slot = match f.path.rsplit('.').next() {
                Some("obj") => &mut self.obj,
                Some("mtl") => &mut self.mtl,
                Some("csv") => &mut self.crowds,
                Some("jsonl") => &mut self.cityjson,
                // Shared: a GLB's variant models, CityJSON's geometry templates.
                Some("bin" | "json") => {
                    self.models.push(f);
                    continue;
                }
                _ => &mut self.glb,
            };
            *slot = Some(f);
        }
    }

    /// The bytes of its own files (a shared model is counted once by the caller, not with
    /// each tile that draws it).
    pub fn bytes(&self) -> u64 {
        self.own_files().map(|f| f.bytes).sum()
    }
}

/// One file written by the build.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestFile {
    /// Its path, relative to the output directory.
    pub path: String,
    /// Its size in bytes.
    pub bytes: u64,
    /// Its sha256, lower-case hex.
    pub sha256: String,
}
