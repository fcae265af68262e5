//! Landmarks (section 5: what the method cannot generate, modelled elsewhere and placed in
//! the city): each record's model is set on its point, turned, scaled and grounded; checked
//! for an absurd size or a footprint far from its point; and the houses, kura, walls and
//! gates under its footprint are taken out of the plan (listed as displaced). Runs after the
//! fences and before the halls, gardens, trees and people, which keep out of its footprint
//! through the obstacles.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use geo::{ConvexHull, Distance, Euclidean, Intersects};
use geo_types::{Coord, MultiPoint, Point, Polygon};

use super::lot_index::LotIndex;
use super::product::{ByTile, Landmarks};
use crate::model::landmark::{
    z_up, Displaced, LandmarkReport, PaletteEntry, PlacedLandmark, SkippedLandmark,
};
use crate::model::number::Num;
use crate::model::{
    Dataset, KuraDecision, LandmarkRecord, Model, PlannedFence, PlannedHouse, PlannedLandmark,
    Skipped,
};
use crate::params::{Params, MAX_OFFSET, MAX_SIZE, MIN_SIZE};

/// How many library ids materials may take in all (mesh faces hold a `u16`).
const MAX_MATERIAL_IDS: usize = u16::MAX as usize;

/// Places every landmark read, takes what its footprint covers out of `houses` and `fences`,
/// and makes the palette.
pub fn plan_landmarks(
    data: &Dataset,
    houses: &mut ByTile<PlannedHouse>,
    fences: &mut ByTile<PlannedFence>,
    params: &Params,
    library: usize,
) -> Landmarks {
    let file = data
        .layers
        .iter()
        .find(|l| l.role == "landmarks")
        .map(|l| l.file.clone())
        .unwrap_or_default();
    let mut out = Landmarks::default();
    let report = &mut out.report;
    // What reading skipped (a model that cannot be used), for the report too.
    for s in data.skipped.iter().filter(|s| s.layer == "landmarks") {
        report.skipped.push(SkippedLandmark {
            id: s.id.clone(),
            record: s.record.unwrap_or(0),
            reason: s.reason.clone(),
        });
    }
    // The lots' R-tree, built when the first landmark needs the lot it stands in.
    let lots = std::cell::OnceCell::new();
    let mut placed = Vec::new();
    for r in &data.landmarks {
        let Some(model) = data.models.get(&r.model) else {
            continue;
        };
        match place(r, model, data, &lots, params) {
            Ok(p) => placed.push(p),
            Err(reason) => skip(report, &mut out.skipped, &file, (&r.id, r.record), reason),
        }
    }
    // Budgets before the palette, so a skipped model's textures are not written.
    let mut budget = Budget::default();
    let mut kept = Vec::with_capacity(placed.len());
    for p in placed {
        match budget.take(&p.tile, p.model.triangles.len()) {
            Ok(()) => kept.push(p),
            Err(reason) => skip(report, &mut out.skipped, &file, (&p.id, p.record), reason),
        }
    }
    let placed = kept;
    let (palette, textures, bases) = palette(&placed, library);
    for mut p in placed {
        let Some(&base) = bases.get(&p.model.file) else {
            let reason = format!(
                "its model's materials do not fit: the build's materials would pass \
                 {MAX_MATERIAL_IDS}; merge materials in {}",
                p.model.file
            );
            skip(report, &mut out.skipped, &file, (&p.id, p.record), reason);
            continue;
        };
        p.material_base = base;
        if params.landmarks.displace {
            let built = Built {
                houses: &mut *houses,
                fences: &mut *fences,
                skipped: &mut out.skipped,
            };
            displace(&p, data, built, &mut report.displaced);
        }
        report.placed.push(PlacedLandmark {
            id: p.id.clone(),
            model: p.model.file.clone(),
            tile: p.tile.clone(),
            bounds: p.bounds,
            triangles: p.model.triangles.len(),
        });
        out.by_tile.entry(p.tile.clone()).or_default().push(p);
    }
    out.palette = palette;
    out.textures = textures;
    out
}

/// Landmark triangles one tile may hold: one model at the model limit fills a tile (its GLB
/// is then ~120 MB); ten rows naming it at one point would make a tile no viewer opens.
pub const MAX_TILE_TRIANGLES: usize = 1_000_000;
/// Landmark triangles one build may hold (~1 GB of GLB in all).
pub const MAX_BUILD_TRIANGLES: usize = 8_000_000;

/// Landmark triangles taken so far, per tile and for the build: the records in their order
/// take them, so which ones are skipped does not depend on threads or `--tiles`.
#[derive(Default)]
struct Budget {
    tiles: BTreeMap<String, usize>,
    build: usize,
}

impl Budget {
    /// Takes `triangles` for `tile`, or says which budget it would pass.
    fn take(&mut self, tile: &str, triangles: usize) -> Result<(), String> {
        let in_tile = self.tiles.get(tile).copied().unwrap_or(0);
        if in_tile + triangles > MAX_TILE_TRIANGLES {
            return Err(format!(
                "its model's {triangles} triangles would bring tile {tile}'s landmarks past \
                 {MAX_TILE_TRIANGLES} (it holds {in_tile}): decimate the models or place \
                 fewer in one tile"
            ));
        }
        if self.build + triangles > MAX_BUILD_TRIANGLES {
            return Err(format!(
                "its model's {triangles} triangles would bring the build's landmarks past \
                 {MAX_BUILD_TRIANGLES} (it holds {}): decimate the models",
                self.build
            ));
        }
        self.tiles.insert(tile.to_string(), in_tile + triangles);
        self.build += triangles;
        Ok(())
    }
}

/// A landmark not placed: in the report's `landmarks.skipped` and the build's skipped list
/// (so the ledger counts it).
fn skip(
    report: &mut LandmarkReport,
    skipped: &mut Vec<Skipped>,
    file: &str,
    (id, record): (&str, usize),
    reason: String,
) {
    report.skipped.push(SkippedLandmark {
        id: id.to_string(),
        record,
        reason: reason.clone(),
    });
    skipped.push(Skipped {
        layer: "landmarks".into(),
        file: file.to_string(),
        id: id.to_string(),
        record: Some(record),
        reason,
    });
}

/// A record's model set on its point, or why it cannot be.
fn place<'a>(
    r: &LandmarkRecord,
    model: &Arc<Model>,
    data: &'a Dataset,
    lots: &std::cell::OnceCell<LotIndex<'a>>,
    params: &Params,
) -> Result<PlannedLandmark, String> {
    let lp = &params.landmarks;
    let z_is_up = lp.up == "z";
    let (lo, hi) = model_box(model, z_is_up);
    let size = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]].map(|s| s * r.scale);
    let largest = size.iter().copied().fold(0.0, f64::max);
    if largest > MAX_SIZE {
        return Err(format!(
            "absurd scale: the model is {:.0} x {:.0} x {:.0} m after scaling by {}, over \
             {MAX_SIZE} m: give the scale that makes it metres (a model in centimetres \
             needs 0.01), or check landmarks.up",
            Num(size[0]),
            Num(size[1]),
            Num(size[2]),
            Num(r.scale)
        ));
    }
    if largest < MIN_SIZE {
        return Err(format!(
            "absurd scale: the model is {:.3} m at most after scaling by {}, under {MIN_SIZE} \
             m: give the scale that makes it metres (a model in kilometres needs 1000)",
            Num(largest),
            Num(r.scale)
        ));
    }
    let anchor = match lp.anchor.as_str() {
        "origin" => [0.0; 3],
        _ => [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, lo[2]],
    };
    let z = ground(r, data, lots, params)?;
    let mut p = PlannedLandmark {
        id: r.id.clone(),
        record: r.record,
        model: model.clone(),
        anchor,
        at: [r.at.x, r.at.y, z],
        rotation: r.rotation.to_radians(),
        scale: r.scale,
        z_up: z_is_up,
        material_base: 0,
        footprint: Polygon::new(geo_types::LineString::new(vec![]), vec![]),
        bounds: [0.0; 6],
        tile: crate::model::tile::tile_id(r.at, params.tile_size, params.tile_origin),
    };
    let placed: Vec<[f64; 3]> = model.positions.iter().map(|&q| p.place(q)).collect();
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for q in &placed {
        for k in 0..3 {
            b[k] = b[k].min(q[k]);
            b[k + 3] = b[k + 3].max(q[k]);
        }
    }
    p.bounds = b;
    let hull = MultiPoint::from(
        placed
            .iter()
            .map(|q| Point::new(q[0], q[1]))
            .collect::<Vec<_>>(),
    )
    .convex_hull();
    let off = Euclidean.distance(&Point::from(r.at), &hull);
    if off > MAX_OFFSET {
        return Err(format!(
            "its model's footprint lies {off:.0} m from its point, more than {MAX_OFFSET} m: \
             the model's coordinates are not around its origin (set landmarks.anchor = \
             \"base\"), or the point is wrong"
        ));
    }
    p.footprint = r.footprint.clone().unwrap_or(hull);
    Ok(p)
}

/// The model's box with its up axis turned to z: minimum and maximum.
fn model_box(model: &Model, z_is_up: bool) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &model.triangles {
        for &i in &t.positions {
            let q = z_up(model.positions[i as usize], z_is_up);
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
    }
    (lo, hi)
}

/// The elevation a landmark stands on, by `landmarks.ground`.
fn ground<'a>(
    r: &LandmarkRecord,
    data: &'a Dataset,
    lots: &std::cell::OnceCell<LotIndex<'a>>,
    params: &Params,
) -> Result<f64, String> {
    let l = &params.layers.landmarks;
    match params.landmarks.ground.as_str() {
        "given" => r.z.ok_or_else(|| {
            format!(
                "`{}` is empty, and landmarks.ground = \"given\" needs the elevation it stands \
                 on",
                l.z_field
            )
        }),
        "dem" => match &data.dem {
            Some(dem) => Ok(dem.sample(r.at).z),
            None => Err(
                "landmarks.ground = \"dem\", but the input has no DEM: add one \
                         (layers.dem), or use \"lot\" or \"given\""
                    .into(),
            ),
        },
        _ => Ok(lot_ground(
            r.at,
            data,
            lots.get_or_init(|| LotIndex::new(data)),
        )),
    }
}

/// The ground of the lot holding `at`; else the DEM there when there is one, else the ground of
/// the nearest lot, else 0.
fn lot_ground(at: Coord<f64>, data: &Dataset, lots: &LotIndex) -> f64 {
    if let Some(i) = lots.containing(at) {
        return data.lots[i].ground;
    }
    if let Some(dem) = &data.dem {
        return dem.sample(at).z;
    }
    let p = Point::from(at);
    data.lots
        .iter()
        .map(|l| (Euclidean.distance(&p, &l.outline), l.ground))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(0.0, |(_, z)| z)
}

/// The palette of the models placed (in the order of their file names), their textures, and
/// each model's first library id; a model whose materials would pass the ids is left out.
#[allow(clippy::type_complexity)]
fn palette(
    placed: &[PlannedLandmark],
    library: usize,
) -> (
    Vec<PaletteEntry>,
    Vec<(String, Arc<Vec<u8>>)>,
    BTreeMap<String, u16>,
) {
    let models: BTreeMap<&str, &Arc<Model>> = placed
        .iter()
        .map(|p| (p.model.file.as_str(), &p.model))
        .collect();
    let (mut entries, mut textures, mut bases) = (Vec::new(), Vec::new(), BTreeMap::new());
    let mut prefixes = BTreeSet::new();
    let mut texture_names = BTreeSet::new();
    for (file, model) in models {
        if library + entries.len() + model.materials.len() > MAX_MATERIAL_IDS {
            continue;
        }
        // Two models of the same stem (keep/a.obj, old/a.obj) get their own prefixes.
        let mut prefix = format!("lm_{}", model.stem);
        let mut k = 2;
        while !prefixes.insert(prefix.clone()) {
            prefix = format!("lm_{}{k}", model.stem);
            k += 1;
        }
        bases.insert(file.to_string(), (library + entries.len()) as u16);
        for m in &model.materials {
            let texture = m.texture.as_ref().map(|(name, bytes)| {
                let name = format!("{prefix}_{}", safe(name));
                if texture_names.insert(name.clone()) {
                    textures.push((name.clone(), bytes.clone()));
                }
                name
            });
            entries.push(PaletteEntry {
                name: format!("{prefix}_{}", safe(&m.name)),
                kd: m.kd,
                texture,
            });
        }
    }
    (entries, textures, bases)
}

/// A name with only letters, digits, `-`, `_` and `.` (others become `_`): safe in MTL,
/// file names and URLs.
fn safe(name: &str) -> String {
    name.chars()
        .map(|c| match c.is_ascii_alphanumeric() || "-_.".contains(c) {
            true => c,
            false => '_',
        })
        .collect()
}

/// What a landmark can displace, and where the houses it takes out are listed.
struct Built<'a> {
    houses: &'a mut ByTile<PlannedHouse>,
    fences: &'a mut ByTile<PlannedFence>,
    skipped: &'a mut Vec<Skipped>,
}

/// Takes out of the plan the houses, kura, walls and gates under `p`'s footprint.
fn displace(p: &PlannedLandmark, data: &Dataset, built: Built, out: &mut Vec<Displaced>) {
    let fp = &p.footprint;
    let Some(fp_box) = geo::BoundingRect::bounding_rect(fp) else {
        return;
    };
    let near = |poly: &Polygon<f64>| {
        geo::BoundingRect::bounding_rect(poly).is_some_and(|b| b.intersects(&fp_box))
            && poly.intersects(fp)
    };
    let file_of = |role: &str| {
        data.layers
            .iter()
            .find(|l| l.role == role)
            .map(|l| l.file.clone())
            .unwrap_or_default()
    };
    let why = format!(
        "displaced by landmark {} ({}): its footprint covers it",
        p.id, p.model.file
    );
    for houses in built.houses.values_mut() {
        let mut kept = Vec::with_capacity(houses.len());
        for mut h in houses.drain(..) {
            if near(&h.outline) {
                let (role, kind) = match h.is_footprint() {
                    true => ("footprints", "footprint"),
                    false => ("lots", "machiya"),
                };
                out.push(Displaced {
                    landmark: p.id.clone(),
                    kind: kind.into(),
                    id: h.id.clone(),
                    reason: "the house's outline overlaps the landmark's footprint".into(),
                });
                built.skipped.push(Skipped {
                    layer: role.into(),
                    file: file_of(role),
                    id: h.id.clone(),
                    record: Some(h.record),
                    reason: why.clone(),
                });
                continue;
            }
            if let Some(q) = h.kura.rect().map(|r| {
                let f = super::house::frame_of(&h);
                let q = f.quad(r);
                Polygon::new(q.iter().chain(&q[..1]).copied().collect(), vec![])
            }) {
                if near(&q) {
                    out.push(Displaced {
                        landmark: p.id.clone(),
                        kind: "kura".into(),
                        id: h.id.clone(),
                        reason: "the kura's plot overlaps the landmark's footprint; the \
                                 house is built without it"
                            .into(),
                    });
                    h.kura = KuraDecision::NoRoom;
                }
            }
            kept.push(h);
        }
        *houses = kept;
    }
    for fences in built.fences.values_mut() {
        fences.retain(|f| {
            let line = geo_types::Line::new(f.a, f.b);
            if !line.intersects(fp) {
                return true;
            }
            let kind = match f.kind {
                crate::model::FenceKind::Gate => "gate",
                crate::model::FenceKind::Wall => "wall",
            };
            // One entry per wall of a lot, not per segment.
            if !out
                .iter()
                .any(|d| d.landmark == p.id && d.kind == kind && d.id == f.id)
            {
                out.push(Displaced {
                    landmark: p.id.clone(),
                    kind: kind.into(),
                    id: f.id.clone(),
                    reason: format!(
                        "the lot's {kind} crosses the landmark's footprint; the {kind} \
                         segments it crosses are left out"
                    ),
                });
            }
            false
        });
    }
}

#[cfg(test)]
mod budget_tests {
    use super::*;

    #[test]
    fn budgets_hold_per_tile_and_per_build_in_record_order() {
        let mut b = Budget::default();
        b.take("a", MAX_TILE_TRIANGLES - 10).unwrap();
        let e = b.take("a", 11).unwrap_err();
        assert!(e.contains("tile a") && e.contains("holds 999990"), "{e}");
        b.take("a", 10).unwrap();
        // Other tiles fill the build's budget, and then nothing more is taken anywhere.
        let tiles = MAX_BUILD_TRIANGLES / MAX_TILE_TRIANGLES;
        for t in 1..tiles {
            b.take(&format!("t{t}"), MAX_TILE_TRIANGLES).unwrap();
        }
        let e = b.take("fresh", 1).unwrap_err();
        assert!(e.contains("the build's landmarks"), "{e}");
    }
}
