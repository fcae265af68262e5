//! The landmarks layer: points or polygons (a shapefile), or a CSV/XLSX table with x, y in
//! the output CRS, each naming a model file (its `model` field, or its `kind` through
//! `[landmarks.models]`). Each model is read once (`models.rs`); a record whose model cannot
//! be used, or whose numbers are not numbers, is skipped with the reason.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use geo::Centroid;
use geo_types::{Coord, Polygon};

use super::fields::resolve_field;
use super::geometry::{map_polygon, points_of, polygons_of};
use super::models::load_model;
use super::{to_target, InputError, Opened};
use crate::model::{Dataset, LandmarkRecord, LayerInfo, Model, Skipped};
use crate::params::Params;

/// A record as read, before its model is loaded.
struct Raw {
    id: String,
    record: usize,
    /// Where it stands and its polygon, or why it has no usable place.
    place: Result<(Coord<f64>, Option<Polygon<f64>>), String>,
    /// The record's attribute `name` (trimmed; "" when missing).
    attrs: BTreeMap<String, String>,
}

/// The landmarks of a point or polygon shapefile.
pub(super) fn read_landmark_shapes(
    dir: &Path,
    params: &Params,
    o: &Opened,
    target: &Option<super::crs::Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let l = &params.layers.landmarks;
    let fields: Vec<(String, String)> = [
        &l.id_field,
        &l.model_field,
        &l.kind_field,
        &l.rotation_field,
        &l.scale_field,
        &l.z_field,
    ]
    .into_iter()
    .filter_map(|want| {
        resolve_field(want, &o.layer.fields, o.layer.text_encoding)
            .map(|f| (want.clone(), f.to_string()))
    })
    .collect();
    let mut raws = Vec::new();
    for f in &o.layer.features {
        let attrs = fields
            .iter()
            .filter_map(|(want, have)| Some((want.clone(), f.attrs.get(have)?.trim().to_string())))
            .collect::<BTreeMap<_, _>>();
        let id = attrs
            .get(&l.id_field)
            .filter(|v| !v.is_empty())
            .cloned()
            .unwrap_or_else(|| (f.record + 1).to_string());
        let place = match points_of(&f.shape) {
            Ok(points) => point_place(o, target, points),
            Err(_) => {
                let read = polygons_of(&f.shape)
                    .map_err(|kind| o.wrong_shape(f.record, kind, "points or polygons"))?;
                o.count_winding(read.against_winding);
                polygon_place(o, target, read.polygons)
            }
        };
        raws.push(Raw {
            id,
            record: f.record,
            place,
            attrs,
        });
    }
    finish(dir, params, &o.file, raws, data);
    Ok(())
}

/// The first point of a record, in the output CRS.
fn point_place(
    o: &Opened,
    target: &Option<super::crs::Crs>,
    mut points: Vec<Coord<f64>>,
) -> Result<(Coord<f64>, Option<Polygon<f64>>), String> {
    if points.is_empty() {
        return Err("null shape: the record has no point; place it or delete the record".into());
    }
    to_target(o, target, &mut points[..1])?;
    Ok((points[0], None))
}

/// A polygon record's footprint (its largest part) and its middle, in the output CRS.
fn polygon_place(
    o: &Opened,
    target: &Option<super::crs::Crs>,
    polygons: Vec<Polygon<f64>>,
) -> Result<(Coord<f64>, Option<Polygon<f64>>), String> {
    use geo::Area;
    let mut best: Option<Polygon<f64>> = None;
    for mut p in polygons {
        map_polygon(&mut p, &mut |c| to_target(o, target, c))?;
        if best
            .as_ref()
            .is_none_or(|b| p.unsigned_area() > b.unsigned_area())
        {
            best = Some(p);
        }
    }
    let poly = best.ok_or("null shape: the record has no outline; draw it or delete the record")?;
    let at = poly
        .centroid()
        .ok_or("the outline has no area: draw the landmark's footprint")?;
    Ok((at.0, Some(poly)))
}

/// The landmarks of a CSV or XLSX table (x, y in the output CRS). Rows a table cannot use
/// (a repeated id) are skipped after the others, numbered on from them.
pub(super) fn read_landmark_table(
    dir: &Path,
    params: &Params,
    path: &Path,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let l = &params.layers.landmarks;
    let is_xlsx = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xlsx"));
    let table = match is_xlsx {
        true => super::table::read_xlsx(path, &l.sheet, &l.id_field)?,
        false => super::table::read_csv(path, &l.id_field)?,
    };
    let file = path.display().to_string();
    let columns: Vec<&String> = table.rows.iter().flat_map(|(_, r)| r.keys()).collect();
    for need in [&l.x_field, &l.y_field] {
        if !table.rows.is_empty() && !columns.contains(&need) {
            return Err(InputError::Table {
                file: file.clone(),
                message: format!(
                    "no column `{need}`: set `layers.landmarks.x_field` / `y_field` to the \
                     columns of the coordinates (output CRS)"
                ),
            });
        }
    }
    let mut raws = Vec::new();
    for (record, (id, row)) in table.rows.iter().enumerate() {
        let num = |k: &str| row.get(k).and_then(|v| v.trim().parse::<f64>().ok());
        let place = match (num(&l.x_field), num(&l.y_field)) {
            (Some(x), Some(y)) if x.is_finite() && y.is_finite() => Ok((Coord { x, y }, None)),
            _ => Err(format!(
                "`{}`, `{}` are not numbers: give the landmark's coordinates",
                l.x_field, l.y_field
            )),
        };
        raws.push(Raw {
            id: id.clone(),
            record,
            place,
            attrs: row.clone(),
        });
    }
    let rows = raws.len();
    for (k, (row, id, why)) in table.unusable.iter().enumerate() {
        data.skipped.push(Skipped {
            layer: "landmarks".into(),
            file: file.clone(),
            id: id.clone(),
            record: Some(rows + k),
            reason: format!("row {row}: {why}"),
        });
    }
    data.warnings.extend(table.warnings.iter().cloned());
    data.layers.push(LayerInfo {
        role: "landmarks".into(),
        file: file.clone(),
        features: rows + table.unusable.len(),
        encoding: if is_xlsx { "XLSX" } else { "UTF-8 (CSV)" }.into(),
        crs: "the output CRS (a table's x, y)".into(),
        reprojected: false,
        vertices_before: 0,
        vertices_after: 0,
    });
    finish(dir, params, &file, raws, data);
    Ok(())
}

/// Where model files are looked up.
pub fn models_dir(input: &Path, params: &Params) -> PathBuf {
    match params.landmarks.models_dir.trim() {
        "" => input.to_path_buf(),
        d => PathBuf::from(d),
    }
}

/// Loads each record's model (each file once) and keeps the record, or skips it with why.
fn finish(dir: &Path, params: &Params, file: &str, raws: Vec<Raw>, data: &mut Dataset) {
    let l = &params.layers.landmarks;
    let models_dir = models_dir(dir, params);
    // Model files, and every file they name, are read only inside the input directory and
    // the models directory the parameter file names.
    let confined = crate::bounded::Confined::new(
        [dir, models_dir.as_path()],
        "the directories a build reads (the input directory, or landmarks.models_dir)",
    );
    let mut loaded: BTreeMap<String, Result<Arc<Model>, String>> = BTreeMap::new();
    let mut seen = std::collections::HashSet::new();
    let city = data.city_box();
    for raw in raws {
        let get = |k: &str| raw.attrs.get(k).map(String::as_str).unwrap_or("");
        let number = |k: &str, default: f64| -> Result<f64, String> {
            match get(k) {
                "" => Ok(default),
                v => v
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("`{k}` = `{v}` is not a number")),
            }
        };
        let result = (|| -> Result<LandmarkRecord, String> {
            if !seen.insert(raw.id.clone()) {
                return Err(
                    "duplicate id: an earlier landmark has it; give this one its own \
                            (its object is `landmark_<id>`)"
                        .into(),
                );
            }
            let (at, footprint) = raw.place.clone()?;
            if let Some(why) = super::geometry::beyond_city(at, city) {
                return Err(why);
            }
            let model = match (get(&l.model_field), get(&l.kind_field)) {
                ("", "") => {
                    return Err(format!(
                        "no model: neither `{}` nor `{}` is given; name the model file, or a \
                         kind that [landmarks.models] maps to one",
                        l.model_field, l.kind_field
                    ))
                }
                ("", kind) => params.landmarks.models.get(kind).cloned().ok_or_else(|| {
                    format!(
                        "kind `{kind}` has no model: add it to [landmarks.models] (kinds mapped: \
                         {})",
                        mapped(params)
                    )
                })?,
                (m, _) => m.to_string(),
            };
            let rotation = number(&l.rotation_field, 0.0)?;
            let scale = number(&l.scale_field, 1.0)?;
            if scale <= 0.0 {
                return Err(format!(
                    "`{}` = {}: a scale is above 0",
                    l.scale_field,
                    crate::model::number::Num(scale)
                ));
            }
            let z = match get(&l.z_field) {
                "" => None,
                _ => Some(number(&l.z_field, 0.0)?),
            };
            let m = loaded.entry(model.clone()).or_insert_with(|| {
                let mut notes = Vec::new();
                let r = load_model(&models_dir.join(&model), &model, &confined, &mut notes)
                    .map(Arc::new);
                for n in notes {
                    data.warnings
                        .push(crate::model::Warning::layer("landmarks", file, n));
                }
                r
            });
            m.clone()?;
            Ok(LandmarkRecord {
                id: raw.id.clone(),
                record: raw.record,
                at,
                footprint,
                model,
                rotation,
                scale,
                z,
            })
        })();
        match result {
            Ok(r) => data.landmarks.push(r),
            Err(reason) => data.skipped.push(Skipped {
                layer: "landmarks".into(),
                file: file.to_string(),
                id: raw.id,
                record: Some(raw.record),
                reason,
            }),
        }
    }
    data.models = loaded
        .into_iter()
        .filter_map(|(k, m)| Some((k, m.ok()?)))
        .collect();
}

/// The kinds `[landmarks.models]` maps, for a message.
fn mapped(params: &Params) -> String {
    let kinds: Vec<&str> = params.landmarks.models.keys().map(String::as_str).collect();
    match kinds.is_empty() {
        true => "none".into(),
        false => kinds.join(", "),
    }
}
