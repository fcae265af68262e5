//! What analysis gives generation: the plan of every tile (houses with their frontage,
//! type and kura, fences and gates, people and trees), and what a tile held once made.

use std::collections::BTreeMap;

use geo_types::{Coord, Polygon};
use serde::{Deserialize, Serialize};

use super::{
    as_json, landmark, object, CrowdStat, GardenStat, HallStat, LandmarkReport, PlannedGarden,
    PlannedGround, PlannedHall, PlannedLandmark, Skipped, TileId, Walk, Warning,
};

/// The frontage (maguchi 間口): the lot edge facing the street, from Fig.4 of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Frontage {
    /// Start and end vertex; walking a -> b the lot lies on the left.
    pub a: Coord<f64>,
    /// End vertex.
    pub b: Coord<f64>,
    /// True when no pair passed the paper's test and the nearest edge was taken.
    pub fallback: bool,
}

impl Frontage {
    /// Its length, metres (the frontage width, maguchi).
    pub fn width(&self) -> f64 {
        ((self.b.x - self.a.x).powi(2) + (self.b.y - self.a.y).powi(2)).sqrt()
    }

    /// Unit vector along the street (u axis of the local frame).
    pub fn u_axis(&self) -> Coord<f64> {
        let w = self.width();
        Coord {
            x: (self.b.x - self.a.x) / w,
            y: (self.b.y - self.a.y) / w,
        }
    }

    /// Unit vector from the street into the lot (v axis of the local frame).
    pub fn v_axis(&self) -> Coord<f64> {
        let u = self.u_axis();
        Coord { x: -u.y, y: u.x }
    }
}

/// What a planned house stands for.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum HouseSource {
    /// A lot-filling machiya on a town lot: its template decides its height.
    Lot,
    /// A building footprint of the data (PLATEAU, OSM), built to its own total height, metres.
    Footprint {
        /// Ground to top, metres.
        height: f64,
    },
}

impl PlannedHouse {
    /// The footprint's total height, for a house from a footprint layer.
    pub fn footprint_height(&self) -> Option<f64> {
        match self.source {
            HouseSource::Lot => None,
            HouseSource::Footprint { height } => Some(height),
        }
    }

    /// Whether the house comes from a footprint layer (not a lot).
    pub fn is_footprint(&self) -> bool {
        self.footprint_height().is_some()
    }
}

/// A house after analysis (a machiya on its lot, or a building of a footprint layer):
/// everything generation needs, nothing more.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PlannedHouse {
    /// The lot's or footprint's id.
    pub id: String,
    /// Its record in its file.
    pub record: usize,
    /// Its outline in the output CRS.
    pub outline: Polygon<f64>,
    /// The frontage Fig.4 found.
    pub frontage: Frontage,
    /// Template name of the resolved type.
    pub mtype: String,
    /// True when the type came from the data, false when drawn from the type mix.
    pub type_given: bool,
    /// Its district.
    pub district: Option<String>,
    /// The tile it is written to.
    pub tile: TileId,
    /// Ground elevation under the house, metres.
    pub ground: f64,
    /// What the house is: a machiya filling its lot, or a building footprint of the data.
    pub source: HouseSource,
    /// The feature's numeric attributes that its template declares (`[attributes]`).
    pub attrs: Vec<(String, f64)>,
    /// Its kura, as section 4.2 decided.
    pub kura: KuraDecision,
}

/// A wall segment or a gate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum FenceKind {
    /// A length of wall.
    Wall,
    /// A gate (Fig.11), the wall split at its sides.
    Gate,
}

/// One fence segment or gate (section 4.3): the site of a fence or gate template, from `a` to
/// `b` with the enclosed side on the left.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PlannedFence {
    /// The lot's (or fence line's) id.
    pub id: String,
    /// The lot's or line's record in its file.
    pub record: usize,
    /// "lots" or "fences": the layer it came from.
    pub layer: String,
    /// The fence template (`fence`, `tsuiji`, or the gate's).
    pub template: String,
    /// Wall or gate.
    pub kind: FenceKind,
    /// The edge of the outline (from 0) it stands on.
    pub edge: usize,
    /// Start, map metres.
    pub a: Coord<f64>,
    /// End, map metres.
    pub b: Coord<f64>,
    /// Mitres at the two ends (cot of half the interior angle; 0 = a square end).
    pub start_mitre: f64,
    /// The mitre at `b`.
    pub end_mitre: f64,
    /// Ground elevation at `a` and at `b` (the same without a DEM).
    pub ground: f64,
    /// Ground elevation at `b`.
    pub ground_end: f64,
    /// How deep a wall on the segment may be and stay inside its lot (a free-standing line:
    /// `analyse::room::MAX_ROOM`): the template's `lot_depth`.
    pub room: f64,
    /// The lot's district.
    pub district: Option<String>,
    /// The tile it is written to (its lot's or line's).
    pub tile: TileId,
    /// Numeric attributes for the template (`height`).
    pub attrs: Vec<(String, f64)>,
}

/// A billboard: a person or a tree (section 4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub enum BillboardKind {
    /// A person: one quad facing along the street.
    Person,
    /// A tree: two crossed quads.
    Tree,
}

impl BillboardKind {
    /// The layer name in reports, and the object name in a tile.
    pub fn layer(self) -> &'static str {
        match self {
            BillboardKind::Person => "people",
            BillboardKind::Tree => "trees",
        }
    }
}

/// One person or tree to build.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedBillboard {
    /// Person or tree.
    pub kind: BillboardKind,
    /// The point's id, or for a generated point `<street or lot id>/<n>`.
    pub id: String,
    /// Where it stands, map metres.
    pub at: Coord<f64>,
    /// The direction the picture faces, radians counter-clockwise from map east: along its
    /// street for a person, any for a tree.
    pub facing: f64,
    /// Its height, metres.
    pub height: f64,
    /// Library material of the picture.
    pub texture: String,
    /// Ground elevation under it.
    pub ground: f64,
    /// The district it stands in.
    pub district: Option<String>,
    /// The tile it is written to.
    pub tile: TileId,
    /// For a tree of a species: which, and how it is drawn. `None` for a person and for a
    /// tree of `trees.style = "billboard"` without a species.
    pub tree: Option<TreeForm>,
}

/// A tree of a species (ki 木), as `analyse::trees` planted it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TreeForm {
    /// The species (a file of templates/trees/).
    pub species: String,
    /// Grown (`lsystem` / `colonization`): meshed from its own skeleton when the tile's
    /// budget allows; otherwise the species' billboard.
    pub grown: bool,
    /// The lot it stands in, if any (else a street margin).
    pub lot: Option<String>,
    /// The crown's radius at the planted height, metres: clear of buildings and inside the
    /// lot by `trees.clearance`.
    pub crown: f64,
    /// How much the crown is narrowed to fit (1: as grown), as a gardener prunes a tree in a
    /// narrow yard; below [`MIN_SQUEEZE`] the whole tree is made smaller instead.
    pub squeeze: f64,
}

/// The narrowest a crown is pruned to fit its room (a share of its grown width).
pub const MIN_SQUEEZE: f64 = 0.4;

/// What section 4.2 decided for a machiya's kura (蔵). A rectangle is `[u0, v0, u1, v1]` in
/// the machiya's frontage frame (u along the street, v into the lot).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum KuraDecision {
    /// Frontage narrower than `kura.min_frontage` or lot shallower than `kura.depth_ratio`
    /// times it (or a footprint building).
    #[default]
    NotCandidate,
    /// A candidate with no room for a kura behind its house.
    NoRoom,
    /// The kura fits, but its provisional plot overlaps another machiya's: built only with
    /// `kura.collision = false`.
    Collides([f64; 4]),
    /// The kura fits and its plot overlaps no other.
    Clear([f64; 4]),
}

impl KuraDecision {
    /// Whether the machiya was a kura candidate (frontage and depth rule).
    pub fn is_candidate(&self) -> bool {
        !matches!(self, KuraDecision::NotCandidate)
    }
    /// The kura's rectangle when it fits (whether or not it collides).
    pub fn rect(&self) -> Option<[f64; 4]> {
        match self {
            KuraDecision::Collides(r) | KuraDecision::Clear(r) => Some(*r),
            _ => None,
        }
    }
    /// The rectangle of the kura to build, given whether collisions are avoided.
    pub fn to_build(&self, avoid: bool) -> Option<[f64; 4]> {
        match self {
            KuraDecision::Clear(r) => Some(*r),
            KuraDecision::Collides(r) if !avoid => Some(*r),
            _ => None,
        }
    }
}

/// The paper's Table 2 counts for a set of machiya.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct KuraCounts {
    /// Machiya built.
    pub machiya: usize,
    /// Of them, candidates for a kura (frontage and depth rule).
    pub candidates: usize,
    /// Kura that fit: what is built without collision avoidance.
    pub without_avoidance: usize,
    /// Kura that fit and whose plots collide with no other: built with avoidance.
    pub with_avoidance: usize,
}

impl KuraCounts {
    /// Adds another tile's or district's counts.
    pub fn add(&mut self, o: &KuraCounts) {
        self.machiya += o.machiya;
        self.candidates += o.candidates;
        self.without_avoidance += o.without_avoidance;
        self.with_avoidance += o.with_avoidance;
    }
}

impl PlannedHouse {
    /// Object name in the OBJ: `machiya_<id>` for lots, `footprint_<id>` for footprints.
    pub fn object_name(&self) -> String {
        match self.source {
            HouseSource::Lot => format!("machiya_{}", self.id),
            HouseSource::Footprint { .. } => format!("footprint_{}", self.id),
        }
    }

    /// What its house is: a machiya or a house on a footprint.
    pub fn object_kind(&self) -> object::ObjectKind {
        match self.source {
            HouseSource::Lot => object::ObjectKind::Machiya,
            HouseSource::Footprint { .. } => object::ObjectKind::Footprint,
        }
    }

    /// Whose its house and kura are: its lot's, or its footprint's.
    pub fn owner(&self) -> object::Owner {
        let layer = match self.source {
            HouseSource::Lot => object::OwnerLayer::Lots,
            HouseSource::Footprint { .. } => object::OwnerLayer::Footprints,
        };
        object::Owner::of(layer, &self.id)
    }
}

/// The output of analysis: what to build, tile by tile. Serialized only into the analysis
/// cache (`build::cache`): a field added here is cached with it, and one whose type skips
/// fields when it serializes needs `#[serde(with = "as_json")]`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Plan {
    /// Dataset origin in projected metres: output coordinates are relative to it.
    pub origin: [f64; 2],
    /// Houses (machiya and footprints) per tile, each tile's list in input order.
    pub houses: BTreeMap<TileId, Vec<PlannedHouse>>,
    /// Every tile with something to build (houses, fences or given people and trees): the
    /// tiles a full build writes.
    pub tiles: std::collections::BTreeSet<TileId>,
    /// Lots where no edge pair passed Fig.4 and the nearest edge was taken.
    pub frontage_fallback: usize,
    /// Footprints planned (they share the tiles with the machiya).
    pub footprints: usize,
    /// Features analysis left out, with their reasons.
    #[serde(with = "as_json")]
    pub skipped: Vec<Skipped>,
    /// What analysis noticed.
    #[serde(with = "as_json")]
    pub warnings: Vec<Warning>,
    /// Time spent placing kura and testing their provisional plots (for `--timings`).
    #[serde(skip)]
    pub kura_time: std::time::Duration,
    /// Time spent placing halls, gardens, people and trees and the ground.
    #[serde(skip)]
    pub billboards_time: std::time::Duration,
    /// Of `billboards_time`, each step by name (for `--timings`).
    #[serde(skip)]
    pub step_times: Vec<(&'static str, std::time::Duration)>,
    /// Fence segments and gates per tile, in input order (each of these tiles is in
    /// `tiles`).
    pub fences: BTreeMap<TileId, Vec<PlannedFence>>,
    /// People and trees per tile, only in tiles of `tiles`; people first, each kind in a
    /// fixed order.
    pub billboards: BTreeMap<TileId, Vec<PlannedBillboard>>,
    /// The street crowds' order parameters, per street stretch (`people.motion = "boids"`).
    #[serde(with = "as_json")]
    pub crowds: Vec<CrowdStat>,
    /// The walkers' clips per tile (the tile each stands in at time 0), each tile's in the
    /// order of its people in `billboards`.
    pub walks: BTreeMap<TileId, Vec<Walk>>,
    /// The rock gardens, per tile (the tile of their lot).
    pub gardens: BTreeMap<TileId, Vec<PlannedGarden>>,
    /// What became of every lot that could have had a garden.
    #[serde(with = "as_json")]
    pub garden_reports: Vec<GardenStat>,
    /// The halls of estates and temples, per tile (the tile of their plot's centre).
    pub halls: BTreeMap<TileId, Vec<PlannedHall>>,
    /// What became of every hall a lot's use asked for.
    #[serde(with = "as_json")]
    pub hall_reports: Vec<HallStat>,
    /// The ground of every tile to write (`[ground]`): the surfaces it is cut from.
    pub grounds: BTreeMap<TileId, PlannedGround>,
    /// The landmarks, per tile (the tile of their point).
    pub landmarks: BTreeMap<TileId, Vec<PlannedLandmark>>,
    /// The materials the landmarks' models bring, in palette order (library ids from
    /// `materials::MATERIALS.len()` on).
    pub palette: Vec<landmark::PaletteEntry>,
    /// Their textures: prefixed file name and bytes.
    pub model_textures: Vec<(String, std::sync::Arc<Vec<u8>>)>,
    /// What became of the landmarks layer.
    #[serde(with = "as_json")]
    pub landmark_report: LandmarkReport,
}

/// What generation found in one tile.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TileStats {
    /// Machiya built in the tile.
    pub machiya: usize,
    /// Footprint houses built in the tile.
    pub footprints: usize,
    /// Machiya per type.
    pub by_type: BTreeMap<String, usize>,
    /// Footprint houses per type.
    pub footprints_by_type: BTreeMap<String, usize>,
    /// Houses per district ("" = none).
    pub by_district: BTreeMap<String, usize>,
    /// Machiya whose type the data gave (the rest were drawn from `type_mix`).
    pub type_given: usize,
    /// Types drawn from a type mix (not given by the data), per district: to check a
    /// district's mix against its parameter.
    #[serde(default)]
    pub drawn_by_district: BTreeMap<String, BTreeMap<String, usize>>,
    /// Kura built.
    #[serde(default)]
    pub kura: usize,
    /// Fence segments and gates built, and wall length per fence template in whole
    /// millimetres (integers, so a manifest read back and written again is byte-identical).
    #[serde(default)]
    pub fence_segments: usize,
    /// Gates built.
    #[serde(default)]
    pub gates: usize,
    /// Millimetres of wall per fence template.
    #[serde(default)]
    pub wall_mm: BTreeMap<String, u64>,
    /// People and trees built, per district ("" = none), and per texture.
    #[serde(default)]
    pub people_by_district: BTreeMap<String, usize>,
    /// Trees built, per district.
    #[serde(default)]
    pub trees_by_district: BTreeMap<String, usize>,
    /// Trees of a species, per species and how they were drawn: `lod1` (grown and meshed)
    /// or `billboard` (the species' picture).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub trees_by_species: BTreeMap<String, BTreeMap<String, usize>>,
    /// Rock gardens built in the tile.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub gardens: usize,
    /// Halls built in the tile, per template.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub halls: BTreeMap<String, usize>,
    /// Landmarks written in the tile, with their boxes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub landmarks: Vec<landmark::PlacedLandmark>,
    /// Bytes of the tile's OBJ taken by its ground (objects `ground` and `streets`).
    #[serde(default, skip_serializing_if = "is_zero_u64")]
    pub ground_bytes: u64,
    /// Bytes of the tile's OBJ taken by its trees (objects `trees` and `trees_grown`).
    #[serde(default)]
    pub tree_bytes: u64,
    /// Billboards per texture.
    #[serde(default)]
    pub billboard_textures: BTreeMap<String, usize>,
    /// Table 2 counts per district ("" = none).
    #[serde(default)]
    pub kura_counts: BTreeMap<String, KuraCounts>,
    /// Features generation left out (a template check failed), with their reasons.
    pub skipped: Vec<Skipped>,
}

/// For serde: leave a zero count out.
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// For serde: leave a zero byte count out.
fn is_zero_u64(n: &u64) -> bool {
    *n == 0
}
