//! People and trees given as points (`people.shp`, `trees.shp`), section 4.4: where the data
//! records them, they replace the generated ones.

use geo_types::Coord;

use super::fields::resolve_field;
use super::geometry::points_of;
use super::{to_target, InputError, Opened};
use crate::model::{PointFeature, Skipped};
use crate::params::PointsLayer;

/// Every point of the layer with its id, height and texture. A feature that is not a point
/// stops the build (the wrong layer); a point without usable coordinates, or with a height
/// that is not a positive number, is skipped or warned about.
pub(super) fn read_points(
    settings: &PointsLayer,
    o: &Opened,
    target: &Option<super::crs::Crs>,
    skipped: &mut Vec<Skipped>,
    warnings: &mut Vec<crate::model::Warning>,
) -> Result<Vec<PointFeature>, InputError> {
    let field = |name: &str| resolve_field(name, &o.layer.fields, o.layer.text_encoding);
    let (id_field, height_field, texture_field, species_field) = (
        field(&settings.id_field),
        field(&settings.height_field),
        field(&settings.texture_field),
        field(&settings.species_field),
    );
    let mut out = Vec::new();
    for f in &o.layer.features {
        let points = points_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "points"))?;
        let value = |k: Option<&str>| {
            k.and_then(|k| f.attrs.get(k))
                .map(|v| v.trim().to_string())
                .filter(|v| !v.is_empty())
        };
        let id = value(id_field).unwrap_or_else(|| (f.record + 1).to_string());
        let height = match value(height_field) {
            None => None,
            Some(raw) => match raw.parse::<f64>() {
                Ok(h) if h.is_finite() && h > 0.0 && h <= 100.0 => Some(h),
                _ => {
                    warnings.push(crate::model::Warning::feature(
                        o.role,
                        &o.file,
                        &id,
                        format!(
                            "{}: {} {id}: height `{raw}` is not a number of metres above 0 and \
                         up to 100; a height was drawn",
                            o.file, o.role
                        ),
                    ));
                    None
                }
            },
        };
        let texture = value(texture_field);
        let species = value(species_field);
        let parts = points.len();
        for (k, at) in points.into_iter().enumerate() {
            let id = if parts > 1 {
                format!("{id}-{}", k + 1)
            } else {
                id.clone()
            };
            let mut at = [at];
            let ok = at[0].x.is_finite()
                && at[0].y.is_finite()
                && to_target(o, target, &mut at).is_ok()
                && at[0].x.is_finite()
                && at[0].y.is_finite();
            if !ok {
                skipped.push(Skipped {
                    layer: o.role.into(),
                    file: o.file.clone(),
                    id,
                    record: Some(f.record),
                    reason: "the point has no usable coordinates".into(),
                });
                continue;
            }
            let at: Coord<f64> = at[0];
            out.push(PointFeature {
                id,
                record: f.record,
                at,
                height,
                texture: texture.clone(),
                species: species.clone(),
            });
        }
    }
    Ok(out)
}
