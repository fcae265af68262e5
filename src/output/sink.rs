//! The one interface `build` drives every output format through: a [`Sink`] writes a tile's
//! files from its meshes and features, and, once every tile is in the manifest, the files
//! that describe the whole city (the GLB sink's `tileset.json`). A format is a folder of
//! `output/` with a sink; the pipeline does not change when one is added.

use std::path::Path;

use super::features::Feature;
use super::report::{Manifest, ManifestFile};
use crate::generate::mesh::Mesh;

/// What a sink is given of one tile.
pub struct TileContent<'a> {
    /// The tile's id (its files are `tiles/<id>.<ext>`).
    pub id: &'a str,
    /// The dataset origin (projected metres): the meshes' positions are relative to it.
    pub origin: [f64; 2],
    /// The tile's centre relative to `origin`, whole millimetres in the output frame
    /// (x east, y up, z south): formats that write small local coordinates subtract it.
    pub centre: [i64; 3],
    /// The tile's objects.
    pub meshes: &'a [Mesh],
    /// One description per mesh.
    pub features: &'a [Feature],
    /// The grown trees by variant: the `trees_grown` mesh holds copies of them; a format
    /// that instances draws each variant's model at its trees instead.
    pub instanced: &'a [crate::generate::planted::Instanced],
    /// One description per instanced tree, variant by variant.
    pub instance_features: &'a [Feature],
    /// The walkers: the `people_walking` mesh holds them at time 0; a format that animates
    /// draws them walking instead.
    pub crowd: Option<&'a crate::generate::crowd::Crowd>,
    /// What the meshes' material ids name (the library, then the landmarks' materials).
    pub palette: super::palette::Palette<'a>,
}

/// What a sink wrote for one tile.
pub struct TileFiles {
    /// Its files, for the manifest.
    pub files: Vec<ManifestFile>,
    /// The bytes each mesh took in the file, when the format can tell (OBJ).
    pub mesh_bytes: Option<Vec<usize>>,
}

/// One output format.
pub trait Sink: Sync {
    /// The format's name, as `--format` spells it.
    fn format(&self) -> &'static str;
    /// Writes one tile's files under `out`.
    fn write_tile(&self, out: &Path, tile: &TileContent) -> std::io::Result<TileFiles>;
    /// Writes the files describing the whole build, once `manifest` lists every tile; returns
    /// them for the manifest. Re-run by `merge` and by `--tiles` over the whole manifest.
    fn finish(
        &self,
        _out: &Path,
        _manifest: &Manifest,
        _warnings: &mut Vec<String>,
    ) -> std::io::Result<Vec<ManifestFile>> {
        Ok(Vec::new())
    }
}

/// The tile centre the local formats take positions around: the grid square's centre for a
/// grid id, else the middle of the tile's content (`bounds`, output frame millimetres:
/// min then max), both relative to the dataset origin and rounded to whole millimetres.
pub fn tile_centre(
    id: &str,
    origin: [f64; 2],
    tile_size: f64,
    tile_origin: [f64; 2],
    bounds: Option<([i64; 3], [i64; 3])>,
) -> [i64; 3] {
    let mm = |v: f64| (v * 1000.0).round() as i64;
    match crate::model::tile::tile_bounds(id, tile_size, tile_origin) {
        Some(b) => [
            mm((b[0] + b[2]) / 2.0 - origin[0]),
            0,
            -mm((b[1] + b[3]) / 2.0 - origin[1]),
        ],
        None => match bounds {
            Some((lo, hi)) => [(lo[0] + hi[0]) / 2, 0, (lo[2] + hi[2]) / 2],
            None => [0, 0, 0],
        },
    }
}

/// The box holding two boxes (either may be missing).
pub fn union(
    a: Option<([i64; 3], [i64; 3])>,
    b: Option<([i64; 3], [i64; 3])>,
) -> Option<([i64; 3], [i64; 3])> {
    match (a, b) {
        (Some((a0, a1)), Some((b0, b1))) => Some((
            [0, 1, 2].map(|k| a0[k].min(b0[k])),
            [0, 1, 2].map(|k| a1[k].max(b1[k])),
        )),
        (a, b) => a.or(b),
    }
}

/// The extent of `meshes` in the output frame, millimetres: (min, max); `None` when they
/// hold no vertex.
pub fn extent(meshes: &[Mesh]) -> Option<([i64; 3], [i64; 3])> {
    let mut it = meshes.iter().flat_map(|m| m.positions.iter());
    let first = *it.next()?;
    let (mut lo, mut hi) = (first, first);
    for p in it {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Some((lo, hi))
}
