//! The GLB codec both GLB writers share: the tile sink (`output::gltf`) and the levels of
//! detail above the tiles (`output::tiles3d::lod`), which also reads tiles back. The BIN
//! chunk with its views and accessors (`buffer.rs`), the `EXT_structural_metadata` table
//! (`metadata.rs`), colours, images and extensions, and the shared models' URIs: what a
//! leaf writes and a parent or a reader must find the same way. It knows nothing of tiles,
//! sinks or tilesets (issue 58: `gltf/` and `tiles3d/lod/` imported each other).

use serde_json::{json, Value};

pub mod buffer;
pub mod container;
pub mod metadata;

use buffer::Buffer;

/// sRGB to linear, for `baseColorFactor` (glTF factors are linear).
pub fn linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The images and textures of a tile (leaf or parent), with the one sampler they share
/// (linear, mipmapped, repeating); nothing when there are none.
pub fn add_images(doc: &mut Value, images: Vec<Value>, textures: Vec<Value>) {
    if !images.is_empty() {
        doc["images"] = json!(images);
        doc["textures"] = json!(textures);
        doc["samplers"] =
            json!([{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]);
    }
}

/// `extensionsUsed` and `extensionsRequired` of a tile (a leaf or a parent): the metadata
/// extensions, `KHR_mesh_quantization` (byte normals, short positions: not core glTF, so a
/// client must know it to read them) and, when a view of `buf` was compressed,
/// `EXT_meshopt_compression` (those views have no data but what the decoder makes).
pub fn declare_extensions(doc: &mut Value, buf: &Buffer) {
    let mut used = vec![
        "EXT_mesh_features",
        "EXT_structural_metadata",
        "KHR_mesh_quantization",
    ];
    let mut required = vec!["KHR_mesh_quantization"];
    if buf.compressed() {
        used.push("EXT_meshopt_compression");
        required.push("EXT_meshopt_compression");
    }
    doc["extensionsUsed"] = json!(used);
    doc["extensionsRequired"] = json!(required);
}

/// Where the shared models are written, relative to the output directory (beside
/// `tiles/textures/`, so a tile reaches them without `..`).
pub const MODELS_DIR: &str = "tiles/models";

/// The URI of the model named `name`, relative to `tiles/` (a variant's name is
/// `<species>_<k>`, the species' name checked to be letters, digits and `_`).
pub fn uri_of(name: &str) -> String {
    format!("models/{name}.bin")
}

/// Whether `uri` is one [`uri_of`] makes: `models/<name>.bin`, the name of letters, digits,
/// `_` and `.` but no `..`. Readers of our own tiles take no other external buffer.
pub fn is_shared_uri(uri: &str) -> bool {
    let name = uri.strip_prefix("models/").unwrap_or("");
    name.ends_with(".bin")
        && (name.chars()).all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.')
        && !name.contains("..")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_uris_of_shared_models_are_taken() {
        assert!(is_shared_uri(&uri_of("matsu_3")));
        for bad in [
            "../matsu_3.bin",
            "models/../matsu_3.bin",
            "models/a/b.bin",
            "models/matsu_3.png",
            "https://example.org/models/matsu_3.bin",
            "/models/matsu_3.bin",
            "models/.bin.",
        ] {
            assert!(!is_shared_uri(bad), "{bad}");
        }
    }
}
