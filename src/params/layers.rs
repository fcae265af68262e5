//! `[layers.*]`: where each role's features are read from (the file, its fields, value
//! maps and constants), one table a role.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::{LandmarksLayer, PointsLayer};

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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
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
