//! `compare A B --gpkg diff.gpkg`: the lots two hypotheses disagree on (type, kura, house,
//! trees), with both values, and the tiles that differ, read from the two builds'
//! `plan.gpkg` and written as a GeoPackage of their own.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rusqlite::{Connection, OpenFlags};

use super::rows::{optional, text_or_null};
use super::styles::{self, Look, Shape};
use super::{int, text, GeoPackage, GeomKind, GpkgError, Srs, Value};

/// Why a difference layer could not be made.
#[derive(Debug, thiserror::Error)]
pub enum DiffError {
    /// A build has no `plan.gpkg` (made before it existed, or without `gpkg` in `--format`).
    #[error(
        "{0} does not exist: build that hypothesis again with gpkg among its formats (the \
         default), then compare"
    )]
    Missing(PathBuf),
    /// A `plan.gpkg` is not one a build wrote.
    #[error("{path} cannot be read as a build's plan.gpkg ({why}): build that hypothesis again")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// SQLite's words.
        why: String,
    },
    /// Writing the result failed.
    #[error(transparent)]
    Write(#[from] GpkgError),
}

/// One lot of a build, as its `lots` layer has it.
#[derive(Debug, Clone, PartialEq)]
struct LotRow {
    record: Option<i64>,
    geom: Option<Vec<u8>>,
    mtype: Option<String>,
    kura: Option<String>,
    status: Option<String>,
    trees: Option<i64>,
}

/// What is compared of a lot, by name.
const ASPECTS: [&str; 4] = ["type", "kura", "house", "trees"];

/// The `lots` layer of a difference: each aspect in A, then in B.
const LOT_COLUMNS: [super::Column; 11] = [
    text("id"),
    int("record"),
    text("differs"),
    text("type_a"),
    text("type_b"),
    text("kura_a"),
    text("kura_b"),
    text("house_a"),
    text("house_b"),
    int("trees_a"),
    int("trees_b"),
];

impl LotRow {
    fn values(&self) -> [Value; 4] {
        [
            optional(self.mtype.as_deref()),
            optional(self.kura.as_deref()),
            optional(self.status.as_deref()),
            self.trees.map_or(Value::Null, Value::Integer),
        ]
    }
}

struct Build {
    conn: Connection,
    path: PathBuf,
}

/// SQLite virtual-machine steps between two looks at the budget.
const STEPS_A_LOOK: i32 = 10_000;
/// Looks at the budget a build's `plan.gpkg` may take: 2e9 steps, about a minute; a
/// million lots' layers are read in a few hundred million.
const LOOKS: u64 = 200_000;
/// The longest string or blob a value may be (a lot's geometry is a few hundred bytes).
const MAX_VALUE_BYTES: i32 = 64 << 20;
/// The tables read, each of which must be a plain table.
const READ: [&str; 4] = [
    "lots",
    "tiles",
    "gpkg_spatial_ref_sys",
    "gpkg_geometry_columns",
];

impl Build {
    /// Opens another build's `plan.gpkg` as untrusted input (issue 57: a `lots` VIEW over an
    /// endless recursive query, a few hundred bytes, ran on with gigabytes of temporary
    /// files): read-only and `query_only`, every table read checked to be a plain table
    /// (no view, virtual table or generated column runs code of the file's), values bounded
    /// in length, and the whole read bounded in steps, which is the same for any machine.
    fn open(dir: &Path) -> Result<Build, DiffError> {
        let path = dir.join("plan.gpkg");
        if !path.is_file() {
            return Err(DiffError::Missing(path));
        }
        let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        let conn = Connection::open_with_flags(&path, flags).map_err(|e| unreadable(&path, e))?;
        conn.pragma_update(None, "query_only", true)
            .map_err(|e| unreadable(&path, e))?;
        conn.set_limit(
            rusqlite::limits::Limit::SQLITE_LIMIT_LENGTH,
            MAX_VALUE_BYTES,
        )
        .map_err(|e| unreadable(&path, e))?;
        let mut looks = 0u64;
        conn.progress_handler(
            STEPS_A_LOOK,
            Some(move || {
                looks += 1;
                looks > LOOKS
            }),
        );
        let build = Build { conn, path };
        for table in READ {
            build.plain_table(table)?;
        }
        Ok(build)
    }

    /// Refuses `table` unless it is an ordinary table without generated columns.
    fn plain_table(&self, table: &str) -> Result<(), DiffError> {
        let not = |why: &str| DiffError::Unreadable {
            path: self.path.clone(),
            why: format!("its `{table}` {why}"),
        };
        let sql: Option<String> = self
            .conn
            .query_row(
                "SELECT sql FROM sqlite_master WHERE type = 'table' AND name = ?1",
                [table],
                |r| r.get(0),
            )
            .map_err(|_| not("is not a table (a view, or missing)"))?;
        let sql = sql.unwrap_or_default().to_ascii_uppercase();
        if sql.trim_start().starts_with("CREATE VIRTUAL") {
            return Err(not("is a virtual table"));
        }
        let generated: i64 = self
            .conn
            .query_row(
                "SELECT count(*) FROM pragma_table_xinfo(?1) WHERE hidden <> 0",
                [table],
                |r| r.get(0),
            )
            .map_err(|e| unreadable(&self.path, e))?;
        match generated {
            0 => Ok(()),
            _ => Err(not("has generated or hidden columns")),
        }
    }

    fn lots(&self) -> Result<BTreeMap<String, LotRow>, DiffError> {
        let read = || -> rusqlite::Result<BTreeMap<String, LotRow>> {
            let mut q = self.conn.prepare(
                "SELECT id, record, geom, type, kura, status, trees FROM lots ORDER BY fid",
            )?;
            let rows = q.query_map([], |r| {
                Ok((
                    r.get::<_, Option<String>>(0)?.unwrap_or_default(),
                    LotRow {
                        record: r.get(1)?,
                        geom: r.get(2)?,
                        mtype: r.get(3)?,
                        kura: r.get(4)?,
                        status: r.get(5)?,
                        trees: r.get(6)?,
                    },
                ))
            })?;
            let mut out = BTreeMap::new();
            for row in rows {
                let (id, lot) = row?;
                // A repeated id (a skipped duplicate) keeps the first: the one built.
                out.entry(id).or_insert(lot);
            }
            Ok(out)
        };
        read().map_err(|e| unreadable(&self.path, e))
    }

    fn tiles(&self) -> Result<BTreeMap<String, Option<Vec<u8>>>, DiffError> {
        let read = || -> rusqlite::Result<BTreeMap<String, Option<Vec<u8>>>> {
            let mut q = self
                .conn
                .prepare("SELECT id, geom FROM tiles ORDER BY fid")?;
            let rows = q.query_map([], |r| {
                Ok((
                    r.get::<_, Option<String>>(0)?.unwrap_or_default(),
                    r.get(1)?,
                ))
            })?;
            rows.collect()
        };
        read().map_err(|e| unreadable(&self.path, e))
    }

    fn srs(&self) -> Result<Srs, DiffError> {
        let read = || -> rusqlite::Result<Srs> {
            self.conn.query_row(
                "SELECT s.srs_id, s.srs_name, s.organization, s.organization_coordsys_id, \
                 s.definition, s.description FROM gpkg_spatial_ref_sys s JOIN \
                 gpkg_geometry_columns c ON c.srs_id = s.srs_id WHERE c.table_name = 'lots'",
                [],
                |r| {
                    Ok(Srs {
                        id: r.get(0)?,
                        name: r.get(1)?,
                        organization: r.get(2)?,
                        code: r.get(3)?,
                        definition: r.get(4)?,
                        description: r.get::<_, Option<String>>(5)?.unwrap_or_default(),
                    })
                },
            )
        };
        read().map_err(|e| unreadable(&self.path, e))
    }
}

fn unreadable(path: &Path, e: rusqlite::Error) -> DiffError {
    DiffError::Unreadable {
        path: path.to_path_buf(),
        why: e.to_string(),
    }
}

/// What differs of a lot between two builds (`type, kura`), `only in A` / `B`, or "".
fn differs(x: Option<&LotRow>, y: Option<&LotRow>) -> String {
    match (x, y) {
        (Some(x), Some(y)) => {
            let (vx, vy) = (x.values(), y.values());
            let d: Vec<&str> = ASPECTS
                .iter()
                .zip(vx.iter().zip(vy.iter()))
                .filter(|(_, (p, q))| p != q)
                .map(|(name, _)| *name)
                .collect();
            d.join(", ")
        }
        (Some(_), None) => "only in A".into(),
        (None, Some(_)) => "only in B".into(),
        (None, None) => String::new(),
    }
}

/// The lots of one build's `plan.gpkg` as `compare --gpkg` reads them.
#[derive(Debug, Clone, Default)]
pub struct PlanLots(BTreeMap<String, LotRow>);

/// The lots of the build in `dir` (its `plan.gpkg`, read as untrusted input).
pub fn plan_lots(dir: &Path) -> Result<PlanLots, DiffError> {
    Build::open(dir)?.lots().map(PlanLots)
}

/// A lot two builds disagree on: its id, what differs, its outline's exterior ring in the
/// CRS's metres (the workbench outlines it in the viewer).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LotDiff {
    /// The lot's id.
    pub lot: String,
    /// `type, kura, house, trees` (those that differ), `only in A` or `only in B`.
    pub differs: String,
    /// The exterior ring, east and north.
    pub ring: Vec<[f64; 2]>,
}

/// The lots whose type, kura, house or trees differ between `a` and `b`, in id order.
pub fn lot_differences(a: &PlanLots, b: &PlanLots) -> Vec<LotDiff> {
    let ids: std::collections::BTreeSet<&String> = a.0.keys().chain(b.0.keys()).collect();
    let mut out = Vec::new();
    for id in ids {
        let (x, y) = (a.0.get(id), b.0.get(id));
        let differs = differs(x, y);
        if differs.is_empty() {
            continue;
        }
        let geom = y.or(x).and_then(|r| r.geom.as_deref());
        out.push(LotDiff {
            lot: id.clone(),
            differs,
            ring: geom.map(ring_of).unwrap_or_default(),
        });
    }
    out
}

/// The exterior ring of a GeoPackage polygon blob (its header, then WKB); empty when it is
/// none.
fn ring_of(blob: &[u8]) -> Vec<[f64; 2]> {
    use geo_traits::to_geo::ToGeoGeometry;
    // The header: "GP", version, flags, srs id; then an envelope its flags size.
    let Some(&flags) = blob.get(3) else {
        return Vec::new();
    };
    let envelope = match (flags >> 1) & 0b111 {
        0 => 0,
        1 => 32,
        2 | 3 => 48,
        4 => 64,
        _ => return Vec::new(),
    };
    let Some(wkb) = blob.get(8 + envelope..) else {
        return Vec::new();
    };
    let Ok(g) = wkb::reader::read_wkb(wkb) else {
        return Vec::new();
    };
    let ring = match g.to_geometry() {
        geo_types::Geometry::Polygon(p) => p.exterior().clone(),
        geo_types::Geometry::MultiPolygon(m) => match m.0.first() {
            Some(p) => p.exterior().clone(),
            None => return Vec::new(),
        },
        _ => return Vec::new(),
    };
    ring.0.iter().map(|c| [c.x, c.y]).collect()
}

/// Writes `out`: layer `lots` (each lot whose type, kura, house or trees differ between the
/// builds in `a` and `b`, or that only one has) and layer `tiles` (the tiles `differ`,
/// `only_a` and `only_b` name). Returns the number of lots that differ.
pub fn write_diff(
    a: &Path,
    b: &Path,
    differ: &[String],
    only_a: &[String],
    only_b: &[String],
    out: &Path,
) -> Result<usize, DiffError> {
    let (ba, bb) = (Build::open(a)?, Build::open(b)?);
    let (la, lb) = (ba.lots()?, bb.lots()?);
    let mut g = GeoPackage::create(out, ba.srs()?)?;
    let style = styles::categorized(
        Shape::Fill,
        "CASE WHEN \"differs\" LIKE 'only%' THEN 'only in one' WHEN \"differs\" LIKE \
         '%house%' THEN 'house' WHEN \"differs\" LIKE '%type%' THEN 'type' WHEN \"differs\" \
         LIKE '%kura%' THEN 'kura' ELSE 'trees' END",
        &[
            ("house".into(), Look::of([200, 60, 60])),
            ("type".into(), Look::of([230, 160, 60])),
            ("kura".into(), Look::of([70, 90, 210]).faded()),
            ("trees".into(), Look::of([70, 150, 70])),
            ("only in one".into(), Look::of([150, 150, 150]).hatched()),
        ],
        None,
    );
    let mut w = g.layer(
        "lots",
        Some(GeomKind::Polygon),
        &LOT_COLUMNS,
        "Lots whose type, kura, house or trees differ between A and B, with both values",
        Some(style),
    )?;
    let mut count = 0;
    let ids: std::collections::BTreeSet<&String> = la.keys().chain(lb.keys()).collect();
    for id in ids {
        let (x, y) = (la.get(id), lb.get(id));
        let differs = differs(x, y);
        if differs.is_empty() {
            continue;
        }
        count += 1;
        let first = y.or(x).expect("an id of either build");
        let mut row = vec![
            text_or_null(id),
            first.record.map_or(Value::Null, Value::Integer),
            text_or_null(&differs),
        ];
        let none = [Value::Null, Value::Null, Value::Null, Value::Null];
        let (vx, vy) = (
            x.map_or(none.clone(), LotRow::values),
            y.map_or(none, LotRow::values),
        );
        for (p, q) in vx.into_iter().zip(vy) {
            row.push(p);
            row.push(q);
        }
        w.add_blob(first.geom.as_deref(), &row)?;
    }
    w.end()?;
    let (ta, tb) = (ba.tiles()?, bb.tiles()?);
    let mut w = g.layer(
        "tiles",
        Some(GeomKind::Polygon),
        &[text("id"), text("difference")],
        "Tiles whose files differ between A and B, or that only one has",
        Some(styles::single(
            Shape::Fill,
            Look::of([230, 120, 40]).outline().sized(0.8),
        )),
    )?;
    for (ids, what) in [
        (differ, "differ"),
        (only_a, "only in A"),
        (only_b, "only in B"),
    ] {
        for id in ids {
            let geom = ta.get(id).or_else(|| tb.get(id)).cloned().flatten();
            w.add_blob(geom.as_deref(), &[text_or_null(id), text_or_null(what)])?;
        }
    }
    w.end()?;
    g.finish()?;
    Ok(count)
}
