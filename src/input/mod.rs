//! Stage 1: read the input directory into a [`Dataset`].
//!
//! Layer problems that make the build meaningless (no lots layer, a lots layer of points, a
//! `.dbf` that does not match its `.shp`) are errors. Problems with single features (no id, a
//! duplicate id, a ring of fewer than three points) skip that feature and are reported, so
//! the rest of the city is still built.

pub mod shp;
pub mod table;

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;

use geo::{orient::Direction, Area, Orient};
use geo_types::{Coord, LineString, MultiPolygon, Polygon};
use shapefile::Shape;
use thiserror::Error;

use crate::model::{Dataset, Lot, LotUse, Skipped, Street, TableJoin};
use crate::params::Params;

#[derive(Debug, Error)]
pub enum InputError {
    #[error("{file}: {message}")]
    Layer { file: String, message: String },
    #[error("attribute table {file}: {message}")]
    Table { file: String, message: String },
    #[error("{0}")]
    Missing(String),
}

/// Reads lots, blocks and streets from `dir` as the parameter file maps them.
pub fn read_dataset(dir: &Path, params: &Params) -> Result<Dataset, InputError> {
    if !dir.is_dir() {
        return Err(InputError::Missing(format!(
            "input directory {} does not exist or is not a directory",
            dir.display()
        )));
    }
    let mut data = Dataset::default();
    let lp = &params.layers.lots;
    let lots_path = dir.join(&lp.file);
    if !lots_path.exists() {
        return Err(InputError::Missing(format!(
            "no lots layer: {} does not exist (set `layers.lots.file` in the parameter file \
             if your lots have another name)",
            lots_path.display()
        )));
    }
    let layer = shp::read_layer(&lots_path, &lp.encoding)?;
    data.warnings.extend(layer.warnings.iter().cloned());
    data.crs_wkt = layer.prj.clone();
    let file = lots_path.display().to_string();

    let table = table::find_and_read(dir, &lp.table, &lp.sheet, &lp.fields.id)?;
    let mut seen = HashSet::new();
    let mut lots = Vec::with_capacity(layer.features.len());
    for f in layer.features {
        let skip = |id: String, reason: String| Skipped {
            layer: "lots".into(),
            file: file.clone(),
            id,
            reason,
        };
        let polys = match polygons_of(&f.shape) {
            Ok(p) => p,
            Err(ShapeKind(kind)) => {
                return Err(InputError::Layer {
                    file,
                    message: format!(
                        "record {} is a {kind}; the lots layer must hold polygons",
                        f.record
                    ),
                })
            }
        };
        let base_id = f.attrs.get(&lp.fields.id).cloned().unwrap_or_default();
        if base_id.is_empty() {
            data.skipped.push(skip(
                format!("record {}", f.record),
                format!("no value in the id field `{}`", lp.fields.id),
            ));
            continue;
        }
        let multi = polys.0.len() > 1;
        for (part, poly) in polys.0.into_iter().enumerate() {
            // A multipart lot becomes one lot per part, ids suffixed, so that every id stays
            // unique and the parts can still be traced to their record.
            let id = if multi {
                format!("{base_id}-{}", part + 1)
            } else {
                base_id.clone()
            };
            if let Err(reason) = check_polygon(&poly) {
                data.skipped.push(skip(id, reason));
                continue;
            }
            if !seen.insert(id.clone()) {
                data.skipped.push(skip(
                    id,
                    format!(
                        "duplicate id: record {} repeats an earlier lot's id",
                        f.record
                    ),
                ));
                continue;
            }
            lots.push(Lot {
                id,
                record: f.record,
                outline: poly,
                lot_use: LotUse::Machiya,
                mtype: None,
                district: None,
                tile: None,
                attrs: f.attrs.clone(),
            });
        }
    }
    if let Some(t) = table {
        data.joins.push(join(&mut lots, t, "lots"));
    }
    let fields = &lp.fields;
    let text = |lot: &Lot, key: &str| lot.attrs.get(key).filter(|v| !v.is_empty()).cloned();
    for lot in &mut lots {
        lot.lot_use = LotUse::parse(&text(lot, &fields.lot_use).unwrap_or_default());
        lot.mtype = text(lot, &fields.mtype);
        lot.district = text(lot, &fields.district);
        lot.tile = text(lot, &fields.tile);
    }
    data.lots = lots;

    let blocks_path = dir.join(&params.layers.blocks.file);
    if blocks_path.exists() {
        let layer = shp::read_layer(&blocks_path, &params.layers.blocks.encoding)?;
        data.warnings.extend(layer.warnings.iter().cloned());
        for f in layer.features {
            match polygons_of(&f.shape) {
                Ok(mp) => data.blocks.extend(mp.0),
                Err(ShapeKind(kind)) => {
                    return Err(InputError::Layer {
                        file: blocks_path.display().to_string(),
                        message: format!(
                            "record {} is a {kind}; the blocks layer must hold polygons",
                            f.record
                        ),
                    })
                }
            }
        }
    }
    let sp = &params.layers.streets;
    let streets_path = dir.join(&sp.file);
    if streets_path.exists() {
        let layer = shp::read_layer(&streets_path, &sp.encoding)?;
        data.warnings.extend(layer.warnings.iter().cloned());
        let sfile = streets_path.display().to_string();
        let mut bad_width = 0usize;
        for f in layer.features {
            let lines = match lines_of(&f.shape) {
                Ok(l) => l,
                Err(ShapeKind(kind)) => {
                    return Err(InputError::Layer {
                        file: sfile,
                        message: format!(
                            "record {} is a {kind}; the streets layer must hold polylines",
                            f.record
                        ),
                    })
                }
            };
            let width = match f.attrs.get(&sp.width_field).map(|w| w.parse::<f64>()) {
                Some(Ok(w)) if w.is_finite() && w > 0.0 => w,
                Some(_) => {
                    bad_width += 1;
                    sp.default_width
                }
                None => sp.default_width,
            };
            let id = f
                .attrs
                .get("id")
                .cloned()
                .unwrap_or_else(|| f.record.to_string());
            for line in lines {
                if line.0.len() >= 2 && line.0.iter().all(|c| c.x.is_finite() && c.y.is_finite()) {
                    data.streets.push(Street {
                        id: id.clone(),
                        line,
                        width,
                    });
                }
            }
        }
        if bad_width > 0 {
            data.warnings.push(format!(
                "{sfile}: {bad_width} street(s) have no usable `{}`; they get the default width {} m",
                sp.width_field, sp.default_width
            ));
        }
    }
    if data.blocks.is_empty() && data.streets.is_empty() {
        return Err(InputError::Missing(format!(
            "no street edges: neither {} nor {} exists (or both are empty); the frontage of each \
             lot is found from its distance to the street, so one of them is needed",
            blocks_path.display(),
            streets_path.display()
        )));
    }
    Ok(data)
}

/// Applies a table to the features: table values win. Returns the match counts.
fn join(lots: &mut [Lot], table: table::Table, layer: &str) -> TableJoin {
    let mut index: HashMap<String, Vec<usize>> = HashMap::new();
    for (i, lot) in lots.iter().enumerate() {
        // Parts of a multipart lot share the record's id; the row applies to all of them.
        let key = lot
            .attrs
            .get("id")
            .cloned()
            .unwrap_or_else(|| lot.id.clone());
        index.entry(key).or_default().push(i);
        if !index.contains_key(&lot.id) {
            index.entry(lot.id.clone()).or_default().push(i);
        }
    }
    let mut matched_lots = vec![false; lots.len()];
    let mut out = TableJoin {
        layer: layer.to_string(),
        file: table.file.clone(),
        rows: table.rows.len(),
        matched: 0,
        rows_without_feature: 0,
        rows_without_feature_ids: Vec::new(),
        features_without_row: 0,
    };
    for (id, values) in table.rows {
        match index.get(&id) {
            Some(targets) => {
                out.matched += 1;
                for &i in targets {
                    matched_lots[i] = true;
                    for (k, v) in &values {
                        lots[i].attrs.insert(k.clone(), v.clone());
                    }
                }
            }
            None => {
                out.rows_without_feature += 1;
                if out.rows_without_feature_ids.len() < 20 {
                    out.rows_without_feature_ids.push(id);
                }
            }
        }
    }
    out.features_without_row = matched_lots.iter().filter(|m| !**m).count();
    out
}

struct ShapeKind(&'static str);

fn shape_kind(shape: &Shape) -> &'static str {
    match shape {
        Shape::NullShape => "null shape",
        Shape::Point(_) | Shape::PointM(_) | Shape::PointZ(_) => "point",
        Shape::Multipoint(_) | Shape::MultipointM(_) | Shape::MultipointZ(_) => "multipoint",
        Shape::Polyline(_) | Shape::PolylineM(_) | Shape::PolylineZ(_) => "polyline",
        Shape::Polygon(_) | Shape::PolygonM(_) | Shape::PolygonZ(_) => "polygon",
        Shape::Multipatch(_) => "multipatch",
    }
}

/// Polygons of a shape (Z and M dropped: elevation comes from a DEM in a later stage).
/// Exterior rings come out counter-clockwise.
fn polygons_of(shape: &Shape) -> Result<MultiPolygon<f64>, ShapeKind> {
    let mp: Result<MultiPolygon<f64>, _> = match shape {
        Shape::Polygon(p) => MultiPolygon::try_from(p.clone()),
        Shape::PolygonM(p) => MultiPolygon::try_from(p.clone()),
        Shape::PolygonZ(p) => MultiPolygon::try_from(p.clone()),
        Shape::NullShape => return Ok(MultiPolygon(Vec::new())),
        other => return Err(ShapeKind(shape_kind(other))),
    };
    Ok(mp
        .map(|m| m.orient(Direction::Default))
        .unwrap_or_else(|_| MultiPolygon(Vec::new())))
}

fn lines_of(shape: &Shape) -> Result<Vec<LineString<f64>>, ShapeKind> {
    let parts: Vec<Vec<Coord<f64>>> = match shape {
        Shape::Polyline(p) => p
            .parts()
            .iter()
            .map(|r| r.iter().map(|q| Coord { x: q.x, y: q.y }).collect())
            .collect(),
        Shape::PolylineM(p) => p
            .parts()
            .iter()
            .map(|r| r.iter().map(|q| Coord { x: q.x, y: q.y }).collect())
            .collect(),
        Shape::PolylineZ(p) => p
            .parts()
            .iter()
            .map(|r| r.iter().map(|q| Coord { x: q.x, y: q.y }).collect())
            .collect(),
        Shape::NullShape => Vec::new(),
        other => return Err(ShapeKind(shape_kind(other))),
    };
    Ok(parts.into_iter().map(LineString).collect())
}

/// A lot the later stages can work on: finite, at least a triangle, with an area.
fn check_polygon(poly: &Polygon<f64>) -> Result<(), String> {
    let ext = poly.exterior();
    if ext.0.iter().any(|c| !c.x.is_finite() || !c.y.is_finite()) {
        return Err("a coordinate is not a finite number".into());
    }
    let distinct: BTreeMap<(u64, u64), ()> = ext
        .0
        .iter()
        .map(|c| ((c.x.to_bits()), (c.y.to_bits())))
        .map(|k| (k, ()))
        .collect();
    if distinct.len() < 3 {
        return Err(format!(
            "the outline has {} distinct vertices; a lot needs at least 3",
            distinct.len()
        ));
    }
    if poly.unsigned_area() < 1e-6 {
        return Err("the outline has no area".into());
    }
    Ok(())
}
