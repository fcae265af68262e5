//! Stage 1: read the input directory into a [`Dataset`].
//!
//! Every role (lots, blocks, streets, street widths, footprints) is a shapefile the parameter
//! file points at, with its fields mapped by name. All coordinates are brought into one
//! projected CRS (see [`crs`]). Layer problems that make the build meaningless (a lots layer
//! of points, a `.dbf` that does not match its `.shp`, an unreadable `.prj`) are errors;
//! problems with single features skip that feature with a reason, and the rest is built.

/// Coordinate reference systems (in [`crate::geom::crs`]: the tileset uses them too).
pub use crate::geom::crs;
pub use fgb::read_layer as read_flatgeobuf;
pub use geojson::{looks_like_geojson, read_layer as read_geojson};
pub use landmarks::models_dir;
pub mod dem;
pub mod fields;
pub mod geometry;
mod points;
pub mod shp;
pub mod simplify;
pub mod table;
pub mod widths;

mod areas;
mod designs;
mod features;
mod fgb;
mod geojson;
pub mod gpkg;
mod landmarks;
mod layers;
mod lines;
mod links;
pub mod models;
pub mod overrides;
mod polygons;
mod target;

use layers::{is_table, links_file, null_shape, report_layer, Layers, Opened};
use lines::{read_fence_lines, read_streets};
use polygons::{assign_districts, read_footprints, read_lots};
use target::{resolve_crs, to_target};

use std::collections::HashMap;
use std::path::Path;

use thiserror::Error;

use crate::model::{Dataset, Lot, Skipped, TableJoin};
use crate::params::Params;
use crs::Crs;
use fields::{resolve_field, AttributeRule};
use geometry::{map_polygon, polygons_of};

/// Why the input cannot be read: the build stops before anything is written (exit code 2).
/// Every message names the file and says what to do.
#[derive(Debug, Error)]
pub enum InputError {
    /// A layer (or one of its sidecar files) cannot be used.
    #[error("{file}: {message}")]
    Layer {
        /// The file, as the user named it.
        file: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// An attribute table cannot be joined.
    #[error("attribute table {file}: {message}")]
    Table {
        /// The table's file.
        file: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// Something the build needs is not there (a directory, a layer, street edges).
    #[error("{0}")]
    Missing(String),
}

/// Reads every layer the parameter file maps, as one dataset in one CRS.
pub fn read_dataset(dir: &Path, params: &Params) -> Result<Dataset, InputError> {
    if !dir.is_dir() {
        return Err(InputError::Missing(format!(
            "input directory {} does not exist or is not a directory",
            dir.display()
        )));
    }
    let l = &params.layers;
    let defaults = Params::default();
    let dl = &defaults.layers;
    let mut layers = Layers::open(dir, params, dl)?;
    let mut data = Dataset::default();
    let target = {
        let mut all: Vec<&mut Opened> = layers.all_mut().collect();
        resolve_crs(params, &mut all, &mut data.warnings)?
    };
    for o in layers.all_mut() {
        o.reproject = matches!((&o.src, &target), (Some(s), Some(t)) if !s.same_as(t));
    }
    data.crs = target
        .as_ref()
        .map(|c| c.definition.clone())
        .unwrap_or_default();
    for o in layers.all() {
        report_layer(o, &mut data);
    }
    if let Some(o) = &mut layers.lots {
        data.crs_wkt = o.layer.prj.clone();
        read_lots(dir, params, o, &target, &mut data)?;
    }
    if let Some(o) = &layers.footprints {
        if data.crs_wkt.is_none() {
            data.crs_wkt = o.layer.prj.clone();
        }
        read_footprints(params, o, &target, &mut data)?;
    }
    if let Some(o) = &layers.blocks {
        for f in &o.layer.features {
            let read =
                polygons_of(&f.shape).map_err(|kind| o.wrong_shape(f.record, kind, "polygons"))?;
            o.count_winding(read.against_winding);
            if read.polygons.is_empty() {
                data.skipped.push(null_shape(o, f.record, "its outline"));
            }
            for mut p in read.polygons {
                map_polygon(&mut p, &mut |c| to_target(o, &target, c)).map_err(|m| {
                    InputError::Layer {
                        file: o.file.clone(),
                        message: m,
                    }
                })?;
                data.blocks.push(p);
                o.kept_or_skipped(&mut data, f.record, true, String::new);
            }
        }
    }
    if let Some(o) = &layers.streets {
        read_streets(params, o, &target, layers.widths.as_ref(), &mut data)?;
    }
    if let Some(o) = &layers.districts {
        assign_districts(params, o, &target, &mut data)?;
    }
    let something = !data.lots.is_empty() || !data.footprints.is_empty();
    if !something {
        data.warnings.push(crate::model::Warning::new(
            crate::model::WarningClass::Build,
            "no lots and no footprints were read: there is nothing to build (set `layers.lots.file` \
             or `layers.footprints.file`)"
                .to_string(),
        ));
    } else if data.blocks.is_empty() && data.streets.is_empty() {
        return Err(InputError::Missing(format!(
            "no street edges: neither a blocks layer ({}) nor a streets layer ({}) was read; the \
             frontage of each lot is found from its distance to the street, so one of them is needed",
            dir.join(&l.blocks.file).display(),
            dir.join(&l.streets.file).display()
        )));
    }
    if let Some(o) = &layers.fences {
        read_fence_lines(params, o, &target, &mut data)?;
    }
    for (o, settings, slot) in [
        (&layers.people, &l.people, &mut data.people),
        (&layers.trees, &l.trees, &mut data.trees),
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
    if let Some(o) = &layers.gardens {
        areas::read_garden_areas(params, o, &target, &mut data)?;
    }
    if let Some(o) = &layers.water {
        areas::read_water(params, o, &target, &mut data)?;
    }
    if let Some(o) = &layers.links {
        links::read_link_points(&l.links, o, &target, &mut data)?;
    } else if is_table(&links_file(dir, params, dl)) {
        let path = dir.join(links_file(dir, params, dl));
        if !path.exists() {
            return Err(InputError::Missing(format!(
                "no links table: {} does not exist (set `layers.links.file` to the right path, \
                 or to \"\")",
                path.display()
            )));
        }
        links::read_link_table(&l.links, &path, &mut data)?;
    }
    if let Some(o) = &layers.landmarks {
        landmarks::read_landmark_shapes(dir, params, o, &target, &mut data)?;
    } else if params.landmarks.enabled && is_table(&l.landmarks.file) {
        let path = dir.join(&l.landmarks.file);
        if !path.exists() {
            return Err(InputError::Missing(format!(
                "no landmarks table: {} does not exist (set `layers.landmarks.file` to the right \
                 path, or to \"\")",
                path.display()
            )));
        }
        landmarks::read_landmark_table(dir, params, &path, &mut data)?;
    }
    data.dem = read_dem(dir, params, &target, &dl.dem.file, &mut data.warnings)?;
    designs::read_designs(params, &mut data)?;
    for o in layers.all() {
        data.warnings.extend(o.winding_warning());
    }
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
    warnings: &mut Vec<crate::model::Warning>,
) -> AttributeRule {
    let resolved = resolve_field(field, &o.layer.fields, o.layer.text_encoding)
        .or_else(|| resolve_field(field, extra_fields, None))
        .map(String::from);
    if resolved.is_none() && !field.is_empty() && field != default_field {
        warnings.push(crate::model::Warning::layer(
            o.role,
            &o.file,
            format!(
                "{}: no field `{field}` for `{attr}` (fields: {}); the attribute is left empty",
                o.file,
                o.layer.fields.join(", ")
            ),
        ));
    }
    AttributeRule {
        field: resolved,
        constant: constants.get(attr).cloned(),
        values: values.get(attr).cloned().unwrap_or_default(),
    }
}

/// The DEM, if there is one; its `.prj`, if any, must name the output CRS.
fn read_dem(
    dir: &Path,
    params: &Params,
    target: &Option<Crs>,
    default_file: &str,
    warnings: &mut Vec<crate::model::Warning>,
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
    if let (Ok(wkt), Some(t)) = (crate::bounded::read_text(&prj, 1 << 20), target) {
        let own = Crs::from_wkt(&wkt).map_err(|m| InputError::Layer {
            file: prj.display().to_string(),
            message: m.to_string(),
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
    let dem = dem::read(&path)?;
    if dem.implausible > 0 {
        warnings.push(crate::model::Warning::layer(
            "dem",
            &dem.file,
            format!(
                "{}: {} cell(s) hold a number no ground has (outside {}..{} m, such as an \
             undeclared no-data value like -3.4e38); they are read as NODATA: declare the \
             value (NODATA_value, or GDAL's no-data tag) to silence this",
                dem.file,
                dem.implausible,
                crate::model::ELEVATION_RANGE.start(),
                crate::model::ELEVATION_RANGE.end()
            ),
        ));
    }
    Ok(Some(dem))
}

/// "lot" for "lots": how a feature of the layer is called in messages.
fn singular(layer: &str) -> &str {
    layer.strip_suffix('s').unwrap_or(layer)
}

/// Applies a table to the lots by id, table values winning; returns the match counts. A row
/// with no lot is skipped and reported. `base_ids` holds each lot's record id.
fn join(
    lots: &mut [Lot],
    base_ids: &[String],
    mut table: table::Table,
    layer: &str,
    skipped: &mut Vec<Skipped>,
) -> TableJoin {
    let mut index: HashMap<String, Vec<usize>> = HashMap::new();
    for (i, (lot, base)) in lots.iter().zip(base_ids).enumerate() {
        // Parts of a multipart lot share their record's id; a row applies to all of them.
        index.entry(base.clone()).or_default().push(i);
        if lot.id != *base {
            index.entry(lot.id.clone()).or_default().push(i);
        }
    }
    let mut matched_lots = vec![false; lots.len()];
    let mut names = crate::model::FieldNames::default();
    let mut out = TableJoin {
        layer: layer.to_string(),
        file: table.file.clone(),
        rows: table.rows.len(),
        matched: 0,
        rows_without_feature: 0,
        rows_without_feature_ids: Vec::new(),
        features_without_row: 0,
    };
    for (id, values) in std::mem::take(&mut table.rows) {
        match index.get(&id) {
            Some(targets) => {
                out.matched += 1;
                for &i in targets {
                    matched_lots[i] = true;
                    for (k, v) in &values {
                        lots[i].attrs.insert(names.intern(k), v.as_str());
                    }
                }
            }
            None => {
                out.rows_without_feature += 1;
                skipped.push(Skipped {
                    layer: format!("{layer} table"),
                    file: table.file.clone(),
                    id: id.clone(),
                    record: None,
                    reason: format!("no {} has this id; the row was not used", singular(layer)),
                });
                if out.rows_without_feature_ids.len() < 20 {
                    out.rows_without_feature_ids.push(id);
                }
            }
        }
    }
    out.rows += table.unusable.len();
    for (row, id, reason) in table.unusable {
        skipped.push(Skipped {
            layer: format!("{layer} table"),
            file: table.file.clone(),
            id,
            record: Some(row),
            reason,
        });
    }
    out.features_without_row = matched_lots.iter().filter(|m| !**m).count();
    out
}
