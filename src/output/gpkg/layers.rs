//! `plan.gpkg`: every decision of a build as a layer, each feature carrying the input's id
//! and record number so it joins back to the user's own layer. Lots, frontages, houses and
//! kura here; the rest of the city in `places.rs`.

use std::collections::HashMap;
use std::path::Path;

use geo_types::{Coord, Geometry, LineString, Polygon};
use rstar::RTree;

use super::styles::{self, Look, Shape};
use super::{int, real, text, GeoPackage, GeomKind, GpkgError, Srs, Value};
use crate::geom::segment::Segment;
use crate::model::{Dataset, KuraDecision, Lot, Plan, PlannedHouse, Skipped};
use crate::output::report::Manifest;
use crate::params::Params;

use super::{houses, places};

/// What `plan.gpkg` is made from: the input read, the analysis and the parameters.
pub struct PlanSources<'a> {
    /// The input as read.
    pub data: &'a Dataset,
    /// The analysis.
    pub plan: &'a Plan,
    /// The build's parameters.
    pub params: &'a Params,
    /// The band behind its frontage a machiya's body fills (`analyse::house::house_band`:
    /// its template decides it); `None` for a footprint building.
    pub band: &'a (dyn Fn(&PlannedHouse) -> Option<(f64, f64)> + Sync),
}

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

/// Lookups every layer needs: lots by id, skips by layer and id, the streets' segments.
pub(super) struct Index<'a> {
    /// Lots read, by id.
    pub lots: HashMap<&'a str, &'a Lot>,
    /// The skips of each (layer, id), in report order.
    skips: HashMap<(&'a str, &'a str), Vec<&'a Skipped>>,
    /// Features a landmark displaced: (kind, id) -> landmark.
    pub displaced: HashMap<(&'a str, &'a str), &'a str>,
    /// Every street's segments, the street's index in `value`.
    streets: RTree<Segment>,
}

impl<'a> Index<'a> {
    /// The lots by id alone: where a skipped record without an outline of its own is drawn.
    fn lots_of(data: &'a Dataset) -> Index<'a> {
        Index {
            lots: data.lots.iter().map(|l| (l.id.as_str(), l)).collect(),
            skips: HashMap::new(),
            displaced: HashMap::new(),
            streets: RTree::new(),
        }
    }

    /// Every lookup, with `skipped`: the skips analysis knows of (generation's are marked
    /// afterwards).
    fn of(s: &'a PlanSources, skipped: impl Iterator<Item = &'a Skipped>) -> Index<'a> {
        let (data, plan) = (s.data, s.plan);
        let mut index = Index::lots_of(data);
        for k in skipped {
            index
                .skips
                .entry((k.layer.as_str(), k.id.as_str()))
                .or_default()
                .push(k);
        }
        for d in &plan.landmark_report.displaced {
            index
                .displaced
                .entry((d.kind.as_str(), d.id.as_str()))
                .or_insert(d.landmark.as_str());
        }
        let segments = data.streets.iter().enumerate().flat_map(|(i, st)| {
            st.line.0.windows(2).map(move |w| Segment {
                a: [w[0].x, w[0].y],
                b: [w[1].x, w[1].y],
                value: i as f64,
            })
        });
        index.streets = RTree::bulk_load(segments.collect());
        index
    }

    /// The first skip of a feature: its layer, its id and its record (a skip of a repeated
    /// id names another record than the feature built under that id).
    pub fn skip_of(&self, layer: &str, id: &str, record: usize) -> Option<&'a Skipped> {
        self.skips
            .get(&(layer, id))?
            .iter()
            .find(|k| k.record.is_none_or(|r| r == record))
            .copied()
    }

    /// The id of the street nearest a point.
    fn street_at(&self, p: Coord<f64>, data: &'a Dataset) -> Option<&'a str> {
        let nearest = self.streets.nearest_neighbor(&[p.x, p.y])?;
        data.streets
            .get(nearest.value as usize)
            .map(|s| s.id.as_str())
    }
}

/// A string value, or NULL when empty.
pub(super) fn t(s: &str) -> Value {
    match s {
        "" => Value::Null,
        s => Value::Text(s.to_string()),
    }
}

/// An optional string value.
pub(super) fn opt(s: Option<&str>) -> Value {
    s.map_or(Value::Null, t)
}

/// An integer value.
pub(super) fn n(v: usize) -> Value {
    Value::Integer(v as i64)
}

/// A real value, NULL unless finite.
pub(super) fn r(v: f64) -> Value {
    if v.is_finite() {
        Value::Real(v)
    } else {
        Value::Null
    }
}

/// A ring of map points as a polygon.
pub(super) fn polygon_of(points: Vec<Coord<f64>>) -> Geometry<f64> {
    Geometry::Polygon(Polygon::new(LineString::from(points), Vec::new()))
}

/// Every planned house, lot by lot, in the plan's order.
pub(super) fn planned(plan: &Plan) -> impl Iterator<Item = &PlannedHouse> {
    plan.houses.values().flatten()
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

/// What section 4.2 decided for a machiya's kura, in words: (decision, why).
pub(super) fn kura_words(k: &KuraDecision, avoid: bool) -> (&'static str, &'static str) {
    match k {
        KuraDecision::NotCandidate => (
            "not a candidate",
            "frontage narrower than kura.min_frontage or lot shallower than kura.depth_ratio \
             times it",
        ),
        KuraDecision::NoRoom => ("refused", "no room behind the house"),
        KuraDecision::Collides(_) if avoid => (
            "refused",
            "its plot overlaps another machiya's (kura.collision = true)",
        ),
        KuraDecision::Collides(_) => ("placed", "its plot overlaps another machiya's"),
        KuraDecision::Clear(_) => ("placed", ""),
    }
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
    let houses: HashMap<&str, &PlannedHouse> = planned(s.plan)
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
                edge_index(&lot.outline, h.frontage.a, h.frontage.b).map_or(Value::Null, n),
                opt(index.street_at(mid(h.frontage.a, h.frontage.b), s.data)),
                n(h.frontage.fallback as usize),
            ),
            None => (Value::Null, Value::Null, Value::Null),
        };
        let (kura, kura_reason) = match house {
            Some(h) => {
                let (k, why) = kura_words(&h.kura, avoid);
                (t(k), t(why))
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
                t(&lot.id),
                n(lot.record),
                t(lot.lot_use.name()),
                opt(lot.district.as_deref()),
                opt(mtype),
                opt(source),
                edge,
                street,
                fallback,
                kura,
                kura_reason,
                n(trees.get(lot.id.as_str()).copied().unwrap_or(0)),
                opt(house.map(|h| h.tile.as_str())),
                t(status),
                t(&reason),
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
        let mut row = vec![t(&k.id), k.record.map_or(Value::Null, n)];
        row.extend(std::iter::repeat_n(Value::Null, LOT_COLUMNS.len() - 4));
        row.push(t("skipped"));
        row.push(t(&k.reason));
        w.add(
            shape.map(|p| Geometry::Polygon((*p).clone())).as_ref(),
            &row,
        )?;
    }
    w.end()
}

/// The outlines reading kept of skipped records, by (layer, record, id).
pub(super) fn shapes_of(data: &Dataset) -> HashMap<(&str, Option<usize>, &str), &Polygon<f64>> {
    data.skipped_shapes
        .iter()
        .map(|k| ((k.layer.as_str(), Some(k.record), k.id.as_str()), &k.shape))
        .collect()
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
    for h in planned(s.plan) {
        let f = h.frontage;
        w.add(
            Some(&Geometry::LineString(LineString::from(vec![f.a, f.b]))),
            &[
                t(&h.id),
                n(h.record),
                t(source(h)),
                edge_index(&h.outline, f.a, f.b).map_or(Value::Null, n),
                opt(index.street_at(mid(f.a, f.b), s.data)),
                r(f.width()),
                n(f.fallback as usize),
            ],
        )?;
    }
    w.end()
}

pub(super) fn source(h: &PlannedHouse) -> &'static str {
    match h.is_footprint() {
        true => "footprints",
        false => "lots",
    }
}
