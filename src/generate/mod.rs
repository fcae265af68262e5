//! Stage 3: generation. Turns the plan of one tile into mesh objects.
//!
//! Generation is a pure function of the plan, the type catalog and the parameters: no I/O,
//! no randomness of its own. A lot whose house cannot be built is skipped with a reason.

pub mod billboards;
pub mod clip;
pub mod crowd;
pub mod envelope;
pub mod fences;
pub mod figure;
pub mod garden;
pub mod ground;
pub mod halls;
pub mod instance;
pub mod kura;
pub mod landmarks;
pub mod machiya;
pub mod mesh;
pub mod planted;
pub mod species;
pub mod terrain;
pub mod tree;
pub mod variant;

use crate::model::{
    FenceKind, KuraDecision, PlannedBillboard, PlannedFence, PlannedHouse, Skipped, TileStats,
};
use crate::params::Params;
use crate::templates::Catalog;
use mesh::{Frame, Mesh};

/// Meshes of one tile, in plan (input) order, and what they are (with the lots that could
/// not be built).
#[derive(Debug, Default)]
pub struct TileMeshes {
    /// The tile's meshes, one per object, in input order.
    pub meshes: Vec<Mesh>,
    /// What the tile holds, for the report.
    pub stats: TileStats,
    /// The grown trees by variant (their copies are in the `trees_grown` mesh too), for
    /// formats that instance.
    pub instanced: Vec<planted::Instanced>,
    /// The walkers (their copies at time 0 are the `people_walking` mesh), for formats that
    /// animate.
    pub crowd: Option<crowd::Crowd>,
}

/// The files features came from, for skip reports.
#[derive(Debug, Clone, Default)]
pub struct LayerFiles {
    /// The lots layer's file.
    pub lots: String,
    /// The footprints layer's file.
    pub footprints: String,
    /// The fence lines layer's file.
    pub fences: String,
    /// The people point layer's file.
    pub people: String,
    /// The trees point layer's file.
    pub trees: String,
}

/// What one tile of the plan holds.
#[derive(Debug, Clone, Copy, Default)]
pub struct TilePlan<'a> {
    /// The tile's houses, in input order.
    pub lots: &'a [PlannedHouse],
    /// The tile's fence segments and gates.
    pub fences: &'a [PlannedFence],
    /// The tile's people and trees.
    pub billboards: &'a [PlannedBillboard],
    /// The clips of the tile's walking people.
    pub walks: &'a [crate::model::Walk],
    /// The tile's rock gardens.
    pub gardens: &'a [crate::model::PlannedGarden],
    /// The tile's halls.
    pub halls: &'a [crate::model::PlannedHall],
    /// The tile's landmarks.
    pub landmarks: &'a [crate::model::PlannedLandmark],
    /// What the tile's ground is cut from, when `[ground]` is on.
    pub surface: Option<&'a crate::model::PlannedGround>,
    /// The DEM, the tile's id and its bounds, when the terrain is to be written.
    pub ground: Option<(&'a crate::model::dem::Dem, &'a str, [f64; 4])>,
}

impl<'a> TilePlan<'a> {
    /// Tile `id` of `plan`, without terrain.
    pub fn of(plan: &'a crate::model::Plan, id: &str) -> TilePlan<'a> {
        TilePlan {
            lots: plan.houses.get(id).map_or(&[][..], Vec::as_slice),
            fences: plan.fences.get(id).map_or(&[][..], Vec::as_slice),
            billboards: plan.billboards.get(id).map_or(&[][..], Vec::as_slice),
            walks: plan.walks.get(id).map_or(&[][..], Vec::as_slice),
            gardens: plan.gardens.get(id).map_or(&[][..], Vec::as_slice),
            halls: plan.halls.get(id).map_or(&[][..], Vec::as_slice),
            landmarks: plan.landmarks.get(id).map_or(&[][..], Vec::as_slice),
            surface: plan.grounds.get(id),
            ground: None,
        }
    }
}

/// The `random` input of a feature's template: its own stream, apart from the type draw.
fn template_random(seed: u64, layer: &str, id: &str) -> f64 {
    use rand::RngExt;
    crate::rng::feature_rng(seed, &format!("{layer}/template"), id).random::<f64>()
}

/// Every model of one tile: houses with their kura, landmarks, halls, fences and gates,
/// people, trees, gardens and the ground, in that order.
pub fn generate_tile(
    tile: &TilePlan,
    catalog: &Catalog,
    params: &Params,
    variants: &variant::Variants,
    origin: [f64; 2],
    files: &LayerFiles,
) -> TileMeshes {
    let frame = Frame { origin };
    let mut out = TileMeshes::default();
    let kura_template = params
        .kura
        .enabled
        .then(|| catalog.get(&params.kura.template))
        .flatten();
    for m in tile.lots {
        let layer = if m.is_footprint() {
            "footprints"
        } else {
            "lots"
        };
        let result = match catalog.machiya(&m.mtype) {
            Some(t) => {
                let overrides = catalog.overrides(&m.mtype, m.district.as_deref());
                let random = template_random(params.seed_for("machiya"), layer, &m.id);
                machiya::build(m, t, &overrides, &params.machiya, random, frame)
            }
            None => Err(format!("machiya type `{}` has no template", m.mtype)),
        };
        let (file, skipped) = match m.footprint_height() {
            None => (&files.lots, "lots"),
            Some(_) => (&files.footprints, "footprints"),
        };
        let skip = |reason: String| Skipped {
            layer: skipped.into(),
            file: file.clone(),
            id: m.id.clone(),
            record: Some(m.record),
            reason,
        };
        let mesh = match result {
            Ok(mesh) => mesh,
            Err(reason) => {
                out.stats.skipped.push(skip(reason));
                continue;
            }
        };
        out.meshes.push(mesh);
        let st = &mut out.stats;
        let district = m.district.clone().unwrap_or_default();
        let by_type = if m.is_footprint() {
            st.footprints += 1;
            &mut st.footprints_by_type
        } else {
            st.machiya += 1;
            st.type_given += m.type_given as usize;
            if !m.type_given {
                *st.drawn_by_district
                    .entry(district.clone())
                    .or_default()
                    .entry(m.mtype.clone())
                    .or_default() += 1;
            }
            let k = st.kura_counts.entry(district.clone()).or_default();
            k.machiya += 1;
            k.candidates += m.kura.is_candidate() as usize;
            k.without_avoidance += m.kura.rect().is_some() as usize;
            k.with_avoidance += matches!(m.kura, KuraDecision::Clear(_)) as usize;
            &mut st.by_type
        };
        *by_type.entry(m.mtype.clone()).or_default() += 1;
        *st.by_district.entry(district).or_default() += 1;
        // Its kura, in the same tile: the plan decided it for the whole city at once.
        let (Some(rect), Some(t)) = (m.kura.to_build(params.kura.collision), kura_template) else {
            continue;
        };
        let overrides = catalog.overrides(&t.name, m.district.as_deref());
        let random = template_random(params.seed_for("machiya"), "kura", &m.id);
        match kura::build(m, rect, t, &overrides, &params.machiya, random, frame) {
            Ok(mesh) => {
                out.meshes.push(mesh);
                out.stats.kura += 1;
            }
            Err(reason) => out
                .stats
                .skipped
                .push(skip(Skipped::part_reason("kura", &reason))),
        }
    }
    for l in tile.landmarks {
        out.meshes.push(landmarks::mesh(l, frame));
        out.stats
            .landmarks
            .push(crate::model::landmark::PlacedLandmark {
                id: l.id.clone(),
                model: l.model.file.clone(),
                tile: l.tile.clone(),
                bounds: l.bounds.map(|v| (v * 1000.0).round() / 1000.0),
                triangles: l.model.triangles.len(),
            });
    }
    build_halls(tile.halls, catalog, params, frame, files, &mut out);
    build_fences(tile.fences, catalog, params, frame, files, &mut out);
    let people_and_trees = billboards::build(
        tile,
        catalog,
        params,
        variants,
        frame,
        files,
        &mut out.stats,
    );
    out.meshes.extend(people_and_trees.meshes);
    out.instanced = people_and_trees.instanced;
    out.crowd = people_and_trees.crowd;
    for g in tile.gardens {
        out.meshes
            .extend(garden::planned(g, params.seed_for("gardens"), frame));
        out.stats.gardens += 1;
    }
    let dem = tile.ground.map(|g| g.0);
    match tile.surface {
        // The ground drapes the DEM itself: no separate terrain mesh under it.
        Some(surface) => {
            let (ground, streets) = ground::tile_ground(surface, &params.ground, dem, frame);
            out.meshes.push(ground);
            out.meshes.extend(streets);
        }
        None => {
            if let Some((dem, id, bounds)) = tile.ground {
                out.meshes.extend(terrain::terrain_mesh(
                    format!("terrain_{id}"),
                    dem,
                    bounds,
                    frame,
                ));
            }
        }
    }
    out
}

/// The halls of a tile, each its own object; a hall whose template fails on its plot is
/// skipped with the reason (the lot keeps its walls).
fn build_halls(
    halls: &[crate::model::PlannedHall],
    catalog: &Catalog,
    params: &Params,
    frame: Frame,
    files: &LayerFiles,
    out: &mut TileMeshes,
) {
    for h in halls {
        let Some(t) = catalog.get(&h.template) else {
            continue;
        };
        let overrides = catalog.overrides(&t.name, h.district.as_deref());
        let random = template_random(params.seed, "halls", &format!("{}/{}", h.lot, h.template));
        match halls::build(h, t, &overrides, &params.machiya, random, frame) {
            Ok(mesh) => {
                out.meshes.push(mesh);
                *out.stats.halls.entry(h.template.clone()).or_default() += 1;
            }
            Err(reason) => out.stats.skipped.push(Skipped {
                layer: "lots".into(),
                file: files.lots.clone(),
                id: h.lot.clone(),
                record: Some(h.record),
                reason: Skipped::part_reason(&h.template, &reason),
            }),
        }
    }
}

/// The fences and gates of a tile: a lot's walls in one object, each gate in its own. A
/// segment whose template fails skips that lot's fence with the reason.
fn build_fences(
    fences: &[PlannedFence],
    catalog: &Catalog,
    params: &Params,
    frame: Frame,
    files: &LayerFiles,
    out: &mut TileMeshes,
) {
    // One object per name (a lot's walls, one gate), in the order they first appear: a gate
    // splits its edge, but the walls on both sides stay one object.
    let mut groups: Vec<(String, Vec<&PlannedFence>)> = Vec::new();
    let mut index: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for f in fences {
        let name = fences::object_name(f);
        let k = *index.entry(name.clone()).or_insert_with(|| {
            groups.push((name, Vec::new()));
            groups.len() - 1
        });
        groups[k].1.push(f);
    }
    for (name, segments) in groups {
        let mut mesh = Mesh::object(
            name,
            fences::object_kind(segments[0]),
            fences::owner(segments[0]),
        );
        let mut built: Result<Vec<(String, f64)>, String> = Ok(Vec::new());
        for f in &segments {
            let random = template_random(params.seed, "fences", &format!("{}/{}", f.id, f.edge));
            built = built.and_then(|mut lens| {
                let len = fences::build_segment(f, catalog, params, random, frame, &mut mesh)?;
                lens.push((f.template.clone(), len));
                Ok(lens)
            });
        }
        let first = segments[0];
        match built {
            Ok(lens) => {
                let st = &mut out.stats;
                match first.kind {
                    FenceKind::Gate => st.gates += 1,
                    FenceKind::Wall => {
                        st.fence_segments += lens.len();
                        for (t, l) in lens {
                            *st.wall_mm.entry(t).or_default() += (l * 1000.0).round() as u64;
                        }
                    }
                }
                out.meshes.push(mesh.finish());
            }
            Err(reason) => out.stats.skipped.push(Skipped {
                layer: first.layer.clone(),
                file: if first.layer == "fences" {
                    files.fences.clone()
                } else {
                    files.lots.clone()
                },
                id: first.id.clone(),
                record: Some(first.record),
                reason: Skipped::part_reason("fence", &reason),
            }),
        }
    }
}
