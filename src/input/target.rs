//! Which CRS the output is in, and what each layer's coordinates are taken to be in: the
//! parameter file's `crs`, else the lots' own `.prj`, else the UTM zone of their centre; a
//! layer without a `.prj`, or whose numbers look like degrees under one that says metres, is
//! assumed with a warning.

use geo_types::Coord;

use super::crs::{self, Crs};
use super::geometry::{self, lines_of, polygons_of};
use super::{InputError, Opened};
use crate::params::Params;

/// Every coordinate of a layer, for choosing a CRS and spotting degrees.
pub(super) fn layer_coords(o: &Opened) -> Vec<Coord<f64>> {
    let mut out = Vec::new();
    for f in &o.layer.features {
        if let Ok(read) = polygons_of(&f.shape) {
            for p in read.polygons {
                out.extend(p.exterior().0.iter().copied());
            }
        } else if let Ok(lines) = lines_of(&f.shape) {
            for l in lines {
                out.extend(l.0);
            }
        } else if let Ok(points) = geometry::points_of(&f.shape) {
            out.extend(points);
        }
    }
    out
}

/// Warns when a layer said to be in projected metres (by its `.prj` or by `crs`) has every
/// coordinate within +-180 / +-90, as longitude/latitude degrees would be: a town that small
/// around a CRS's origin is rare, a `.prj` copied from the wrong file is not.
pub(super) fn degrees_in_metres(
    o: &Opened,
    params: &Params,
    warnings: &mut Vec<crate::model::Warning>,
) {
    let said = match &o.layer.prj {
        Some(wkt) => Crs::from_wkt(wkt).ok(),
        None => Crs::from_user(&params.crs).ok(),
    };
    let Some(said) = said.filter(|c| !c.is_geographic()) else {
        return;
    };
    let coords = layer_coords(o);
    if !coords.is_empty() && crs::looks_like_degrees(coords) {
        let source = match o.layer.prj {
            Some(_) => format!("its {}", said_by(o)),
            None => format!("`crs` = {}", params.crs),
        };
        warnings.push(crate::model::Warning::layer(
            o.role,
            &o.file,
            format!(
            "{}: every coordinate lies within +-180 / +-90, like longitude/latitude in degrees, \
             but {source} says projected metres ({}); if they are degrees, {}",
            o.file,
            said.definition,
            match is_shapefile(o) {
                true => "replace the .prj with a WGS84 one or remove it",
                false => "assign the layer WGS84 in QGIS (Layer > Assign Projection) and save it again",
            }
        ),
        ));
    }
}

/// Whether the layer is a shapefile (its CRS in a `.prj` beside it).
fn is_shapefile(o: &Opened) -> bool {
    super::layers::Format::of(&o.layer.path) == super::layers::Format::Shapefile
}

/// What says a layer's CRS, for a message: a shapefile's `.prj`, a GeoPackage's spatial
/// reference, GeoJSON's CRS, a FlatGeobuf header.
fn said_by(o: &Opened) -> &'static str {
    use super::layers::Format;
    match Format::of(&o.layer.path) {
        Format::Shapefile => ".prj",
        Format::GeoPackage => "GeoPackage spatial reference",
        Format::GeoJson => "CRS (RFC 7946: longitude/latitude, or the `crs` member)",
        Format::FlatGeobuf => "header's CRS",
    }
}

/// Refuses a layer said to be in longitude/latitude (by its `.prj`) whose coordinates go past
/// +-180 / +-90: metres under a degrees `.prj` (one copied from another file) would fail to
/// reproject feature by feature, and the layer would be lost in a list of skips.
fn metres_in_degrees(o: &Opened) -> Result<(), InputError> {
    let Some(src) = o.src.as_ref().filter(|c| c.is_geographic()) else {
        return Ok(());
    };
    let outside = layer_coords(o)
        .into_iter()
        .filter(|c| c.x.is_finite() && c.y.is_finite())
        .find(|c| c.x.abs() > 180.0 + 1e-9 || c.y.abs() > 90.0 + 1e-9);
    match outside {
        None => Ok(()),
        Some(c) => Err(InputError::Layer {
            file: o.file.clone(),
            message: match is_shapefile(o) {
                true => format!(
                    "its .prj says longitude/latitude degrees ({}) but a coordinate is ({}, {}), \
                     far past +-180 / +-90: the numbers are projected metres and the .prj \
                     belongs to another file; put the layer's own .prj beside it, or remove \
                     the .prj and set `crs` to the CRS the numbers are in",
                    src.definition, c.x, c.y
                ),
                false => format!(
                    "its {} says longitude/latitude degrees ({}) but a coordinate is ({}, {}), \
                     far past +-180 / +-90: the numbers are projected metres; assign the layer \
                     the CRS they are in (in QGIS: Layer > Assign Projection) and save it again",
                    said_by(o),
                    src.definition,
                    c.x,
                    c.y
                ),
            },
        }),
    }
}

/// Chooses the output CRS and the CRS of every layer, with warnings for what was assumed.
pub(super) fn resolve_crs(
    params: &Params,
    layers: &mut [&mut Opened],
    warnings: &mut Vec<crate::model::Warning>,
) -> Result<Option<Crs>, InputError> {
    let mut target = None;
    if !params.crs.trim().is_empty() {
        let c = Crs::from_user(&params.crs)
            .map_err(|m| InputError::Missing(format!("parameter `crs`: {m}")))?;
        if c.is_geographic() {
            return Err(InputError::Missing(format!(
                "parameter `crs` = `{}` is geographic (degrees); the output needs a projected CRS in metres",
                params.crs
            )));
        }
        target = Some(c);
    }
    for o in layers.iter_mut() {
        if o.layer.prj.is_some() || !params.crs.trim().is_empty() {
            degrees_in_metres(o, params, warnings);
        }
        o.src = match &o.layer.prj {
            Some(wkt) => Some(Crs::from_wkt(wkt).map_err(|m| match is_shapefile(o) {
                true => InputError::Layer {
                    file: o.file.replace(".shp", ".prj"),
                    message: format!("{m}; fix the .prj or remove it and set `crs`"),
                },
                false => InputError::Layer {
                    file: o.file.clone(),
                    message: format!(
                        "its {}: {m}; assign the layer a CRS edo-city knows (an EPSG code) in \
                         QGIS and save it again",
                        said_by(o)
                    ),
                },
            })?),
            None if !params.crs.trim().is_empty() => {
                warnings.push(
                    crate::model::Warning::layer(
                        o.role,
                        &o.file,
                        format!(
                            "{}: no .prj; its coordinates are taken to be in `crs` = {}",
                            o.file, params.crs
                        ),
                    )
                    .for_key("crs"),
                );
                Crs::from_user(&params.crs).ok()
            }
            None if crs::looks_like_degrees(layer_coords(o)) => {
                warnings.push(crate::model::Warning::layer(
                    o.role,
                    &o.file,
                    format!(
                    "{}: no .prj, and every coordinate looks like longitude/latitude in degrees; \
                     read as WGS84 degrees (add a .prj or set `crs` if that is wrong)",
                    o.file
                ),
                ));
                Crs::from_user("EPSG:4326").ok()
            }
            None => {
                warnings.push(crate::model::Warning::layer(
                    o.role,
                    &o.file,
                    format!(
                    "{}: no .prj; its coordinates are taken as projected metres in the output CRS",
                    o.file
                ),
                ));
                None
            }
        };
        metres_in_degrees(o)?;
    }
    if target.is_none() {
        // The first layer (lots, else footprints, streets, blocks) decides.
        if let Some(o) = layers.first() {
            target = match &o.src {
                Some(c) if !c.is_geographic() => {
                    Crs::from_wkt(o.layer.prj.as_deref().unwrap_or(""))
                        .ok()
                        .or_else(|| Crs::from_user(&c.definition).ok())
                }
                Some(_) => {
                    let pts = layer_coords(o);
                    let n = pts.len().max(1) as f64;
                    let lon = pts.iter().map(|c| c.x).sum::<f64>() / n;
                    let lat = pts.iter().map(|c| c.y).sum::<f64>() / n;
                    let utm = Crs::utm_for(lon, lat);
                    warnings.push(crate::model::Warning::layer(o.role, &o.file, format!(
                        "{} is in longitude/latitude; the city is built in {} (set `crs` to choose)",
                        o.file, utm.definition
                    )).for_key("crs"));
                    Some(utm)
                }
                None => None,
            };
        }
    }
    Ok(target)
}

/// Reprojects a layer's feature geometry as it is converted.
pub(super) fn to_target(
    o: &Opened,
    target: &Option<Crs>,
    coords: &mut [Coord<f64>],
) -> Result<(), String> {
    match (&o.src, target) {
        (Some(src), Some(dst)) if o.reproject => {
            crs::reproject(coords, src, dst).map_err(|e| e.to_string())
        }
        _ => Ok(()),
    }
}
