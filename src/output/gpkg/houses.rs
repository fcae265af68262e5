//! The layers of `plan.gpkg` about houses: `houses` (the ground each covers) and `kura`,
//! and the marking of the houses generation could not build.

use std::collections::HashMap;

use geo_types::{Coord, Geometry, LineString, Polygon};

use super::rows::{
    count, house_layer, kura_words, optional, planned_houses, polygon_of, real_or_null,
    text_or_null, Index, PlanSources,
};
use super::styles::{self, Look, Shape};
use super::{int, real, text, GeoPackage, GeomKind, GpkgError, Value};
use crate::geom::frame::Frame;
use crate::model::{PlannedHouse, Skipped};

/// Marks in `lots` and `houses` what generation found of the planned houses. A layer's
/// fids run from 1 in the order its features were added (nothing is deleted): a lot's is its
/// place in the dataset, a house's its place in the plan, so no map of a million ids is
/// kept for the few skips there are.
pub(super) fn mark_generated(
    g: &GeoPackage,
    s: &PlanSources,
    skips: &[&Skipped],
) -> Result<(), GpkgError> {
    if skips.is_empty() {
        return Ok(());
    }
    let mut by_key: HashMap<(&str, &str), Vec<&Skipped>> = HashMap::new();
    for k in skips {
        by_key
            .entry((k.layer.as_str(), k.id.as_str()))
            .or_default()
            .push(k);
    }
    let lot_fid: HashMap<&str, i64> = s
        .data
        .lots
        .iter()
        .enumerate()
        .filter(|(_, l)| by_key.contains_key(&("lots", l.id.as_str())))
        .map(|(i, l)| (l.id.as_str(), i as i64 + 1))
        .collect();
    for (i, h) in planned_houses(s.plan).enumerate() {
        let Some(found) = by_key.get(&(house_layer(h), h.id.as_str())) else {
            continue;
        };
        let lot = match h.is_footprint() {
            false => lot_fid.get(h.id.as_str()).copied(),
            true => None,
        };
        for k in found {
            // A part of the lot (its kura, fence or a hall): the house stands.
            mark(g, (lot, i as i64 + 1), &k.reason, k.is_part())?;
        }
    }
    Ok(())
}

/// Marks what generation found of a planned house: its lot skipped and the house not built
/// (`part` false), or a part of it left out, in their `reason`s.
fn mark(
    g: &GeoPackage,
    (lot, house): (Option<i64>, i64),
    reason: &str,
    part: bool,
) -> Result<(), GpkgError> {
    let sql = |e| g.err(e);
    let add = "reason = coalesce(reason || '; ', '') || ?1";
    let (lots, houses) = match part {
        false => (
            "UPDATE lots SET status = 'skipped', reason = ?1 WHERE fid = ?2".to_string(),
            "UPDATE houses SET built = 0, reason = ?1 WHERE fid = ?2".to_string(),
        ),
        true => (
            format!("UPDATE lots SET {add} WHERE fid = ?2"),
            format!("UPDATE houses SET {add} WHERE fid = ?2"),
        ),
    };
    if let Some(lot) = lot {
        g.conn
            .execute(&lots, rusqlite::params![reason, lot])
            .map_err(sql)?;
    }
    g.conn
        .execute(&houses, rusqlite::params![reason, house])
        .map_err(sql)?;
    Ok(())
}

/// `houses`: every house planned, on the ground it covers (a machiya its lot's band behind
/// the frontage, a footprint building its outline), with its template; generation's skips
/// are marked.
pub(super) fn houses(g: &mut GeoPackage, s: &PlanSources, index: &Index) -> Result<(), GpkgError> {
    let colours = crate::output::plan::type_colours(s.plan);
    let mut categories: Vec<(String, Look)> = colours
        .into_iter()
        .map(|(ty, rgb)| (ty, Look::of(rgb)))
        .collect();
    categories.push(("skipped".into(), Look::of(crate::output::plan::SKIPPED)));
    let style = styles::categorized(
        Shape::Fill,
        "CASE WHEN \"built\" = 0 THEN 'skipped' ELSE \"template\" END",
        &categories,
        Some(Look::of(crate::output::plan::FOOTPRINT)),
    );
    let mut w = g.layer(
        "houses",
        Some(GeomKind::MultiPolygon),
        &[
            text("id"),
            int("record"),
            text("source"),
            text("template"),
            int("type_given"),
            text("district"),
            real("height"),
            text("tile"),
            int("built"),
            text("reason"),
        ],
        "Each house planned: the ground it covers (a machiya the band of its lot behind the \
         frontage its template fills, a footprint building its outline) and its template",
        Some(style),
    )?;
    for h in planned_houses(s.plan) {
        let skip = index.skip_of(house_layer(h), &h.id, h.record);
        w.add(
            Some(&footprint(h, (s.band)(h))),
            &[
                text_or_null(&h.id),
                count(h.record),
                text_or_null(house_layer(h)),
                text_or_null(&h.mtype),
                count(h.type_given as usize),
                optional(h.district.as_deref()),
                h.footprint_height().map_or(Value::Null, real_or_null),
                text_or_null(&h.tile),
                count(skip.is_none() as usize),
                optional(skip.map(|k| k.reason.as_str())),
            ],
        )?;
    }
    w.end()
}

/// The ground a house covers: the lot clipped to its band behind the frontage (in the
/// frontage frame, as generation clips it), or its whole outline.
fn footprint(h: &PlannedHouse, band: Option<(f64, f64)>) -> Geometry<f64> {
    use crate::generate::clip::{clip_band, LocalPoly};
    let whole = || Geometry::MultiPolygon(vec![h.outline.clone()].into());
    let Some((lo, hi)) = band else {
        return whole();
    };
    let frame = Frame::along(h.frontage.a, h.frontage.u_axis());
    let local = |r: &LineString<f64>| -> Vec<[f64; 2]> {
        crate::geom::ring::open(r)
            .iter()
            .map(|c| frame.local(*c))
            .collect()
    };
    let poly = LocalPoly {
        exterior: local(h.outline.exterior()),
        holes: h.outline.interiors().iter().map(local).collect(),
    };
    let parts: Vec<Polygon<f64>> = clip_band(&poly, lo, hi)
        .iter()
        .map(|p| {
            let ring = |r: &Vec<[f64; 2]>| {
                let mut c: Vec<Coord<f64>> = r.iter().map(|q| frame.map(*q)).collect();
                c.extend(c.first().copied());
                LineString::from(c)
            };
            Polygon::new(ring(&p.exterior), p.holes.iter().map(ring).collect())
        })
        .collect();
    match parts.is_empty() {
        true => whole(),
        false => Geometry::MultiPolygon(parts.into()),
    }
}

/// `kura`: every kura plot section 4.2 found room for, placed or refused (hatched).
pub(super) fn kura(g: &mut GeoPackage, s: &PlanSources) -> Result<(), GpkgError> {
    let avoid = s.params.kura.collision;
    let style = styles::categorized(
        Shape::Fill,
        "status",
        &[
            ("placed".into(), Look::of([120, 120, 120])),
            ("refused".into(), Look::of([200, 40, 40]).hatched()),
        ],
        None,
    );
    let mut w = g.layer(
        "kura",
        Some(GeomKind::Polygon),
        &[
            text("id"),
            int("record"),
            text("status"),
            text("reason"),
            real("width"),
            real("depth"),
            text("tile"),
        ],
        "The kura (storehouse) plots of section 4.2: placed, or refused for a collision",
        Some(style),
    )?;
    for h in planned_houses(s.plan) {
        let Some(rect) = h.kura.rect() else {
            continue;
        };
        let frame = Frame::along(h.frontage.a, h.frontage.u_axis());
        let (status, why) = kura_words(&h.kura, avoid);
        w.add(
            Some(&polygon_of(frame.quad(rect).to_vec())),
            &[
                text_or_null(&h.id),
                count(h.record),
                text_or_null(status),
                text_or_null(why),
                real_or_null(rect[2] - rect[0]),
                real_or_null(rect[3] - rect[1]),
                text_or_null(&h.tile),
            ],
        )?;
    }
    w.end()
}
