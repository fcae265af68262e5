//! Stage 3: generation. Turns the plan of one tile into mesh objects.
//!
//! Generation is a pure function of the plan, the type catalog and the parameters: no I/O,
//! no randomness of its own. A lot whose house cannot be built is skipped with a reason.

pub mod clip;
pub mod machiya;
pub mod materials;
pub mod mesh;

use crate::model::{PlannedMachiya, Skipped};
use crate::params::Params;
use crate::templates::Catalog;
use mesh::{Frame, Mesh};

/// Meshes of one tile, in plan (input) order, and the lots that could not be built.
#[derive(Debug, Default)]
pub struct TileMeshes {
    pub meshes: Vec<Mesh>,
    pub skipped: Vec<Skipped>,
    /// Type name of each mesh and whether it is a footprint, parallel to `meshes`.
    pub types: Vec<(String, bool)>,
    /// District of each mesh ("" = none), parallel to `meshes`.
    pub districts: Vec<String>,
}

/// The files features came from, for skip reports.
#[derive(Debug, Clone, Default)]
pub struct LayerFiles {
    pub lots: String,
    pub footprints: String,
}

pub fn generate_tile(
    lots: &[PlannedMachiya],
    catalog: &Catalog,
    params: &Params,
    origin: [f64; 2],
    files: &LayerFiles,
) -> TileMeshes {
    let frame = Frame { origin };
    let mut out = TileMeshes::default();
    for m in lots {
        let result = match catalog.get(&m.mtype) {
            Some(t) => machiya::build(m, t, &params.machiya, frame),
            None => Err(format!("machiya type `{}` has no type file", m.mtype)),
        };
        match result {
            Ok(mesh) => {
                out.meshes.push(mesh);
                out.types.push((m.mtype.clone(), m.height.is_some()));
                out.districts.push(m.district.clone().unwrap_or_default());
            }
            Err(reason) => {
                let (layer, file) = match m.height {
                    None => ("lots", &files.lots),
                    Some(_) => ("footprints", &files.footprints),
                };
                out.skipped.push(Skipped {
                    layer: layer.into(),
                    file: file.clone(),
                    id: m.id.clone(),
                    reason,
                })
            }
        }
    }
    out
}
