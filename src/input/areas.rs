//! The gardens and water layers: polygons where the user has drawn a rock garden's ground,
//! or a river or pond. Every part
//! of a multipart record is an area of its own (`<id>-<n>`); a record without a usable
//! outline is skipped with the reason.

use std::collections::HashSet;

use super::crs::Crs;
use super::fields::resolve_field;
use super::geometry::polygons_of;
use super::polygons::checked_parts;
use super::{InputError, Opened};
use crate::model::{Dataset, GardenArea};
use crate::params::Params;

/// Reads every polygon of the gardens layer into `data.gardens`.
pub(super) fn read_garden_areas(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    data.gardens = read_areas(
        &params.layers.gardens.id_field,
        "the garden's outline",
        o,
        target,
        data,
    )?;
    Ok(())
}

/// Reads every polygon of the water layer into `data.water`.
pub(super) fn read_water(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    data.water = read_areas(
        &params.layers.water.id_field,
        "the water's outline",
        o,
        target,
        data,
    )?;
    Ok(())
}

/// Every polygon of a layer whose features need only an id, each part an area of its own.
fn read_areas(
    id_field: &str,
    what: &str,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<Vec<GardenArea>, InputError> {
    let mut out = Vec::new();
    let id_field = resolve_field(id_field, &o.layer.fields, o.layer.text_encoding);
    let mut seen = HashSet::new();
    for f in &o.layer.features {
        let read =
            polygons_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "polygons"))?;
        o.count_winding(read.against_winding);
        if read.polygons.is_empty() {
            data.skipped.push(super::null_shape(o, f.record, what));
            continue;
        }
        let id = id_field
            .and_then(|k| f.attrs.get(k))
            .map(|v| v.trim().to_string())
            .filter(|v| !v.is_empty())
            .unwrap_or_else(|| (f.record + 1).to_string());
        let parts = checked_parts(
            o,
            target,
            read.polygons,
            &id,
            f.record,
            &mut seen,
            (&mut data.skipped, &mut data.skipped_shapes),
        );
        for (id, outline) in parts {
            out.push(GardenArea {
                id,
                record: f.record,
                outline,
            });
        }
    }
    Ok(out)
}
