//! Stage 4: output. Writes tiles (OBJ + MTL), textures, `report.json` and `manifest.json`.
//!
//! Every file goes through [`atomic::write_atomic`]; `manifest.json` is written last, so a
//! manifest always describes complete tiles.

pub mod atomic;
pub mod mtl;
pub mod obj;
pub mod plan;
pub mod report;
pub mod text;

use std::path::Path;

use sha2::{Digest, Sha256};

use crate::generate::materials::TEXTURES;
use crate::generate::mesh::Mesh;
use report::ManifestFile;

pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Writes `<out>/tiles/<tile>.obj` and `.mtl`; returns their manifest entries.
pub fn write_tile(
    out: &Path,
    tile: &str,
    origin: [f64; 2],
    meshes: &[Mesh],
) -> std::io::Result<(ManifestFile, ManifestFile)> {
    let mut obj = Vec::with_capacity(meshes.len() * 4096);
    obj::write_tile(&mut obj, tile, origin, meshes);
    let mtl = mtl::mtl_text().into_bytes();
    let dir = out.join("tiles");
    atomic::write_atomic(&dir.join(format!("{tile}.obj")), &obj)?;
    atomic::write_atomic(&dir.join(format!("{tile}.mtl")), &mtl)?;
    Ok((
        ManifestFile {
            path: format!("tiles/{tile}.obj"),
            bytes: obj.len() as u64,
            sha256: sha256_hex(&obj),
        },
        ManifestFile {
            path: format!("tiles/{tile}.mtl"),
            bytes: mtl.len() as u64,
            sha256: sha256_hex(&mtl),
        },
    ))
}

/// Copies the texture library to `<out>/textures/`.
pub fn write_textures(out: &Path) -> std::io::Result<Vec<ManifestFile>> {
    let dir = out.join("textures");
    std::fs::create_dir_all(&dir)?;
    TEXTURES
        .iter()
        .map(|(name, bytes)| {
            atomic::write_atomic(&dir.join(name), bytes)?;
            Ok(ManifestFile {
                path: format!("textures/{name}"),
                bytes: bytes.len() as u64,
                sha256: sha256_hex(bytes),
            })
        })
        .collect()
}
