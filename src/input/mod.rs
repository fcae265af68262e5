//! Stage 1: read the input directory into a [`Dataset`].
//!
//! Every role (lots, blocks, streets, street widths, footprints) is a shapefile the parameter
//! file points at, with its fields mapped by name. All coordinates are brought into one
//! projected CRS (see [`crs`]). Layer problems that make the build meaningless (a lots layer
//! of points, a `.dbf` that does not match its `.shp`, an unreadable `.prj`) are errors;
//! problems with single features skip that feature with a reason, and the rest is built.

pub mod crs;
pub mod dem;
pub mod fields;
pub mod geometry;
mod points;
pub mod shp;
pub mod simplify;
pub mod table;
pub mod widths;

use std::collections::{HashMap, HashSet};
use std::path::Path;

use geo_types::{Coord, LineString};
use thiserror::Error;

use crate::model::{
    Dataset, FenceLine, Footprint, LayerInfo, Lot, LotUse, Skipped, Street, TableJoin,
};
use crate::params::Params;
use crs::Crs;
use fields::{resolve_field, AttributeRule};
use geometry::{check_polygon, lines_of, map_polygon, polygons_of};

#[derive(Debug, Error)]
pub enum InputError {
    #[error("{file}: {message}")]
    Layer { file: String, message: String },
    #[error("attribute table {file}: {message}")]
    Table { file: String, message: String },
    #[error("{0}")]
    Missing(String),
}

/// A layer as opened, with the CRS its coordinates are in.
struct Opened {
    role: &'static str,
    layer: shp::Layer,
    src: Option<Crs>,
    /// Whether `src` differs from the output CRS (decided once: comparing per polygon cost
    /// a fifth of the read stage).
    reproject: bool,
    file: String,
}

impl Opened {
    /// The layer's field that `wanted` names (see [`resolve_field`]), or an error listing the
    /// layer's fields and the parameter `key` that sets the name.
    fn required_field(&self, wanted: &str, what: &str, key: &str) -> Result<String, InputError> {
        resolve_field(wanted, &self.layer.fields, self.layer.text_encoding)
            .map(String::from)
            .ok_or_else(|| InputError::Layer {
                file: self.file.clone(),
                message: format!(
                    "no {what} field `{wanted}` (fields: {}); set `{key}`",
                    self.layer.fields.join(", ")
                ),
            })
    }
}

/// Opens a role's layer. `None` when the role is switched off (`file = ""`) or when an
/// optional role's default file is not there.
fn open(
    dir: &Path,
    role: &'static str,
    file: &str,
    encoding: &str,
    default_file: &str,
) -> Result<Option<Opened>, InputError> {
    if file.trim().is_empty() {
        return Ok(None);
    }
    let path = dir.join(file);
    if !path.exists() {
        if file == default_file && role != "lots" {
            return Ok(None);
        }
        return Err(InputError::Missing(format!(
            "no {role} layer: {} does not exist (set `layers.{role}.file` in the parameter file \
             to the right path, or to \"\" if there is no such layer)",
            path.display()
        )));
    }
    let layer = shp::read_layer(&path, encoding)?;
    Ok(Some(Opened {
        role,
        file: path.display().to_string(),
        layer,
        src: None,
        reproject: false,
    }))
}

/// Every coordinate of a layer, for choosing a CRS and spotting degrees.
fn layer_coords(o: &Opened) -> Vec<Coord<f64>> {
    let mut out = Vec::new();
    for f in &o.layer.features {
        if let Ok((polys, _)) = polygons_of(&f.shape) {
            for p in polys {
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
fn degrees_in_metres(o: &Opened, params: &Params, warnings: &mut Vec<String>) {
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
            Some(_) => "its .prj".to_string(),
            None => format!("`crs` = {}", params.crs),
        };
        warnings.push(format!(
            "{}: every coordinate lies within +-180 / +-90, like longitude/latitude in degrees, \
             but {source} says projected metres ({}); if they are degrees, replace the .prj \
             with a WGS84 one or remove it",
            o.file, said.definition
        ));
    }
}

/// Chooses the output CRS and the CRS of every layer, with warnings for what was assumed.
fn resolve_crs(
    params: &Params,
    layers: &mut [&mut Opened],
    warnings: &mut Vec<String>,
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
            Some(wkt) => Some(Crs::from_wkt(wkt).map_err(|m| InputError::Layer {
                file: o.file.replace(".shp", ".prj"),
                message: format!("{m}; fix the .prj or remove it and set `crs`"),
            })?),
            None if !params.crs.trim().is_empty() => {
                warnings.push(format!(
                    "{}: no .prj; its coordinates are taken to be in `crs` = {}",
                    o.file, params.crs
                ));
                Crs::from_user(&params.crs).ok()
            }
            None if crs::looks_like_degrees(layer_coords(o)) => {
                warnings.push(format!(
                    "{}: no .prj, and every coordinate looks like longitude/latitude in degrees; \
                     read as WGS84 degrees (add a .prj or set `crs` if that is wrong)",
                    o.file
                ));
                Crs::from_user("EPSG:4326").ok()
            }
            None => {
                warnings.push(format!(
                    "{}: no .prj; its coordinates are taken as projected metres in the output CRS",
                    o.file
                ));
                None
            }
        };
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
                    warnings.push(format!(
                        "{} is in longitude/latitude; the city is built in {} (set `crs` to choose)",
                        o.file, utm.definition
                    ));
                    Some(utm)
                }
                None => None,
            };
        }
    }
    Ok(target)
}

/// Reprojects a layer's feature geometry as it is converted.
fn to_target(o: &Opened, target: &Option<Crs>, coords: &mut [Coord<f64>]) -> Result<(), String> {
    match (&o.src, target) {
        (Some(src), Some(dst)) if o.reproject => crs::reproject(coords, src, dst),
        _ => Ok(()),
    }
}

/// Reads every layer the parameter file maps, as one dataset in one CRS.
pub fn read_dataset(dir: &Path, params: &Params) -> Result<Dataset, InputError> {
    if !dir.is_dir() {
        return Err(InputError::Missing(format!(
            "input directory {} does not exist or is not a directory",
            dir.display()
        )));
    }
    let defaults = Params::default();
    let l = &params.layers;
    let dl = &defaults.layers;
    let mut lots = open(dir, "lots", &l.lots.file, &l.lots.encoding, &dl.lots.file)?;
    let mut footprints = open(
        dir,
        "footprints",
        &l.footprints.file,
        &l.footprints.encoding,
        "",
    )?;
    let mut streets = open(
        dir,
        "streets",
        &l.streets.file,
        &l.streets.encoding,
        &dl.streets.file,
    )?;
    let mut blocks = open(
        dir,
        "blocks",
        &l.blocks.file,
        &l.blocks.encoding,
        &dl.blocks.file,
    )?;
    let mut widths = open(
        dir,
        "street_widths",
        &l.street_widths.file,
        &l.street_widths.encoding,
        "",
    )?;
    let mut districts = open(
        dir,
        "districts",
        &l.districts.file,
        &l.districts.encoding,
        "",
    )?;
    let mut fences = open(
        dir,
        "fences",
        &l.fences.file,
        &l.fences.encoding,
        &dl.fences.file,
    )?;
    let mut people = open(
        dir,
        "people",
        &l.people.file,
        &l.people.encoding,
        &dl.people.file,
    )?;
    let mut trees = open(
        dir,
        "trees",
        &l.trees.file,
        &l.trees.encoding,
        &dl.trees.file,
    )?;

    let mut data = Dataset::default();
    let target = {
        let mut all: Vec<&mut Opened> = [
            &mut lots,
            &mut footprints,
            &mut streets,
            &mut blocks,
            &mut widths,
            &mut districts,
            &mut fences,
            &mut people,
            &mut trees,
        ]
        .into_iter()
        .filter_map(|o| o.as_mut())
        .collect();
        resolve_crs(params, &mut all, &mut data.warnings)?
    };
    for o in [
        &mut lots,
        &mut footprints,
        &mut streets,
        &mut blocks,
        &mut widths,
        &mut districts,
        &mut fences,
        &mut people,
        &mut trees,
    ]
    .into_iter()
    .flatten()
    {
        o.reproject = matches!((&o.src, &target), (Some(s), Some(t)) if !s.same_as(t));
    }
    data.crs = target
        .as_ref()
        .map(|c| c.definition.clone())
        .unwrap_or_default();
    for o in [
        &lots,
        &footprints,
        &streets,
        &blocks,
        &widths,
        &fences,
        &people,
        &trees,
    ]
    .into_iter()
    .flatten()
    {
        data.warnings.extend(o.layer.warnings.iter().cloned());
        data.layers.push(LayerInfo {
            role: o.role.into(),
            file: o.file.clone(),
            features: o.layer.features.len(),
            encoding: o.layer.encoding.clone(),
            crs: o
                .src
                .as_ref()
                .map(|c| c.definition.clone())
                .unwrap_or_else(|| "unknown (no .prj)".into()),
            reprojected: o.reproject,
            vertices_before: 0,
            vertices_after: 0,
        });
    }

    if let Some(o) = &mut lots {
        data.crs_wkt = o.layer.prj.clone();
        read_lots(dir, params, o, &target, &mut data)?;
    }
    if let Some(o) = &footprints {
        if data.crs_wkt.is_none() {
            data.crs_wkt = o.layer.prj.clone();
        }
        read_footprints(params, o, &target, &mut data)?;
    }
    if let Some(o) = &blocks {
        for f in &o.layer.features {
            let (polys, _) = polygons_of(&f.shape).map_err(|kind| InputError::Layer {
                file: o.file.clone(),
                message: format!(
                    "record {} is a {kind}; the blocks layer must hold polygons",
                    f.record
                ),
            })?;
            for mut p in polys {
                map_polygon(&mut p, &mut |c| to_target(o, &target, c)).map_err(|m| {
                    InputError::Layer {
                        file: o.file.clone(),
                        message: m,
                    }
                })?;
                data.blocks.push(p);
            }
        }
    }
    if let Some(o) = &streets {
        read_streets(params, o, &target, widths.as_ref(), &mut data)?;
    }
    if let Some(o) = &districts {
        assign_districts(params, o, &target, &mut data)?;
    }
    let something = !data.lots.is_empty() || !data.footprints.is_empty();
    if !something {
        data.warnings.push(
            "no lots and no footprints were read: there is nothing to build (set `layers.lots.file` \
             or `layers.footprints.file`)"
                .into(),
        );
    } else if data.blocks.is_empty() && data.streets.is_empty() {
        return Err(InputError::Missing(format!(
            "no street edges: neither a blocks layer ({}) nor a streets layer ({}) was read; the \
             frontage of each lot is found from its distance to the street, so one of them is needed",
            dir.join(&l.blocks.file).display(),
            dir.join(&l.streets.file).display()
        )));
    }
    if let Some(o) = &fences {
        read_fence_lines(params, o, &target, &mut data)?;
    }
    for (o, settings, slot) in [
        (&people, &l.people, &mut data.people),
        (&trees, &l.trees, &mut data.trees),
    ] {
        if let Some(o) = o {
            *slot = Some(points::read_points(
                settings,
                o,
                &target,
                &mut data.skipped,
                &mut data.warnings,
            )?);
        }
    }
    data.dem = read_dem(dir, params, &target, &dl.dem.file)?;
    simplify::generalise(&mut data, &params.simplify);
    Ok(data)
}

/// The rule for one attribute of a layer: its field (if the layer has it), constant, values.
#[allow(clippy::too_many_arguments)]
fn rule(
    o: &Opened,
    extra_fields: &[String],
    attr: &str,
    field: &str,
    default_field: &str,
    values: &std::collections::BTreeMap<String, std::collections::BTreeMap<String, String>>,
    constants: &std::collections::BTreeMap<String, String>,
    warnings: &mut Vec<String>,
) -> AttributeRule {
    let resolved = resolve_field(field, &o.layer.fields, o.layer.text_encoding)
        .or_else(|| resolve_field(field, extra_fields, None))
        .map(String::from);
    if resolved.is_none() && !field.is_empty() && field != default_field {
        warnings.push(format!(
            "{}: no field `{field}` for `{attr}` (fields: {}); the attribute is left empty",
            o.file,
            o.layer.fields.join(", ")
        ));
    }
    AttributeRule {
        field: resolved,
        constant: constants.get(attr).cloned(),
        values: values.get(attr).cloned().unwrap_or_default(),
    }
}

fn read_lots(
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
            &mut data.skipped,
        );
        let count = parts.len();
        let mut record_attrs = Some(f.attrs);
        for (part, (id, poly)) in parts.into_iter().enumerate() {
            // The last part takes the record's attributes; earlier parts get a copy.
            let mut attrs = if part + 1 == count {
                record_attrs.take().unwrap_or_default()
            } else {
                record_attrs.clone().unwrap_or_default()
            };
            attrs.insert("\u{0}base_id".into(), base_id.clone());
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
    if let Some(t) = table {
        data.joins
            .push(join(&mut lots, t, "lots", &mut data.skipped));
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
        lot.attrs.remove("\u{0}base_id");
    }
    if bad_ground > 0 {
        data.warnings.push(format!(
            "{}: {bad_ground} lot(s) have a `{}` that is not a number; they stand on the \
             lowest Z of their outline, else 0",
            o.file, lp.fields.ground
        ));
    }
    data.lots = lots;
    Ok(())
}

fn read_footprints(
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
    let number = |r: &AttributeRule, a| {
        let raw = r.value(a)?;
        let n = raw
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0);
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
        let h = number(&height, &f.attrs)
            .or_else(|| number(&storeys, &f.attrs).map(|s| s * fp.storey_height + 1.0))
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
            &mut data.skipped,
        ) {
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
        data.warnings.push(format!(
            "{}: {n} footprint(s) have a `{field}` that is not a positive number; their \
             height came from the next source (height, storeys x storey_height, default_height)",
            o.file
        ));
    }
    Ok(())
}

/// The DEM, if there is one; its `.prj`, if any, must name the output CRS.
fn read_dem(
    dir: &Path,
    params: &Params,
    target: &Option<Crs>,
    default_file: &str,
) -> Result<Option<dem::Dem>, InputError> {
    let file = params.layers.dem.file.trim();
    if file.is_empty() {
        return Ok(None);
    }
    let mut path = dir.join(file);
    if !path.exists() {
        // The default name also finds a GeoTIFF of the same stem.
        let tif = path.with_extension("tif");
        if file == default_file && tif.exists() {
            path = tif;
        } else if file == default_file {
            return Ok(None);
        } else {
            return Err(InputError::Missing(format!(
                "no DEM: {} does not exist (set `layers.dem.file` to the right path, or to \"\")",
                path.display()
            )));
        }
    }
    let prj = path.with_extension("prj");
    if let (Ok(wkt), Some(t)) = (std::fs::read_to_string(&prj), target) {
        let own = Crs::from_wkt(&wkt).map_err(|m| InputError::Layer {
            file: prj.display().to_string(),
            message: m,
        })?;
        if !own.same_as(t) {
            return Err(InputError::Layer {
                file: path.display().to_string(),
                message: format!(
                    "the DEM is in {} but the city is built in {}: reproject the DEM (for \
                     example with gdalwarp) to the output CRS",
                    own.definition, t.definition
                ),
            });
        }
    }
    Ok(Some(dem::Dem::read(&path)?))
}

/// Free-standing fence lines: each part of each polyline, with the feature's attributes.
fn read_fence_lines(
    params: &Params,
    o: &Opened,
    target: &Option<Crs>,
    data: &mut Dataset,
) -> Result<(), InputError> {
    let fp = &params.layers.fences;
    let id_field = resolve_field(&fp.id_field, &o.layer.fields, o.layer.text_encoding);
    for f in &o.layer.features {
        let lines = lines_of(&f.shape).map_err(|kind| InputError::Layer {
            file: o.file.clone(),
            message: format!(
                "record {} is a {kind}; the fences layer must hold polylines",
                f.record
            ),
        })?;
        let id = id_field
            .and_then(|k| f.attrs.get(k))
            .map(|v| v.trim().to_string())
            .filter(|v| !v.is_empty())
            .unwrap_or_else(|| (f.record + 1).to_string());
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

fn read_streets(
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
        let lines = lines_of(&f.shape).map_err(|kind| InputError::Layer {
            file: o.file.clone(),
            message: format!(
                "record {} is a {kind}; the streets layer must hold polylines",
                f.record
            ),
        })?;
        let width = match width_field
            .and_then(|wf| f.attrs.get(wf))
            .map(|w| w.parse::<f64>())
        {
            Some(Ok(w)) if w.is_finite() && w > 0.0 => w,
            Some(_) => {
                bad_width += 1;
                sp.default_width
            }
            None => sp.default_width,
        };
        for mut line in lines {
            if line.0.len() >= 2
                && line.0.iter().all(|c| c.x.is_finite() && c.y.is_finite())
                && to_target(o, target, &mut line.0).is_ok()
            {
                streets.push(Street {
                    id: f.record.to_string(),
                    line,
                    width,
                });
            }
        }
    }
    if bad_width > 0 {
        data.warnings.push(format!(
            "{}: {bad_width} street(s) have no usable `{}`; they get the default width {} m",
            o.file, sp.width_field, sp.default_width
        ));
    }
    if let Some(wl) = widths {
        let wp = &params.layers.street_widths;
        let field =
            wl.required_field(&wp.width_field, "width", "layers.street_widths.width_field")?;
        let mut lines: Vec<(LineString<f64>, f64)> = Vec::new();
        for f in &wl.layer.features {
            let Some(w) = f.attrs.get(&field).and_then(|v| v.parse::<f64>().ok()) else {
                continue;
            };
            if !(w.is_finite() && w > 0.0) {
                continue;
            }
            for mut line in lines_of(&f.shape).unwrap_or_default() {
                if to_target(wl, target, &mut line.0).is_ok() {
                    lines.push((line, w));
                }
            }
        }
        let (pieces, matched) = widths::apply_widths(streets, &lines, wp.max_distance);
        data.warnings.push(format!(
            "{}: {matched} of {} street pieces took their width from {}",
            o.file,
            pieces.len(),
            wl.file
        ));
        streets = pieces;
    }
    data.streets = streets;
    Ok(())
}

/// Gives every lot and footprint without a district the district holding its centroid.
fn assign_districts(
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
        let (parts, _) = polygons_of(&f.shape).map_err(|kind| InputError::Layer {
            file: o.file.clone(),
            message: format!(
                "record {} is a {kind}; the districts layer must hold polygons",
                f.record
            ),
        })?;
        let id = f.attrs.get(&field).cloned().unwrap_or_default();
        for mut p in parts {
            if map_polygon(&mut p, &mut |c| to_target(o, target, c)).is_ok() && !id.is_empty() {
                if let Some(bb) = p.bounding_rect() {
                    polys.push((bb, p, id.clone()));
                }
            }
        }
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
        data.warnings.push(format!(
            "{}: {outside} lot(s) or footprint(s) lie in no district polygon and have no district",
            o.file
        ));
    }
    Ok(())
}

/// A record's polygons, lowest Z and id. A shape that is not a polygon stops the build (the
/// layer is the wrong one); a record without an id is skipped (`None`).
type RecordPolygons = (Vec<geo_types::Polygon<f64>>, Option<f64>, String);

fn record_polygons(
    o: &Opened,
    f: &shp::Feature,
    id_field: &str,
    skipped: &mut Vec<Skipped>,
) -> Result<Option<RecordPolygons>, InputError> {
    let (polys, z) = polygons_of(&f.shape).map_err(|kind| InputError::Layer {
        file: o.file.clone(),
        message: match kind {
            "multipatch" => format!(
                "record {} is a MultiPatch (3D surfaces); edo-city builds from 2D polygons: \
                 export the {} as Polygon/PolygonZ",
                f.record, o.role
            ),
            _ => format!(
                "record {} is a {kind}; the {} layer must hold polygons",
                f.record, o.role
            ),
        },
    })?;
    let id = f.attrs.get(id_field).cloned().unwrap_or_default();
    if id.is_empty() {
        skipped.push(Skipped {
            layer: o.role.into(),
            file: o.file.clone(),
            id: format!("record {}", f.record),
            reason: format!("no value in the id field `{id_field}`"),
        });
        return Ok(None);
    }
    Ok(Some((polys, z, id)))
}

/// The usable parts of one record's polygons, each with its id: a multipart record becomes one
/// feature per part, ids suffixed `-<n>` so every id stays unique and traceable to its record.
/// Each part is reprojected, then checked (the area check is in metres); a bad part or a
/// repeated id is skipped with the reason.
fn checked_parts(
    o: &Opened,
    target: &Option<Crs>,
    polys: Vec<geo_types::Polygon<f64>>,
    base_id: &str,
    record: usize,
    seen: &mut HashSet<String>,
    skipped: &mut Vec<Skipped>,
) -> Vec<(String, geo_types::Polygon<f64>)> {
    let multi = polys.len() > 1;
    let mut out = Vec::with_capacity(polys.len());
    for (part, mut poly) in polys.into_iter().enumerate() {
        let id = if multi {
            format!("{base_id}-{}", part + 1)
        } else {
            base_id.to_string()
        };
        let reason = map_polygon(&mut poly, &mut |c| to_target(o, target, c))
            .and_then(|_| check_polygon(&poly))
            .err()
            .or_else(|| {
                (!seen.insert(id.clone())).then(|| {
                    format!("duplicate id: record {record} repeats an earlier feature's id")
                })
            });
        match reason {
            Some(reason) => skipped.push(Skipped {
                layer: o.role.into(),
                file: o.file.clone(),
                id,
                reason,
            }),
            None => out.push((id, poly)),
        }
    }
    out
}

/// "lot" for "lots": how a feature of the layer is called in messages.
fn singular(layer: &str) -> &str {
    layer.strip_suffix('s').unwrap_or(layer)
}

/// Applies a table to the lots by id, table values winning; returns the match counts. A row
/// with no lot is skipped and reported.
fn join(
    lots: &mut [Lot],
    table: table::Table,
    layer: &str,
    skipped: &mut Vec<Skipped>,
) -> TableJoin {
    let mut index: HashMap<String, Vec<usize>> = HashMap::new();
    for (i, lot) in lots.iter().enumerate() {
        // Parts of a multipart lot share their record's id; a row applies to all of them.
        let base = lot.attrs.get("\u{0}base_id").cloned().unwrap_or_default();
        index.entry(base.clone()).or_default().push(i);
        if lot.id != base {
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
                skipped.push(Skipped {
                    layer: format!("{layer} table"),
                    file: table.file.clone(),
                    id: id.clone(),
                    reason: format!("no {} has this id; the row was not used", singular(layer)),
                });
                if out.rows_without_feature_ids.len() < 20 {
                    out.rows_without_feature_ids.push(id);
                }
            }
        }
    }
    out.features_without_row = matched_lots.iter().filter(|m| !**m).count();
    out
}
