//! The MTL file of a tile, and the texture library copied beside the tiles.
//!
//! Textured materials get a white `Kd`: three.js multiplies the texture by `Kd`, Blender and
//! MeshLab ignore it when a texture is present, so white shows the texture right everywhere.
//! Billboards (trees, people) are cut out by their texture's alpha: `map_d` names its mask
//! (RGBA = a,a,a,a of the texture, written beside it), which Blender's importer reads as
//! alpha and three.js's MTLLoader as an `alphaMap` (from the green channel): the same cut
//! in both. Viewers that read only `map_Kd` still get the RGBA texture.

use std::fmt::Write;

use crate::generate::mesh::Mesh;
use crate::materials::MATERIALS;
use crate::output::palette::{Entry, Palette};

/// MTL text listing every material, for a tile in `tiles/`: textures are referenced as
/// `textures/<file>` (the library is in `tiles/textures/`, no `..`).
pub fn mtl_text() -> String {
    mtl_text_at("textures/")
}

/// A tile's MTL text: the library, then the landmark materials its meshes use (a tile
/// without a landmark has the library's text alone).
pub fn tile_mtl_text(meshes: &[Mesh], palette: Palette) -> String {
    let mut s = mtl_text();
    let mut extra: Vec<u16> = meshes
        .iter()
        .flat_map(|m| m.faces.iter().map(|f| f.material))
        .filter(|&id| Palette::is_extra(id))
        .collect();
    extra.sort_unstable();
    extra.dedup();
    for id in extra {
        write_material(&mut s, &palette.get(id), "textures/");
    }
    s
}

/// MTL text with textures referenced as `<prefix><file>`.
pub fn mtl_text_at(prefix: &str) -> String {
    let mut s = format!(
        "# edo-city {} materials; textures in {prefix}\n",
        env!("CARGO_PKG_VERSION")
    );
    let library = Palette::LIBRARY;
    for id in 0..MATERIALS.len() {
        write_material(&mut s, &library.get(id as u16), prefix);
    }
    s
}

/// One `newmtl` block: a textured material white with its texture (and its alpha mask when
/// it is cut out), an untextured one its colour.
fn write_material(s: &mut String, m: &Entry, prefix: &str) {
    let _ = writeln!(s, "\nnewmtl {}", m.name);
    match m.texture {
        Some(t) => {
            let _ = writeln!(
                s,
                "# untextured colour: {:.3} {:.3} {:.3}",
                m.kd[0], m.kd[1], m.kd[2]
            );
            s.push_str("Ka 1.000 1.000 1.000\nKd 1.000 1.000 1.000\n");
            let _ = writeln!(
                s,
                "Ks 0.000 0.000 0.000\nd 1.0\nillum 1\nmap_Kd {prefix}{t}"
            );
            if let (true, Some(mask)) = (m.alpha, m.mask) {
                let _ = writeln!(s, "map_d {prefix}{mask}");
            }
        }
        None => {
            let _ = writeln!(
                s,
                "Ka {0:.3} {1:.3} {2:.3}\nKd {0:.3} {1:.3} {2:.3}\nKs 0.000 0.000 0.000\nd 1.0\nillum 1",
                m.kd[0], m.kd[1], m.kd[2]
            );
        }
    }
}
