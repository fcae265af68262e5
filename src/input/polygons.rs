//! The polygon roles: lots and footprints with their attributes joined and checked, every
//! part of a multipart feature a feature of its own, and districts given to both.

use std::collections::HashSet;
use std::path::Path;

use super::crs::Crs;
use super::fields::AttributeRule;
use super::geometry::{check_polygon, map_polygon, polygons_of};
use super::target::to_target;
use super::{join, overrides, rule, shp, table, InputError, Opened};
use crate::model::{Dataset, Footprint, Lot, LotUse, Skipped, SkippedShape};
use crate::params::Params;

pub(super) fn read_lots(
    dir: &Path,
    params: &Params,
    o: &mut Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let lp = &params.layers.lots;
    let defaults = Params::default().layers.lots.fields;
    let id_field = o.required_field(&lp.fields.id, "id", "layers.lots.fields.id")?;
    let table = table::find_and_read(dir, &lp.table, &lp.sheet, &lp.fields.id)?;
    // Table columns count as fields of the layer: a user may keep `mtype` only in lots.csv.
    let columns: Vec<String> = table
        .iter()
        .flat_map(|t| t.rows.iter().flat_map(|r| r.1.keys().cloned()))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let w = &mut data.warnings;
    let (v, c, x) = (&lp.values, &lp.constants, &columns);
    let use_rule = rule(o, x, "use", &lp.fields.lot_use, &defaults.lot_use, v, c, w);
    let mtype_rule = rule(o, x, "mtype", &lp.fields.mtype, &defaults.mtype, v, c, w);
    let district_rule = rule(
        o,
        x,
        "district",
        &lp.fields.district,
        &defaults.district,
        v,
        c,
        w,
    );
    let tile_rule = rule(o, x, "tile", &lp.fields.tile, &defaults.tile, v, c, w);
    let ground_rule = rule(o, x, "ground", &lp.fields.ground, "", v, c, w);

    let mut seen = HashSet::new();
    let mut lots = Vec::with_capacity(o.layer.features.len());
    // Each lot's record id (a multipart record's parts share it), for the table join.
    let mut base_ids = Vec::with_capacity(o.layer.features.len());
    // The features are used up here: their attributes move into the lots.
    let features = std::mem::take(&mut o.layer.features);
    let o = &*o;
    for f in features {
        let Some((polys, z, base_id)) = record_polygons(o, &f, &id_field, &mut data.skipped)?
        else {
            continue;
        };
        let parts = checked_parts(
            o,
            target,
            polys,
            &base_id,
            f.record,
            &mut seen,
            (&mut data.skipped, &mut data.skipped_shapes),
        );
        let count = parts.len();
        let mut record_attrs = Some(f.attrs);
        for (part, (id, poly)) in parts.into_iter().enumerate() {
            // The last part takes the record's attributes; earlier parts get a copy.
            let attrs = if part + 1 == count {
                record_attrs.take().unwrap_or_default()
            } else {
                record_attrs.clone().unwrap_or_default()
            };
            base_ids.push(base_id.clone());
            lots.push(Lot {
                id,
                record: f.record,
                outline: poly,
                lot_use: LotUse::Machiya,
                mtype: None,
                district: None,
                tile: None,
                attrs,
                ground: z.unwrap_or(0.0),
            });
        }
    }
    if let Some(mut t) = table {
        data.warnings.append(&mut t.warnings);
        data.joins
            .push(join(&mut lots, &base_ids, t, "lots", &mut data.skipped));
    }
    let overrides = overrides::read(&params.input)?;
    if let Some((file, rows)) = &overrides {
        let joined = overrides::apply_attributes(&mut lots, &base_ids, rows, file)?;
        data.joins.push(joined);
    }
    let mut bad_ground = 0usize;
    for lot in &mut lots {
        lot.lot_use = LotUse::parse(&use_rule.value(&lot.attrs).unwrap_or_default());
        lot.mtype = mtype_rule.value(&lot.attrs);
        lot.district = district_rule.value(&lot.attrs);
        lot.tile = tile_rule.value(&lot.attrs);
        if let Some(raw) = ground_rule.value(&lot.attrs) {
            match raw.parse::<f64>() {
                Ok(g) if g.is_finite() => lot.ground = g,
                _ => bad_ground += 1,
            }
        }
    }
    if let Some((file, rows)) = &overrides {
        overrides::apply_roles(&mut lots, &base_ids, rows, file)?;
    }
    lots.retain(|lot| match ground_problem(lot.ground) {
        None => true,
        Some(reason) => {
            data.skipped_shapes.push(SkippedShape {
                layer: o.role.into(),
                record: lot.record,
                id: lot.id.clone(),
                shape: lot.outline.clone(),
            });
            data.skipped.push(Skipped {
                layer: o.role.into(),
                file: o.file.clone(),
                id: lot.id.clone(),
                record: Some(lot.record),
                reason,
            });
            false
        }
    });
    if bad_ground > 0 {
        data.warnings.push(
            crate::model::Warning::layer(
                o.role,
                &o.file,
                format!(
                    "{}: {bad_ground} lot(s) have a `{}` that is not a number; they stand on the \
             lowest Z of their outline, else 0",
                    o.file, lp.fields.ground
                ),
            )
            .for_key("layers.lots.fields.ground"),
        );
    }
    data.lots = lots;
    Ok(())
}

/// The tallest building a footprint's `height` may give, metres (the tallest tower stands
/// 828 m).
pub const MAX_BUILDING_HEIGHT: f64 = 1000.0;

pub(super) fn read_footprints(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let fp = &params.layers.footprints;
    let id_field = o.required_field(&fp.fields.id, "id", "layers.footprints.fields.id")?;
    let (nv, nc) = (Default::default(), Default::default());
    let w = &mut data.warnings;
    let mtype = rule(
        o,
        &[],
        "mtype",
        &fp.fields.mtype,
        "mtype",
        &fp.values,
        &nc,
        w,
    );
    let height = rule(o, &[], "height", &fp.fields.height, "height", &nv, &nc, w);
    let storeys = rule(
        o,
        &[],
        "storeys",
        &fp.fields.storeys,
        "storeys",
        &nv,
        &nc,
        w,
    );
    let ground = rule(o, &[], "ground", &fp.fields.ground, "", &nv, &nc, w);
    let mut seen = HashSet::new();
    // Values that are there but are not positive numbers: counted per field and reported,
    // since the default then stands in for the data.
    let unusable = std::cell::RefCell::new(std::collections::BTreeMap::<String, usize>::new());
    // Up to `max`: a footprint 1e9 m high is damaged data, not a building.
    let number = |r: &AttributeRule, a, max: f64| {
        let raw = r.value(a)?;
        let n = raw
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0 && *v <= max);
        if n.is_none() {
            let field = r.field.clone().unwrap_or_default();
            *unusable.borrow_mut().entry(field).or_default() += 1;
        }
        n
    };
    for f in &o.layer.features {
        let Some((polys, z, base_id)) = record_polygons(o, f, &id_field, &mut data.skipped)? else {
            continue;
        };
        let h = number(&height, &f.attrs, MAX_BUILDING_HEIGHT)
            .or_else(|| number(&storeys, &f.attrs, 200.0).map(|s| s * fp.storey_height + 1.0))
            .unwrap_or(fp.default_height);
        let g = ground
            .value(&f.attrs)
            .and_then(|v| v.parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .or(z)
            .unwrap_or(0.0);
        for (id, poly) in checked_parts(
            o,
            target,
            polys,
            &base_id,
            f.record,
            &mut seen,
            (&mut data.skipped, &mut data.skipped_shapes),
        ) {
            if let Some(reason) = ground_problem(g) {
                data.skipped.push(Skipped {
                    layer: o.role.into(),
                    file: o.file.clone(),
                    id,
                    record: Some(f.record),
                    reason,
                });
                continue;
            }
            data.footprints.push(Footprint {
                id,
                record: f.record,
                outline: poly,
                mtype: mtype.value(&f.attrs),
                district: None,
                height: h,
                ground: g,
            });
        }
    }
    for (field, n) in unusable.into_inner() {
        data.warnings.push(crate::model::Warning::layer(
            o.role,
            &o.file,
            format!(
                "{}: {n} footprint(s) have a `{field}` that is not a positive number (heights up \
             to {MAX_BUILDING_HEIGHT} m, storeys up to 200); their height came from the next \
             source (height, storeys x storey_height, default_height)",
                o.file
            ),
        ));
    }
    Ok(())
}

/// Why a ground elevation cannot be a place's, if it cannot (see
/// [`crate::model::ELEVATION_RANGE`]).
fn ground_problem(ground: f64) -> Option<String> {
    let range = crate::model::ELEVATION_RANGE;
    (!range.contains(&ground)).then(|| {
        format!(
            "the ground elevation {ground} m (the `ground` field or the lowest Z) is outside \
             {}..{} m: the Z values are damaged or in another unit; correct them, or map \
             `ground` to a field that holds metres",
            range.start(),
            range.end()
        )
    })
}

/// Gives every lot and footprint without a district the district holding its centroid.
pub(super) fn assign_districts(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    use geo::{BoundingRect, Centroid, Contains};
    let dp = &params.layers.districts;
    let field = o.required_field(&dp.id_field, "district id", "layers.districts.id_field")?;
    let mut polys = Vec::new();
    for f in &o.layer.features {
        let read =
            polygons_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "polygons"))?;
        o.count_winding(read.against_winding);
        let parts = read.polygons;
        let id = f.attrs.get(&field).unwrap_or_default().to_string();
        let mut usable = false;
        for mut p in parts {
            if map_polygon(&mut p, &mut |c| to_target(o, target, c)).is_ok() && !id.is_empty() {
                if let Some(bb) = p.bounding_rect() {
                    usable = true;
                    polys.push((bb, p, id.clone()));
                }
            }
        }
        o.kept_or_skipped(data, f.record, usable, || match id.is_empty() {
            true => format!("no value in the district id field `{field}`: give the district an id"),
            false => {
                "null shape or no usable outline: draw the district or delete the record".into()
            }
        });
    }
    let find = |poly: &geo_types::Polygon<f64>| -> Option<String> {
        let c = poly.centroid()?;
        polys
            .iter()
            .find(|(bb, p, _)| bb.contains(&c) && p.contains(&c))
            .map(|(_, _, id)| id.clone())
    };
    let mut outside = 0;
    for lot in data.lots.iter_mut().filter(|l| l.district.is_none()) {
        lot.district = find(&lot.outline);
        outside += lot.district.is_none() as usize;
    }
    for f in data.footprints.iter_mut().filter(|f| f.district.is_none()) {
        f.district = find(&f.outline);
        outside += f.district.is_none() as usize;
    }
    if outside > 0 {
        data.warnings.push(crate::model::Warning::layer(
            o.role,
            &o.file,
            format!(
            "{}: {outside} lot(s) or footprint(s) lie in no district polygon and have no district",
            o.file
        ),
        ));
    }
    Ok(())
}

/// A record's polygons, lowest Z and id. A shape that is not a polygon stops the build (the
/// layer is the wrong one); a record without an id is skipped (`None`).
type RecordPolygons = (Vec<geo_types::Polygon<f64>>, Option<f64>, String);

pub(super) fn record_polygons(
    o: &Opened,
    f: &shp::Feature,
    id_field: &str,
    skipped: &mut Vec<Skipped>,
) -> Result<Option<RecordPolygons>, InputError> {
    let read = polygons_of(&f.shape).map_err(|kind| match kind {
        "multipatch" => InputError::Layer {
            file: o.file.clone(),
            message: format!(
                "record {} is a MultiPatch (3D surfaces); edo-city builds from 2D polygons: \
                 export the {} as Polygon/PolygonZ",
                f.record, o.role
            ),
        },
        _ => o.wrong_shape(f.record, kind, "polygons"),
    })?;
    o.count_winding(read.against_winding);
    let (polys, z) = (read.polygons, read.lowest_z);
    if matches!(f.shape, shapefile::Shape::NullShape) {
        let id = f.attrs.get(id_field).unwrap_or_default().to_string();
        skipped.push(Skipped {
            layer: o.role.into(),
            file: o.file.clone(),
            id: if id.is_empty() {
                format!("record {}", f.record)
            } else {
                id
            },
            record: Some(f.record),
            reason: "null shape: the record has attributes but no geometry; draw its outline \
                     or delete the record"
                .into(),
        });
        return Ok(None);
    }
    let id = f.attrs.get(id_field).unwrap_or_default().to_string();
    if id.is_empty() {
        skipped.push(Skipped {
            layer: o.role.into(),
            file: o.file.clone(),
            id: format!("record {}", f.record),
            record: Some(f.record),
            reason: format!("no value in the id field `{id_field}`: give the feature an id"),
        });
        return Ok(None);
    }
    Ok(Some((polys, z, id)))
}

/// The usable parts of one record's polygons, each with its id: a multipart record becomes one
/// feature per part, ids suffixed `-<n>` so every id stays unique and traceable to its record.
/// Each part is reprojected, then checked (the area check is in metres); a bad part or a
/// repeated id is skipped with the reason.
pub(super) fn checked_parts(
    o: &Opened,
    target: &Option<Crs>,
    polys: Vec<geo_types::Polygon<f64>>,
    base_id: &str,
    record: usize,
    seen: &mut HashSet<String>,
    (skipped, shapes): (&mut Vec<Skipped>, &mut Vec<SkippedShape>),
) -> Vec<(String, geo_types::Polygon<f64>)> {
    let multi = polys.len() > 1;
    let mut out = Vec::with_capacity(polys.len());
    for (part, mut poly) in polys.into_iter().enumerate() {
        let id = if multi {
            format!("{base_id}-{}", part + 1)
        } else {
            base_id.to_string()
        };
        let mapped = map_polygon(&mut poly, &mut |c| to_target(o, target, c));
        let reason = mapped
            .clone()
            .and_then(|_| check_polygon(&poly))
            .err()
            .or_else(|| {
                (!seen.insert(id.clone())).then(|| {
                    "duplicate id: the record repeats an earlier feature's id; the first was \
                     built, give this one an id of its own"
                        .to_string()
                })
            });
        if reason.is_some() && mapped.is_ok() && near_origin(&poly) {
            shapes.push(SkippedShape {
                layer: o.role.into(),
                record,
                id: id.clone(),
                shape: poly.clone(),
            });
        }
        match reason {
            Some(reason) => skipped.push(Skipped {
                layer: o.role.into(),
                file: o.file.clone(),
                id,
                record: Some(record),
                reason,
            }),
            None => out.push((id, poly)),
        }
    }
    out
}

/// Whether every vertex of a polygon is a usable coordinate (finite, nearer than
/// [`crate::model::FAR`]): only those are kept to draw a skipped record.
fn near_origin(poly: &geo_types::Polygon<f64>) -> bool {
    std::iter::once(poly.exterior())
        .chain(poly.interiors())
        .flat_map(|r| r.0.iter())
        .all(|c| crate::model::sane(*c))
}
