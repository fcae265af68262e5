//! `edo-city synth`: writes a Kyoto-like shapefile directory of any size.
//!
//! A grid of square blocks of 40 jo (121.2 m) with streets between them (every fourth street a
//! wide avenue). Town lots are narrow, deep strips ("eel's beds", unagi no nedoko) along every
//! block face, 1.5 to 5 ken wide; the lots on the north and south faces reach up to half the
//! block deep, those on the east and west faces hold the corners. A few blocks are whole
//! samurai or temple lots. Attributes are written in Shift_JIS with a `.cpg`, as Japanese
//! municipal data is, and about a quarter of the town lots carry a machiya type in kanji.
//! Coordinates are JGD2011 plane rectangular zone VI metres near central Kyoto.

use std::path::Path;

use rand::RngExt;
use rand_pcg::Pcg64;
use shapefile::{Point, Polygon, PolygonRing, Polyline};

use crate::rng::feature_rng;

/// One ken (間), the unit of frontage, in metres.
pub const KEN: f64 = 1.818;
/// One jo (丈) in metres.
pub const JO: f64 = 3.03;
const BLOCK: f64 = 40.0 * JO;
const STREET: f64 = 7.0;
const AVENUE: f64 = 12.0;
/// South-west corner of the synthetic town (zone VI: x east, y north).
const BASE: [f64; 2] = [-23_000.0, -110_000.0];
const ZONE6_PRJ: &str = r#"PROJCS["JGD2011 / Japan Plane Rectangular CS VI",GEOGCS["JGD2011",DATUM["Japanese_Geodetic_Datum_2011",SPHEROID["GRS 1980",6378137,298.257222101]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",36],PARAMETER["central_meridian",136],PARAMETER["scale_factor",0.9999],PARAMETER["false_easting",0],PARAMETER["false_northing",0],UNIT["metre",1]]"#;

/// What `synth` wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SynthSummary {
    /// Lots written.
    pub lots: usize,
    /// Of them town lots (machiya).
    pub machiya: usize,
    /// Blocks written.
    pub blocks: usize,
    /// Street centrelines written.
    pub streets: usize,
}

/// A lot before it is written: outline (counter-clockwise) and attributes.
#[derive(Debug, Clone)]
pub struct SynthLot {
    /// The lot's id, from 1.
    pub id: u64,
    /// Its outline, counter-clockwise, not closed.
    pub ring: Vec<[f64; 2]>,
    /// Its use (`machiya`, `buke`, ...).
    pub lot_use: &'static str,
    /// Its machiya type in kanji, or "" (drawn by the build).
    pub mtype: &'static str,
    /// Its district.
    pub district: &'static str,
}

/// A synthetic town in memory.
#[derive(Debug, Clone)]
pub struct Town {
    /// The lots, in id order.
    pub lots: Vec<SynthLot>,
    /// Block outlines, counter-clockwise.
    pub blocks: Vec<Vec<[f64; 2]>>,
    /// Street centrelines with their full width.
    pub streets: Vec<(Vec<[f64; 2]>, f64)>,
}

/// Machiya types written into the data (kanji, as in the machiya database), with weights.
const GIVEN_TYPES: &[(&str, f64)] = &[
    ("平屋", 30.0),
    ("中二階", 30.0),
    ("総二階", 15.0),
    ("仕舞屋", 8.0),
    ("塀付", 6.0),
    ("三階", 5.0),
    ("看板建", 6.0),
];
const DISTRICTS: [&str; 3] = ["上京", "中京", "下京"];

fn pick<'a>(rng: &mut Pcg64, items: &'a [(&'a str, f64)]) -> &'a str {
    let total: f64 = items.iter().map(|i| i.1).sum();
    let mut r = rng.random::<f64>() * total;
    for (name, w) in items {
        if r < *w {
            return name;
        }
        r -= w;
    }
    items[items.len() - 1].0
}

/// Makes the town in memory: lots, block outlines and street centrelines (with widths).
pub fn make_town(lots_wanted: usize, seed: u64) -> Town {
    // About 64 lots fit a block; lay the blocks out in a near-square grid.
    let blocks_needed = lots_wanted.div_ceil(60).max(1);
    let nx = (blocks_needed as f64).sqrt().ceil() as usize;
    let ny = blocks_needed.div_ceil(nx);
    let width = |i: usize| if i.is_multiple_of(4) { AVENUE } else { STREET };
    // Street centreline positions along each axis.
    let lines = |n: usize| {
        let mut pos = vec![0.0];
        for i in 0..n {
            let next = pos[i] + width(i) / 2.0 + BLOCK + width(i + 1) / 2.0;
            pos.push(next);
        }
        pos
    };
    let xs = lines(nx);
    let ys = lines(ny);

    let mut lots = Vec::with_capacity(lots_wanted);
    let mut blocks = Vec::new();
    'grid: for by in 0..ny {
        for (bx, x) in xs[..nx].iter().enumerate() {
            if lots.len() >= lots_wanted {
                break 'grid;
            }
            let x0 = BASE[0] + x + width(bx) / 2.0;
            let y0 = BASE[1] + ys[by] + width(by) / 2.0;
            blocks.push(rect(x0, y0, BLOCK, BLOCK));
            let district = DISTRICTS[(2 - (by * 3 / ny).min(2)).min(2)];
            let block_id = (by * nx + bx) as u64;
            let mut rng = feature_rng(seed, "synth/block", &block_id.to_string());
            let roll = rng.random::<f64>();
            if roll < 0.05 || (roll < 0.08 && lots_wanted - lots.len() > 1) {
                lots.push(SynthLot {
                    id: lots.len() as u64 + 1,
                    ring: rect(x0, y0, BLOCK, BLOCK),
                    lot_use: if roll < 0.05 { "buke" } else { "jisha" },
                    mtype: "",
                    district,
                });
                continue;
            }
            block_lots(&mut lots, lots_wanted, &mut rng, x0, y0, district);
        }
    }
    let mut streets = Vec::new();
    let (x_end, y_end) = (xs[nx], ys[ny]);
    for (i, x) in xs.iter().enumerate() {
        streets.push((
            vec![[BASE[0] + x, BASE[1]], [BASE[0] + x, BASE[1] + y_end]],
            width(i),
        ));
    }
    for (j, y) in ys.iter().enumerate() {
        streets.push((
            vec![[BASE[0], BASE[1] + y], [BASE[0] + x_end, BASE[1] + y]],
            width(j),
        ));
    }
    Town {
        lots,
        blocks,
        streets,
    }
}

fn rect(x0: f64, y0: f64, w: f64, h: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]
}

/// Frontage widths that fill `length` exactly: 1.5 to 5 ken each.
fn frontages(rng: &mut Pcg64, length: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut left = length;
    while left > 0.0 {
        let w = rng.random_range(1.5..5.0) * KEN;
        if left - w < 1.5 * KEN {
            if left > 5.0 * KEN {
                out.push(left / 2.0);
                out.push(left / 2.0);
            } else {
                out.push(left);
            }
            break;
        }
        out.push(w);
        left -= w;
    }
    out
}

/// Lots along the four faces of one block.
fn block_lots(
    lots: &mut Vec<SynthLot>,
    wanted: usize,
    rng: &mut Pcg64,
    x0: f64,
    y0: f64,
    district: &'static str,
) {
    let side_depth = rng.random_range(14.0..22.0);
    let push = |lots: &mut Vec<SynthLot>, rng: &mut Pcg64, ring: Vec<[f64; 2]>| {
        if lots.len() >= wanted {
            return;
        }
        let mtype = if rng.random::<f64>() < 0.25 {
            pick(rng, GIVEN_TYPES)
        } else {
            ""
        };
        lots.push(SynthLot {
            id: lots.len() as u64 + 1,
            ring,
            lot_use: "machiya",
            mtype,
            district,
        });
    };
    // West and east faces: full height of the block, they hold the corners.
    for east in [false, true] {
        let mut y = y0;
        for w in frontages(rng, BLOCK) {
            let ring = if east {
                let x = x0 + BLOCK;
                vec![
                    [x - side_depth, y],
                    [x, y],
                    [x, y + w],
                    [x - side_depth, y + w],
                ]
            } else {
                vec![
                    [x0, y],
                    [x0 + side_depth, y],
                    [x0 + side_depth, y + w],
                    [x0, y + w],
                ]
            };
            push(lots, rng, ring);
            y += w;
        }
    }
    // South and north faces between the side lots: deep strips with slightly slanted sides,
    // as cadastral lots are; neighbours share their side lines, so lots never overlap.
    let inner = BLOCK - 2.0 * side_depth;
    for north in [false, true] {
        let widths = frontages(rng, inner);
        let mut bounds = vec![(x0 + side_depth, 0.0)];
        let mut x = x0 + side_depth;
        for (k, w) in widths.iter().enumerate() {
            x += w;
            let slant = if k + 1 == widths.len() {
                0.0
            } else {
                rng.random_range(-0.01..0.01)
            };
            bounds.push((x, slant));
        }
        for k in 0..widths.len() {
            let depth = BLOCK / 2.0 * rng.random_range(0.55..1.0);
            let (xa, sa) = bounds[k];
            let (xb, sb) = bounds[k + 1];
            let ring = if north {
                let yf = y0 + BLOCK;
                vec![
                    [xa + sa * depth, yf - depth],
                    [xb + sb * depth, yf - depth],
                    [xb, yf],
                    [xa, yf],
                ]
            } else {
                vec![
                    [xa, y0],
                    [xb, y0],
                    [xb + sb * depth, y0 + depth],
                    [xa + sa * depth, y0 + depth],
                ]
            };
            push(lots, rng, ring);
        }
    }
}

/// Writes `lots.shp`, `blocks.shp`, `streets.shp` (with `.cpg` and `.prj`) into `dir`.
/// The largest town `synth` makes (ten times the largest benchmark).
pub const MAX_LOTS: usize = 10_000_000;

/// Writes a town of `lots_wanted` lots into `dir`. A directory that already holds files is
/// refused unless `force`: synth would overwrite a user's shapefiles, and a `lots.csv` left
/// there would be joined onto the synthetic lots.
pub fn write_town(
    dir: &Path,
    lots_wanted: usize,
    seed: u64,
    force: bool,
) -> Result<SynthSummary, String> {
    if lots_wanted == 0 || lots_wanted > MAX_LOTS {
        return Err(format!(
            "--lots must be from 1 to {MAX_LOTS}, got {lots_wanted}"
        ));
    }
    if !force {
        if let Ok(mut entries) = std::fs::read_dir(dir) {
            if let Some(e) = entries.next() {
                let name = e.map(|e| e.file_name().to_string_lossy().into_owned());
                return Err(format!(
                    "{} is not empty (it holds {}): synth would overwrite its files, and a \
                     lots.csv there would be joined onto the synthetic lots; give an empty or \
                     new directory, or --force",
                    dir.display(),
                    name.unwrap_or_default()
                ));
            }
        } else if dir.exists() {
            return Err(format!("{} is not a directory", dir.display()));
        }
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let Town {
        lots,
        blocks,
        streets,
    } = make_town(lots_wanted, seed);
    write_lots(&dir.join("lots.shp"), &lots)?;
    write_blocks(&dir.join("blocks.shp"), &blocks)?;
    write_streets(&dir.join("streets.shp"), &streets)?;
    Ok(SynthSummary {
        lots: lots.len(),
        machiya: lots.iter().filter(|l| l.lot_use == "machiya").count(),
        blocks: blocks.len(),
        streets: streets.len(),
    })
}

fn shp_err(path: &Path) -> impl Fn(shapefile::Error) -> String + '_ {
    move |e| format!("cannot write {}: {e}", path.display())
}

/// The date written into every DBF header we make (bytes 1-3: years since 1900, month, day).
/// The dbase crate stamps the day of writing; a fixed date makes the same town the same bytes
/// on any day (the committed fixtures and the corpus of broken inputs are compared byte for
/// byte with what their scripts make).
pub const DBF_DATE: [u8; 3] = [100, 1, 1];

/// Overwrites the last-update date of the DBF at `path` with [`DBF_DATE`]. A file too short
/// to hold a header is left as it is.
pub fn stamp_dbf_date(path: &Path) -> std::io::Result<()> {
    use std::io::{Seek, SeekFrom, Write};
    let mut f = std::fs::OpenOptions::new().write(true).open(path)?;
    if f.metadata()?.len() >= 32 {
        f.seek(SeekFrom::Start(1))?;
        f.write_all(&DBF_DATE)?;
    }
    Ok(())
}

fn sidecars(path: &Path, cpg: &str) -> Result<(), String> {
    let dbf = path.with_extension("dbf");
    stamp_dbf_date(&dbf).map_err(|e| format!("cannot write {}: {e}", dbf.display()))?;
    let w = |ext: &str, text: &str| {
        std::fs::write(path.with_extension(ext), text)
            .map_err(|e| format!("cannot write {}: {e}", path.with_extension(ext).display()))
    };
    w("cpg", cpg)?;
    w("prj", ZONE6_PRJ)
}

/// Clockwise ring for the shapefile (outer rings are clockwise there).
fn shp_polygon(ring: &[[f64; 2]]) -> Polygon {
    let mut pts: Vec<Point> = ring.iter().rev().map(|p| Point::new(p[0], p[1])).collect();
    pts.push(pts[0]);
    Polygon::new(PolygonRing::Outer(pts))
}

fn field(name: &str) -> dbase::FieldName {
    dbase::FieldName::try_from(name).expect("field names here are short ASCII")
}

/// Writes a lots layer in Shift_JIS (also used by tests to make small fixtures).
pub fn write_lots(path: &Path, lots: &[SynthLot]) -> Result<(), String> {
    let table = dbase::TableWriterBuilder::with_encoding(dbase::encoding::EncodingRs::from(
        encoding_rs::SHIFT_JIS,
    ))
    .add_numeric_field(field("id"), 10, 0)
    .add_character_field(field("use"), 10)
    .add_character_field(field("mtype"), 20)
    .add_character_field(field("district"), 20);
    let mut w = shapefile::Writer::from_path(path, table).map_err(shp_err(path))?;
    for lot in lots {
        let mut rec = dbase::Record::default();
        rec.insert("id".into(), dbase::FieldValue::Numeric(Some(lot.id as f64)));
        rec.insert(
            "use".into(),
            dbase::FieldValue::Character(Some(lot.lot_use.into())),
        );
        rec.insert(
            "mtype".into(),
            dbase::FieldValue::Character(Some(lot.mtype.into())),
        );
        rec.insert(
            "district".into(),
            dbase::FieldValue::Character(Some(lot.district.into())),
        );
        w.write_shape_and_record(&shp_polygon(&lot.ring), &rec)
            .map_err(shp_err(path))?;
    }
    drop(w);
    sidecars(path, "SHIFT_JIS")
}

/// Writes the blocks layer (UTF-8, zone VI `.prj`).
pub fn write_blocks(path: &Path, blocks: &[Vec<[f64; 2]>]) -> Result<(), String> {
    let table = dbase::TableWriterBuilder::new().add_numeric_field(field("id"), 10, 0);
    let mut w = shapefile::Writer::from_path(path, table).map_err(shp_err(path))?;
    for (i, b) in blocks.iter().enumerate() {
        let mut rec = dbase::Record::default();
        rec.insert(
            "id".into(),
            dbase::FieldValue::Numeric(Some(i as f64 + 1.0)),
        );
        w.write_shape_and_record(&shp_polygon(b), &rec)
            .map_err(shp_err(path))?;
    }
    drop(w);
    sidecars(path, "UTF-8")
}

fn write_streets(path: &Path, streets: &[(Vec<[f64; 2]>, f64)]) -> Result<(), String> {
    let table = dbase::TableWriterBuilder::new()
        .add_numeric_field(field("id"), 10, 0)
        .add_numeric_field(field("width"), 8, 2);
    let mut w = shapefile::Writer::from_path(path, table).map_err(shp_err(path))?;
    for (i, (line, width)) in streets.iter().enumerate() {
        let pts: Vec<Point> = line.iter().map(|p| Point::new(p[0], p[1])).collect();
        let mut rec = dbase::Record::default();
        rec.insert(
            "id".into(),
            dbase::FieldValue::Numeric(Some(i as f64 + 1.0)),
        );
        rec.insert("width".into(), dbase::FieldValue::Numeric(Some(*width)));
        w.write_shape_and_record(&Polyline::new(pts), &rec)
            .map_err(shp_err(path))?;
    }
    drop(w);
    sidecars(path, "UTF-8")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exactly_the_lots_asked_for_and_deterministic() {
        let a = make_town(1000, 3).lots;
        let b = make_town(1000, 3).lots;
        assert_eq!(a.len(), 1000);
        assert_eq!(a.len(), b.len());
        assert!(a
            .iter()
            .zip(&b)
            .all(|(x, y)| x.ring == y.ring && x.mtype == y.mtype));
    }

    #[test]
    fn frontages_fill_the_face_within_the_ken_range() {
        let mut rng = feature_rng(1, "t", "t");
        for _ in 0..200 {
            let ws = frontages(&mut rng, 80.0);
            assert!((ws.iter().sum::<f64>() - 80.0).abs() < 1e-9);
            assert!(
                ws.iter()
                    .all(|w| *w >= 1.5 * KEN - 1e-9 && *w <= 5.0 * KEN + 1e-9),
                "{ws:?}"
            );
        }
    }
}
