//! Wavefront OBJ text for one tile.
//!
//! Coordinates are whole millimetres in the mesh, printed as fixed-point metres with an
//! integer formatter: measured six times faster than `{:.3}` on this kind of file when the
//! writer was made, with the same bytes. Faces are grouped by material within each object so
//! each object has at most one `usemtl` per material.

pub mod mtl;

use std::io::Write;
use std::path::Path;

use super::palette::Palette;
use super::sink::{Sink, TileContent, TileFiles};
use super::write_listed;
use crate::generate::mesh::Mesh;

/// The OBJ format: `tiles/<id>.obj` and its `tiles/<id>.mtl`.
pub struct ObjSink {
    /// `output.obj_objects = "kind"`: one object per kind of object (all machiya, all kura,
    /// ...) with one `usemtl` run per material, instead of one object per house.
    pub by_kind: bool,
}

impl Sink for ObjSink {
    fn format(&self) -> &'static str {
        "obj"
    }

    fn write_tile(&self, out: &Path, tile: &TileContent) -> std::io::Result<TileFiles> {
        let id = tile.id;
        let mut obj = Vec::with_capacity(tile.meshes.len() * 4096);
        let sizes = if self.by_kind {
            let kinds: Vec<&str> = tile.features.iter().map(|f| f.kind.as_str()).collect();
            write_tile_by_kind(&mut obj, id, tile.origin, tile.meshes, &kinds, tile.palette);
            None
        } else {
            Some(write_tile_in(
                &mut obj,
                id,
                tile.origin,
                tile.meshes,
                tile.palette,
            ))
        };
        let mtl = mtl::tile_mtl_text(tile.meshes, tile.palette).into_bytes();
        Ok(TileFiles {
            files: vec![
                write_listed(out, format!("tiles/{id}.obj"), &[&obj])?,
                write_listed(out, format!("tiles/{id}.mtl"), &[&mtl])?,
            ],
            mesh_bytes: sizes,
        })
    }
}

/// Appends `v` (millimetres) as metres with three decimals.
fn push_mm(buf: &mut Vec<u8>, v: i64) {
    push_fixed(buf, v, 1000, 3);
}

/// Appends `v / scale` with `digits` decimals, `scale == 10^digits`: `v`'s digits with the
/// point set in, so one integer formatting (not a division and two) per number.
fn push_fixed(buf: &mut Vec<u8>, v: i64, scale: i64, digits: usize) {
    debug_assert_eq!(10i64.checked_pow(digits as u32), Some(scale));
    let mut itoa_buf = itoa::Buffer::new();
    if v < 0 {
        buf.push(b'-');
    }
    let all = itoa_buf.format(v.unsigned_abs()).as_bytes();
    match all.len().checked_sub(digits) {
        Some(whole) if whole > 0 => {
            buf.extend_from_slice(&all[..whole]);
            buf.push(b'.');
            buf.extend_from_slice(&all[whole..]);
        }
        _ => {
            buf.extend_from_slice(b"0.");
            buf.extend(std::iter::repeat_n(b'0', digits - all.len()));
            buf.extend_from_slice(all);
        }
    }
}

/// The tile's header: version, origin, frame, the MTL.
fn header(buf: &mut Vec<u8>, tile: &str, origin: [f64; 2]) {
    let _ = write!(
        buf,
        "# edo-city {} tile {tile}\n\
         # origin: x0 = {:.3} (east), y0 = {:.3} (north), projected metres of the input CRS\n\
         # frame: x = east - x0, y = up, z = -(north - y0); units metres\n\
         mtllib {tile}.mtl\n",
        env!("CARGO_PKG_VERSION"),
        origin[0],
        origin[1]
    );
}

/// Appends a mesh's positions and texture coordinates.
fn vertices(buf: &mut Vec<u8>, mesh: &Mesh) {
    for p in &mesh.positions {
        buf.extend_from_slice(b"v ");
        push_mm(buf, p[0]);
        buf.push(b' ');
        push_mm(buf, p[1]);
        buf.push(b' ');
        push_mm(buf, p[2]);
        buf.push(b'\n');
    }
    for t in &mesh.uvs {
        buf.extend_from_slice(b"vt ");
        push_fixed(buf, i64::from(t[0]), 10_000, 4);
        buf.push(b' ');
        push_fixed(buf, i64::from(t[1]), 10_000, 4);
        buf.push(b'\n');
    }
}

/// Appends one face, its indices offset by the bases of its mesh.
fn face(buf: &mut Vec<u8>, f: &crate::generate::mesh::Face, v_base: u64, vt_base: u64) {
    let mut itoa_buf = itoa::Buffer::new();
    buf.push(b'f');
    for &(v, t) in &f.corners {
        buf.push(b' ');
        buf.extend_from_slice(itoa_buf.format(v_base + u64::from(v)).as_bytes());
        buf.push(b'/');
        buf.extend_from_slice(itoa_buf.format(vt_base + u64::from(t)).as_bytes());
    }
    buf.push(b'\n');
}

/// Appends `usemtl` when the material changes.
fn use_material(buf: &mut Vec<u8>, current: &mut Option<u16>, material: u16, palette: Palette) {
    if *current != Some(material) {
        *current = Some(material);
        buf.extend_from_slice(b"usemtl ");
        buf.extend_from_slice(palette.get(material).name.as_bytes());
        buf.push(b'\n');
    }
}

/// Writes a whole tile into `buf`, one object per mesh; returns the bytes each mesh's object
/// took.
pub fn write_tile<'a>(
    buf: &mut Vec<u8>,
    tile: &str,
    origin: [f64; 2],
    meshes: impl IntoIterator<Item = &'a Mesh>,
) -> Vec<usize> {
    write_tile_in(buf, tile, origin, meshes, Palette::LIBRARY)
}

/// The same, with material ids looked up in `palette`.
pub fn write_tile_in<'a>(
    buf: &mut Vec<u8>,
    tile: &str,
    origin: [f64; 2],
    meshes: impl IntoIterator<Item = &'a Mesh>,
    palette: Palette,
) -> Vec<usize> {
    header(buf, tile, origin);
    let (mut v_base, mut vt_base) = (1u64, 1u64);
    let mut sizes = Vec::new();
    for mesh in meshes {
        let start = buf.len();
        buf.extend_from_slice(b"o ");
        buf.extend_from_slice(mesh.name.as_bytes());
        buf.push(b'\n');
        vertices(buf, mesh);
        let mut order: Vec<usize> = (0..mesh.faces.len()).collect();
        order.sort_by_key(|&i| mesh.faces[i].material);
        let mut current = None;
        for i in order {
            let f = &mesh.faces[i];
            use_material(buf, &mut current, f.material, palette);
            face(buf, f, v_base, vt_base);
        }
        v_base += mesh.positions.len() as u64;
        vt_base += mesh.uvs.len() as u64;
        sizes.push(buf.len() - start);
    }
    sizes
}

/// Writes a whole tile into `buf` with one object per kind (`kinds[i]` is mesh i's, e.g.
/// `machiya`), in order of first appearance, and in each one `usemtl` run per material over
/// all its meshes: a loader makes one draw call per kind and material instead of one per
/// house and material. The houses' own names are gone (the GLB's metadata keeps them).
pub fn write_tile_by_kind(
    buf: &mut Vec<u8>,
    tile: &str,
    origin: [f64; 2],
    meshes: &[Mesh],
    kinds: &[&str],
    palette: Palette,
) {
    header(buf, tile, origin);
    let mut order: Vec<&str> = Vec::new();
    for k in kinds {
        if !order.contains(k) {
            order.push(k);
        }
    }
    let (mut v_base, mut vt_base) = (1u64, 1u64);
    for kind in order {
        buf.extend_from_slice(b"o ");
        buf.extend_from_slice(kind.as_bytes());
        buf.push(b'\n');
        // (material, mesh, face) over the kind's meshes, with each mesh's index bases.
        let mut faces: Vec<(u16, usize, usize)> = Vec::new();
        // Each mesh's index bases by its index (a search per face was quadratic in a tile's
        // houses).
        let mut bases = vec![(0u64, 0u64); meshes.len()];
        for (i, mesh) in meshes.iter().enumerate().filter(|(i, _)| kinds[*i] == kind) {
            vertices(buf, mesh);
            bases[i] = (v_base, vt_base);
            v_base += mesh.positions.len() as u64;
            vt_base += mesh.uvs.len() as u64;
            faces.extend(
                mesh.faces
                    .iter()
                    .enumerate()
                    .map(|(k, f)| (f.material, i, k)),
            );
        }
        faces.sort();
        let mut current = None;
        for (material, i, k) in faces {
            let (vb, tb) = bases[i];
            use_material(buf, &mut current, material, palette);
            face(buf, &meshes[i].faces[k], vb, tb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(v: i64, scale: i64, digits: usize) -> String {
        let mut b = Vec::new();
        push_fixed(&mut b, v, scale, digits);
        String::from_utf8(b).unwrap()
    }

    #[test]
    fn fixed_point_matches_float_formatting() {
        for v in [
            0i64,
            1,
            -1,
            999,
            -1000,
            1001,
            123_456_789,
            -5,
            10,
            -10_000_001,
        ] {
            assert_eq!(
                fixed(v, 1000, 3),
                format!("{:.3}", v as f64 / 1000.0),
                "{v}"
            );
        }
        assert_eq!(fixed(-12_345, 10_000, 4), "-1.2345");
        assert_eq!(fixed(7, 10_000, 4), "0.0007");
    }

    proptest::proptest! {
        /// The digits with the point set in are the whole part, the point and the fraction
        /// padded to `digits`, for numbers of every length (and i64's ends).
        #[test]
        fn fixed_point_is_whole_point_fraction(
            v in proptest::prop_oneof![
                -20_000i64..20_000,
                proptest::num::i64::ANY,
                proptest::strategy::Just(i64::MIN),
                proptest::strategy::Just(i64::MAX),
            ],
            digits in 1usize..6,
        ) {
            let scale = 10i64.pow(digits as u32);
            let a = v.unsigned_abs();
            let (whole, frac) = (a / scale as u64, a % scale as u64);
            let sign = if v < 0 { "-" } else { "" };
            proptest::prop_assert_eq!(
                fixed(v, scale, digits),
                format!("{sign}{whole}.{frac:0digits$}")
            );
        }
    }
}
