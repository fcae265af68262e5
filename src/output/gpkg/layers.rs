//! `plan.gpkg`: every decision of a build as a layer, each feature carrying the input's id
//! and record number so it joins back to the user's own layer. Lots, frontages, houses and
//! kura here; the rest of the city in `places.rs`.

use std::collections::HashMap;
use std::path::Path;

use geo_types::{Coord, Geometry, LineString, Polygon};

use super::styles::{self, Look, Shape};
use super::{int, real, text, GeoPackage, GeomKind, GpkgError, Srs, Value};
use crate::model::{Dataset, Plan, PlannedHouse, Skipped};
use crate::output::report::Manifest;
use crate::params::Params;

use super::rows::{
    count, house_layer, kura_words, optional, planned_houses, real_or_null, shapes_of,
    text_or_null, Index, PlanSources,
};
use super::{houses, places};

/// A `plan.gpkg` being written: the layers analysis alone decides are written by
/// [`PlanWriter::start`] while the tiles are made; the ones that need the tiles' manifest
/// (what generation skipped, the bytes of each tile) by [`PlanWriter::finish`].
pub struct PlanWriter {
    g: GeoPackage,
}

impl PlanWriter {
    /// Creates the file and writes every layer analysis decides: frontages, kura, walls,
    /// gates, halls, gardens, trees, people, landmarks, lots and houses.
    pub fn start(path: &Path, s: &PlanSources) -> Result<PlanWriter, GpkgError> {
        let mut g = GeoPackage::create(path, srs_of(s.data, s.params))?;
        let index = Index::of(s, s.data.skipped.iter().chain(&s.plan.skipped));
        frontages(&mut g, s, &index)?;
        houses::kura(&mut g, s)?;
        places::fences(&mut g, s)?;
        places::halls(&mut g, s, &index)?;
        places::gardens(&mut g, s, &index)?;
        places::billboards(&mut g, s)?;
        places::landmarks(&mut g, s)?;
        lots(&mut g, s, &index)?;
        houses::houses(&mut g, s, &index)?;
        Ok(PlanWriter { g })
    }

    /// Once every tile is in `manifest`: marks the houses generation could not build, writes
    /// the tiles and every skipped record, and renames the file into place.
    pub fn finish(self, s: &PlanSources, manifest: &Manifest) -> Result<(), GpkgError> {
        let report = crate::output::report::assemble_report(manifest);
        let generated: Vec<&Skipped> = manifest
            .tiles
            .iter()
            .flat_map(|t| &t.stats.skipped)
            .collect();
        houses::mark_generated(&self.g, s, &generated)?;
        let mut g = self.g;
        places::tiles(&mut g, s, manifest)?;
        places::skipped(&mut g, s.data, &report.skipped, &Index::lots_of(s.data))?;
        g.finish()
    }
}

/// Writes a whole `plan.gpkg` at once (`merge`, which has the manifest before it starts).
pub fn write_plan(path: &Path, s: &PlanSources, manifest: &Manifest) -> Result<(), GpkgError> {
    PlanWriter::start(path, s)?.finish(s, manifest)
}

/// Writes what `check` found: layer `problems` (each record a build would skip, at its
/// outline where one is known, else its lot's) and layer `warnings`.
pub fn write_problems(
    path: &Path,
    data: &Dataset,
    params: &Params,
    skipped: &[Skipped],
    warnings: &[crate::model::Warning],
) -> Result<(), GpkgError> {
    let mut g = GeoPackage::create(path, srs_of(data, params))?;
    places::problems(&mut g, data, skipped, warnings, &Index::lots_of(data))?;
    g.finish()
}

/// The output CRS of a build, for the GeoPackage.
pub fn srs_of(data: &Dataset, params: &Params) -> Srs {
    let reprojected = data
        .layers
        .iter()
        .filter(|l| l.role == "lots" || l.role == "footprints")
        .any(|l| l.reprojected);
    Srs::of_build(&params.crs, data.crs_wkt.as_deref(), &data.crs, reprojected)
}

/// The index of the outline's exterior edge from `a` to `b` (from 0).
fn edge_index(outline: &Polygon<f64>, a: Coord<f64>, b: Coord<f64>) -> Option<usize> {
    let same = |p: Coord<f64>, q: Coord<f64>| (p.x - q.x).abs() < 1e-6 && (p.y - q.y).abs() < 1e-6;
    outline
        .exterior()
        .0
        .windows(2)
        .position(|w| same(w[0], a) && same(w[1], b))
}

const LOT_COLUMNS: [super::Column; 15] = [
    text("id"),
    int("record"),
    text("use"),
    text("district"),
    text("type"),
    text("type_source"),
    int("frontage_edge"),
    text("frontage_street"),
    int("frontage_fallback"),
    text("kura"),
    text("kura_reason"),
    int("trees"),
    text("tile"),
    text("status"),
    text("reason"),
];

/// `lots`: every lot read, and every lot record skipped while reading (at its outline where
/// it had one).
fn lots(g: &mut GeoPackage, s: &PlanSources, index: &Index) -> Result<(), GpkgError> {
    let avoid = s.params.kura.collision;
    let houses: HashMap<&str, &PlannedHouse> = planned_houses(s.plan)
        .filter(|h| !h.is_footprint())
        .map(|h| (h.id.as_str(), h))
        .collect();
    let mut trees: HashMap<&str, usize> = HashMap::new();
    for b in s.plan.billboards.values().flatten() {
        if let Some(lot) = b.tree.as_ref().and_then(|t| t.lot.as_deref()) {
            *trees.entry(lot).or_default() += 1;
        }
    }
    let style = lot_style(s.plan);
    let mut w = g.layer(
        "lots",
        Some(GeomKind::Polygon),
        &LOT_COLUMNS,
        "Every lot read: its use, type and where it came from, the frontage Fig. 4 chose, \
         the kura decision of section 4.2, built or skipped and why",
        Some(style),
    )?;
    for lot in &s.data.lots {
        let house = houses.get(lot.id.as_str());
        let skip = index.skip_of("lots", &lot.id, lot.record);
        let displaced = index.displaced.get(&("machiya", lot.id.as_str()));
        let (status, reason) = match (house, skip, displaced) {
            (_, Some(k), _) => ("skipped", k.reason.clone()),
            (_, _, Some(l)) => ("displaced", format!("landmark {l} stands there")),
            (Some(_), _, _) => ("built", String::new()),
            (None, _, _) => ("no house", format!("a lot of use {}", lot.lot_use.name())),
        };
        let (edge, street, fallback) = match house {
            Some(h) => (
                edge_index(&lot.outline, h.frontage.a, h.frontage.b).map_or(Value::Null, count),
                optional(index.street_at(mid(h.frontage.a, h.frontage.b), s.data)),
                count(h.frontage.fallback as usize),
            ),
            None => (Value::Null, Value::Null, Value::Null),
        };
        let (kura, kura_reason) = match house {
            Some(h) => {
                let (k, why) = kura_words(&h.kura, avoid);
                (text_or_null(k), text_or_null(why))
            }
            None => (Value::Null, Value::Null),
        };
        let mtype = house.map(|h| h.mtype.as_str()).or(lot.mtype.as_deref());
        let source = house.map(|h| match h.type_given {
            true => "data",
            false => "type_mix",
        });
        w.add(
            Some(&Geometry::Polygon(lot.outline.clone())),
            &[
                text_or_null(&lot.id),
                count(lot.record),
                text_or_null(lot.lot_use.name()),
                optional(lot.district.as_deref()),
                optional(mtype),
                optional(source),
                edge,
                street,
                fallback,
                kura,
                kura_reason,
                count(trees.get(lot.id.as_str()).copied().unwrap_or(0)),
                optional(house.map(|h| h.tile.as_str())),
                text_or_null(status),
                text_or_null(&reason),
            ],
        )?;
    }
    // Lot records that never became lots: at their outline where reading kept it.
    let shapes = shapes_of(s.data);
    // A skip of a lot that was read all the same (none today) is not a lot of its own; a
    // repeated id is (the record skipped beside the one built).
    let read: std::collections::HashSet<(&str, usize)> = s
        .data
        .lots
        .iter()
        .map(|l| (l.id.as_str(), l.record))
        .collect();
    for k in s.data.skipped.iter().filter(|k| k.layer == "lots") {
        if k.record.is_some_and(|r| read.contains(&(k.id.as_str(), r))) {
            continue;
        }
        let shape = shapes.get(&(k.layer.as_str(), k.record, k.id.as_str()));
        let mut row = vec![text_or_null(&k.id), k.record.map_or(Value::Null, count)];
        row.extend(std::iter::repeat_n(Value::Null, LOT_COLUMNS.len() - 4));
        row.push(text_or_null("skipped"));
        row.push(text_or_null(&k.reason));
        w.add(
            shape.map(|p| Geometry::Polygon((*p).clone())).as_ref(),
            &row,
        )?;
    }
    w.end()
}

fn mid(a: Coord<f64>, b: Coord<f64>) -> Coord<f64> {
    Coord {
        x: (a.x + b.x) / 2.0,
        y: (a.y + b.y) / 2.0,
    }
}

/// `lots` as plan.png paints them: machiya types by colour, footprints grey, other uses
/// pale, skipped red.
fn lot_style(plan: &Plan) -> String {
    use crate::output::plan as png;
    // Faded: the houses over them, in the same colours, show how far each house reaches.
    let mut categories: Vec<(String, Look)> = png::type_colours(plan)
        .into_iter()
        .map(|(ty, rgb)| (ty, Look::of(rgb).faded()))
        .collect();
    categories.push(("skipped".into(), Look::of(png::SKIPPED)));
    categories.push(("displaced".into(), Look::of(png::FOOTPRINT).faded()));
    let expr = "CASE WHEN \"status\" IN ('skipped', 'displaced') THEN \"status\" \
                WHEN \"status\" = 'built' THEN \"type\" ELSE '' END";
    styles::categorized(
        Shape::Fill,
        expr,
        &categories,
        Some(Look::of(png::OTHER_USE)),
    )
}

/// `frontages`: the edge Fig. 4 chose for each house, as a line from `a` to `b` (the lot on
/// its left).
fn frontages(g: &mut GeoPackage, s: &PlanSources, index: &Index) -> Result<(), GpkgError> {
    let mut w = g.layer(
        "frontages",
        Some(GeomKind::LineString),
        &[
            text("id"),
            int("record"),
            text("source"),
            int("edge"),
            text("street"),
            real("width"),
            int("fallback"),
        ],
        "The frontage (maguchi) Fig. 4 chose for each house, the lot on its left",
        Some(styles::single(
            Shape::Line,
            Look::of(crate::output::plan::FRONTAGE).sized(0.6),
        )),
    )?;
    for h in planned_houses(s.plan) {
        let f = h.frontage;
        w.add(
            Some(&Geometry::LineString(LineString::from(vec![f.a, f.b]))),
            &[
                text_or_null(&h.id),
                count(h.record),
                text_or_null(house_layer(h)),
                edge_index(&h.outline, f.a, f.b).map_or(Value::Null, count),
                optional(index.street_at(mid(f.a, f.b), s.data)),
                real_or_null(f.width()),
                count(f.fallback as usize),
            ],
        )?;
    }
    w.end()
}
