//! What reading gives analysis: the lots, footprints, streets, points and layers of the
//! input, each with its record, and what reading skipped and warned of.

use std::collections::BTreeMap;

use geo_types::{Coord, LineString, Polygon};
use serde::{Deserialize, Serialize};

use super::{as_json, attrs, dem, design, LandmarkRecord, Model, Warning};

use super::Attrs;

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
