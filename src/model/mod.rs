//! Plain data passed between the pipeline stages.
//!
//! Every stage takes these types and returns new ones; none of them does I/O. Keeping them
//! here (and not inside a stage) lets the stages depend on the data, never on each other:
//! `model` depends on nothing of ours.

pub mod as_json;
pub mod attrs;
pub mod crowd;
pub mod dem;
pub mod design;
pub mod landmark;
pub mod object;
pub mod precinct;
pub mod source;
pub mod tile;
pub mod warning;

use std::collections::BTreeMap;

pub use attrs::{Attrs, FieldNames};
use geo_types::{Coord, LineString, Polygon};
use serde::{Deserialize, Serialize};

/// Coordinates this far from the CRS's origin (metres; the Earth is 4e7 m round) come from
/// damaged data: their squares overflow, and with them the R-trees' distance arithmetic.
/// `input/` skips polygons with such a vertex; later stages leave such points out of their
/// indexes.
pub const FAR: f64 = 1e8;

/// The lowest and highest ground an elevation may give, metres (the shore of the Dead Sea
/// lies at -430 m, the top of Everest at 8,849 m). Outside them a number is damaged data or a
/// no-data value nobody declared (GDAL's float32 -3.4e38): DEM cells are then no-data, lots
/// and footprints are skipped.
pub const ELEVATION_RANGE: std::ops::RangeInclusive<f64> = -1000.0..=9000.0;

/// The widest street taken from the data or the parameters, metres (the widest avenues are
/// about 100 m; a larger number is a unit error or damaged data).
pub const MAX_STREET_WIDTH: f64 = 200.0;

/// Whether a point is nearer than [`FAR`] to the CRS's origin.
pub fn sane(c: Coord<f64>) -> bool {
    c.x.abs() < FAR && c.y.abs() < FAR
}

/// What a lot (shikichi 敷地) is used for; decides which generator it gets.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LotUse {
    /// Town lot (machi-chi 町地): gets a townhouse, machiya 町家.
    Machiya,
    /// Samurai residence (buke-chi 武家地): fence and gate (a later stage).
    Buke,
    /// Court noble residence (kuge-chi 公家地): fence and gate (a later stage).
    Kuge,
    /// Temple or shrine (jisha-chi 寺社地): earthen wall and gate (a later stage).
    Jisha,
    /// Anything else, kept verbatim so the report can name it.
    Other(String),
}

impl LotUse {
    /// Parses the `use` attribute; an empty value means a town lot, as the paper's data did.
    pub fn parse(raw: &str) -> LotUse {
        let t = raw.trim();
        match t.to_lowercase().as_str() {
            "" | "machiya" | "machi" | "machichi" | "町地" | "町家" | "町屋" => {
                LotUse::Machiya
            }
            "buke" | "bukechi" | "武家地" | "武家" => LotUse::Buke,
            "kuge" | "kugechi" | "公家地" | "公家" => LotUse::Kuge,
            "jisha" | "jishachi" | "寺社地" | "寺社" | "寺" | "社" => LotUse::Jisha,
            _ => LotUse::Other(t.to_string()),
        }
    }

    /// The name used in reports.
    pub fn name(&self) -> &str {
        match self {
            LotUse::Machiya => "machiya",
            LotUse::Buke => "buke",
            LotUse::Kuge => "kuge",
            LotUse::Jisha => "jisha",
            LotUse::Other(s) => s,
        }
    }
}

/// One lot polygon with the attributes the pipeline needs, after the table join.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Lot {
    /// The `id` attribute, unique within the layer.
    pub id: String,
    /// Position in the shapefile (0-based), used to keep every output in input order.
    pub record: usize,
    /// Outline in projected metres, exterior ring counter-clockwise, closed.
    pub outline: Polygon<f64>,
    /// What the lot is used for.
    pub lot_use: LotUse,
    /// Raw machiya type (`mtype`), resolved against the templates during analysis.
    pub mtype: Option<String>,
    /// The district it belongs to (its attribute, else the district polygon holding it).
    pub district: Option<String>,
    /// A tile id given in the data; wins over the computed one.
    pub tile: Option<String>,
    /// Every attribute of the feature (DBF fields, then table values on top).
    pub attrs: Attrs,
    /// Ground elevation, metres: the `ground` field, else the lowest Z of a PolygonZ, else 0.
    pub ground: f64,
}

/// A free-standing fence or wall from a line layer.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FenceLine {
    /// The line's id (its field, else its record number from 1; parts `<id>-<n>`).
    pub id: String,
    /// Its record in the file.
    pub record: usize,
    /// The line, in the output CRS; a closed one walls in its inside.
    pub line: LineString<f64>,
    /// Every attribute of the feature.
    pub attrs: Attrs,
}

/// A polygon of the optional gardens layer (`layers.gardens`): where a user has drawn a rock
/// garden's ground, whatever the lot's use.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GardenArea {
    /// Its id (the layer's id field, else its record number from 1; parts `<id>-<n>`).
    pub id: String,
    /// Its record in the file.
    pub record: usize,
    /// The polygon, in the output CRS.
    pub outline: Polygon<f64>,
}

/// A link placed in the city (the paper's hyperlinks): a point that opens a page or image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Link {
    /// Its id (the id field, else its record number from 1).
    pub id: String,
    /// Its record (a table's row from 0).
    pub record: usize,
    /// Where it stands, in the output CRS.
    pub at: Coord<f64>,
    /// What the marker is called.
    pub title: String,
    /// The page it opens (http(s)), or empty.
    pub url: String,
    /// The image it opens (http(s)), or empty.
    pub image: String,
}

/// A person or a tree given as a point (`people.shp`, `trees.shp`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PointFeature {
    /// The point's id.
    pub id: String,
    /// Its record in the file.
    pub record: usize,
    /// Where it stands, in the output CRS.
    pub at: Coord<f64>,
    /// The `height` field, metres, when given.
    pub height: Option<f64>,
    /// The `texture` field as written (a material name or a number), when given.
    pub texture: Option<String>,
    /// The `species` field as written (trees), when given.
    pub species: Option<String>,
}

/// A building footprint from the data, built as a house of its own height.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Footprint {
    /// The footprint's id, unique within the layer.
    pub id: String,
    /// Its record in the file.
    pub record: usize,
    /// Its outline in the output CRS, exterior counter-clockwise.
    pub outline: Polygon<f64>,
    /// Its machiya type as the data names it (else `default_type`).
    pub mtype: Option<String>,
    /// The district polygon holding it.
    pub district: Option<String>,
    /// Total height, ground to ridge, metres.
    pub height: f64,
    /// Ground elevation, metres.
    pub ground: f64,
}

/// What was read from one layer, for the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayerInfo {
    /// The layer's role: lots, footprints, streets, blocks, street_widths, districts,
    /// fences, people, trees.
    pub role: String,
    /// The file, as the user named it.
    pub file: String,
    /// Records in the file (deleted ones included).
    pub features: usize,
    /// The text encoding its DBF was read in, and how it was chosen.
    pub encoding: String,
    /// The layer's CRS as a proj string, or how it was assumed.
    pub crs: String,
    /// Whether its coordinates were reprojected into the output CRS.
    pub reprojected: bool,
    /// Vertices read and left after generalisation (`simplify.tolerance`).
    #[serde(default)]
    pub vertices_before: usize,
    /// Vertices left after generalisation.
    #[serde(default)]
    pub vertices_after: usize,
}

/// A street centreline with its full width in metres.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Street {
    /// The street's id (its record in the file).
    pub id: String,
    /// The centreline, in the output CRS.
    pub line: LineString<f64>,
    /// Full width, metres.
    pub width: f64,
}

/// A feature left out of the build, with the reason, for `report.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Skipped {
    /// The layer's role (`lots`, `lots table`, `people`, ...).
    pub layer: String,
    /// The file the feature came from.
    pub file: String,
    /// The feature's id (`record N` when it has none).
    pub id: String,
    /// The record number in the file (from 0, as the FID of QGIS and ArcGIS), where the
    /// feature came from one; for a row of an attribute table, its row as the spreadsheet
    /// numbers it (the header is row 1). Kept apart from `reason` so skips group by cause.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub record: Option<usize>,
    /// Why it was left out, and what to do.
    pub reason: String,
}

impl Skipped {
    /// The reason for a part of a feature left out while the feature stands (its kura, its
    /// walls, one of its halls): "its <part>: <why>". [`Skipped::is_part`] reads it back; the
    /// report keeps the words, so the scope travels through merged manifests with them.
    pub fn part_reason(part: &str, why: &str) -> String {
        format!("its {part}: {why}")
    }

    /// Whether a part of the feature was left out ([`Skipped::part_reason`]), the feature
    /// itself standing; else the whole feature was skipped.
    pub fn is_part(&self) -> bool {
        self.reason.starts_with("its ")
    }
}

/// The outline of a record skipped while reading, where it had a usable one (a repeated id,
/// a ground out of range): `plan.gpkg` and `check --gpkg` draw the skip there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedShape {
    /// The layer's role, as in its [`Skipped`].
    pub layer: String,
    /// The record, as in its [`Skipped`].
    pub record: usize,
    /// The feature's id, as in its [`Skipped`].
    pub id: String,
    /// Its outline, in the output CRS.
    pub shape: Polygon<f64>,
}

/// Everything read from the input directory, in input order. (Serialized only into the
/// analysis cache, `build::cache`, with the plan made from it.)
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Dataset {
    /// Lot polygons, parts of multipart lots split.
    pub lots: Vec<Lot>,
    /// Free-standing fence lines.
    pub fence_lines: Vec<FenceLine>,
    /// People and trees from point layers; `None` when the layer is absent (then they are
    /// generated).
    pub people: Option<Vec<PointFeature>>,
    /// Trees from a point layer, as `people`.
    pub trees: Option<Vec<PointFeature>>,
    /// The terrain, when the input has one.
    pub dem: Option<dem::Dem>,
    /// City blocks (machi 町 / gaiku 街区): their boundaries are street edges.
    pub blocks: Vec<Polygon<f64>>,
    /// The polygons of the gardens layer, each to get a rock garden.
    pub gardens: Vec<GardenArea>,
    /// Polygons of the water layer (rivers, ponds), each with its id and record.
    pub water: Vec<GardenArea>,
    /// The links layer's points.
    pub links: Vec<Link>,
    /// The rock-garden designs of `garden.designs` that are usable, with their records.
    pub designs: Vec<(usize, design::Design)>,
    /// The landmarks layer's records whose model was read.
    pub landmarks: Vec<LandmarkRecord>,
    /// The landmarks' models, each read once, by the name the records give.
    pub models: BTreeMap<String, std::sync::Arc<Model>>,
    /// Street centrelines with their widths.
    pub streets: Vec<Street>,
    /// Building footprints, each built to its own height.
    pub footprints: Vec<Footprint>,
    /// Contents of the lots layer's `.prj`, if any, carried to the manifest.
    pub crs_wkt: Option<String>,
    /// The CRS all coordinates are in (proj string); empty when unknown (no `.prj` anywhere).
    pub crs: String,
    /// Every layer read, for the report.
    pub layers: Vec<LayerInfo>,
    /// Features left out while reading, with their reasons.
    #[serde(with = "as_json")]
    pub skipped: Vec<Skipped>,
    /// The outlines of skipped records that had one.
    pub skipped_shapes: Vec<SkippedShape>,
    /// What reading noticed.
    #[serde(with = "as_json")]
    pub warnings: Vec<Warning>,
    /// How each attribute table matched its layer.
    pub joins: Vec<TableJoin>,
    /// For the layers whose features keep no record number (blocks, streets, districts,
    /// street widths): the records that gave at least one usable feature, by role. The
    /// report's ledger checks every other record was skipped with a reason.
    pub records: BTreeMap<String, std::collections::BTreeSet<usize>>,
}

impl Dataset {
    /// The box of the city read so far (lots, footprints, streets), or `None` before any:
    /// what a point feature of another layer (a landmark, a link) must lie near.
    pub fn city_box(&self) -> Option<geo_types::Rect<f64>> {
        use geo::BoundingRect;
        let boxes = self
            .lots
            .iter()
            .filter_map(|l| l.outline.bounding_rect())
            .chain(
                self.footprints
                    .iter()
                    .filter_map(|f| f.outline.bounding_rect()),
            )
            .chain(self.streets.iter().filter_map(|s| s.line.bounding_rect()));
        boxes.reduce(|a, b| {
            geo_types::Rect::new(
                Coord {
                    x: a.min().x.min(b.min().x),
                    y: a.min().y.min(b.min().y),
                },
                Coord {
                    x: a.max().x.max(b.max().x),
                    y: a.max().y.max(b.max().y),
                },
            )
        })
    }

    /// Shares the features' attribute names again, one allocation per name (as reading
    /// made them) after the analysis cache read them back each on its own.
    pub fn share_field_names(&mut self) {
        let mut names = attrs::FieldNames::default();
        for lot in &mut self.lots {
            lot.attrs.share_names(&mut names);
        }
        for fence in &mut self.fence_lines {
            fence.attrs.share_names(&mut names);
        }
    }
}

/// How an attribute table matched its layer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableJoin {
    /// The layer the table joins (`lots`).
    pub layer: String,
    /// The table's file.
    pub file: String,
    /// Rows in the table.
    pub rows: usize,
    /// Rows whose id matched a feature.
    pub matched: usize,
    /// Row ids with no feature of that id (first few kept for the report).
    pub rows_without_feature: usize,
    /// The first of them, for the report.
    pub rows_without_feature_ids: Vec<String>,
    /// Features with no row.
    pub features_without_row: usize,
}

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

/// A tile id `<col>_<row>` on the fixed grid.
pub use crowd::{CrowdStat, MeanLambdas, Walk, WalkKey};
pub use landmark::{LandmarkRecord, LandmarkReport, Model, PlannedLandmark};
pub use precinct::{GardenStat, GroundHeight, HallStat, PlannedGarden, PlannedGround, PlannedHall};
pub use tile::TileId;
pub use warning::{Warning, WarningClass};

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
