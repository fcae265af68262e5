//! The layers a build reads, as opened: one slot a role, each with the CRS its coordinates are
//! in, what reading it noticed, and its line of the report.

use std::path::Path;

use super::crs::Crs;
use super::fields::resolve_field;
use super::{shp, InputError};
use crate::model::{Dataset, LayerInfo, Skipped};
use crate::params::Params;

/// A layer as opened, with the CRS its coordinates are in.
pub(super) struct Opened {
    pub(super) role: &'static str,
    pub(super) layer: shp::Layer,
    pub(super) src: Option<Crs>,
    /// Whether `src` differs from the output CRS (decided once: comparing per polygon cost
    /// a fifth of the read stage).
    pub(super) reproject: bool,
    pub(super) file: String,
    /// Rings read so far that are wound against the shapefile standard (see
    /// [`geometry::ShapePolygons::against_winding`]), for one warning per layer.
    pub(super) against_winding: std::cell::Cell<usize>,
}

impl Opened {
    /// Counts rings wound against the standard.
    pub(super) fn count_winding(&self, n: usize) {
        self.against_winding.set(self.against_winding.get() + n);
    }

    /// Records what became of `record` for the ledger: it gave a usable feature (`kept`), or
    /// it is skipped with the reason `why` gives.
    pub(super) fn kept_or_skipped(
        &self,
        data: &mut Dataset,
        record: usize,
        kept: bool,
        why: impl FnOnce() -> String,
    ) {
        if kept {
            data.records
                .entry(self.role.into())
                .or_default()
                .insert(record);
        } else {
            data.skipped.push(Skipped {
                layer: self.role.into(),
                file: self.file.clone(),
                id: format!("record {record}"),
                record: Some(record),
                reason: why(),
            });
        }
    }

    /// The warning for the rings wound against the standard, if any.
    pub(super) fn winding_warning(&self) -> Option<crate::model::Warning> {
        let n = self.against_winding.get();
        (n > 0).then(|| {
            let message = format!(
                "{}: {n} ring(s) are wound against the shapefile standard (outer rings \
                 counter-clockwise or holes clockwise, as many non-ESRI tools write them); they \
                 were read by where they lie, as GDAL and QGIS read them",
                self.file
            );
            crate::model::Warning::layer(self.role, &self.file, message)
        })
    }

    /// The error for record `record` whose shape is a `kind` where this layer must hold
    /// `wanted` (polygons, polylines, points).
    pub(super) fn wrong_shape(&self, record: usize, kind: &str, wanted: &str) -> InputError {
        InputError::Layer {
            file: self.file.clone(),
            message: format!(
                "record {record} is a {kind}; the {} layer must hold {wanted}",
                self.role
            ),
        }
    }

    /// The layer's field that `wanted` names (see [`resolve_field`]), or an error listing the
    /// layer's fields and the parameter `key` that sets the name.
    pub(super) fn required_field(
        &self,
        wanted: &str,
        what: &str,
        key: &str,
    ) -> Result<String, InputError> {
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
    (file, layer): (&str, &str),
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
             to the right path, or to \"\" if there is no such layer){}",
            path.display(),
            other_layer_files(dir)
        )));
    }
    let layer = read(&path, layer, role, encoding)?;
    Ok(Some(Opened {
        role,
        file: path.display().to_string(),
        layer,
        src: None,
        reproject: false,
        against_winding: Default::default(),
    }))
}

/// A hint naming the GeoPackages and GeoJSON files in `dir`, when it holds any: a person
/// whose town is in one has not named it yet.
fn other_layer_files(dir: &Path) -> String {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return String::new();
    };
    let mut names: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| Format::of(Path::new(n)) != Format::Shapefile)
        .collect();
    names.sort();
    names.truncate(5);
    match names.first() {
        None => String::new(),
        Some(first) => format!(
            "; the directory holds {}: name one, e.g. `file = {first:?}` (and `layer = \"...\"` \
             for a GeoPackage), or let `edo-city init {}` write the parameter file",
            names.join(", "),
            dir.display()
        ),
    }
}

/// Reads the layer at `path` by its kind: a GeoPackage's `layer`, a GeoJSON or FlatGeobuf
/// file, else a shapefile (`encoding` is a DBF's).
fn read(path: &Path, layer: &str, role: &str, encoding: &str) -> Result<shp::Layer, InputError> {
    match Format::of(path) {
        Format::GeoPackage => super::gpkg::read_layer(path, layer, role),
        Format::GeoJson => super::geojson::read_layer(path),
        Format::FlatGeobuf => super::fgb::read_layer(path),
        Format::Shapefile => shp::read_layer(path, encoding),
    }
}

/// The kinds of layer file a build reads, by their names' endings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Shapefile,
    GeoPackage,
    GeoJson,
    FlatGeobuf,
}

impl Format {
    /// The format of the file at `path`, by its ending (a shapefile unless it is another's).
    pub fn of(path: &Path) -> Format {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "gpkg" => Format::GeoPackage,
            "geojson" | "json" => Format::GeoJson,
            "fgb" => Format::FlatGeobuf,
            _ => Format::Shapefile,
        }
    }
}

/// Every layer a build reads, one slot a role; `None` where the role is switched off or its
/// optional default file is not there. The one list of roles: opening, CRS resolution, the
/// read warnings and the report all walk [`Layers::all`] in this order (lots first: the
/// first layer decides the output CRS).
pub(super) struct Layers {
    pub(super) lots: Option<Opened>,
    pub(super) footprints: Option<Opened>,
    pub(super) streets: Option<Opened>,
    pub(super) blocks: Option<Opened>,
    pub(super) widths: Option<Opened>,
    pub(super) districts: Option<Opened>,
    pub(super) fences: Option<Opened>,
    pub(super) people: Option<Opened>,
    pub(super) trees: Option<Opened>,
    pub(super) gardens: Option<Opened>,
    pub(super) water: Option<Opened>,
    pub(super) links: Option<Opened>,
    pub(super) landmarks: Option<Opened>,
}

impl Layers {
    /// Opens every role's layer (see [`open`]); `d` are the default layers, whose files an
    /// optional role may lack.
    pub(super) fn open(
        dir: &Path,
        params: &Params,
        d: &crate::params::Layers,
    ) -> Result<Layers, InputError> {
        let l = &params.layers;
        // (role, file, encoding, the default file: an optional role's is allowed to be absent)
        let role = |role, file: (&str, &str), encoding: &str, default: &str| {
            open(dir, role, file, encoding, default)
        };
        Ok(Layers {
            lots: role(
                "lots",
                (&l.lots.file, &l.lots.layer),
                &l.lots.encoding,
                &d.lots.file,
            )?,
            footprints: role(
                "footprints",
                (&l.footprints.file, &l.footprints.layer),
                &l.footprints.encoding,
                "",
            )?,
            streets: role(
                "streets",
                (&l.streets.file, &l.streets.layer),
                &l.streets.encoding,
                &d.streets.file,
            )?,
            blocks: role(
                "blocks",
                (&l.blocks.file, &l.blocks.layer),
                &l.blocks.encoding,
                &d.blocks.file,
            )?,
            widths: role(
                "street_widths",
                (&l.street_widths.file, &l.street_widths.layer),
                &l.street_widths.encoding,
                "",
            )?,
            districts: role(
                "districts",
                (&l.districts.file, &l.districts.layer),
                &l.districts.encoding,
                "",
            )?,
            fences: role(
                "fences",
                (&l.fences.file, &l.fences.layer),
                &l.fences.encoding,
                &d.fences.file,
            )?,
            people: role(
                "people",
                (&l.people.file, &l.people.layer),
                &l.people.encoding,
                &d.people.file,
            )?,
            trees: role(
                "trees",
                (&l.trees.file, &l.trees.layer),
                &l.trees.encoding,
                &d.trees.file,
            )?,
            gardens: role(
                "gardens",
                (&l.gardens.file, &l.gardens.layer),
                &l.gardens.encoding,
                &d.gardens.file,
            )?,
            water: role(
                "water",
                (&l.water.file, &l.water.layer),
                &l.water.encoding,
                &d.water.file,
            )?,
            // A table of links is read by its own reader.
            links: match is_table(&links_file(dir, params, d)) {
                true => None,
                false => role(
                    "links",
                    (&l.links.file, &l.links.layer),
                    &l.links.encoding,
                    &d.links.file,
                )?,
            },
            // So is a table of landmarks.
            landmarks: match params.landmarks.enabled && !is_table(&l.landmarks.file) {
                true => role(
                    "landmarks",
                    (&l.landmarks.file, &l.landmarks.layer),
                    &l.landmarks.encoding,
                    &d.landmarks.file,
                )?,
                false => None,
            },
        })
    }

    /// The opened layers, in the order of the roles.
    pub(super) fn all(&self) -> impl Iterator<Item = &Opened> {
        [
            &self.lots,
            &self.footprints,
            &self.streets,
            &self.blocks,
            &self.widths,
            &self.districts,
            &self.fences,
            &self.people,
            &self.trees,
            &self.gardens,
            &self.water,
            &self.links,
            &self.landmarks,
        ]
        .into_iter()
        .flatten()
    }

    /// The same, to change.
    pub(super) fn all_mut(&mut self) -> impl Iterator<Item = &mut Opened> {
        [
            &mut self.lots,
            &mut self.footprints,
            &mut self.streets,
            &mut self.blocks,
            &mut self.widths,
            &mut self.districts,
            &mut self.fences,
            &mut self.people,
            &mut self.trees,
            &mut self.gardens,
            &mut self.water,
            &mut self.links,
            &mut self.landmarks,
        ]
        .into_iter()
        .flatten()
    }
}

/// What reading a layer noticed, into the dataset: its read warnings, a skip for every record
/// the DBF marks deleted, and its line of the report.
pub(super) fn report_layer(o: &Opened, data: &mut Dataset) {
    // The reader of the file knows the file; the role is known here.
    data.warnings
        .extend(o.layer.warnings.iter().map(|w| crate::model::Warning {
            layer: Some(o.role.to_string()),
            ..w.clone()
        }));
    for &record in &o.layer.deleted {
        data.skipped.push(Skipped {
            layer: o.role.into(),
            file: o.file.clone(),
            id: format!("record {record}"),
            record: Some(record),
            reason: "the DBF marks the record as deleted (an edit that was never packed): it \
                     is not built; undelete it, or save the layer as a new file to drop it"
                .into(),
        });
    }
    data.layers.push(LayerInfo {
        role: o.role.into(),
        file: o.file.clone(),
        features: o.layer.records,
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

/// The links layer's file: the parameter's, where the default `links.shp` is missing but a
/// `links.csv` is there that one (as the DEM's default finds a GeoTIFF).
pub(super) fn links_file(dir: &Path, params: &Params, d: &crate::params::Layers) -> String {
    let file = &params.layers.links.file;
    if *file == d.links.file && !dir.join(file).exists() && dir.join("links.csv").exists() {
        return "links.csv".into();
    }
    file.clone()
}

/// Whether a layer file is a table (CSV, or an XLSX workbook) rather than a shapefile.
pub(super) fn is_table(file: &str) -> bool {
    let f = file.to_lowercase();
    f.ends_with(".csv") || f.ends_with(".xlsx")
}

/// The skip entry for a record of `o` whose shape is null (no geometry, only attributes).
pub(super) fn null_shape(o: &Opened, record: usize, what: &str) -> Skipped {
    Skipped {
        layer: o.role.into(),
        file: o.file.clone(),
        id: format!("record {record}"),
        record: Some(record),
        reason: format!(
            "null shape: the record has attributes but no geometry; draw {what} or delete the \
             record"
        ),
    }
}
