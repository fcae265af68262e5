//! Stage 3: generation. Turns the plan of one tile into mesh objects.
//!
//! Generation is a pure function of the plan, the type catalog and the parameters: no I/O,
//! no randomness of its own. A lot whose house cannot be built is skipped with a reason.

pub mod clip;
pub mod instance;
pub mod machiya;
pub mod materials;
pub mod mesh;

use crate::model::{PlannedMachiya, Skipped, TileStats};
use crate::params::Params;
use crate::templates::Catalog;
use mesh::{Frame, Mesh};

/// Meshes of one tile, in plan (input) order, and what they are (with the lots that could
/// not be built).
#[derive(Debug, Default)]
pub struct TileMeshes {
    pub meshes: Vec<Mesh>,
    /// What the tile holds, for the report.
    pub stats: TileStats,
}

/// The files features came from, for skip reports.
#[derive(Debug, Clone, Default)]
pub struct LayerFiles {
    pub lots: String,
    pub footprints: String,
}

/// The `random` input of a feature's template: its own stream, apart from the type draw.
fn template_random(seed: u64, layer: &str, id: &str) -> f64 {
    use rand::RngExt;
    crate::rng::feature_rng(seed, &format!("{layer}/template"), id).random::<f64>()
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
        let layer = if m.height.is_some() {
            "footprints"
        } else {
            "lots"
        };
        let result = match catalog.machiya(&m.mtype) {
            Some(t) => {
                let overrides = catalog.overrides(&m.mtype, m.district.as_deref());
                let random = template_random(params.seed, layer, &m.id);
                machiya::build(m, t, &overrides, &params.machiya, random, frame)
            }
            None => Err(format!("machiya type `{}` has no template", m.mtype)),
        };
        match result {
            Ok(mesh) => {
                out.meshes.push(mesh);
                let st = &mut out.stats;
                let by_type = if m.height.is_some() {
                    st.footprints += 1;
                    &mut st.footprints_by_type
                } else {
                    st.machiya += 1;
                    st.type_given += m.type_given as usize;
                    &mut st.by_type
                };
                *by_type.entry(m.mtype.clone()).or_default() += 1;
                *st.by_district
                    .entry(m.district.clone().unwrap_or_default())
                    .or_default() += 1;
            }
            Err(reason) => {
                let (layer, file) = match m.height {
                    None => ("lots", &files.lots),
                    Some(_) => ("footprints", &files.footprints),
                };
                out.stats.skipped.push(Skipped {
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
