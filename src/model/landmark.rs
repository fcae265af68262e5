//! Landmarks: buildings modelled elsewhere (a castle keep, a great hall) and placed in the
//! city from their own files, as the paper placed the lost keep of Nijo castle (section 5).
//! Input reads the records and loads each model once; analysis places them and lists what
//! they displace; generation copies their triangles into the tile of their point.

use std::sync::Arc;

use geo_types::{Coord, Polygon};
use serde::{Deserialize, Serialize};

use super::TileId;

/// A model as read from its file: triangles in the model's own frame and units.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// The file, as the user named it (relative to the models' directory).
    pub file: String,
    /// A short name for the output's prefixed materials: the file's stem, letters, digits,
    /// `-` and `_` only.
    pub stem: String,
    /// Vertex positions, the model's frame (its up axis as `landmarks.up` says).
    pub positions: Vec<[f64; 3]>,
    /// Texture coordinates.
    pub uvs: Vec<[f64; 2]>,
    /// Triangles: corners as (position, uv) indices, counter-clockwise seen from outside, and
    /// the index of their material in `materials`.
    pub triangles: Vec<ModelTriangle>,
    /// The model's materials.
    pub materials: Vec<ModelMaterial>,
}

/// One triangle of a model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModelTriangle {
    /// Position indices.
    pub positions: [u32; 3],
    /// Texture coordinate indices, when the model has them.
    pub uvs: Option<[u32; 3]>,
    /// Index in the model's materials.
    pub material: u32,
}

/// A model's material as its file gives it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelMaterial {
    /// Its name in the model's file.
    pub name: String,
    /// Diffuse colour (linear 0-1 as the file has it).
    pub kd: [f32; 3],
    /// Its texture, when it has one that could be read: the file's name and its bytes (PNG
    /// or JPEG, copied as they are).
    pub texture: Option<(String, Arc<Vec<u8>>)>,
}

/// A material a model brought, as the tiles name it: after the library's materials, its
/// name prefixed `lm_<model>_` so it never clashes with ours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaletteEntry {
    /// The prefixed name.
    pub name: String,
    /// Diffuse colour.
    pub kd: [f32; 3],
    /// Its texture's prefixed file name in `tiles/textures/`.
    pub texture: Option<String>,
}

/// A record of the landmarks layer, as read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LandmarkRecord {
    /// Its id (the id field, else the record number from 1).
    pub id: String,
    /// Its record in the layer.
    pub record: usize,
    /// Where it stands: the point, or the middle of its polygon.
    pub at: Coord<f64>,
    /// The polygon of a polygon record: its footprint.
    pub footprint: Option<Polygon<f64>>,
    /// The model (a key of [`super::Dataset::models`]).
    pub model: String,
    /// Turn about the vertical, degrees clockwise seen from above.
    pub rotation: f64,
    /// Scale factor.
    pub scale: f64,
    /// The given elevation (the z field), if any.
    pub z: Option<f64>,
}

/// A landmark analysis placed: its model, where and how, in the tile of its point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedLandmark {
    /// The record's id.
    pub id: String,
    /// Its record in the layer.
    pub record: usize,
    /// The model.
    pub model: Arc<Model>,
    /// The model's point that stands on `at` (model frame, after the up axis is turned to
    /// z): the base's middle, or the origin.
    pub anchor: [f64; 3],
    /// Where the anchor stands: map point and elevation.
    pub at: [f64; 3],
    /// Turn about the vertical, radians clockwise seen from above.
    pub rotation: f64,
    /// Scale factor.
    pub scale: f64,
    /// Whether the model is z-up (else y-up).
    pub z_up: bool,
    /// The library id of the model's first material in the build's palette (its materials
    /// follow in order).
    pub material_base: u16,
    /// The footprint on the map (its polygon, else its model's hull).
    pub footprint: Polygon<f64>,
    /// Its box on the map after placing: east, north, up minimum then maximum.
    pub bounds: [f64; 6],
    /// The tile it is written to, whole.
    pub tile: TileId,
}

impl PlannedLandmark {
    /// Its object name: `landmark_<id>`.
    pub fn object_name(&self) -> String {
        format!("landmark_{}", self.id)
    }

    /// A model point (model frame, its own up axis) on the map: east, north, up.
    pub fn place(&self, p: [f64; 3]) -> [f64; 3] {
        place(
            p,
            self.z_up,
            self.anchor,
            self.scale,
            self.rotation,
            self.at,
        )
    }
}

/// A model point with `up` turned to z (x east, y north, z up): a y-up model's -z is north.
pub fn z_up(p: [f64; 3], model_z_up: bool) -> [f64; 3] {
    if model_z_up {
        p
    } else {
        [p[0], -p[2], p[1]]
    }
}

/// A model point on the map: its up axis turned to z, less the anchor, scaled, turned
/// clockwise by `rotation` radians and moved to `at`.
pub fn place(
    p: [f64; 3],
    model_z_up: bool,
    anchor: [f64; 3],
    scale: f64,
    rotation: f64,
    at: [f64; 3],
) -> [f64; 3] {
    let q = z_up(p, model_z_up);
    let (x, y, z) = (
        (q[0] - anchor[0]) * scale,
        (q[1] - anchor[1]) * scale,
        (q[2] - anchor[2]) * scale,
    );
    let (s, c) = rotation.sin_cos();
    // Clockwise seen from above: east turns towards south.
    [at[0] + x * c + y * s, at[1] - x * s + y * c, at[2] + z]
}

/// A feature a landmark displaced, in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Displaced {
    /// The landmark's id.
    pub landmark: String,
    /// What was not built: `machiya`, `footprint`, `kura`, `wall` or `gate`.
    pub kind: String,
    /// Its id (the lot's or fence line's).
    pub id: String,
    /// Why: what of it overlapped the landmark's footprint, and what was kept.
    pub reason: String,
}

/// A placed landmark in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlacedLandmark {
    /// The record's id.
    pub id: String,
    /// The model file.
    pub model: String,
    /// The tile it is in.
    pub tile: String,
    /// Its box: east, north, up minimum then maximum (projected metres).
    pub bounds: [f64; 6],
    /// Triangles of its model.
    pub triangles: usize,
}

/// A landmark not placed, in the report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedLandmark {
    /// The record's id.
    pub id: String,
    /// Its record.
    pub record: usize,
    /// Why.
    pub reason: String,
}

/// What became of the landmarks layer: `report.json`'s `landmarks`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LandmarkReport {
    /// The landmarks placed.
    pub placed: Vec<PlacedLandmark>,
    /// Generated features not built because a landmark stands there.
    pub displaced: Vec<Displaced>,
    /// The landmarks not placed, with why.
    pub skipped: Vec<SkippedLandmark>,
}
