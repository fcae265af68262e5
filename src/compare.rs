//! `edo-city compare outA outB`: what changed between two builds (two hypotheses).
//!
//! Reads only the two manifests: the parameters that differ, the counts side by side (per
//! type and per district), and which tiles' bytes differ. `--plan` draws the tiles that
//! changed on a map.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::Path;

use serde::Serialize;
use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

use crate::build::{shards, BuildError};
use crate::model::tile::parse_tile_id;
use crate::output::report::{assemble_report, Manifest, Report};
use crate::output::text::{draw_text, text_width};

/// One parameter whose value differs between the two builds.
#[derive(Debug, Clone, Serialize)]
pub struct ParamDiff {
    /// The parameter's dotted key (`kura.collision`).
    pub key: String,
    /// Its value in build A (`-` when absent).
    pub a: String,
    /// Its value in build B.
    pub b: String,
}

/// One count of both builds side by side.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// What is counted.
    pub name: String,
    /// In build A.
    pub a: usize,
    /// In build B.
    pub b: usize,
}

/// How the two builds' tiles compare, by the sha256 of their OBJ.
#[derive(Debug, Clone, Default, Serialize)]
pub struct TileDiff {
    /// Tiles identical in both.
    pub same: usize,
    /// Tiles in both whose bytes differ.
    pub differ: Vec<String>,
    /// Tiles only build A has.
    pub only_a: Vec<String>,
    /// Tiles only build B has.
    pub only_b: Vec<String>,
}

/// Two builds (two hypotheses) compared: what `compare` prints and `--json` writes.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Build A's directory.
    pub a: String,
    /// Build B's directory.
    pub b: String,
    /// The parameters that differ.
    pub params: Vec<ParamDiff>,
    /// The totals: lots, machiya, types given and drawn, footprints, kura, skips, tiles.
    pub totals: Vec<Row>,
    /// Machiya per type.
    pub by_type: Vec<Row>,
    /// Houses per district.
    pub by_district: Vec<Row>,
    /// The paper's Table 2 for both builds.
    pub table2: Vec<Row>,
    /// The tiles that changed.
    pub tiles: TileDiff,
    /// The street crowds per district (`people.motion = "boids"`): walkers and the mean
    /// lambda1-3 over the clip, in each build.
    pub crowds: Vec<CrowdRow>,
    /// Why the two builds' tiles are not the same places (another tile size, tile origin or
    /// CRS), when they are not: then a tile id names other ground in each.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grids_differ: Option<String>,
}

/// One district's crowd in both builds.
#[derive(Debug, Clone, Serialize)]
pub struct CrowdRow {
    /// The district ("" = none).
    pub district: String,
    /// Walkers in build A and in build B.
    pub agents: [usize; 2],
    /// Mean lambda1 over the clip, A and B.
    pub lambda1: [f64; 2],
    /// Mean lambda2, A and B.
    pub lambda2: [f64; 2],
    /// Mean lambda3, A and B.
    pub lambda3: [f64; 2],
}

/// The crowd rows of two reports, every district either has.
fn crowd_rows(
    a: &crate::output::report::Crowds,
    b: &crate::output::report::Crowds,
) -> Vec<CrowdRow> {
    let names: BTreeSet<&String> = a.by_district.keys().chain(b.by_district.keys()).collect();
    names
        .into_iter()
        .map(|d| {
            let (x, y) = (a.by_district.get(d), b.by_district.get(d));
            let m = |c: Option<&crate::output::report::DistrictCrowd>, k: usize| {
                c.map_or(0.0, |c| [c.mean.lambda1, c.mean.lambda2, c.mean.lambda3][k])
            };
            CrowdRow {
                district: d.clone(),
                agents: [x.map_or(0, |c| c.agents), y.map_or(0, |c| c.agents)],
                lambda1: [m(x, 0), m(y, 0)],
                lambda2: [m(x, 1), m(y, 1)],
                lambda3: [m(x, 2), m(y, 2)],
            }
        })
        .collect()
}

/// Why two builds' tile grids differ, if they do.
fn grids_differ(a: &Manifest, b: &Manifest) -> Option<String> {
    if a.params.tile_size != b.params.tile_size {
        return Some(format!(
            "the builds have other tile sizes ({} and {} m)",
            a.params.tile_size, b.params.tile_size
        ));
    }
    if a.params.tile_origin != b.params.tile_origin {
        return Some("the builds have other tile origins".into());
    }
    (a.crs != b.crs).then(|| "the builds are in other CRSs".into())
}

/// Leaf values of a JSON value by dotted key.
fn flatten(v: &serde_json::Value, prefix: &str, out: &mut BTreeMap<String, String>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(x, &key, out);
            }
        }
        other => {
            out.insert(prefix.to_string(), other.to_string());
        }
    }
}

fn rows(a: &BTreeMap<String, usize>, b: &BTreeMap<String, usize>) -> Vec<Row> {
    let keys: BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    keys.into_iter()
        .map(|k| Row {
            name: if k.is_empty() {
                "(none)".into()
            } else {
                k.clone()
            },
            a: a.get(k).copied().unwrap_or(0),
            b: b.get(k).copied().unwrap_or(0),
        })
        .collect()
}

fn load(dir: &Path) -> Result<(Manifest, Report), BuildError> {
    let m = shards::previous_manifest(dir, "`edo-city compare` compares two finished builds")?;
    let r = assemble_report(&m);
    Ok((m, r))
}

/// Compares the builds in two output directories.
pub fn compare(dir_a: &Path, dir_b: &Path) -> Result<Comparison, BuildError> {
    let (ma, ra) = load(dir_a)?;
    let (mb, rb) = load(dir_b)?;
    let (mut pa, mut pb) = (BTreeMap::new(), BTreeMap::new());
    flatten(
        &serde_json::to_value(&ma.params).expect("serialises"),
        "",
        &mut pa,
    );
    flatten(
        &serde_json::to_value(&mb.params).expect("serialises"),
        "",
        &mut pb,
    );
    let keys: BTreeSet<&String> = pa.keys().chain(pb.keys()).collect();
    let params = keys
        .into_iter()
        .filter(|k| pa.get(*k) != pb.get(*k))
        .map(|k| ParamDiff {
            key: k.clone(),
            a: pa.get(k).cloned().unwrap_or_else(|| "-".into()),
            b: pb.get(k).cloned().unwrap_or_else(|| "-".into()),
        })
        .collect();
    let (ca, cb) = (&ra.counts, &rb.counts);
    let totals = [
        ("lots", ca.lots, cb.lots),
        ("machiya", ca.machiya, cb.machiya),
        ("type from data", ca.type_given, cb.type_given),
        ("type drawn", ca.type_drawn, cb.type_drawn),
        ("footprints", ca.footprints, cb.footprints),
        (
            "frontage fallback",
            ca.frontage_fallback,
            cb.frontage_fallback,
        ),
        ("kura", ca.kura, cb.kura),
        ("skipped", ca.skipped, cb.skipped),
        ("tiles", ca.tiles, cb.tiles),
    ]
    .into_iter()
    .map(|(n, a, b)| Row {
        name: n.into(),
        a,
        b,
    })
    .collect();
    let hashes = |m: &Manifest| -> BTreeMap<String, String> {
        m.tiles
            .iter()
            .map(|t| {
                // A tile is the same when every file of it is (whatever the formats).
                let h: Vec<&str> = t.files().map(|f| f.sha256.as_str()).collect();
                (t.id.clone(), h.join(" "))
            })
            .collect()
    };
    let (ha, hb) = (hashes(&ma), hashes(&mb));
    let mut tiles = TileDiff::default();
    for (id, h) in &ha {
        match hb.get(id) {
            Some(x) if x == h => tiles.same += 1,
            Some(_) => tiles.differ.push(id.clone()),
            None => tiles.only_a.push(id.clone()),
        }
    }
    tiles.only_b = hb
        .keys()
        .filter(|id| !ha.contains_key(*id))
        .cloned()
        .collect();
    Ok(Comparison {
        a: dir_a.display().to_string(),
        b: dir_b.display().to_string(),
        params,
        totals,
        by_type: rows(&ca.by_type, &cb.by_type),
        by_district: rows(&ca.by_district, &cb.by_district),
        table2: {
            let (ta, tb) = (&ra.table2.all, &rb.table2.all);
            [
                ("machiya", ta.machiya, tb.machiya),
                ("kura candidates", ta.kura_candidates, tb.kura_candidates),
                (
                    "without avoidance",
                    ta.kura_without_avoidance,
                    tb.kura_without_avoidance,
                ),
                (
                    "with avoidance",
                    ta.kura_with_avoidance,
                    tb.kura_with_avoidance,
                ),
            ]
            .into_iter()
            .map(|(n, a, b)| Row {
                name: n.into(),
                a,
                b,
            })
            .collect()
        },
        tiles,
        crowds: crowd_rows(&ra.crowds, &rb.crowds),
        grids_differ: grids_differ(&ma, &mb),
    })
}

/// The comparison as a table for people.
pub fn render(c: &Comparison) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "A = {}\nB = {}\n", c.a, c.b);
    if c.params.is_empty() {
        let _ = writeln!(s, "parameters: the same");
    } else {
        let _ = writeln!(s, "parameters that differ:");
        for p in &c.params {
            let _ = writeln!(s, "  {:<36} {:>14} {:>14}", p.key, p.a, p.b);
        }
    }
    let table = |s: &mut String, title: &str, rows: &[Row]| {
        let _ = writeln!(s, "\n{title:<24} {:>9} {:>9} {:>9}", "A", "B", "B-A");
        for r in rows {
            let d = r.b as i64 - r.a as i64;
            let _ = writeln!(s, "  {:<22} {:>9} {:>9} {:>+9}", r.name, r.a, r.b, d);
        }
    };
    table(&mut s, "counts", &c.totals);
    table(&mut s, "machiya by type", &c.by_type);
    table(&mut s, "houses by district", &c.by_district);
    table(&mut s, "kura (Table 2)", &c.table2);
    if !c.crowds.is_empty() {
        let _ = writeln!(
            s,
            "\n{:<24} {:>13} {:>15} {:>15} {:>15}",
            "crowds (mean over the clip)",
            "walkers A/B",
            "lambda1 A/B",
            "lambda2 A/B",
            "lambda3 A/B"
        );
        for r in &c.crowds {
            let _ = writeln!(
                s,
                "  {:<22} {:>6}/{:<6} {:>7.3}/{:<7.3} {:>7.3}/{:<7.3} {:>7.3}/{:<7.3}",
                r.district,
                r.agents[0],
                r.agents[1],
                r.lambda1[0],
                r.lambda1[1],
                r.lambda2[0],
                r.lambda2[1],
                r.lambda3[0],
                r.lambda3[1]
            );
        }
    }
    let t = &c.tiles;
    let list = |v: &[String]| {
        if v.is_empty() {
            "-".to_string()
        } else {
            v.join(", ")
        }
    };
    let _ = writeln!(
        s,
        "\ntiles: {} identical, {} differ ({}), only in A: {}, only in B: {}",
        t.same,
        t.differ.len(),
        list(&t.differ),
        list(&t.only_a),
        list(&t.only_b)
    );
    if let Some(why) = &c.grids_differ {
        let _ = writeln!(
            s,
            "note: {why}: a tile id names other ground in each, so the tile lines compare \
             files, not places"
        );
    }
    s
}

/// Writes `path`: the lots and tiles that differ between the builds in `dir_a` and
/// `dir_b`, as GeoPackage layers (`output::gpkg::write_diff`); returns how many lots differ.
pub fn write_gpkg(
    c: &Comparison,
    dir_a: &Path,
    dir_b: &Path,
    path: &Path,
) -> Result<usize, CompareError> {
    let reads = [(dir_a, "build A"), (dir_b, "build B")];
    crate::output::target::check(path, crate::output::target::Kind::GeoPackage, &reads)?;
    let t = &c.tiles;
    crate::output::gpkg::write_diff(dir_a, dir_b, &t.differ, &t.only_a, &t.only_b, path).map_err(
        |e| match e {
            crate::output::gpkg::DiffError::Write(w) => {
                let (file, cause) = w.into_io();
                CompareError::Write {
                    file: file.display().to_string(),
                    cause,
                }
            }
            other => CompareError::Diff(other),
        },
    )
}

/// Why two builds cannot be compared so, or their comparison not written.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A build cannot be read.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The GeoPackage would be written over a build.
    #[error(transparent)]
    Target(#[from] crate::output::target::Refused),
    /// The differing tiles' GeoPackage cannot be written.
    #[error("cannot write {file}: {cause}")]
    Write {
        /// The file.
        file: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
    /// A build's tiles cannot be read for the GeoPackage.
    #[error(transparent)]
    Diff(crate::output::gpkg::DiffError),
    /// The builds cut the city on other grids.
    #[error(
        "no difference map: {0}, so their tiles are not the same places; compare the \
         counts (without --plan), or build both with one grid"
    )]
    OtherGrids(String),
    /// No tile on the grid.
    #[error("no tiles on the grid to draw")]
    NoTiles,
    /// The tiles span too many cells.
    #[error(
        "no difference map: the tiles span {cols} x {rows} cells of the grid, more than \
         {MAX_MAP_CELLS} a side (tiles far apart, or ids given in the data); compare the \
         counts (without --plan)"
    )]
    MapTooWide {
        /// Columns spanned.
        cols: i64,
        /// Rows spanned.
        rows: i64,
    },
    /// The picture cannot be made.
    #[error("map too large")]
    MapTooLarge,
    /// The picture cannot be encoded.
    #[error("cannot encode the map: {0}")]
    Encode(String),
}

/// The widest difference map, in tiles a side (8 pixels each at most: 12,000 pixels).
const MAX_MAP_CELLS: i64 = 1500;

/// A map of the tile grid: unchanged tiles grey, changed orange, only in A blue, only in B
/// green, with their ids. Tiles named in the data (not `col_row`) are left out.
pub fn difference_map(c: &Comparison, dir_a: &Path) -> Result<Vec<u8>, CompareError> {
    let m = shards::previous_manifest(dir_a, "`edo-city compare --plan` maps two finished builds")?;
    let (size, origin) = (m.params.tile_size, m.params.tile_origin);
    // One grid for both builds, or the map would draw tiles of two grids as one.
    if let Some(why) = &c.grids_differ {
        return Err(CompareError::OtherGrids(why.clone()));
    }
    let mut cells: Vec<(i64, i64, &String, [u8; 3])> = Vec::new();
    let same: Vec<String> = m
        .tiles
        .iter()
        .map(|t| t.id.clone())
        .filter(|id| !c.tiles.differ.contains(id) && !c.tiles.only_a.contains(id))
        .collect();
    for (ids, colour) in [
        (&same, [215, 215, 210]),
        (&c.tiles.differ, [240, 150, 60]),
        (&c.tiles.only_a, [90, 130, 210]),
        (&c.tiles.only_b, [100, 180, 100]),
    ] {
        for id in ids {
            if let Some((col, row)) = parse_tile_id(id) {
                cells.push((col, row, id, colour));
            }
        }
    }
    if cells.is_empty() {
        return Err(CompareError::NoTiles);
    }
    let (c0, c1) = (
        cells.iter().map(|x| x.0).min().unwrap_or(0),
        cells.iter().map(|x| x.0).max().unwrap_or(0),
    );
    let (r0, r1) = (
        cells.iter().map(|x| x.1).min().unwrap_or(0),
        cells.iter().map(|x| x.1).max().unwrap_or(0),
    );
    let (cols, rows) = (c1 - c0 + 1, r1 - r0 + 1);
    if cols.max(rows) > MAX_MAP_CELLS {
        return Err(CompareError::MapTooWide { cols, rows });
    }
    let cell = (1200 / (cols.max(rows)) as u32).clamp(8, 200);
    let (w, h) = (
        ((c1 - c0 + 1) as u32) * cell,
        ((r1 - r0 + 1) as u32) * cell + 40,
    );
    let mut pm = Pixmap::new(w, h).ok_or(CompareError::MapTooLarge)?;
    pm.fill(Color::from_rgba8(250, 248, 242, 255));
    for (col, row, id, colour) in &cells {
        let x = ((col - c0) as u32 * cell) as f32;
        let y = ((r1 - row) as u32 * cell) as f32 + 40.0;
        let mut p = Paint::default();
        p.set_color_rgba8(colour[0], colour[1], colour[2], 255);
        if let Some(r) = Rect::from_xywh(x + 1.0, y + 1.0, cell as f32 - 2.0, cell as f32 - 2.0) {
            pm.fill_rect(r, &p, Transform::identity(), None);
        }
        if text_width(id, 1) + 4 < cell {
            draw_text(&mut pm, x + 3.0, y + 3.0, id, 1, [40, 40, 40]);
        }
    }
    let caption = format!(
        "{} m tiles from x {} y {}: grey same, orange differ, blue only A, green only B",
        size, origin[0], origin[1]
    );
    draw_text(&mut pm, 4.0, 4.0, &caption, 1, [30, 30, 30]);
    pm.encode_png()
        .map_err(|e| CompareError::Encode(e.to_string()))
}
