//! The layers of `plan.gpkg` beyond the houses: walls and gates, halls, gardens, trees and
//! people, landmarks, tiles, and every record skipped; and `check`'s problems.

use std::collections::HashMap;

use geo_types::{Geometry, LineString, Point};

use super::rows::{
    count, optional, polygon_of, real_or_null, shapes_of, text_or_null, Index, PlanSources,
};
use super::styles::{self, Look, Shape};
use super::{int, real, text, GeoPackage, GeomKind, GpkgError, Value};
use crate::model::{BillboardKind, Dataset, FenceKind, Skipped};

/// `fences` (walls) and `gates`: section 4.3's segments, each a line from `a` to `b` with the
/// enclosed side on its left.
pub(super) fn fences(g: &mut GeoPackage, s: &PlanSources) -> Result<(), GpkgError> {
    for (name, kind, rgb, about) in [
        (
            "fences",
            FenceKind::Wall,
            [70, 70, 70],
            "Wall segments of section 4.3, the enclosed side on the left",
        ),
        (
            "gates",
            FenceKind::Gate,
            [150, 60, 30],
            "Gates of section 4.3 (Fig. 11)",
        ),
    ] {
        let mut w = g.layer(
            name,
            Some(GeomKind::LineString),
            &[
                text("id"),
                int("record"),
                text("layer"),
                text("template"),
                int("edge"),
                real("length"),
                text("district"),
                text("tile"),
            ],
            about,
            Some(styles::single(Shape::Line, Look::of(rgb).sized(0.5))),
        )?;
        for f in s.plan.fences.values().flatten().filter(|f| f.kind == kind) {
            w.add(
                Some(&Geometry::LineString(LineString::from(vec![f.a, f.b]))),
                &[
                    text_or_null(&f.id),
                    count(f.record),
                    text_or_null(&f.layer),
                    text_or_null(&f.template),
                    count(f.edge),
                    real_or_null((f.b.x - f.a.x).hypot(f.b.y - f.a.y)),
                    optional(f.district.as_deref()),
                    text_or_null(&f.tile),
                ],
            )?;
        }
        w.end()?;
    }
    Ok(())
}

/// `halls`: each hall asked for, on its plot where it was placed, else on its lot, with why
/// not.
pub(super) fn halls(g: &mut GeoPackage, s: &PlanSources, index: &Index) -> Result<(), GpkgError> {
    let style = styles::categorized(
        Shape::Fill,
        "placed",
        &[
            ("1".into(), Look::of(crate::output::plan::HALL)),
            ("0".into(), Look::of(crate::output::plan::SKIPPED).hatched()),
        ],
        None,
    );
    let mut w = g.layer(
        "halls",
        Some(GeomKind::Polygon),
        &[
            text("lot"),
            int("record"),
            text("use"),
            text("template"),
            int("placed"),
            text("reason"),
            real("width"),
            real("depth"),
            text("district"),
            text("tile"),
        ],
        "The halls each lot use asks for: placed on their plot, or not placed (on the lot) \
         with why",
        Some(style),
    )?;
    let placed: HashMap<(&str, &str), &crate::model::PlannedHall> = s
        .plan
        .halls
        .values()
        .flatten()
        .map(|h| ((h.lot.as_str(), h.template.as_str()), h))
        .collect();
    for stat in &s.plan.hall_reports {
        let lot = index.lots.get(stat.lot.as_str());
        let hall = placed.get(&(stat.lot.as_str(), stat.template.as_str()));
        let geom = match (hall, lot) {
            (Some(h), _) => Some(polygon_of(h.outline())),
            (None, Some(l)) => Some(Geometry::Polygon(l.outline.clone())),
            (None, None) => None,
        };
        w.add(
            geom.as_ref(),
            &[
                text_or_null(&stat.lot),
                lot.map_or(Value::Null, |l| count(l.record)),
                text_or_null(&stat.lot_use),
                text_or_null(&stat.template),
                count(stat.placed as usize),
                text_or_null(&stat.reason),
                real_or_null(stat.size[0]),
                real_or_null(stat.size[1]),
                optional(lot.and_then(|l| l.district.as_deref())),
                optional(hall.map(|h| h.tile.as_str())),
            ],
        )?;
    }
    w.end()
}

/// `gardens`: each rock garden designed (its rectangle, fitness and the five rule scores),
/// or the lot of one that found no room, with why.
pub(super) fn gardens(g: &mut GeoPackage, s: &PlanSources, index: &Index) -> Result<(), GpkgError> {
    let mut columns = vec![
        text("lot"),
        text("area"),
        int("placed"),
        text("reason"),
        real("width"),
        real("depth"),
        int("stones"),
        real("fitness"),
    ];
    let rules = crate::growers::garden::rules::WEIGHTS.map(|(rule, _)| rule);
    columns.extend(rules.iter().map(|&rule| real(rule)));
    columns.push(text("tile"));
    let style = styles::categorized(
        Shape::Fill,
        "placed",
        &[
            ("1".into(), Look::of([225, 220, 200])),
            ("0".into(), Look::of(crate::output::plan::SKIPPED).hatched()),
        ],
        None,
    );
    let mut w = g.layer(
        "gardens",
        Some(GeomKind::Polygon),
        &columns,
        "Rock gardens (karesansui) of seed 000: fitness and the degree each of the five rules \
         is broken (0: kept)",
        Some(style),
    )?;
    let planned: HashMap<&str, &crate::model::PlannedGarden> = s
        .plan
        .gardens
        .values()
        .flatten()
        .map(|g| (g.lot.as_str(), g))
        .collect();
    for stat in &s.plan.garden_reports {
        let key = match &stat.area {
            Some(a) => format!("area-{a}"),
            None => stat.lot.clone(),
        };
        let garden = planned.get(key.as_str());
        let geom = match (garden, index.lots.get(stat.lot.as_str())) {
            (Some(g), _) => Some(polygon_of(g.outline())),
            (None, Some(l)) => Some(Geometry::Polygon(l.outline.clone())),
            (None, None) => None,
        };
        let mut row = vec![
            text_or_null(&stat.lot),
            optional(stat.area.as_deref()),
            count(stat.placed as usize),
            text_or_null(&stat.reason),
            real_or_null(stat.size[0]),
            real_or_null(stat.size[1]),
            count(stat.stones),
            if stat.placed {
                real_or_null(stat.fitness)
            } else {
                Value::Null
            },
        ];
        row.extend(rules.iter().map(|rule| {
            stat.scores
                .get(*rule)
                .map_or(Value::Null, |v| real_or_null(*v))
        }));
        row.push(optional(garden.map(|g| g.tile.as_str())));
        w.add(geom.as_ref(), &row)?;
    }
    w.end()
}

/// `trees` and `people`: section 4.4's billboards and grown trees, as points.
pub(super) fn billboards(g: &mut GeoPackage, s: &PlanSources) -> Result<(), GpkgError> {
    for (kind, rgb, about) in [
        (
            BillboardKind::Tree,
            [60, 130, 60],
            "Trees: species, height, crown, grown or drawn as a billboard, and the lot",
        ),
        (
            BillboardKind::Person,
            [40, 60, 160],
            "People of section 4.4 along the streets",
        ),
    ] {
        let mut w = g.layer(
            kind.layer(),
            Some(GeomKind::Point),
            &[
                text("id"),
                text("species"),
                text("lot"),
                real("height"),
                real("crown"),
                text("form"),
                text("variant"),
                real("facing_deg"),
                text("district"),
                text("tile"),
            ],
            about,
            Some(styles::single(Shape::Marker, Look::of(rgb).sized(1.0))),
        )?;
        for b in s
            .plan
            .billboards
            .values()
            .flatten()
            .filter(|b| b.kind == kind)
        {
            let tree = b.tree.as_ref();
            let form = match (kind, tree) {
                (BillboardKind::Person, _) => None,
                (_, Some(f)) if f.grown => Some("grown"),
                _ => Some("billboard"),
            };
            w.add(
                Some(&Geometry::Point(Point(b.at))),
                &[
                    text_or_null(&b.id),
                    optional(tree.map(|f| f.species.as_str())),
                    optional(tree.and_then(|f| f.lot.as_deref())),
                    real_or_null(b.height),
                    tree.map_or(Value::Null, |f| real_or_null(f.crown)),
                    optional(form),
                    text_or_null(&b.texture),
                    real_or_null(b.facing.to_degrees()),
                    optional(b.district.as_deref()),
                    text_or_null(&b.tile),
                ],
            )?;
        }
        w.end()?;
    }
    Ok(())
}

/// `landmarks`: each landmark placed, on its footprint, with what it displaced.
pub(super) fn landmarks(g: &mut GeoPackage, s: &PlanSources) -> Result<(), GpkgError> {
    let mut w = g.layer(
        "landmarks",
        Some(GeomKind::Polygon),
        &[
            text("id"),
            int("record"),
            text("model"),
            real("rotation_deg"),
            real("scale"),
            text("displaced"),
            text("tile"),
        ],
        "Landmarks placed from their models, and what generated features they displaced",
        Some(styles::single(Shape::Fill, Look::of([90, 60, 140]))),
    )?;
    let mut displaced: HashMap<&str, Vec<String>> = HashMap::new();
    for d in &s.plan.landmark_report.displaced {
        displaced
            .entry(d.landmark.as_str())
            .or_default()
            .push(format!("{} {}", d.kind, d.id));
    }
    for l in s.plan.landmarks.values().flatten() {
        w.add(
            Some(&Geometry::Polygon(l.footprint.clone())),
            &[
                text_or_null(&l.id),
                count(l.record),
                text_or_null(&l.model.file),
                real_or_null(l.rotation.to_degrees()),
                real_or_null(l.scale),
                text_or_null(
                    &displaced
                        .get(l.id.as_str())
                        .map(|v| v.join("; "))
                        .unwrap_or_default(),
                ),
                text_or_null(&l.tile),
            ],
        )?;
    }
    w.end()
}

/// `tiles`: each tile of the build, with the bytes of each of its files.
pub(super) fn tiles(
    g: &mut GeoPackage,
    s: &PlanSources,
    manifest: &crate::output::report::Manifest,
) -> Result<(), GpkgError> {
    let mut w = g.layer(
        "tiles",
        Some(GeomKind::Polygon),
        &[
            text("id"),
            int("obj_bytes"),
            int("mtl_bytes"),
            int("glb_bytes"),
            int("machiya"),
            int("footprints"),
            int("kura"),
        ],
        "The tiles written, with the bytes of each format",
        Some(styles::single(
            Shape::Fill,
            Look::of([90, 90, 200]).outline().sized(0.3),
        )),
    )?;
    let m = manifest;
    for tile in &m.tiles {
        let bounds = crate::model::tile::tile_bounds(&tile.id, m.tile_size, s.params.tile_origin)
            .or_else(|| {
                tile.bounds.map(|b| {
                    let o = m.origin;
                    [o[0] + b[0], o[1] + b[1], o[0] + b[3], o[1] + b[4]]
                })
            });
        let geom = bounds.map(|[x0, y0, x1, y1]| {
            polygon_of(vec![
                (x0, y0).into(),
                (x1, y0).into(),
                (x1, y1).into(),
                (x0, y1).into(),
            ])
        });
        let bytes = |f: &Option<crate::output::report::ManifestFile>| {
            f.as_ref()
                .map_or(Value::Null, |f| Value::Integer(f.bytes as i64))
        };
        w.add(
            geom.as_ref(),
            &[
                text_or_null(&tile.id),
                bytes(&tile.obj),
                bytes(&tile.mtl),
                bytes(&tile.glb),
                count(tile.stats.machiya),
                count(tile.stats.footprints),
                count(tile.stats.kura),
            ],
        )?;
    }
    w.end()
}

/// `skipped`: every record skipped in any layer, as the report lists them.
pub(super) fn skipped(
    g: &mut GeoPackage,
    data: &Dataset,
    skipped: &[Skipped],
    index: &Index,
) -> Result<(), GpkgError> {
    records(
        g,
        "skipped",
        "Every record skipped in any layer, at its own outline where reading kept it, else \
         at its lot's; with the reason and what to do",
        data,
        skipped,
        index,
    )
}

/// A layer of skipped records, each where it is known to be.
fn records(
    g: &mut GeoPackage,
    name: &str,
    about: &str,
    data: &Dataset,
    skipped: &[Skipped],
    index: &Index,
) -> Result<(), GpkgError> {
    let mut w = g.layer(
        name,
        Some(GeomKind::Polygon),
        &[
            text("layer"),
            text("file"),
            int("record"),
            text("id"),
            text("reason"),
        ],
        about,
        Some(styles::single(
            Shape::Fill,
            Look::of(crate::output::plan::SKIPPED).hatched(),
        )),
    )?;
    let shapes = shapes_of(data);
    for k in skipped {
        w.add(
            where_skipped(k, &shapes, index).as_ref(),
            &[
                text_or_null(&k.layer),
                text_or_null(&k.file),
                k.record.map_or(Value::Null, count),
                text_or_null(&k.id),
                text_or_null(&k.reason),
            ],
        )?;
    }
    w.end()
}

/// Where a skipped record is drawn: its own outline if reading kept one, else the lot of
/// its id (a house generation could not build, a tree of a lot), else nowhere.
fn where_skipped(
    k: &Skipped,
    shapes: &HashMap<(&str, Option<usize>, &str), &geo_types::Polygon<f64>>,
    index: &Index,
) -> Option<Geometry<f64>> {
    if let Some(p) = shapes.get(&(k.layer.as_str(), k.record, k.id.as_str())) {
        return Some(Geometry::Polygon((*p).clone()));
    }
    let lot = index
        .lots
        .get(k.id.as_str())
        .or_else(|| k.id.split('/').next().and_then(|l| index.lots.get(l)));
    lot.map(|l| Geometry::Polygon(l.outline.clone()))
}

/// `check --gpkg`: the `problems` layer (every record `check` would skip, where it is) and
/// `warnings` (what concerns a whole layer or parameter, without a place).
pub(super) fn problems(
    g: &mut GeoPackage,
    data: &Dataset,
    skipped: &[Skipped],
    warnings: &[crate::model::Warning],
    index: &Index,
) -> Result<(), GpkgError> {
    records(
        g,
        "problems",
        "Every record a build would skip, where it is: fix them in QGIS, then build",
        data,
        skipped,
        index,
    )?;
    let mut w = g.layer(
        "warnings",
        None,
        &[
            text("class"),
            text("layer"),
            text("file"),
            text("key"),
            text("message"),
        ],
        "Warnings about whole layers, tables and parameters",
        None,
    )?;
    for warning in warnings {
        let class = serde_json::to_value(warning.class).unwrap_or_default();
        w.add(
            None,
            &[
                optional(class.as_str()),
                optional(warning.layer.as_deref()),
                optional(warning.file.as_deref()),
                optional(warning.key.as_deref()),
                text_or_null(&warning.message),
            ],
        )?;
    }
    w.end()
}
