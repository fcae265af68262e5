//! Reads one layer of a GeoPackage (issue 77): `[layers.<role>] file = "town.gpkg"` and
//! `layer = "lots"` (or the file's only features table, or the table named as the role).
//!
//! A GeoPackage is an SQLite database from somewhere else, so it is opened read-only, with
//! `trusted_schema` off (no function a view or trigger names runs), SQLite's limits set low
//! (no attached databases, short SQL, shallow expressions, blobs within [`MAX_BLOB`]) and a
//! progress handler that stops any statement past [`MAX_STEPS`] virtual-machine steps (a
//! recursive CTE hidden in a view would otherwise run forever). Only tables are read, never
//! views; rows are read in their primary key's order, each geometry decoded by geozero
//! (GeoPackage binary: its header's envelope is skipped, never trusted), each attribute as
//! text as the DBF reader writes it. A FIFO, a device or a link loop is refused before
//! SQLite opens anything.

use std::path::Path;

use rusqlite::limits::Limit;
use rusqlite::types::ValueRef;
use rusqlite::{Connection, OpenFlags};

use super::features::Collector;
use super::shp::{fmt_number, Layer};
use super::InputError;

/// The largest value (a geometry blob, a text) a row may hold.
const MAX_BLOB: i32 = 256 << 20;
/// Virtual-machine steps a read may take, in all: a 30,000-lot layer takes a few million.
const MAX_STEPS: u64 = 20_000_000_000;
/// Steps between two calls of the progress handler.
const STEP: i32 = 100_000;

/// The tables of a GeoPackage that hold features or attributes, in `gpkg_contents`' order:
/// `(name, data_type)`.
pub fn tables(path: &Path) -> Result<Vec<(String, String)>, InputError> {
    tables_in(&open(path)?, path)
}

/// [`tables`] of the package `conn` has open (`path` for messages).
fn tables_in(conn: &Connection, path: &Path) -> Result<Vec<(String, String)>, InputError> {
    let err = |e: rusqlite::Error| {
        layer_err(
            path,
            format!(
                "cannot list its tables: {e} (a GeoPackage cut short or damaged, or another \
                 SQLite file: save the layers again from QGIS as a GeoPackage)"
            ),
        )
    };
    let mut st = conn
        .prepare("SELECT table_name, data_type FROM gpkg_contents ORDER BY rowid")
        .map_err(err)?;
    let rows = st
        .query_map([], |r| Ok((r.get::<_, String>(0)?, r.get::<_, String>(1)?)))
        .map_err(err)?;
    rows.collect::<Result<Vec<_>, _>>().map_err(err)
}

/// Reads the features table `layer` of the GeoPackage at `path` (`""`: its only one, else
/// the one named `role`).
pub fn read_layer(path: &Path, layer: &str, role: &str) -> Result<Layer, InputError> {
    let conn = open(path)?;
    let all = tables_in(&conn, path)?;
    let features: Vec<&String> = (all.iter())
        .filter(|(_, t)| t == "features")
        .map(|(n, _)| n)
        .collect();
    let name = match layer.trim() {
        "" if features.len() == 1 => features[0].clone(),
        "" if features.iter().any(|n| *n == role) => role.to_string(),
        "" => {
            return Err(layer_err(
                path,
                format!(
                    "it holds {} feature layers ({}): name one with `layer = \"...\"` in \
                     [layers.{role}]",
                    features.len(),
                    list(&features)
                ),
            ))
        }
        l if features.iter().any(|n| *n == l) => l.to_string(),
        l => {
            return Err(layer_err(
                path,
                format!(
                    "it has no feature layer `{l}` (its feature layers: {})",
                    list(&features)
                ),
            ))
        }
    };
    read_table(&conn, path, &name)
}

fn read_table(conn: &Connection, path: &Path, table: &str) -> Result<Layer, InputError> {
    let at = |what: &str| {
        let what = what.to_string();
        move |e: rusqlite::Error| layer_err(path, format!("layer `{table}`: {what}: {e}"))
    };
    let kind: Option<String> = conn
        .query_row(
            "SELECT type FROM sqlite_master WHERE name = ?1",
            [table],
            |r| r.get(0),
        )
        .ok();
    if kind.as_deref() != Some("table") {
        return Err(layer_err(
            path,
            format!(
                "layer `{table}` is a {}, not a table: edo-city reads tables only (save the \
                 layer as a table of its own in QGIS)",
                kind.as_deref().unwrap_or("name nothing holds")
            ),
        ));
    }
    let (geom, srs): (String, i64) = conn
        .query_row(
            "SELECT column_name, srs_id FROM gpkg_geometry_columns WHERE table_name = ?1",
            [table],
            |r| Ok((r.get(0)?, r.get(1)?)),
        )
        .map_err(at("no geometry column in gpkg_geometry_columns"))?;
    let prj = crs_of(conn, srs);
    // The columns: the integer primary key is the feature id, not an attribute.
    let cols = columns(conn, table).map_err(at("cannot read its columns"))?;
    let pk = cols.iter().find(|c| c.1).map(|c| c.0.clone());
    let fields: Vec<String> = (cols.iter())
        .filter(|(n, is_pk)| !is_pk && *n != geom)
        .map(|(n, _)| n.clone())
        .collect();
    let select: Vec<String> = std::iter::once(quote(&geom))
        .chain(fields.iter().map(|f| quote(f)))
        .collect();
    let order = pk.as_deref().map_or("rowid".to_string(), quote);
    let sql = format!(
        "SELECT {} FROM {} ORDER BY {order}",
        select.join(", "),
        quote(table)
    );
    let mut st = conn.prepare(&sql).map_err(at("cannot read its rows"))?;
    let mut rows = st.query([]).map_err(at("cannot read its rows"))?;
    let mut c = Collector::default();
    let mut broken = 0usize;
    let mut record = 0usize;
    while let Some(row) = rows.next().map_err(at("cannot read its rows"))? {
        c.begin();
        for (i, f) in fields.iter().enumerate() {
            let v = row.get_ref(i + 1).map_err(at("cannot read a value"))?;
            c.attribute(f, text(v));
        }
        if let Ok(ValueRef::Blob(blob)) = row.get_ref(0) {
            let mut geom = blob;
            if geozero::wkb::process_gpkg_geom(&mut geom, &mut c).is_err() {
                broken += 1;
                c.begin_geometry_again();
            }
        }
        c.end(record);
        record += 1;
    }
    let mut warnings = Vec::new();
    let file = path.display().to_string();
    if broken > 0 {
        warnings.push(
            crate::model::Warning::new(
                crate::model::WarningClass::Layer,
                format!(
                    "{file} layer `{table}`: {broken} geometries could not be decoded (a blob \
                     that is not GeoPackage binary, or cut short): read as empty and skipped"
                ),
            )
            .in_file(&file),
        );
    }
    warnings.extend(c.unsupported_warning(&file));
    Ok(Layer {
        path: path.to_path_buf(),
        records: c.features.len(),
        features: std::mem::take(&mut c.features),
        encoding: "UTF-8 (GeoPackage)".into(),
        text_encoding: Some(encoding_rs::UTF_8),
        fields,
        prj,
        warnings,
        deleted: Vec::new(),
    })
}

/// A row of an attributes table: its number as a spreadsheet gives it, and its values.
pub type Row = (usize, Vec<String>);

/// The rows of the attributes table `name` of the GeoPackage at `path` (`""`: its only
/// attributes table): its column names (the primary key left out) and each row's values as
/// text, numbered as a spreadsheet numbers them (the header is row 1).
pub fn attribute_rows(path: &Path, name: &str) -> Result<(Vec<String>, Vec<Row>), InputError> {
    let conn = open(path)?;
    let all = tables_in(&conn, path)?;
    let attributes: Vec<&String> = (all.iter())
        .filter(|(_, t)| t == "attributes")
        .map(|(n, _)| n)
        .collect();
    let table = match name.trim() {
        "" if attributes.len() == 1 => attributes[0].clone(),
        "" => {
            return Err(layer_err(
                path,
                format!(
                    "it holds {} attribute tables ({}): name one with `sheet = \"...\"`",
                    attributes.len(),
                    list(&attributes)
                ),
            ))
        }
        n if all.iter().any(|(t, _)| t == n) => n.to_string(),
        n => {
            return Err(layer_err(
                path,
                format!(
                    "it has no table `{n}` (its attribute tables: {})",
                    list(&attributes)
                ),
            ))
        }
    };
    let err = |e: rusqlite::Error| layer_err(path, format!("table `{table}`: {e}"));
    let cols = columns(&conn, &table).map_err(err)?;
    let names: Vec<String> = cols.iter().filter(|c| !c.1).map(|c| c.0.clone()).collect();
    let select: Vec<String> = names.iter().map(|n| quote(n)).collect();
    let order = cols
        .iter()
        .find(|c| c.1)
        .map_or("rowid".to_string(), |c| quote(&c.0));
    let sql = format!(
        "SELECT {} FROM {} ORDER BY {order}",
        select.join(", "),
        quote(&table)
    );
    let mut st = conn.prepare(&sql).map_err(err)?;
    let mut rows = st.query([]).map_err(err)?;
    let mut out = Vec::new();
    while let Some(row) = rows.next().map_err(err)? {
        let values = (0..names.len())
            .map(|i| row.get_ref(i).map(text))
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        out.push((out.len() + 2, values));
    }
    Ok((names, out))
}

/// A table's columns: each name and whether it is the primary key.
fn columns(conn: &Connection, table: &str) -> rusqlite::Result<Vec<(String, bool)>> {
    let mut st = conn.prepare(&format!("PRAGMA table_info({})", quote(table)))?;
    let cols = st
        .query_map([], |r| {
            Ok((r.get::<_, String>(1)?, r.get::<_, i64>(5)? > 0))
        })?
        .collect();
    cols
}

/// The WKT of the GeoPackage's spatial reference `srs`: an EPSG code's own definition
/// (as a `.prj` would give it) when the package names one, else its `definition`.
fn crs_of(conn: &Connection, srs: i64) -> Option<String> {
    let (org, code, def): (String, i64, String) = conn
        .query_row(
            "SELECT organization, organization_coordsys_id, definition FROM \
             gpkg_spatial_ref_sys WHERE srs_id = ?1",
            [srs],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
        )
        .ok()?;
    let epsg = (org.eq_ignore_ascii_case("epsg"))
        .then(|| u16::try_from(code).ok())
        .flatten()
        .and_then(crs_definitions::from_code);
    match epsg {
        Some(d) => Some(d.wkt.to_string()),
        None if def.trim().is_empty() || def.trim() == "undefined" => None,
        None => Some(def),
    }
}

/// A value as the DBF reader writes it.
fn text(v: ValueRef<'_>) -> String {
    match v {
        ValueRef::Null | ValueRef::Blob(_) => String::new(),
        ValueRef::Integer(i) => i.to_string(),
        ValueRef::Real(f) => fmt_number(f),
        ValueRef::Text(t) => String::from_utf8_lossy(t).into_owned(),
    }
}

/// The GeoPackage at `path`, opened read-only within the limits of the module's doc.
fn open(path: &Path) -> Result<Connection, InputError> {
    // A regular file: a FIFO would be waited on, a device read forever.
    crate::bounded::file(path).map_err(|e| layer_err(path, format!("cannot open it: {e}")))?;
    let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
    let conn = Connection::open_with_flags(path, flags)
        .map_err(|e| layer_err(path, format!("not a GeoPackage SQLite can open: {e}")))?;
    for (limit, value) in [
        (Limit::SQLITE_LIMIT_LENGTH, MAX_BLOB),
        (Limit::SQLITE_LIMIT_SQL_LENGTH, 1 << 20),
        (Limit::SQLITE_LIMIT_COLUMN, 2000),
        (Limit::SQLITE_LIMIT_EXPR_DEPTH, 100),
        (Limit::SQLITE_LIMIT_COMPOUND_SELECT, 10),
        (Limit::SQLITE_LIMIT_VDBE_OP, 1 << 20),
        (Limit::SQLITE_LIMIT_FUNCTION_ARG, 16),
        (Limit::SQLITE_LIMIT_ATTACHED, 0),
        (Limit::SQLITE_LIMIT_LIKE_PATTERN_LENGTH, 1000),
        (Limit::SQLITE_LIMIT_VARIABLE_NUMBER, 100),
        (Limit::SQLITE_LIMIT_TRIGGER_DEPTH, 1),
    ] {
        let _ = conn.set_limit(limit, value);
    }
    let settings = "PRAGMA trusted_schema = OFF; PRAGMA query_only = ON;";
    conn.execute_batch(settings)
        .map_err(|e| layer_err(path, format!("not a GeoPackage SQLite can read: {e}")))?;
    let mut calls = 0u64;
    conn.progress_handler(
        STEP,
        Some(move || {
            calls += 1;
            calls * STEP as u64 > MAX_STEPS
        }),
    );
    Ok(conn)
}

/// An SQL identifier, quoted.
fn quote(name: &str) -> String {
    format!("\"{}\"", name.replace('"', "\"\""))
}

fn list(names: &[&String]) -> String {
    match names.is_empty() {
        true => "none".into(),
        false => names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", "),
    }
}

fn layer_err(path: &Path, message: String) -> InputError {
    InputError::Layer {
        file: path.display().to_string(),
        message,
    }
}
