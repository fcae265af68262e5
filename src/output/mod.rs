//! Stage 4: output. Writes tiles through one [`sink::Sink`] per format (`obj/`: OBJ + MTL,
//! `gltf/`: GLB, with `tiles3d/`'s `tileset.json`), textures, `plan.gpkg` (`gpkg/`: the
//! decisions as GIS layers), `report.json` and `manifest.json`.
//!
//! Every file goes through [`atomic::write_atomic`]; `manifest.json` is written last, so a
//! manifest always describes complete tiles.

pub mod accounting;
pub mod atlas;
pub mod atomic;
pub mod chart;
pub mod cityjson;
pub mod crowds;
pub mod cutout;
pub mod features;
pub mod glb;
pub mod gltf;
pub mod gpkg;
pub mod links;
pub mod listed;
pub mod lock;
pub mod obj;
pub mod palette;
pub mod plan;
pub mod render;
pub mod report;
pub mod sink;
pub mod sketch;
pub mod species;
pub mod target;
pub mod text;
pub mod texture_set;
pub mod tiles3d;

pub use texture_set::{texture_library, with_masks, TextureError, MAX_TEXTURE_BYTES};

use std::borrow::Cow;
use std::path::Path;

use sha2::{Digest, Sha256};

/// The build's decisions as GIS layers, beside the tiles (`gpkg/`).
pub const PLAN_GPKG: &str = "plan.gpkg";

use crate::generate::mesh::Mesh;
use crate::materials::TEXTURES;
use report::ManifestFile;

/// An I/O error at one file of a build's whole-city steps, carried through a `Sink`'s
/// `io::Result` so that the message names the file, not the output directory (a
/// `city.city.jsonl` that was a directory read "cannot write OUT": issue 74).
#[derive(Debug, thiserror::Error)]
#[error("{cause}")]
pub struct AtFile {
    /// The file.
    pub path: std::path::PathBuf,
    /// What the operating system said.
    pub cause: std::io::Error,
}

/// `cause` as an error at `path` (see [`AtFile`]).
pub fn at_file(path: &Path, cause: std::io::Error) -> std::io::Error {
    std::io::Error::new(
        cause.kind(),
        AtFile {
            path: path.to_path_buf(),
            cause,
        },
    )
}

/// The sha256 of `bytes` in lower-case hex, as the manifest lists every file.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// A digest in lower-case hex.
pub fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Writes `<out>/<path>` from `parts` (see [`atomic::write_atomic_hashed`]) and lists it for
/// the manifest: every file of a build is written and listed this one way.
pub fn write_listed(out: &Path, path: String, parts: &[&[u8]]) -> std::io::Result<ManifestFile> {
    let sha256 = atomic::write_atomic_hashed(&out.join(&path), parts)?;
    Ok(ManifestFile {
        bytes: parts.iter().map(|p| p.len() as u64).sum(),
        path,
        sha256,
    })
}

/// The sinks of `output.formats` (names as [`crate::params::output::FORMATS`] has them), in
/// the order given; unknown names were refused when the parameters were read.
/// `atlas` is the cut-out atlas the build wrote beside the textures, for the GLB tiles.
/// The registry is the folder's front door: the trait sits in `sink.rs` with nothing of the
/// formats, each format imports the trait, and only this names the formats (issue 58: the
/// registry beside the trait made the two import each other).
/// `hypothesis` is the parameters' fingerprint ([`report::params_id`]) the city model names.
/// `memory` keeps the levels of detail between builds into one directory (the workbench's).
pub fn sinks(
    output: &crate::params::OutputParams,
    atlas: Option<&atlas::Atlas>,
    hypothesis: &str,
    memory: Option<&std::sync::Arc<tiles3d::memory::Memory>>,
) -> Vec<Box<dyn sink::Sink>> {
    let mut out: Vec<Box<dyn sink::Sink>> = Vec::new();
    for f in &output.formats {
        let s: Box<dyn sink::Sink> = match f.as_str() {
            "obj" => Box::new(obj::ObjSink {
                by_kind: output.obj_objects == "kind",
            }),
            "glb" => Box::new(gltf::GlbSink {
                meshopt: output.glb_compression == "meshopt",
                atlas: atlas.cloned(),
                shared: Default::default(),
                memory: memory.cloned(),
            }),
            "cityjson" => Box::new(cityjson::CityJsonSink::new(
                hypothesis.to_string(),
                output.cityjson_textures,
            )),
            _ => continue,
        };
        if !out.iter().any(|o| o.format() == s.format()) {
            out.push(s);
        }
    }
    out
}

/// Where the texture library is written, relative to the output directory: inside `tiles/`,
/// so a tile's MTL and GLB reach it as `textures/<file>` without climbing out of the tile's
/// folder (trimesh 5 refuses `../` paths).
pub const TEXTURE_DIR: &str = "tiles/textures";

/// One texture file: its name in the texture directory and its PNG bytes.
pub type Texture = (&'static str, Cow<'static, [u8]>);

/// Writes the texture library to `<out>/tiles/textures/` ([`TEXTURE_DIR`]).
pub fn write_textures(out: &Path, library: &[Texture]) -> std::io::Result<Vec<ManifestFile>> {
    write_texture_files(out, library.iter().map(|(n, b)| (*n, &b[..])))
}

/// Writes the textures the landmarks' models brought (prefixed names, see
/// [`crate::model::Plan::model_textures`]) beside the library.
pub fn write_model_textures(
    out: &Path,
    textures: &[(String, std::sync::Arc<Vec<u8>>)],
) -> std::io::Result<Vec<ManifestFile>> {
    write_texture_files(out, textures.iter().map(|(n, b)| (n.as_str(), &b[..])))
}

/// Writes each (file name, bytes) into `<out>/tiles/textures/`.
fn write_texture_files<'a>(
    out: &Path,
    files: impl Iterator<Item = (&'a str, &'a [u8])>,
) -> std::io::Result<Vec<ManifestFile>> {
    let dir = out.join(TEXTURE_DIR);
    std::fs::create_dir_all(&dir)?;
    files
        .map(|(name, bytes)| write_listed(out, format!("{TEXTURE_DIR}/{name}"), &[bytes]))
        .collect()
}

/// Why a model alone cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The path has no file name.
    #[error("{0}: give a file name ending in .obj")]
    NoName(String),
    /// The texture set cannot be used.
    #[error(transparent)]
    Textures(#[from] TextureError),
    /// A file cannot be written.
    #[error("cannot write {path}: {cause}")]
    Write {
        /// The file.
        path: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
}

/// Writes one model alone (a template, a tree): `<stem>.obj` with `meshes` as its objects,
/// `<stem>.mtl` and the texture library in `textures/` beside it; returns the number of
/// textures written.
pub fn write_model(
    obj_path: &Path,
    meshes: &[Mesh],
    texture_set: &str,
) -> Result<usize, ModelError> {
    let stem = obj_path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| ModelError::NoName(obj_path.display().to_string()))?;
    let dir = obj_path.parent().unwrap_or(Path::new(""));
    let io = |p: &Path, cause: std::io::Error| ModelError::Write {
        path: p.display().to_string(),
        cause,
    };
    let textures = with_masks(texture_library(texture_set)?)?;
    let tex_dir = dir.join("textures");
    std::fs::create_dir_all(&tex_dir).map_err(|e| io(&tex_dir, e))?;
    for (name, bytes) in &textures {
        let p = tex_dir.join(name);
        atomic::write_atomic(&p, bytes).map_err(|e| io(&p, e))?;
    }
    let mut buf = Vec::new();
    obj::write_tile(&mut buf, stem, [0.0, 0.0], meshes);
    atomic::write_atomic(obj_path, &buf).map_err(|e| io(obj_path, e))?;
    let mtl_path = dir.join(format!("{stem}.mtl"));
    atomic::write_atomic(&mtl_path, obj::mtl::mtl_text_at("textures/").as_bytes())
        .map_err(|e| io(&mtl_path, e))?;
    Ok(textures.len())
}

/// The bytes `meshes` take in an OBJ file of their own, without the file's header.
pub fn obj_bytes<'a>(meshes: impl IntoIterator<Item = &'a Mesh>) -> usize {
    let mut buf = Vec::new();
    obj::write_tile(&mut buf, "x", [0.0, 0.0], meshes)
        .iter()
        .sum()
}
