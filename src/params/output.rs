//! `[output]`: which formats a build writes, and `origin_lonlat`, where a city in a local or
//! unknown CRS stands on the globe (for the 3D Tiles tileset).

use serde::{Deserialize, Serialize};

pub use super::allowed::{FORMATS, GLB_COMPRESSIONS};

/// The output's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputParams {
    /// The formats: `obj` (OBJ + MTL), `glb` (binary glTF, with `tileset.json`), `gpkg`
    /// (`plan.gpkg`, the decisions as GIS layers).
    pub formats: Vec<String>,
    /// OBJ objects: `"each"` (one per house, kura, wall..., named by its lot: pick a house in
    /// Blender by name) or `"kind"` (one per kind with one run per material: a few dozen
    /// draw calls a tile in three.js instead of thousands; the houses' names are gone).
    #[serde(default = "each")]
    pub obj_objects: String,
    /// GLB vertex and index data: `"meshopt"` (`EXT_meshopt_compression`, required: three.js
    /// with its decoder, CesiumJS, gltfpack read it) or `"none"` (plain views, for clients
    /// without a decoder, such as Blender's importer and the Khronos validator).
    #[serde(default = "meshopt")]
    pub glb_compression: String,
    /// The city model's surfaces name their textures (the library's PNGs in
    /// `tiles/textures/`, with each corner's texture coordinates), for clients that draw
    /// CityJSON textures; off, surfaces carry their materials' colours only. Left out of a
    /// published manifest when off, so builds without it keep their fingerprint.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub cityjson_textures: bool,
}

fn each() -> String {
    "each".into()
}

fn meshopt() -> String {
    "meshopt".into()
}

impl OutputParams {
    pub(super) fn validate(&self) -> Result<(), String> {
        check_formats(&self.formats).map_err(|e| format!("`output.formats`: {e}"))?;
        if !GLB_COMPRESSIONS.contains(&self.glb_compression.as_str()) {
            return Err(format!(
                "`output.glb_compression` must be \"meshopt\" or \"none\" (for clients without \
                 a meshopt decoder), got \"{}\"",
                self.glb_compression
            ));
        }
        super::allowed::check_word("output.obj_objects", &self.obj_objects)
    }
}

/// The error for a list of formats that is empty or names an unknown one.
pub fn check_formats(formats: &[String]) -> Result<(), String> {
    if formats.is_empty() {
        return Err(format!("name at least one format ({})", FORMATS.join(", ")));
    }
    match formats.iter().find(|f| !FORMATS.contains(&f.as_str())) {
        Some(f) => Err(format!(
            "unknown format `{f}`: the formats are {}",
            FORMATS.join(", ")
        )),
        None if formats.iter().all(|f| f == "gpkg") => Err(
            "name a tile format (obj, glb or cityjson) beside gpkg: plan.gpkg describes the tiles"
                .into(),
        ),
        None => Ok(()),
    }
}

/// Checks `origin_lonlat = [lon, lat, h]`.
pub fn check_origin_lonlat(o: &[f64; 3]) -> Result<(), String> {
    let ok = o.iter().all(|v| v.is_finite())
        && (-180.0..=180.0).contains(&o[0])
        && (-90.0..=90.0).contains(&o[1])
        && (-1000.0..=10_000.0).contains(&o[2]);
    if ok {
        Ok(())
    } else {
        Err(format!(
            "`origin_lonlat` must be [longitude -180..180, latitude -90..90, height -1000..10000 m], got {o:?}"
        ))
    }
}

/// The same table with every field optional, for checking a user's partial file.
pub(super) mod partial {
    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Output {
        formats: Option<Vec<String>>,
        obj_objects: Option<String>,
        glb_compression: Option<String>,
        cityjson_textures: Option<bool>,
    }
}
