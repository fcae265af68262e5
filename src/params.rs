//! The parameter file: every constant of the method a user may change, in one TOML file.
//!
//! `params/default.toml` is the documented reference; it is compiled into the binary so that
//! `edo-city build` works from any directory. Unknown keys and wrong types are errors that
//! name the key, line and column (serde's `deny_unknown_fields` plus toml's spans).

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

mod billboards;
mod crowd;
mod garden;
mod halls;
mod landmarks;
pub mod output;
mod partial;
mod resolve;
pub use billboards::{PeopleParams, PointsLayer, TreesParams};
pub use crowd::CrowdParams;
pub use garden::GardenParams;
pub use halls::{GroundParams, HallParams};
pub use landmarks::{LandmarkParams, LandmarksLayer, MAX_OFFSET, MAX_SIZE, MIN_SIZE};
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

/// Every layer's settings, one table a role.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layers {
    /// Lots (the parcels: town lots, estates, temples).
    pub lots: LotsLayer,
    /// City blocks, whose outlines are street edges.
    pub blocks: BlocksLayer,
    /// Street centrelines.
    pub streets: StreetsLayer,
    /// Lines carrying street widths.
    pub street_widths: StreetWidthsLayer,
    /// Building footprints.
    pub footprints: FootprintsLayer,
    /// District polygons.
    pub districts: DistrictsLayer,
    /// Free-standing fence lines.
    pub fences: FencesLayer,
    /// People given as points (none: they are drawn).
    pub people: PointsLayer,
    /// Trees given as points (none: they are drawn).
    pub trees: PointsLayer,
    /// Polygons where rock gardens are laid out (whatever the lot's use).
    pub gardens: GardensLayer,
    /// Links placed in the city (pages and images the viewer opens).
    pub links: LinksLayer,
    /// Water (rivers, ponds): polygons drawn as a water surface in the ground.
    pub water: IdLayer,
    /// Landmarks: points or polygons naming a model each.
    pub landmarks: LandmarksLayer,
    /// The terrain grid.
    pub dem: DemLayer,
}

/// A terrain elevation grid (ESRI ASCII grid) in the output CRS.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemLayer {
    /// Path in the input directory; a missing default file means no DEM.
    pub file: String,
}

/// A layer whose features need only an id (fences, gardens).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdLayer {
    /// Shapefile path, relative to the input directory; "" = no such layer (a missing
    /// default file is no layer).
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Field holding the feature's id (else its record number from 1).
    pub id_field: String,
}

/// Free-standing fences (a PolyLine layer), walled like lot outlines: a closed line encloses
/// its inside, an open one has its wall on its left. Attributes as `[fence]` names them.
pub type FencesLayer = IdLayer;

/// Garden polygons: each gets a rock garden (karesansui) in the largest rectangle that fits
/// it clear of the planned buildings, besides the lots of `garden.uses`.
pub type GardensLayer = IdLayer;

/// Links (the paper's hyperlinks): a point layer, or a CSV table with x, y in the output CRS.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinksLayer {
    /// `links.shp` or `links.csv`, relative to the input directory; "" = none (a missing
    /// default file is no layer).
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Field holding the link's id (else its record number from 1).
    pub id_field: String,
    /// Field holding the marker's title.
    pub title_field: String,
    /// Field holding the page's address (http or https).
    pub url_field: String,
    /// Field holding an image's address (http or https).
    pub image_field: String,
    /// A table's column of x (easting, output CRS).
    pub x_field: String,
    /// A table's column of y (northing, output CRS).
    pub y_field: String,
}

/// District polygons (chiku 地区): a lot or footprint without a district attribute gets the
/// district whose polygon holds its centroid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistrictsLayer {
    /// "" = no such layer.
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Field holding the district id (or name).
    pub id_field: String,
}

/// The lots layer (shikichi 敷地): town lots, estates and precincts, with their attribute
/// table, field names, value maps and constants.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LotsLayer {
    /// Shapefile path, relative to the input directory.
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Attribute table joined on `id`: `<table>.csv` or `<table>.xlsx` in the input directory.
    pub table: String,
    /// XLSX sheet to read; empty = the first sheet.
    #[serde(default)]
    pub sheet: String,
    /// Which fields hold which attribute.
    pub fields: LotFields,
    /// Value maps per attribute (`use`, `mtype`, `district`): raw value -> value.
    #[serde(default)]
    pub values: BTreeMap<String, BTreeMap<String, String>>,
    /// Value per attribute where the field is missing or empty.
    #[serde(default)]
    pub constants: BTreeMap<String, String>,
}

/// The lots layer's fields, by name (a Japanese name may be given whole; the DBF keeps
/// 10 bytes of it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LotFields {
    /// Unique id, joining the attribute table.
    pub id: String,
    /// Lot use: machiya, buke, kuge, jisha or other (empty = machiya).
    #[serde(rename = "use")]
    pub lot_use: String,
    /// Machiya type (empty = drawn from `type_mix`).
    pub mtype: String,
    /// District id.
    pub district: String,
    /// Tile id given in the data (wins over the computed one).
    pub tile: String,
    /// Ground elevation field, metres; "" = none (Z of PolygonZ vertices, else 0).
    #[serde(default)]
    pub ground: String,
}

/// City blocks (machi 町 / gaiku 街区): their outlines are the street edges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlocksLayer {
    /// Shapefile path, relative to the input directory; "" = no such layer.
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
}

/// Street centrelines; the street edge lies half the width from them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StreetsLayer {
    /// Shapefile path, relative to the input directory; "" = no such layer.
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Field holding the full street width in metres.
    pub width_field: String,
    /// Width used where the field is missing, empty or not a positive number.
    pub default_width: f64,
}

/// A line layer whose lines carry street widths (Chino's split lines), joined to the street
/// centrelines by distance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StreetWidthsLayer {
    /// "" = no such layer.
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Field holding the width, metres.
    pub width_field: String,
    /// A centreline piece takes the width of the nearest width line within this distance.
    pub max_distance: f64,
}

/// Building footprints built as houses of their own height (PLATEAU, OSM buildings).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FootprintsLayer {
    /// "" = no such layer.
    pub file: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Which fields hold which attribute.
    pub fields: FootprintFields,
    /// Value maps per attribute (`mtype`), as for lots.
    #[serde(default)]
    pub values: BTreeMap<String, BTreeMap<String, String>>,
    /// Type of footprints whose `mtype` is empty or unknown.
    pub default_type: String,
    /// Height of one storey, for footprints with `storeys` but no height.
    pub storey_height: f64,
    /// Height of footprints with neither.
    pub default_height: f64,
}

/// The footprints layer's fields, by name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FootprintFields {
    /// Unique id.
    pub id: String,
    /// Machiya type (else `default_type`).
    pub mtype: String,
    /// Total height (ground to ridge), metres.
    pub height: String,
    /// Number of storeys (a height of storeys x `storey_height` + 1 m).
    pub storeys: String,
    /// Ground elevation, metres; "" = the lowest Z of a PolygonZ, else 0.
    pub ground: String,
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
const MAX_PARAMS_BYTES: u64 = 16 << 20;

/// The text of a parameter file, through `bounded` (a FIFO or device named instead is
/// refused, never waited on).
fn read_file(path: &Path) -> std::io::Result<String> {
    use crate::bounded::Refusal;
    crate::bounded::read_text(path, MAX_PARAMS_BYTES).map_err(|e| match e {
        Refusal::Io(e) => e,
        e => std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string()),
    })
}

impl Params {
    /// Reads a parameter file. Keys it leaves out keep their default values.
    pub fn from_path(path: &Path) -> Result<Params, ParamsError> {
        let text = read_file(path).map_err(|cause| ParamsError::Io {
            path: path.display().to_string(),
            cause,
        })?;
        let base = path.parent().unwrap_or(Path::new("."));
        Params::from_toml_in(&text, &path.display().to_string(), base, &mut Vec::new())
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

    fn validate(&self, path: &str) -> Result<(), ParamsError> {
        let bad = |message: String| ParamsError::Invalid {
            path: path.to_string(),
            message,
        };
        let k = &self.kura;
        let fp = &self.layers.footprints;
        // Every number a user sets, with the range it must lie in: (key, value, low, high),
        // low exclusive where 0 itself is meaningless (a size), inclusive where 0 switches a
        // thing off. The upper bounds are far past any city and keep a typo (1e9 for 1.9)
        // from allocating the machine away.
        let sizes = [
            ("fence.gate_width", self.fence.gate_width, 100.0),
            ("kura.width", k.width, 100.0),
            ("kura.depth", k.depth, 100.0),
            ("kura.min_width", k.min_width, 100.0),
            ("kura.min_depth", k.min_depth, 100.0),
            ("tile_size", self.tile_size, 1e6),
            ("frontage.min_length", self.frontage.min_length, 1000.0),
            ("machiya.depth", self.machiya.depth, 1000.0),
            (
                "layers.streets.default_width",
                self.layers.streets.default_width,
                crate::model::MAX_STREET_WIDTH,
            ),
            ("layers.footprints.storey_height", fp.storey_height, 100.0),
            (
                "layers.footprints.default_height",
                fp.default_height,
                1000.0,
            ),
            (
                "layers.street_widths.max_distance",
                self.layers.street_widths.max_distance,
                1e5,
            ),
        ];
        for (key, value, high) in sizes {
            if !(value.is_finite() && value > 0.0 && value <= high) {
                return Err(bad(format!(
                    "`{key}` must be a positive number up to {high}, got {value}"
                )));
            }
        }
        if self.tile_size < 1.0 {
            return Err(bad(format!(
                "`tile_size` must be at least 1 (metres), got {}",
                self.tile_size
            )));
        }
        for (key, value) in [
            ("kura.min_frontage", k.min_frontage),
            ("kura.depth_ratio", k.depth_ratio),
            ("kura.gap", k.gap),
            ("kura.back_margin", k.back_margin),
            ("kura.side_margin", k.side_margin),
            ("kura.overlap_tolerance", k.overlap_tolerance),
            ("simplify.tolerance", self.simplify.tolerance),
            ("machiya.min_depth", self.machiya.min_depth),
        ] {
            if !(value.is_finite() && (0.0..=1000.0).contains(&value)) {
                return Err(bad(format!(
                    "`{key}` must be a number from 0 to 1000, got {value}"
                )));
            }
        }
        // Points of the plane: finite, and nearer the CRS's origin than damaged data lies.
        let far = crate::model::FAR;
        for (key, point) in [
            ("tile_origin", Some(self.tile_origin)),
            ("origin", self.origin),
        ] {
            if let Some([x, y]) = point {
                if !(x.is_finite() && y.is_finite() && x.abs() < far && y.abs() < far) {
                    return Err(bad(format!(
                        "`{key}` must be two finite numbers within {far:e} m of the CRS's \
                         origin, got [{x}, {y}]"
                    )));
                }
            }
        }
        if self.simplify.max_vertices == 0 || self.simplify.max_vertices > 100_000_000 {
            return Err(bad(format!(
                "`simplify.max_vertices` must be from 1 to 100000000, got {}",
                self.simplify.max_vertices
            )));
        }
        if k.min_width > k.width || k.min_depth > k.depth {
            return Err(bad(
                "`kura.min_width` / `kura.min_depth` must not exceed `kura.width` / `kura.depth`"
                    .into(),
            ));
        }
        let angle = self.frontage.max_angle_deg;
        if !(angle > 0.0 && angle <= 180.0) {
            return Err(bad(format!(
                "`frontage.max_angle_deg` must be in (0, 180], got {angle}"
            )));
        }
        for key in self
            .layers
            .lots
            .values
            .keys()
            .chain(self.layers.lots.constants.keys())
        {
            if !["use", "mtype", "district"].contains(&key.as_str()) {
                return Err(bad(format!(
                    "`layers.lots.values.{key}` / `constants.{key}`: only use, mtype and district can be mapped"
                )));
            }
        }
        let check_mix = |key: &str, mix: &BTreeMap<String, f64>| {
            if mix.is_empty() {
                return Err(bad(format!("`{key}` lists no machiya type")));
            }
            for (name, w) in mix {
                // Bounded so that the sum of the weights stays finite.
                if !(w.is_finite() && (0.0..=1e9).contains(w)) {
                    return Err(bad(format!(
                        "`{key}.{name}` must be a weight from 0 to 1e9, got {w}"
                    )));
                }
            }
            if mix.values().sum::<f64>() <= 0.0 {
                return Err(bad(format!("`{key}` weights add up to 0")));
            }
            Ok(())
        };
        check_mix("type_mix", &self.type_mix)?;
        for (id, d) in &self.district {
            if let Some(mix) = &d.type_mix {
                check_mix(&format!("district.{id}.type_mix"), mix)?;
            }
            for (key, v, high) in [
                (
                    "people_per_100m",
                    d.people_per_100m,
                    billboards::MAX_PER_100M,
                ),
                ("trees_per_ha", d.trees_per_ha, billboards::MAX_PER_HA),
                (
                    "trees_per_ha_machiya",
                    d.trees_per_ha_machiya,
                    billboards::MAX_PER_HA,
                ),
            ] {
                if let Some(v) = v.filter(|v| !(v.is_finite() && (0.0..=high).contains(v))) {
                    return Err(bad(format!(
                        "`district.{id}.{key}` must be from 0 to {high}, got {v}"
                    )));
                }
            }
        }
        for (id, d) in &self.district {
            if let Some(m) = d
                .people_motion
                .as_deref()
                .filter(|m| !["scatter", "boids"].contains(m))
            {
                return Err(bad(format!(
                    "`district.{id}.people_motion` must be \"scatter\" or \"boids\", got \"{m}\""
                )));
            }
        }
        for (id, d) in &self.district {
            if let Some(style) = &d.trees_style {
                billboards::check_style(&format!("district.{id}.trees_style"), style)
                    .map_err(bad)?;
            }
            if let Some(table) = &d.tree_species {
                billboards::check_species(&format!("district.{id}.tree_species"), table)
                    .map_err(bad)?;
            }
        }
        self.people.validate().map_err(bad)?;
        self.trees.validate().map_err(bad)?;
        self.crowd.validate().map_err(bad)?;
        self.garden.validate().map_err(bad)?;
        self.halls.validate().map_err(bad)?;
        self.ground.validate().map_err(bad)?;
        self.landmarks.validate().map_err(bad)?;
        self.output.validate().map_err(bad)?;
        if let Some(o) = &self.origin_lonlat {
            output::check_origin_lonlat(o).map_err(bad)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
