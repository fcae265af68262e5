//! Adding a layer's features: each row with its geometry blob, each box kept for the layer's
//! packed spatial index (`rtree.rs`), the extent for `gpkg_contents`.

use std::path::PathBuf;

use geo_types::Geometry;
use rusqlite::{params, Connection};

use super::{geometry, rtree, GpkgError, Value};

/// Adds the features of one layer.
pub struct LayerWriter<'c> {
    pub(super) name: String,
    pub(super) conn: &'c Connection,
    pub(super) insert: rusqlite::Statement<'c>,
    pub(super) spatial: bool,
    pub(super) srs: i32,
    pub(super) columns: usize,
    pub(super) extent: Option<[f64; 4]>,
    pub(super) target: PathBuf,
    pub(super) buffer: Vec<u8>,
    /// Each feature's box, packed into the spatial index when the layer ends.
    pub(super) cells: Vec<rtree::Cell>,
}

impl LayerWriter<'_> {
    /// Adds one feature: its geometry (`None`: a feature without one) and its values, one
    /// per column in the layer's order. Returns its fid.
    pub fn add(
        &mut self,
        geom: Option<&Geometry<f64>>,
        values: &[Value],
    ) -> Result<i64, GpkgError> {
        debug_assert_eq!(values.len(), self.columns, "{}", self.name);
        let mut buffer = std::mem::take(&mut self.buffer);
        let geom = geom.filter(|_| self.spatial);
        let envelope = geom.and_then(|g| geometry::encode(g, self.srs, &mut buffer));
        let fid = self.row(geom.map(|_| &buffer[..]), envelope, values);
        self.buffer = buffer;
        fid
    }

    /// Adds one feature whose geometry is a GeoPackage blob already (copied from another
    /// package of the same SRS).
    pub fn add_blob(&mut self, blob: Option<&[u8]>, values: &[Value]) -> Result<(), GpkgError> {
        let envelope = blob.and_then(geometry::envelope_of);
        self.row(blob, envelope, values).map(|_| ())
    }

    /// Inserts one row (its blob first when the layer is spatial) and keeps its box for
    /// the index; returns its fid.
    fn row(
        &mut self,
        blob: Option<&[u8]>,
        envelope: Option<[f64; 4]>,
        values: &[Value],
    ) -> Result<i64, GpkgError> {
        let mut all: Vec<&dyn rusqlite::ToSql> = Vec::with_capacity(values.len() + 1);
        if self.spatial {
            all.push(&blob);
        }
        all.extend(values.iter().map(|v| v as &dyn rusqlite::ToSql));
        self.insert.execute(&all[..]).map_err(|e| self.err(e))?;
        let fid = self.conn.last_insert_rowid();
        if let Some(e) = envelope.filter(|_| self.spatial) {
            self.cells.push((fid, rtree::cell_box(e)));
            self.grow(e);
        }
        Ok(fid)
    }

    fn err(&self, source: rusqlite::Error) -> GpkgError {
        GpkgError::Sqlite {
            path: self.target.clone(),
            source,
        }
    }

    fn grow(&mut self, e: [f64; 4]) {
        self.extent = Some(match self.extent {
            None => e,
            Some(x) => [
                x[0].min(e[0]),
                x[1].max(e[1]),
                x[2].min(e[2]),
                x[3].max(e[3]),
            ],
        });
    }

    /// Ends the layer: its spatial index, packed (`rtree.rs`), and its extent in
    /// `gpkg_contents`.
    pub fn end(mut self) -> Result<(), GpkgError> {
        if self.spatial {
            let table = format!("rtree_{}_geom", self.name);
            let written = rtree::write(self.conn, &table, &mut self.cells);
            written.map_err(|e| self.err(e))?;
        }
        if let Some(e) = self.extent {
            self.conn
                .execute(
                    "UPDATE gpkg_contents SET min_x = ?1, max_x = ?2, min_y = ?3, max_y = ?4 \
                     WHERE table_name = ?5",
                    params![e[0], e[1], e[2], e[3], self.name],
                )
                .map_err(|e| self.err(e))?;
        }
        Ok(())
    }
}
