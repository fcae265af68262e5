//! The line roles: streets (with their widths) and free-standing fence lines.

use geo_types::LineString;

use super::crs::Crs;
use super::fields::resolve_field;
use super::geometry::lines_of;
use super::target::to_target;
use super::{widths, InputError, Opened};
use crate::model::{Dataset, FenceLine, Skipped, Street, MAX_STREET_WIDTH};
use crate::params::Params;

/// Free-standing fence lines: each part of each polyline, with the feature's attributes.
pub(super) fn read_fence_lines(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let fp = &params.layers.fences;
    let id_field = resolve_field(&fp.id_field, &o.layer.fields, o.layer.text_encoding);
    for f in &o.layer.features {
        let lines =
            lines_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "polylines"))?;
        let id = id_field
            .and_then(|k| f.attrs.get(k))
            .map(|v| v.trim().to_string())
            .filter(|v| !v.is_empty())
            .unwrap_or_else(|| (f.record + 1).to_string());
        if lines.is_empty() {
            data.skipped
                .push(super::null_shape(o, f.record, "the line"));
            continue;
        }
        let parts = lines.len();
        for (k, mut line) in lines.into_iter().enumerate() {
            let ok = line.0.len() >= 2
                && line.0.iter().all(|c| c.x.is_finite() && c.y.is_finite())
                && to_target(o, target, &mut line.0).is_ok();
            if !ok {
                data.skipped.push(Skipped {
                    layer: "fences".into(),
                    file: o.file.clone(),
                    id: id.clone(),
                    record: Some(f.record),
                    reason: "a line with fewer than 2 usable points".into(),
                });
                continue;
            }
            data.fence_lines.push(FenceLine {
                id: if parts > 1 {
                    format!("{id}-{}", k + 1)
                } else {
                    id.clone()
                },
                record: f.record,
                line,
                attrs: f.attrs.clone(),
            });
        }
    }
    Ok(())
}

pub(super) fn read_streets(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    widths: Option<&Opened>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let sp = &params.layers.streets;
    let width_field = resolve_field(&sp.width_field, &o.layer.fields, o.layer.text_encoding);
    let mut bad_width = 0usize;
    let mut streets = Vec::new();
    for f in &o.layer.features {
        let lines =
            lines_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "polylines"))?;
        if lines.is_empty() {
            data.skipped
                .push(super::null_shape(o, f.record, "the centreline"));
            continue;
        }
        let width = match width_field
            .and_then(|wf| f.attrs.get(wf))
            .map(|w| w.parse::<f64>())
        {
            Some(Ok(w)) if w.is_finite() && w > 0.0 && w <= MAX_STREET_WIDTH => w,
            Some(_) => {
                bad_width += 1;
                sp.default_width
            }
            None => sp.default_width,
        };
        let mut usable = false;
        for mut line in lines {
            if line.0.len() >= 2
                && line.0.iter().all(|c| c.x.is_finite() && c.y.is_finite())
                && to_target(o, target, &mut line.0).is_ok()
                && line.0.iter().all(|c| crate::model::sane(*c))
            {
                usable = true;
                streets.push(Street {
                    id: f.record.to_string(),
                    line,
                    width,
                });
            }
        }
        o.kept_or_skipped(data, f.record, usable, || {
            "the centreline has fewer than 2 usable points (or a coordinate that is not a \
             finite number within 1e8 m of the CRS's origin): redraw it or delete it"
                .into()
        });
    }
    if bad_width > 0 {
        data.warnings.push(crate::model::Warning::layer(
            o.role,
            &o.file,
            format!(
                "{}: {bad_width} street(s) have a `{}` that is not a number of metres above 0 and \
             up to {MAX_STREET_WIDTH}; they get the default width {} m",
                o.file, sp.width_field, sp.default_width
            ),
        ));
    }
    if let Some(wl) = widths {
        let wp = &params.layers.street_widths;
        let field =
            wl.required_field(&wp.width_field, "width", "layers.street_widths.width_field")?;
        let mut lines: Vec<(LineString<f64>, f64)> = Vec::new();
        for f in &wl.layer.features {
            let w = f
                .attrs
                .get(&field)
                .and_then(|v| v.trim().parse::<f64>().ok());
            let reason = match w {
                Some(w) if w.is_finite() && w > 0.0 && w <= MAX_STREET_WIDTH => None,
                _ => Some(format!(
                    "`{field}` is not a number of metres above 0 and up to {MAX_STREET_WIDTH}: \
                     correct it or delete the line"
                )),
            };
            let mut usable = false;
            if reason.is_none() {
                for mut line in lines_of(&f.shape).unwrap_or_default() {
                    if line.0.len() >= 2 && to_target(wl, target, &mut line.0).is_ok() {
                        usable = true;
                        lines.push((line, w.unwrap_or_default()));
                    }
                }
            }
            wl.kept_or_skipped(data, f.record, usable, || {
                reason.unwrap_or_else(|| {
                    "the line has fewer than 2 usable points (or a null shape): redraw it or \
                     delete it"
                        .into()
                })
            });
        }
        let (pieces, matched) = widths::apply_widths(streets, &lines, wp.max_distance);
        data.warnings.push(crate::model::Warning::layer(
            o.role,
            &o.file,
            format!(
                "{}: {matched} of {} street pieces took their width from {}",
                o.file,
                pieces.len(),
                wl.file
            ),
        ));
        streets = pieces;
    }
    data.streets = streets;
    Ok(())
}
