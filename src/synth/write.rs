//! Writing a synthetic town as shapefiles: Shift_JIS lots with a `.cpg`, UTF-8 blocks and
//! streets, each with the zone VI `.prj`, and DBF headers stamped with a fixed date so the same
//! town is the same bytes on any day.

use std::path::Path;

use shapefile::{Point, Polygon, PolygonRing, Polyline};

use super::{SynthError, SynthLot};

const ZONE6_PRJ: &str = r#"PROJCS["JGD2011 / Japan Plane Rectangular CS VI",GEOGCS["JGD2011",DATUM["Japanese_Geodetic_Datum_2011",SPHEROID["GRS 1980",6378137,298.257222101]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",36],PARAMETER["central_meridian",136],PARAMETER["scale_factor",0.9999],PARAMETER["false_easting",0],PARAMETER["false_northing",0],UNIT["metre",1]]"#;

fn shp_err(path: &Path) -> impl Fn(shapefile::Error) -> SynthError + '_ {
    move |e| SynthError::Write {
        path: path.display().to_string(),
        cause: e.to_string(),
    }
}

/// A file that could not be written, as [`SynthError::Write`].
fn io_err(path: &Path) -> impl Fn(std::io::Error) -> SynthError + '_ {
    move |e| SynthError::Write {
        path: path.display().to_string(),
        cause: e.to_string(),
    }
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

fn sidecars(path: &Path, cpg: &str) -> Result<(), SynthError> {
    let dbf = path.with_extension("dbf");
    stamp_dbf_date(&dbf).map_err(io_err(&dbf))?;
    let w = |ext: &str, text: &str| {
        let file = path.with_extension(ext);
        std::fs::write(&file, text).map_err(io_err(&file))
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
pub fn write_lots(path: &Path, lots: &[SynthLot]) -> Result<(), SynthError> {
    let table = dbase::TableWriterBuilder::with_encoding(dbase::encoding::EncodingRs::from(
        encoding_rs::SHIFT_JIS,
    ))
    .add_numeric_field(field("id"), 10, 0)
    .add_character_field(field("use"), 10)
    .add_character_field(field("mtype"), 20)
    .add_character_field(field("district"), 20);
    // The gate field only where a lot has a gate: the grid profile's files stay as they were.
    let gates = lots.iter().any(|l| !l.gate.is_empty());
    let table = if gates {
        table.add_character_field(field("gate"), 4)
    } else {
        table
    };
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
        if gates {
            rec.insert(
                "gate".into(),
                dbase::FieldValue::Character(Some(lot.gate.into())),
            );
        }
        w.write_shape_and_record(&shp_polygon(&lot.ring), &rec)
            .map_err(shp_err(path))?;
    }
    drop(w);
    sidecars(path, "SHIFT_JIS")
}

/// Writes the blocks layer (UTF-8, zone VI `.prj`).
pub fn write_blocks(path: &Path, blocks: &[Vec<[f64; 2]>]) -> Result<(), SynthError> {
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

pub(super) fn write_streets(
    path: &Path,
    streets: &[(Vec<[f64; 2]>, f64)],
) -> Result<(), SynthError> {
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
