//! A layer's spatial index, `rtree_<layer>_geom`, written packed.
//!
//! SQLite's R*Tree module inserts one box at a time (choose a leaf, split, reinsert): at a
//! million lots that was 40 of the 57 s plan.gpkg took. It has no bulk load, so the index is
//! packed here, as GDAL's GeoPackage driver does since 3.7 (`gdal_sqlite_rtree_bl.cpp`):
//! boxes sorted along a Z-order curve, cut into full nodes, level by level up to one root,
//! and the module's three shadow tables written as it would have left them (rtree.c's node
//! format: a 2-byte depth in the root, a 2-byte cell count, then per cell the 8-byte id and
//! four 4-byte floats, all big-endian). SQLite's `rtreecheck()` passes on the result
//! (tests).

use rusqlite::{params, Connection};

/// A box as the R*Tree keeps it: 32-bit floats rounded outwards.
pub type Cell = (i64, [f32; 4]);

/// `[min_x, max_x, min_y, max_y]` in f64 as the module rounds it into f32 (rtree.c's
/// `rtreeValueDown` / `rtreeValueUp`), so a query never misses a feature on its edge.
pub fn cell_box(e: [f64; 4]) -> [f32; 4] {
    const TOWARDS: f64 = 1.0 - 1.0 / 8_388_608.0;
    const AWAY: f64 = 1.0 + 1.0 / 8_388_608.0;
    let down = |d: f64| {
        let f = d as f32;
        match f64::from(f) > d {
            true => (d * if d < 0.0 { AWAY } else { TOWARDS }) as f32,
            false => f,
        }
    };
    let up = |d: f64| {
        let f = d as f32;
        match f64::from(f) < d {
            true => (d * if d < 0.0 { TOWARDS } else { AWAY }) as f32,
            false => f,
        }
    };
    [down(e[0]), up(e[1]), down(e[2]), up(e[3])]
}

/// Writes `cells` (each feature's fid and box) as the index `table` (created empty by
/// `CREATE VIRTUAL TABLE ... USING rtree`, and not touched through the module since).
pub fn write(conn: &Connection, table: &str, cells: &mut [Cell]) -> rusqlite::Result<()> {
    if cells.is_empty() {
        return Ok(());
    }
    let q = |suffix: &str| super::quoted(&format!("{table}_{suffix}"));
    let size: usize = conn.query_row(
        &format!("SELECT length(data) FROM {} WHERE nodeno = 1", q("node")),
        [],
        |r| r.get(0),
    )?;
    // 51 cells of 24 bytes after a 4-byte header for 4096-byte pages (rtree.c's
    // RTREE_MAXCELLS); read back, not assumed.
    let fan = ((size.saturating_sub(4)) / 24).clamp(2, 51);
    sort_along_z(cells);
    // Levels from the leaves up: each a list of nodes, each node its cells.
    let mut levels: Vec<Vec<Vec<Cell>>> = Vec::new();
    let mut below: Vec<Cell> = cells.to_vec();
    loop {
        let nodes: Vec<Vec<Cell>> = below.chunks(fan).map(<[Cell]>::to_vec).collect();
        let done = nodes.len() == 1;
        below = nodes
            .iter()
            .enumerate()
            .map(|(i, n)| (i as i64, union(n)))
            .collect();
        levels.push(nodes);
        if done {
            break;
        }
    }
    // Node numbers from the root (1) down, level by level.
    levels.reverse();
    let mut first = Vec::with_capacity(levels.len());
    let mut next = 1i64;
    for level in &levels {
        first.push(next);
        next += level.len() as i64;
    }
    let depth = levels.len() - 1;
    let mut node = conn.prepare(&format!(
        "INSERT OR REPLACE INTO {} VALUES (?1, ?2)",
        q("node")
    ))?;
    let mut parent = conn.prepare(&format!("INSERT INTO {} VALUES (?1, ?2)", q("parent")))?;
    let mut blob = vec![0u8; size];
    for (l, level) in levels.iter().enumerate() {
        let leaf = l == depth;
        for (i, cells) in level.iter().enumerate() {
            let number = first[l] + i as i64;
            blob.fill(0);
            if l == 0 {
                blob[..2].copy_from_slice(&(depth as u16).to_be_bytes());
            }
            blob[2..4].copy_from_slice(&(cells.len() as u16).to_be_bytes());
            for (c, (id, b)) in cells.iter().enumerate() {
                // A parent's cells name its children by node number.
                let id = if leaf { *id } else { first[l + 1] + id };
                let at = 4 + 24 * c;
                blob[at..at + 8].copy_from_slice(&id.to_be_bytes());
                for (k, v) in b.iter().enumerate() {
                    let o = at + 8 + 4 * k;
                    blob[o..o + 4].copy_from_slice(&v.to_bits().to_be_bytes());
                }
            }
            node.execute(params![number, &blob[..]])?;
            if !leaf {
                for (id, _) in cells {
                    parent.execute(params![first[l + 1] + id, number])?;
                }
            }
        }
    }
    // Each feature's leaf, in fid order (the table's key: appended, not inserted).
    let leaves = first[depth];
    let mut rows: Vec<(i64, i64)> = levels[depth]
        .iter()
        .enumerate()
        .flat_map(|(i, cells)| cells.iter().map(move |(id, _)| (*id, leaves + i as i64)))
        .collect();
    rows.sort_unstable();
    let mut rowid = conn.prepare(&format!("INSERT INTO {} VALUES (?1, ?2)", q("rowid")))?;
    for (id, n) in rows {
        rowid.execute(params![id, n])?;
    }
    Ok(())
}

/// The spatial index's triggers, as the standard gives them (Annex F.3), for a layer whose
/// index was written when its features were. They call `ST_*` functions that GDAL and
/// QGIS register when they edit the file; this writer never fires them.
pub fn triggers(t: &str) -> String {
    let (tq, r) = (super::quoted(t), super::quoted(&format!("rtree_{t}_geom")));
    let n = |suffix: &str| super::quoted(&format!("rtree_{t}_geom_{suffix}"));
    format!(
        "CREATE TRIGGER {insert} AFTER INSERT ON {tq}
           WHEN (new.geom NOT NULL AND NOT ST_IsEmpty(NEW.geom))
         BEGIN
           INSERT OR REPLACE INTO {r} VALUES (NEW.fid, ST_MinX(NEW.geom), ST_MaxX(NEW.geom),
             ST_MinY(NEW.geom), ST_MaxY(NEW.geom));
         END;
         CREATE TRIGGER {update1} AFTER UPDATE OF geom ON {tq}
           WHEN OLD.fid = NEW.fid AND (NEW.geom NOTNULL AND NOT ST_IsEmpty(NEW.geom))
         BEGIN
           INSERT OR REPLACE INTO {r} VALUES (NEW.fid, ST_MinX(NEW.geom), ST_MaxX(NEW.geom),
             ST_MinY(NEW.geom), ST_MaxY(NEW.geom));
         END;
         CREATE TRIGGER {update2} AFTER UPDATE OF geom ON {tq}
           WHEN OLD.fid = NEW.fid AND (NEW.geom ISNULL OR ST_IsEmpty(NEW.geom))
         BEGIN
           DELETE FROM {r} WHERE id = OLD.fid;
         END;
         CREATE TRIGGER {update3} AFTER UPDATE ON {tq}
           WHEN OLD.fid != NEW.fid AND (NEW.geom NOTNULL AND NOT ST_IsEmpty(NEW.geom))
         BEGIN
           DELETE FROM {r} WHERE id = OLD.fid;
           INSERT OR REPLACE INTO {r} VALUES (NEW.fid, ST_MinX(NEW.geom), ST_MaxX(NEW.geom),
             ST_MinY(NEW.geom), ST_MaxY(NEW.geom));
         END;
         CREATE TRIGGER {update4} AFTER UPDATE ON {tq}
           WHEN OLD.fid != NEW.fid AND (NEW.geom ISNULL OR ST_IsEmpty(NEW.geom))
         BEGIN
           DELETE FROM {r} WHERE id IN (OLD.fid, NEW.fid);
         END;
         CREATE TRIGGER {delete} AFTER DELETE ON {tq}
           WHEN old.geom NOT NULL
         BEGIN
           DELETE FROM {r} WHERE id = OLD.fid;
         END;",
        insert = n("insert"),
        update1 = n("update1"),
        update2 = n("update2"),
        update3 = n("update3"),
        update4 = n("update4"),
        delete = n("delete"),
    )
}

/// The box holding every cell.
fn union(cells: &[Cell]) -> [f32; 4] {
    cells.iter().fold(
        [
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ],
        |a, (_, b)| {
            [
                a[0].min(b[0]),
                a[1].max(b[1]),
                a[2].min(b[2]),
                a[3].max(b[3]),
            ]
        },
    )
}

/// Sorts cells by the Z-order of their centres over their extent (ties by id), so a node's
/// cells lie near each other.
fn sort_along_z(cells: &mut [Cell]) {
    let all = union(cells);
    let q = |v: f32, lo: f32, hi: f32| -> u32 {
        let t = if hi > lo { (v - lo) / (hi - lo) } else { 0.0 };
        (t.clamp(0.0, 1.0) * 65535.0) as u32
    };
    let key = |b: &[f32; 4]| {
        let x = q((b[0] + b[1]) / 2.0, all[0], all[1]);
        let y = q((b[2] + b[3]) / 2.0, all[2], all[3]);
        spread(x) | (spread(y) << 1)
    };
    // Each key once (the ids make them unique, so the order is the same as any sort's).
    cells.sort_by_cached_key(|(id, b)| (key(b), *id));
}

/// The bits of a 16-bit number with a zero between each two.
fn spread(v: u32) -> u64 {
    let mut v = u64::from(v & 0xffff);
    v = (v | (v << 8)) & 0x00ff_00ff;
    v = (v | (v << 4)) & 0x0f0f_0f0f;
    v = (v | (v << 2)) & 0x3333_3333;
    (v | (v << 1)) & 0x5555_5555
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table indexed packed answers box queries as one filled by the module itself, and
    /// passes SQLite's own check of its structure.
    #[test]
    fn a_packed_index_answers_as_the_modules_own() {
        for n in [1usize, 7, 51, 52, 2601, 2602, 9000] {
            // Fresh tables each time: the module never sees them before they are written.
            let conn = Connection::open_in_memory().unwrap();
            conn.execute_batch(
                "CREATE VIRTUAL TABLE packed USING rtree(id, minx, maxx, miny, maxy);
                 CREATE VIRTUAL TABLE plain USING rtree(id, minx, maxx, miny, maxy);",
            )
            .unwrap();
            let mut cells: Vec<Cell> = Vec::new();
            for i in 0..n {
                let (x, y) = (
                    (i * 7919 % 1000) as f64 * 1.37,
                    (i * 104_729 % 997) as f64 * 0.61,
                );
                let e = [x - 5000.123, x - 4990.0, y + 1e5, y + 100_004.5];
                cells.push((i as i64 + 1, cell_box(e)));
                conn.execute(
                    "INSERT INTO plain VALUES (?1, ?2, ?3, ?4, ?5)",
                    params![i as i64 + 1, e[0], e[1], e[2], e[3]],
                )
                .unwrap();
            }
            write(&conn, "packed", &mut cells).unwrap();
            let check: String = conn
                .query_row("SELECT rtreecheck('packed')", [], |r| r.get(0))
                .unwrap();
            assert_eq!(check, "ok", "{n} boxes");
            for (x0, y0) in [(-5000.0, 1e5), (-4000.0, 100_300.0), (-3700.0, 100_500.0)] {
                let q = |t: &str| -> Vec<i64> {
                    let mut s = conn
                        .prepare(&format!(
                            "SELECT id FROM {t} WHERE maxx >= ?1 AND minx <= ?2 AND maxy >= ?3 \
                             AND miny <= ?4 ORDER BY id"
                        ))
                        .unwrap();
                    s.query_map(params![x0, x0 + 300.0, y0, y0 + 200.0], |r| r.get(0))
                        .unwrap()
                        .map(Result::unwrap)
                        .collect()
                };
                assert_eq!(q("packed"), q("plain"), "{n} boxes at {x0} {y0}");
            }
            let count: i64 = conn
                .query_row("SELECT count(*) FROM packed", [], |r| r.get(0))
                .unwrap();
            assert_eq!(count, n as i64);
        }
    }

    #[test]
    fn boxes_round_outwards_as_the_module_rounds_them() {
        let e = [0.1, 0.2, -0.3, 1e8 + 0.5];
        let b = cell_box(e);
        assert!(f64::from(b[0]) <= e[0] && f64::from(b[1]) >= e[1]);
        assert!(f64::from(b[2]) <= e[2] && f64::from(b[3]) >= e[3]);
        assert_eq!(cell_box([2.0, 4.0, -8.0, 16.0]), [2.0, 4.0, -8.0, 16.0]);
    }
}
