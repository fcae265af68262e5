//! `[layers.landmarks]` and `[landmarks]`: buildings the method cannot generate (a castle
//! keep, a great temple hall), modelled elsewhere and placed in the city from their own
//! files, as the paper placed the lost keep of Nijo castle (section 5, fig. 18).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The landmarks layer: points or polygons (a shapefile), or a CSV/XLSX table with x, y in
/// the output CRS, each naming its model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandmarksLayer {
    /// `landmarks.shp`, or a `.csv`/`.xlsx` table, relative to the input directory; "" = none
    /// (a missing default file is no layer).
    pub file: String,
    /// The layer of a GeoPackage `file` holds ("" = its only feature layer, else the one
    /// named as the role); other files have one layer.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub layer: String,
    /// DBF text encoding; empty = the `.cpg` file, else the DBF header, else UTF-8.
    #[serde(default)]
    pub encoding: String,
    /// Field holding the landmark's id (else its record number from 1).
    pub id_field: String,
    /// Field holding the model's file, relative to `landmarks.models_dir`.
    pub model_field: String,
    /// Field holding a kind that `landmarks.models` maps to a file (used when the record has
    /// no model of its own).
    pub kind_field: String,
    /// Field holding the turn about the vertical, degrees clockwise seen from above (as a
    /// GIS point symbol turns); empty or missing = 0.
    pub rotation_field: String,
    /// Field holding the model's scale factor; empty or missing = 1.
    pub scale_field: String,
    /// Field holding the elevation the model stands on (`landmarks.ground = "given"`).
    pub z_field: String,
    /// A table's column of x (easting, output CRS).
    pub x_field: String,
    /// A table's column of y (northing, output CRS).
    pub y_field: String,
    /// The sheet of an XLSX table ("" = the first).
    #[serde(default)]
    pub sheet: String,
}

/// How landmarks are placed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandmarkParams {
    /// Whether the landmarks layer is read and placed.
    pub enabled: bool,
    /// Where model files are looked up: "" = the input directory; a relative path is taken
    /// from the working directory (as `textures` is).
    pub models_dir: String,
    /// The model of each kind (the kind field's value -> a file in `models_dir`).
    pub models: BTreeMap<String, String>,
    /// What of the model stands on the point: "base" (the middle of its box, its lowest
    /// point on the ground) or "origin" (the model's own 0, 0, 0).
    pub anchor: String,
    /// The elevation it stands on: "lot" (the ground of the lot holding it, else the lots'
    /// ground there), "dem" (the DEM at the point) or "given" (the z field).
    pub ground: String,
    /// The model's up axis: "y" (glTF, and OBJ as Blender exports it) or "z".
    pub up: String,
    /// Generated features (houses, kura, walls, gates) that overlap a landmark's footprint
    /// are not built (listed as displaced); false builds them anyway.
    pub displace: bool,
}

/// The largest a model may be after scaling (metres, any axis): beyond it the scale is
/// surely wrong (centimetres read as metres, say).
pub const MAX_SIZE: f64 = 500.0;
/// The smallest a model may be after scaling (metres, its largest side).
pub const MIN_SIZE: f64 = 0.1;
/// How far a model's footprint may lie from its point, metres.
pub const MAX_OFFSET: f64 = 100.0;

impl LandmarkParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        let one_of = |key: &str, v: &str, allowed: &[&str]| {
            if allowed.contains(&v) {
                Ok(())
            } else {
                Err(format!(
                    "`landmarks.{key}` must be one of {}, got \"{v}\"",
                    allowed
                        .iter()
                        .map(|a| format!("\"{a}\""))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            }
        };
        one_of("anchor", &self.anchor, &["base", "origin"])?;
        one_of("ground", &self.ground, &["lot", "dem", "given"])?;
        one_of("up", &self.up, &["y", "z"])?;
        for (kind, file) in &self.models {
            if file.trim().is_empty() {
                return Err(format!(
                    "`landmarks.models.{kind}` is empty: give the model file of that kind"
                ));
            }
        }
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
    pub struct LandmarksLayer {
        file: Option<String>,
        layer: Option<String>,
        encoding: Option<String>,
        id_field: Option<String>,
        model_field: Option<String>,
        kind_field: Option<String>,
        rotation_field: Option<String>,
        scale_field: Option<String>,
        z_field: Option<String>,
        x_field: Option<String>,
        y_field: Option<String>,
        sheet: Option<String>,
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Landmarks {
        enabled: Option<bool>,
        models_dir: Option<String>,
        models: Option<BTreeMap<String, String>>,
        anchor: Option<String>,
        ground: Option<String>,
        up: Option<String>,
        displace: Option<bool>,
    }
}
