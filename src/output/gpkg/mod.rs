//! GeoPackage (OGC 12-128r18, version 1.2) files: the build's decisions as vector layers a
//! historian opens in QGIS (`plan.gpkg`), the problems `check` finds, and the lots two
//! hypotheses disagree on. SQLite through `rusqlite` (its bundled library, R*Tree on); the
//! GeoPackage tables, geometry blobs and spatial indexes as the standard spells them.
//!
//! A file is written to a temporary name beside its target and renamed when complete, like
//! every other output. Its bytes depend only on what is written, in the order written: no
//! clock (`last_change` and the styles' `update_time` are a fixed date), one connection, one
//! transaction, no journal.
//!
//! `layers.rs` makes the build's layers, `styles.rs` their QGIS styles, `diff.rs` the layers
//! of `compare --gpkg`; `geometry.rs` the geometry blob.

mod diff;
mod geometry;
mod houses;
mod layer;
mod layers;
mod places;
mod rows;
mod rtree;
mod styles;

use std::path::{Path, PathBuf};

use rusqlite::{params, Connection};

pub use diff::{lot_differences, plan_lots, write_diff, DiffError, LotDiff, PlanLots};
pub use layer::LayerWriter;
pub use layers::{write_plan, write_problems, PlanWriter};
pub use rows::PlanSources;
pub use rusqlite::types::Value;

/// The date every `last_change` and style `update_time` carries: a build's file never
/// depends on the day it was made (two builds of one hypothesis compare byte for byte).
pub const FIXED_DATE: &str = "2000-01-01T00:00:00.000Z";

/// The SRS every GeoPackage lists (the standard's requirement 11), as GDAL writes it.
const WGS84: &str = r#"GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563,AUTHORITY["EPSG","7030"]],AUTHORITY["EPSG","6326"]],PRIMEM["Greenwich",0,AUTHORITY["EPSG","8901"]],UNIT["degree",0.0174532925199433,AUTHORITY["EPSG","9122"]],AXIS["Latitude",NORTH],AXIS["Longitude",EAST],AUTHORITY["EPSG","4326"]]"#;

/// Where the layers' coordinates are.
#[derive(Debug, Clone, PartialEq)]
pub struct Srs {
    /// `gpkg_spatial_ref_sys.srs_id`: the EPSG code, or 100000 for a CRS without one.
    pub id: i32,
    /// Its name.
    pub name: String,
    /// `EPSG` or `NONE`.
    pub organization: String,
    /// The code within the organization.
    pub code: i32,
    /// OGC WKT, or `undefined` where only a proj string is known.
    pub definition: String,
    /// A line for people: the proj string the build used.
    pub description: String,
}

impl Srs {
    /// The output CRS of a build: `crs` of the parameters (`EPSG:<n>` or WKT), else the
    /// `.prj` of the lots (or footprints) when nothing was reprojected into another CRS;
    /// `proj` is the proj string the build used (the only thing known of a CRS chosen for
    /// data in degrees).
    pub fn of_build(param_crs: &str, prj: Option<&str>, proj: &str, reprojected: bool) -> Srs {
        let t = param_crs.trim();
        let wkt = match t {
            "" if !reprojected => prj.map(str::trim).filter(|w| !w.is_empty()),
            w if w.starts_with("PROJCS") || w.starts_with("PROJCRS") => Some(w),
            _ => None,
        };
        let epsg = t
            .strip_prefix("EPSG:")
            .or_else(|| t.strip_prefix("epsg:"))
            .and_then(|n| n.trim().parse::<i32>().ok())
            .or_else(|| wkt.and_then(last_epsg_authority))
            .or_else(|| utm_code(proj));
        let name = wkt
            .and_then(|w| w.split('"').nth(1))
            .map(str::to_string)
            .or_else(|| epsg.map(|n| format!("EPSG:{n}")))
            .unwrap_or_else(|| "edo-city output CRS".into());
        let (id, organization, code) = match epsg {
            Some(n) => (n, "EPSG", n),
            None => (100_000, "NONE", 100_000),
        };
        Srs {
            id,
            name,
            organization: organization.into(),
            code,
            definition: wkt.unwrap_or("undefined").into(),
            description: proj.into(),
        }
    }
}

/// The EPSG code of a WGS 84 UTM zone as `geom::crs::Crs::utm_for` spells it (the CRS a
/// build chooses for data in degrees): 326zz north, 327zz south.
fn utm_code(proj: &str) -> Option<i32> {
    let words: Vec<&str> = proj.split_whitespace().collect();
    let is = |w: &str| words.contains(&w);
    if !(is("+proj=utm") && is("+datum=WGS84")) {
        return None;
    }
    let zone: i32 = words
        .iter()
        .find_map(|w| w.strip_prefix("+zone="))?
        .parse()
        .ok()?;
    (1..=60)
        .contains(&zone)
        .then(|| if is("+south") { 32700 } else { 32600 } + zone)
}

/// The EPSG code a WKT names for the whole CRS: its last `AUTHORITY["EPSG","n"]`.
fn last_epsg_authority(wkt: &str) -> Option<i32> {
    let at = wkt.rfind("AUTHORITY[\"EPSG\",\"")?;
    let rest = &wkt[at + 18..];
    // Only the CRS's own authority: the last one, closing the text.
    let tail = rest.split_once('"')?;
    let after = tail.1.trim_start_matches(']').trim();
    (after == "]" || after.is_empty())
        .then(|| tail.0.parse().ok())
        .flatten()
}

/// The kind of geometry a layer holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeomKind {
    /// Points.
    Point,
    /// Lines.
    LineString,
    /// Polygons (with holes).
    Polygon,
    /// Polygons of several parts (a house on a lot of a bent shape).
    MultiPolygon,
}

impl GeomKind {
    fn name(self) -> &'static str {
        match self {
            GeomKind::Point => "POINT",
            GeomKind::LineString => "LINESTRING",
            GeomKind::Polygon => "POLYGON",
            GeomKind::MultiPolygon => "MULTIPOLYGON",
        }
    }
}

/// A column's SQLite type, as GeoPackage names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    /// TEXT.
    Text,
    /// INTEGER.
    Integer,
    /// DOUBLE.
    Real,
}

/// One attribute column of a layer.
#[derive(Debug, Clone, Copy)]
pub struct Column {
    /// Its name.
    pub name: &'static str,
    /// Its type.
    pub kind: ColumnType,
}

/// Shorthand for a text column.
pub const fn text(name: &'static str) -> Column {
    Column {
        name,
        kind: ColumnType::Text,
    }
}

/// Shorthand for an integer column.
pub const fn int(name: &'static str) -> Column {
    Column {
        name,
        kind: ColumnType::Integer,
    }
}

/// Shorthand for a real column.
pub const fn real(name: &'static str) -> Column {
    Column {
        name,
        kind: ColumnType::Real,
    }
}

/// A GeoPackage being written: created empty under a temporary name, filled layer by layer,
/// then indexed, styled and renamed over its target by [`GeoPackage::finish`].
pub struct GeoPackage {
    // Closed before its file is removed: fields drop in this order.
    conn: Connection,
    target: PathBuf,
    tmp: Temporary,
    srs: Srs,
    /// Each spatial layer's name, for its spatial index triggers.
    spatial: Vec<String>,
    /// The QGIS style of each layer that has one.
    styles: Vec<(String, String)>,
}

/// A failure while writing a GeoPackage.
#[derive(Debug, thiserror::Error)]
pub enum GpkgError {
    /// SQLite refused a statement (a full disk, an unwritable directory).
    #[error("{path}: {source}")]
    Sqlite {
        /// The file.
        path: PathBuf,
        /// SQLite's error.
        source: rusqlite::Error,
    },
    /// The finished file could not be moved into place.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

impl GpkgError {
    /// The file and the failure as an I/O error (SQLite's "database or disk is full" as the
    /// storage-full error, so a build says what to do about it).
    pub fn into_io(self) -> (PathBuf, std::io::Error) {
        match self {
            GpkgError::Io { path, source } => (path, source),
            GpkgError::Sqlite { path, source } => {
                let full = source.sqlite_error_code() == Some(rusqlite::ErrorCode::DiskFull);
                let kind = match full {
                    true => std::io::ErrorKind::StorageFull,
                    false => std::io::ErrorKind::Other,
                };
                (path, std::io::Error::new(kind, source.to_string()))
            }
        }
    }
}

impl GeoPackage {
    /// Starts `target` (written to a temporary file beside it until [`Self::finish`]).
    pub fn create(target: &Path, srs: Srs) -> Result<GeoPackage, GpkgError> {
        let tmp = Temporary(super::atomic::temporary_for(target));
        let _ = std::fs::remove_file(&tmp.0);
        let sql = |source| GpkgError::Sqlite {
            path: target.to_path_buf(),
            source,
        };
        let conn = Connection::open(&tmp.0).map_err(sql)?;
        let mut g = GeoPackage {
            conn,
            target: target.to_path_buf(),
            tmp,
            srs,
            spatial: Vec::new(),
            styles: Vec::new(),
        };
        g.base_tables().map_err(sql)?;
        Ok(g)
    }

    pub(super) fn err(&self, source: rusqlite::Error) -> GpkgError {
        GpkgError::Sqlite {
            path: self.target.clone(),
            source,
        }
    }

    /// The tables every GeoPackage has, and its SRS.
    fn base_tables(&mut self) -> rusqlite::Result<()> {
        // No journal (a failed write removes the whole temporary), one transaction.
        self.conn.execute_batch(
            "PRAGMA journal_mode = OFF;
             PRAGMA synchronous = OFF;
             PRAGMA page_size = 4096;
             PRAGMA cache_size = -65536;
             PRAGMA application_id = 1196444487;
             PRAGMA user_version = 10200;
             BEGIN;
             CREATE TABLE gpkg_spatial_ref_sys (
               srs_name TEXT NOT NULL, srs_id INTEGER PRIMARY KEY,
               organization TEXT NOT NULL, organization_coordsys_id INTEGER NOT NULL,
               definition TEXT NOT NULL, description TEXT);
             CREATE TABLE gpkg_contents (
               table_name TEXT NOT NULL PRIMARY KEY, data_type TEXT NOT NULL,
               identifier TEXT UNIQUE, description TEXT DEFAULT '',
               last_change DATETIME NOT NULL DEFAULT (strftime('%Y-%m-%dT%H:%M:%fZ','now')),
               min_x DOUBLE, min_y DOUBLE, max_x DOUBLE,
               max_y DOUBLE, srs_id INTEGER,
               CONSTRAINT fk_gc_r_srs_id FOREIGN KEY (srs_id)
                 REFERENCES gpkg_spatial_ref_sys(srs_id));
             CREATE TABLE gpkg_geometry_columns (
               table_name TEXT NOT NULL, column_name TEXT NOT NULL,
               geometry_type_name TEXT NOT NULL, srs_id INTEGER NOT NULL,
               z TINYINT NOT NULL, m TINYINT NOT NULL,
               CONSTRAINT pk_geom_cols PRIMARY KEY (table_name, column_name),
               CONSTRAINT uk_gc_table_name UNIQUE (table_name),
               CONSTRAINT fk_gc_tn FOREIGN KEY (table_name) REFERENCES gpkg_contents(table_name),
               CONSTRAINT fk_gc_srs FOREIGN KEY (srs_id) REFERENCES gpkg_spatial_ref_sys (srs_id));
             CREATE TABLE gpkg_extensions (
               table_name TEXT, column_name TEXT, extension_name TEXT NOT NULL,
               definition TEXT NOT NULL, scope TEXT NOT NULL,
               CONSTRAINT ge_tce UNIQUE (table_name, column_name, extension_name));
             INSERT INTO gpkg_spatial_ref_sys VALUES
               ('Undefined cartesian SRS', -1, 'NONE', -1, 'undefined',
                'undefined cartesian coordinate reference system'),
               ('Undefined geographic SRS', 0, 'NONE', 0, 'undefined',
                'undefined geographic coordinate reference system');",
        )?;
        self.conn.execute(
            "INSERT INTO gpkg_spatial_ref_sys VALUES ('WGS 84 geodetic', 4326, 'EPSG', 4326, \
             ?1, 'longitude/latitude coordinates in decimal degrees on the WGS 84 spheroid')",
            [WGS84],
        )?;
        let s = &self.srs;
        if ![-1, 0, 4326].contains(&s.id) {
            self.conn.execute(
                "INSERT INTO gpkg_spatial_ref_sys VALUES (?1, ?2, ?3, ?4, ?5, ?6)",
                params![
                    s.name,
                    s.id,
                    s.organization,
                    s.code,
                    s.definition,
                    s.description
                ],
            )?;
        }
        Ok(())
    }

    /// Starts a layer: its table, its row in `gpkg_contents` and, for a spatial one, its
    /// geometry column and spatial index. Features are then added through the writer.
    pub fn layer(
        &mut self,
        name: &str,
        geometry: Option<GeomKind>,
        columns: &[Column],
        description: &str,
        style: Option<String>,
    ) -> Result<LayerWriter<'_>, GpkgError> {
        self.layer_sql(name, geometry, columns, description)
            .map_err(|e| self.err(e))?;
        if geometry.is_some() {
            self.spatial.push(name.to_string());
        }
        if let Some(qml) = style {
            self.styles.push((name.to_string(), qml));
        }
        let mut cols: Vec<String> = columns.iter().map(|c| quoted(c.name)).collect();
        if geometry.is_some() {
            cols.insert(0, "geom".into());
        }
        let marks: Vec<String> = (1..=cols.len()).map(|i| format!("?{i}")).collect();
        let insert = format!(
            "INSERT INTO {} ({}) VALUES ({})",
            quoted(name),
            cols.join(", "),
            marks.join(", ")
        );
        let target = self.target.clone();
        let sql = |source| GpkgError::Sqlite {
            path: target.clone(),
            source,
        };
        let insert = self.conn.prepare(&insert).map_err(sql)?;
        Ok(LayerWriter {
            name: name.to_string(),
            conn: &self.conn,
            insert,
            spatial: geometry.is_some(),
            srs: self.srs.id,
            columns: columns.len(),
            extent: None,
            target,
            buffer: Vec::new(),
            cells: Vec::new(),
        })
    }

    fn layer_sql(
        &self,
        name: &str,
        geometry: Option<GeomKind>,
        columns: &[Column],
        description: &str,
    ) -> rusqlite::Result<()> {
        let mut cols = vec!["fid INTEGER PRIMARY KEY NOT NULL".to_string()];
        if let Some(g) = geometry {
            cols.push(format!("geom {}", g.name()));
        }
        for c in columns {
            let kind = match c.kind {
                ColumnType::Text => "TEXT",
                ColumnType::Integer => "INTEGER",
                ColumnType::Real => "DOUBLE",
            };
            cols.push(format!("{} {kind}", quoted(c.name)));
        }
        self.conn.execute(
            &format!("CREATE TABLE {} ({})", quoted(name), cols.join(", ")),
            [],
        )?;
        let kind = if geometry.is_some() {
            "features"
        } else {
            "attributes"
        };
        let srs = geometry.map(|_| self.srs.id);
        self.conn.execute(
            "INSERT INTO gpkg_contents (table_name, data_type, identifier, description, \
             last_change, srs_id) VALUES (?1, ?2, ?1, ?3, ?4, ?5)",
            params![name, kind, description, FIXED_DATE, srs],
        )?;
        if let Some(g) = geometry {
            self.conn.execute(
                "INSERT INTO gpkg_geometry_columns VALUES (?1, 'geom', ?2, ?3, 0, 0)",
                params![name, g.name(), self.srs.id],
            )?;
            self.conn.execute(
                &format!(
                    "CREATE VIRTUAL TABLE {} USING rtree(id, minx, maxx, miny, maxy)",
                    quoted(&format!("rtree_{name}_geom"))
                ),
                [],
            )?;
            self.conn.execute(
                "INSERT INTO gpkg_extensions VALUES (?1, 'geom', 'gpkg_rtree_index', \
                 'http://www.geopackage.org/spec120/#extension_rtree', 'write-only')",
                params![name],
            )?;
        }
        Ok(())
    }

    /// Adds the spatial indexes' triggers and the QGIS styles, ends the transaction and
    /// renames the file over its target.
    pub fn finish(self) -> Result<(), GpkgError> {
        let done = self.finish_sql().map_err(|e| self.err(e));
        let GeoPackage {
            conn, target, tmp, ..
        } = self;
        done?;
        conn.close().map_err(|(_, source)| GpkgError::Sqlite {
            path: target.clone(),
            source,
        })?;
        std::fs::rename(&tmp.0, &target).map_err(|source| GpkgError::Io {
            path: target.clone(),
            source,
        })
    }

    fn finish_sql(&self) -> rusqlite::Result<()> {
        for name in &self.spatial {
            self.conn.execute_batch(&rtree::triggers(name))?;
        }
        styles::write(&self.conn, &self.styles)?;
        self.conn.execute_batch("COMMIT;")
    }
}

/// The temporary file of a package being written: removed when the package is given up
/// (dropped after an error); after the rename there is nothing left to remove.
struct Temporary(PathBuf);

impl Drop for Temporary {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// A name as an SQL identifier.
pub(super) fn quoted(name: &str) -> String {
    format!("\"{}\"", name.replace('"', "\"\""))
}

#[cfg(test)]
mod tests;
