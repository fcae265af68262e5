//! Stage 2: analysis. Turns the [`Dataset`] into a [`Plan`]: for every machiya lot its
//! frontage, type and tile. No I/O; every random choice through [`crate::rng`].

pub mod billboards;
pub mod crowds;
pub mod fences;
pub mod frontage;
pub mod gardens;
pub mod ground;
pub mod halls;
pub mod house;
pub mod kura;
pub mod landmarks;
pub mod lot_index;
pub mod obstacles;
pub mod product;
pub mod room;
pub mod street;
pub mod terrain;
pub mod trees;

use geo::Centroid;
use geo_types::Coord;
use rand::RngExt;
use rayon::prelude::*;

use crate::model::{Dataset, Footprint, Lot, LotUse, Plan, PlannedHouse, Skipped};
use crate::params::Params;
use crate::rng::feature_rng;
use crate::templates::Catalog;
use frontage::{find_frontage, lot_depth, FrontageRule};
use street::StreetEdges;

/// The vectors one after another in one allocation of the exact size. Collecting a flatten
/// grows by doubling, which at a million lots held three copies at the moment of the last
/// growth.
pub(crate) fn concat<T>(parts: Vec<Vec<T>>) -> Vec<T> {
    let mut out = Vec::with_capacity(parts.iter().map(Vec::len).sum());
    for p in parts {
        out.extend(p);
    }
    out
}

/// Runs `f`, noting how long it took under `name` (for `--timings`).
fn timed<T>(
    times: &mut Vec<(&'static str, std::time::Duration)>,
    name: &'static str,
    f: impl FnOnce() -> T,
) -> T {
    let t = std::time::Instant::now();
    let out = f();
    times.push((name, t.elapsed()));
    out
}

/// Why a lot did not make it into the plan, or what it became.
enum Outcome {
    Planned(Box<PlannedHouse>, Vec<crate::model::Warning>),
    Skipped(Skipped),
}

/// Runs the analysis on every machiya lot, in parallel; the result is in input order.
pub fn analyse(
    data: &Dataset,
    params: &Params,
    catalog: &Catalog,
    lots_file: &str,
    progress: &(dyn Fn(u64) + Sync),
) -> Plan {
    let edges = StreetEdges::new(&data.blocks, &data.streets);
    let origin = params.origin.unwrap_or_else(|| {
        default_origin(
            data.lots
                .iter()
                .map(|l| &l.outline)
                .chain(data.footprints.iter().map(|f| &f.outline)),
        )
    });
    let rule = FrontageRule {
        max_angle_deg: params.frontage.max_angle_deg,
        min_length: params.frontage.min_length,
    };
    let outcomes: Vec<Outcome> = data
        .lots
        .par_iter()
        .filter(|lot| lot.lot_use == LotUse::Machiya)
        .map(|lot| {
            let o = plan_lot(lot, &edges, rule, params, catalog, lots_file);
            progress(1);
            o
        })
        .collect();
    let fp_outcomes: Vec<Outcome> = data
        .footprints
        .par_iter()
        .map(|f| plan_footprint(f, &edges, rule, params, catalog))
        .collect();
    let mut outcomes = outcomes;
    let mut fp_outcomes = fp_outcomes;
    let t = std::time::Instant::now();
    let mut planned: Vec<&mut PlannedHouse> = outcomes
        .iter_mut()
        .chain(fp_outcomes.iter_mut())
        .filter_map(|o| match o {
            Outcome::Planned(m, _) => Some(&mut **m),
            Outcome::Skipped(_) => None,
        })
        .collect();
    let mut off_dem = 0;
    if let Some(dem) = &data.dem {
        off_dem += terrain::ground_houses(&mut planned, dem);
    }
    kura::decide(&mut planned, catalog, params);
    let mut plan = Plan {
        origin,
        kura_time: t.elapsed(),
        ..Plan::default()
    };
    plan.footprints = fp_outcomes
        .iter()
        .filter(|o| matches!(o, Outcome::Planned(..)))
        .count();
    // Each tile's houses in one allocation of the right size (pushed one by one, the tiles'
    // vectors held up to twice the houses at a million lots).
    let mut per_tile: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for o in outcomes.iter().chain(&fp_outcomes) {
        if let Outcome::Planned(m, _) = o {
            *per_tile.entry(m.tile.as_str()).or_default() += 1;
        }
    }
    for (tile, n) in per_tile {
        plan.houses.insert(tile.to_string(), Vec::with_capacity(n));
    }
    for o in outcomes.into_iter().chain(fp_outcomes) {
        match o {
            Outcome::Planned(m, warnings) => {
                if m.frontage.fallback {
                    plan.frontage_fallback += 1;
                }
                plan.warnings.extend(warnings);
                plan.tiles.insert(m.tile.clone());
                plan.houses.entry(m.tile.clone()).or_default().push(*m);
            }
            Outcome::Skipped(s) => plan.skipped.push(s),
        }
    }
    if params.fence.enabled {
        let walled: Vec<(Vec<crate::model::PlannedFence>, Vec<crate::model::Warning>)> = data
            .lots
            .par_iter()
            .filter(|l| params.fence.uses.iter().any(|u| u == l.lot_use.name()))
            .map(|l| fences::plan_lot_fences(l, &edges, params, lots_file))
            .collect();
        let fences_file = params.layers.fences.file.clone();
        let lines: Vec<(Vec<crate::model::PlannedFence>, Vec<crate::model::Warning>)> = data
            .fence_lines
            .par_iter()
            .map(|f| fences::plan_line_fences(f, &edges, params, &fences_file))
            .collect();
        for (mut segments, warnings) in walled.into_iter().chain(lines) {
            if let Some(dem) = &data.dem {
                off_dem += terrain::ground_fences(&mut segments, dem);
            }
            plan.warnings.extend(warnings);
            for f in segments {
                plan.tiles.insert(f.tile.clone());
                plan.fences.entry(f.tile.clone()).or_default().push(f);
            }
        }
    }
    if params.landmarks.enabled {
        let library = crate::materials::MATERIALS.len();
        landmarks::plan_landmarks(data, &mut plan.houses, &mut plan.fences, params, library)
            .file(&mut plan);
    }
    let t = std::time::Instant::now();
    let mut times = Vec::new();
    // What people, trees, gardens and halls keep out of: built once (houses, kura, fences,
    // landmarks), then each step's halls and gardens added for the steps after it.
    let mut obstacles = obstacles::Obstacles::of_plan(&plan, catalog, params);
    times.push(("obstacles", t.elapsed()));
    let halls = timed(&mut times, "halls", || {
        halls::plan_halls(data, &plan.fences, &edges, &obstacles, catalog, params)
    });
    obstacles.add_areas(halls.by_tile.values().flatten().map(|h| h.outline()));
    let gardens = timed(&mut times, "gardens", || {
        gardens::plan_gardens(data, &plan.fences, &halls, &obstacles, params)
    });
    obstacles.add_areas(gardens.by_tile.values().flatten().map(|g| g.outline()));
    halls.file(&mut plan);
    gardens.file(&mut plan);
    let mut billboards = timed(&mut times, "people and billboard trees", || {
        billboards::plan_billboards(data, &plan.tiles, &plan.houses, &obstacles, catalog, params)
    });
    let planted = timed(&mut times, "grown trees", || {
        trees::plant(data, &mut billboards.by_tile, &obstacles, catalog, params)
    });
    billboards.file(&mut plan);
    planted.file(&mut plan);
    let grounds = timed(&mut times, "ground", || {
        ground::plan_ground(data, &plan.tiles, params)
    });
    grounds.file(&mut plan);
    plan.step_times.extend(times);
    plan.billboards_time = t.elapsed();
    if off_dem > 0 {
        if let Some(dem) = &data.dem {
            plan.warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Layer,
                    format!(
                "{}: {off_dem} point(s) of houses or fences lie outside the DEM; they stand on \
                 the elevation of its nearest edge",
                dem.file
            ),
                )
                .in_file(&dem.file),
            );
        }
    }
    plan
}

fn plan_lot(
    lot: &Lot,
    edges: &StreetEdges,
    rule: FrontageRule,
    params: &Params,
    catalog: &Catalog,
    lots_file: &str,
) -> Outcome {
    let skip = |reason: String| {
        Outcome::Skipped(Skipped {
            layer: "lots".into(),
            file: lots_file.to_string(),
            id: lot.id.clone(),
            record: Some(lot.record),
            reason,
        })
    };
    let ring: Vec<Coord<f64>> = { crate::geom::ring::open(lot.outline.exterior()).to_vec() };
    let Some(centroid) = lot.outline.centroid() else {
        return skip("the outline has no centroid".into());
    };
    let centroid = centroid.0;
    let dist = edges.distances(&ring);
    let frontage = find_frontage(&ring, &dist, centroid, rule);
    let depth = lot_depth(&ring, &frontage);
    if depth < params.machiya.min_depth {
        return skip(format!(
            "the lot is {depth:.2} m deep behind its frontage, less than machiya.min_depth = {} m",
            params.machiya.min_depth
        ));
    }

    let mut warnings = Vec::new();
    let given = lot.mtype.as_deref().and_then(|m| {
        let r = catalog.resolve(m);
        if r.is_none() {
            warnings.push(crate::model::Warning::feature(
                "lots",
                lots_file,
                &lot.id,
                format!(
                "{lots_file}: lot {}: unknown machiya type `{m}`; a type was drawn from type_mix",
                lot.id
            ),
            ));
        }
        r
    });
    let (mtype, type_given) = match given {
        Some(t) => (t.to_string(), true),
        None => (draw_type(params, &lot.id, lot.district.as_deref()), false),
    };
    let computed = || crate::model::tile::tile_id(centroid, params.tile_size, params.tile_origin);
    let tile = match lot.tile.as_deref() {
        Some(t) if crate::model::tile::is_valid_tile_name(t) => t.to_string(),
        Some(t) => {
            warnings.push(crate::model::Warning::feature(
                "lots",
                lots_file,
                &lot.id,
                format!(
                "{lots_file}: lot {}: tile `{t}` is not usable as a file name (letters, digits, \
                 `_`, `-` and `.` only); the computed tile was used",
                lot.id
            ),
            ));
            computed()
        }
        None => computed(),
    };
    let attrs = template_attributes(lot, &mtype, catalog, lots_file, &mut warnings);
    Outcome::Planned(
        Box::new(PlannedHouse {
            id: lot.id.clone(),
            record: lot.record,
            outline: lot.outline.clone(),
            frontage,
            mtype,
            type_given,
            district: lot.district.clone(),
            tile,
            ground: lot.ground,
            source: crate::model::HouseSource::Lot,
            attrs,
            kura: Default::default(),
        }),
        warnings,
    )
}

/// The lot's values of the attributes its template declares (`[attributes]` of the template),
/// matched by field name without regard to case. A value that is not a number is left to
/// the template's default, with a warning.
fn template_attributes(
    lot: &Lot,
    mtype: &str,
    catalog: &Catalog,
    lots_file: &str,
    warnings: &mut Vec<crate::model::Warning>,
) -> Vec<(String, f64)> {
    let Some(t) = catalog.machiya(mtype) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for name in t.attribute_names() {
        let Some((field, raw)) = lot.attrs.iter().find(|(k, _)| k.eq_ignore_ascii_case(name))
        else {
            continue;
        };
        let raw = raw.trim();
        if raw.is_empty() {
            continue;
        }
        match raw.parse::<f64>() {
            Ok(x) if x.is_finite() => out.push((name.to_string(), x)),
            _ => warnings.push(crate::model::Warning::feature(
                "lots",
                lots_file,
                &lot.id,
                format!(
                    "{lots_file}: lot {}: attribute `{field}` = `{raw}` is not a number; template \
                 {mtype} used its default",
                    lot.id
                ),
            )),
        }
    }
    out
}

/// A footprint: frontage towards the nearest street edge like a lot; its type from its
/// `mtype` or `layers.footprints.default_type` (never drawn: a footprint is a known building).
fn plan_footprint(
    f: &Footprint,
    edges: &StreetEdges,
    rule: FrontageRule,
    params: &Params,
    catalog: &Catalog,
) -> Outcome {
    let fp = &params.layers.footprints;
    let ring: Vec<Coord<f64>> = { crate::geom::ring::open(f.outline.exterior()).to_vec() };
    let Some(centroid) = f.outline.centroid() else {
        return Outcome::Skipped(Skipped {
            layer: "footprints".into(),
            file: fp.file.clone(),
            id: f.id.clone(),
            record: Some(f.record),
            reason: "the outline has no centroid".into(),
        });
    };
    let dist = edges.distances(&ring);
    let frontage = find_frontage(&ring, &dist, centroid.0, rule);
    let mut warnings = Vec::new();
    let given = f.mtype.as_deref().and_then(|m| catalog.resolve(m));
    if let (Some(m), None) = (&f.mtype, given) {
        warnings.push(crate::model::Warning::feature(
            "footprints",
            &fp.file,
            &f.id,
            format!(
                "{}: footprint {}: unknown type `{m}`; built as {}",
                fp.file, f.id, fp.default_type
            ),
        ));
    }
    Outcome::Planned(
        Box::new(PlannedHouse {
            id: f.id.clone(),
            record: f.record,
            outline: f.outline.clone(),
            frontage,
            mtype: given.unwrap_or(&fp.default_type).to_string(),
            type_given: given.is_some(),
            district: f.district.clone(),
            tile: crate::model::tile::tile_id(centroid.0, params.tile_size, params.tile_origin),
            ground: f.ground,
            source: crate::model::HouseSource::Footprint { height: f.height },
            attrs: Vec::new(),
            kura: Default::default(),
        }),
        warnings,
    )
}

/// Draws a type from `type_mix` with the lot's own RNG (the paper: "when a lot's type is
/// unknown, one of the types is drawn at random").
pub fn draw_type(params: &Params, id: &str, district: Option<&str>) -> String {
    let mix = params.type_mix_of(district);
    let total: f64 = mix.values().sum();
    let mut r = feature_rng(params.seed_for("machiya"), "lots/mtype", id).random::<f64>() * total;
    for (name, w) in mix {
        if r < *w {
            return name.clone();
        }
        r -= w;
    }
    // Rounding left r at the very top: the last type with a weight.
    mix.iter()
        .rev()
        .find(|(_, w)| **w > 0.0)
        .map(|(n, _)| n.clone())
        .unwrap_or_default()
}

/// The south-west corner of the lots, rounded down to a whole kilometre, so that small edits
/// to the data rarely move it.
fn default_origin<'a>(outlines: impl Iterator<Item = &'a geo_types::Polygon<f64>>) -> [f64; 2] {
    let (mut x, mut y) = (f64::INFINITY, f64::INFINITY);
    for outline in outlines {
        for c in &outline.exterior().0 {
            x = x.min(c.x);
            y = y.min(c.y);
        }
    }
    if !x.is_finite() {
        return [0.0, 0.0];
    }
    [(x / 1000.0).floor() * 1000.0, (y / 1000.0).floor() * 1000.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawn_types_follow_table_1() {
        let p = Params::default();
        let n = 20_000;
        let hiraya = (0..n)
            .filter(|i| draw_type(&p, &i.to_string(), None) == "hiraya")
            .count();
        let share = hiraya as f64 / n as f64;
        // Table 1: 86 / 236 = 36.4 %.
        assert!((share - 0.364).abs() < 0.015, "{share}");
    }

    #[test]
    fn a_draw_depends_only_on_seed_and_id() {
        let p = Params::default();
        assert_eq!(draw_type(&p, "17", None), draw_type(&p, "17", None));
    }
}
