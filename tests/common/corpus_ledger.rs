//! Cases of the corpus for what used to vanish without a word or be taken as it was: rings
//! wound the other way, null shapes, deleted DBF records, sidecar files that are not what
//! they claim, tables with repeated ids or columns, and numbers no city has (issue 17).

use std::path::Path;

use dbase::{FieldValue, Record, TableWriterBuilder};
use shapefile::{Point, PointZ, Polygon, PolygonRing, PolygonZ, NO_DATA};

use super::corpus::{
    good_lots, good_town, name, ring, strip, town_with, workbook, write_lots, write_street, Case,
    PRJ,
};

/// Turns the last record of a `.shp` into a null shape (a record with attributes and no
/// geometry, as GIS tools write after a geometry is deleted); the `.shx` follows.
fn null_last_record(shp: &Path) {
    let mut b = std::fs::read(shp).unwrap();
    let mut at = 100;
    let mut last = at;
    while at + 8 <= b.len() {
        last = at;
        let words = u32::from_be_bytes(b[at + 4..at + 8].try_into().unwrap()) as usize;
        at += 8 + 2 * words;
    }
    b[last + 4..last + 8].copy_from_slice(&2u32.to_be_bytes());
    b[last + 8..last + 12].copy_from_slice(&0i32.to_le_bytes());
    b.truncate(last + 12);
    let words = (b.len() / 2) as u32;
    b[24..28].copy_from_slice(&words.to_be_bytes());
    std::fs::write(shp, &b).unwrap();
    let shx = shp.with_extension("shx");
    let mut x = std::fs::read(&shx).unwrap();
    let n = x.len();
    x[n - 4..].copy_from_slice(&2u32.to_be_bytes());
    std::fs::write(&shx, &x).unwrap();
}

/// Marks DBF record `i` as deleted (dBASE's `*` flag).
fn delete_record(dbf: &Path, i: usize) {
    let mut b = std::fs::read(dbf).unwrap();
    let header = u16::from_le_bytes([b[8], b[9]]) as usize;
    let len = u16::from_le_bytes([b[10], b[11]]) as usize;
    b[header + i * len] = b'*';
    std::fs::write(dbf, b).unwrap();
}

/// The good town's lots as PolygonZ, the last one at elevation `z`.
fn lots_z(d: &Path, z: f64) {
    let table = TableWriterBuilder::new().add_character_field(name("id"), 12);
    let mut w = shapefile::Writer::from_path(d.join("lots.shp"), table).unwrap();
    let lots = good_lots();
    for (k, (id, r)) in lots.iter().enumerate() {
        let h = if k + 1 == lots.len() { z } else { 10.0 };
        let pts: Vec<PointZ> = r
            .iter()
            .rev()
            .chain(r.last())
            .map(|p| PointZ::new(p[0], p[1], h, NO_DATA))
            .collect();
        let mut rec = Record::default();
        rec.insert("id".into(), FieldValue::Character(Some(id.clone())));
        w.write_shape_and_record(&PolygonZ::new(PolygonRing::Outer(pts)), &rec)
            .unwrap();
    }
    drop(w);
    edo_city::synth::stamp_dbf_date(&d.join("lots.dbf")).unwrap();
    std::fs::write(d.join("lots.prj"), PRJ).unwrap();
    write_street(d);
}

pub fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "counter_clockwise_outer_rings",
            make: |d| {
                // Every outer ring counter-clockwise, as many non-ESRI tools write them, and one
                // lot wound the other way with its courtyard.
                let mut lots: Vec<_> = good_lots()
                    .into_iter()
                    .map(|(id, r)| (id, "machiya", vec![PolygonRing::Inner(ring(&r))]))
                    .collect();
                let (x, y) = (-21_970.0, -110_000.0);
                lots.push((
                    "court".into(),
                    "machiya",
                    vec![
                        PolygonRing::Inner(ring(&[[x, y], [x + 12.0, y], [x + 12.0, y + 30.0], [x, y + 30.0]])),
                        PolygonRing::Outer(ring(&[[x + 3.0, y + 20.0], [x + 9.0, y + 20.0], [x + 9.0, y + 26.0], [x + 3.0, y + 26.0]])),
                    ],
                ));
                write_lots(d, &lots);
                write_street(d);
            },
            expect: "class = \"warning\"\nbuilt = 4\nmessage = \"wound against the shapefile standard\"\n",
        },
        Case {
            name: "null_shape",
            make: |d| {
                town_with(d, ("gone".into(), strip(30.0)));
                null_last_record(&d.join("lots.shp"));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"gone\"\nreason = \"null shape\"\n",
        },
        Case {
            name: "deleted_dbf_record",
            make: |d| {
                town_with(d, ("deleted".into(), strip(30.0)));
                delete_record(&d.join("lots.dbf"), 1);
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"record 1\"\nreason = \"marks the record as deleted\"\n",
        },
        Case {
            name: "two_fields_of_one_name",
            make: |d| {
                let table = TableWriterBuilder::new()
                    .add_character_field(name("id"), 12)
                    .add_character_field(name("use"), 10)
                    .add_character_field(name("usx"), 10);
                let mut w = shapefile::Writer::from_path(d.join("lots.shp"), table).unwrap();
                for (id, r) in good_lots() {
                    let mut rec = Record::default();
                    rec.insert("id".into(), FieldValue::Character(Some(id)));
                    rec.insert("use".into(), FieldValue::Character(Some("buke".into())));
                    rec.insert("usx".into(), FieldValue::Character(Some("machiya".into())));
                    w.write_shape_and_record(&Polygon::new(PolygonRing::Outer(ring(&r))), &rec)
                        .unwrap();
                }
                drop(w);
                // The third field's name becomes `use` too: descriptors start at byte 32.
                let dbf = d.join("lots.dbf");
                let mut b = std::fs::read(&dbf).unwrap();
                b[32 + 2 * 32 + 2] = b'e';
                std::fs::write(&dbf, b).unwrap();
                edo_city::synth::stamp_dbf_date(&dbf).unwrap();
                std::fs::write(d.join("lots.prj"), PRJ).unwrap();
                write_street(d);
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"two fields are named `use`\"\n",
        },
        Case {
            name: "prj_is_a_directory",
            make: |d| {
                good_town(d);
                std::fs::remove_file(d.join("lots.prj")).unwrap();
                std::fs::create_dir_all(d.join("lots.prj")).unwrap();
                std::fs::write(d.join("lots.prj").join("keep"), "").unwrap();
            },
            expect: "class = \"error\"\nmessage = \"lots.prj is a directory\"\n",
        },
        Case {
            name: "cpg_is_not_text",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.cpg"), [0u8, 159, 146, 150, 0, 1, 2]).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"lots.cpg is not a text file\"\n",
        },
        Case {
            name: "degrees_prj_over_metres",
            make: |d| {
                good_town(d);
                std::fs::write(
                    d.join("lots.prj"),
                    "GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],UNIT[\"Degree\",0.0174532925199433]]",
                )
                .unwrap();
            },
            expect: "class = \"error\"\nmessage = \"the .prj belongs to another file\"\n",
        },
        Case {
            name: "table_repeats_an_id",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,mtype\n1,sangai\n2,hiraya\n1,hiraya\n").unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots table\"\nid = \"1\"\nreason = \"row 2 has the same id\"\n",
        },
        Case {
            name: "table_repeats_a_column",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,mtype,mtype\n1,sangai,hiraya\n").unwrap();
            },
            expect: "class = \"error\"\nmessage = \"columns B and C are both named `mtype`\"\n",
        },
        Case {
            name: "table_column_without_a_name",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,,district\n1,sangai,north\n").unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"column(s) B hold values but have no name\"\n",
        },
        Case {
            name: "csv_and_xlsx_both",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,mtype\n1,sangai\n").unwrap();
                let mut book = workbook();
                let sheet = book.add_worksheet();
                sheet.write(0, 0, "id").unwrap();
                sheet.write(1, 0, "1").unwrap();
                book.save(d.join("lots.xlsx")).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"the CSV was joined and the workbook ignored\"\n",
        },
        Case {
            name: "xlsx_ids_that_are_dates",
            make: |d| {
                good_town(d);
                let mut book = workbook();
                let sheet = book.add_worksheet();
                sheet.write(0, 0, "id").unwrap();
                sheet.write(0, 1, "mtype").unwrap();
                sheet.write(1, 0, "2").unwrap();
                sheet.write(1, 1, "sangai").unwrap();
                // `1-2` typed into a cell becomes the 2nd of January.
                let date = rust_xlsxwriter::ExcelDateTime::from_ymd(2001, 1, 2).unwrap();
                let fmt = rust_xlsxwriter::Format::new().set_num_format("d-mmm");
                sheet.write_datetime_with_format(2, 0, &date, &fmt).unwrap();
                sheet.write(2, 1, "hiraya").unwrap();
                book.save(d.join("lots.xlsx")).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"the id is a date\"\n",
        },
        Case {
            name: "xlsx_formula_without_a_value",
            make: |d| {
                good_town(d);
                let mut book = workbook();
                let sheet = book.add_worksheet();
                sheet.write(0, 0, "id").unwrap();
                sheet.write(0, 1, "mtype").unwrap();
                sheet.write(1, 0, "1").unwrap();
                sheet.write_formula(1, 1, "=LOWER(\"SANGAI\")").unwrap();
                let bytes = book.save_to_buffer().unwrap();
                // As a script writes it (openpyxl does): the formula stored, its value not.
                let bytes = super::rezip(&bytes, "xl/worksheets/sheet1.xml", |xml| {
                    String::from_utf8_lossy(xml).replace("</f><v>0</v>", "</f>").into_bytes()
                });
                std::fs::write(d.join("lots.xlsx"), bytes).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"have no saved value\"\n",
        },
        Case {
            name: "xlsx_first_sheet_empty",
            make: |d| {
                good_town(d);
                let mut book = workbook();
                book.add_worksheet().set_name("Notes").unwrap();
                let sheet = book.add_worksheet().set_name("Lots").unwrap();
                sheet.write(0, 0, "id").unwrap();
                sheet.write(1, 0, "1").unwrap();
                book.save(d.join("lots.xlsx")).unwrap();
            },
            expect: "class = \"error\"\nmessage = \"sheet `Notes` is empty (the workbook has: Notes, Lots)\"\n",
        },
        Case {
            name: "lot_ground_far_above_any_city",
            make: |d| lots_z(d, 1e9),
            expect: "class = \"warning\"\nbuilt = 2\n[[skipped]]\nlayer = \"lots\"\nid = \"3\"\nreason = \"ground elevation 1000000000 m\"\n",
        },
        Case {
            name: "street_a_million_km_wide",
            make: |d| {
                good_town(d);
                let table = TableWriterBuilder::new()
                    .add_character_field(name("id"), 4)
                    .add_numeric_field(name("width"), 14, 0);
                let mut w = shapefile::Writer::from_path(d.join("streets.shp"), table).unwrap();
                let mut rec = Record::default();
                rec.insert("id".into(), FieldValue::Character(Some("s1".into())));
                rec.insert("width".into(), FieldValue::Numeric(Some(1e9)));
                let line = shapefile::Polyline::new(vec![
                    Point::new(-22_050.0, -110_004.0),
                    Point::new(-21_900.0, -110_004.0),
                ]);
                w.write_shape_and_record(&line, &rec).unwrap();
                drop(w);
                edo_city::synth::stamp_dbf_date(&d.join("streets.dbf")).unwrap();
                std::fs::write(d.join("streets.prj"), PRJ).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"up to 200; they get the default width\"\n",
        },
        Case {
            name: "wall_heights_that_are_not_heights",
            make: |d| {
                let table = TableWriterBuilder::new()
                    .add_character_field(name("id"), 12)
                    .add_character_field(name("use"), 10)
                    .add_character_field(name("height"), 10);
                let mut w = shapefile::Writer::from_path(d.join("lots.shp"), table).unwrap();
                for (k, (id, r)) in good_lots().into_iter().enumerate() {
                    let mut rec = Record::default();
                    rec.insert("id".into(), FieldValue::Character(Some(id)));
                    rec.insert("use".into(), FieldValue::Character(Some("buke".into())));
                    let h = ["1e9", "-5", "abc"][k];
                    rec.insert("height".into(), FieldValue::Character(Some(h.into())));
                    w.write_shape_and_record(&Polygon::new(PolygonRing::Outer(ring(&r))), &rec)
                        .unwrap();
                }
                drop(w);
                edo_city::synth::stamp_dbf_date(&d.join("lots.dbf")).unwrap();
                std::fs::write(d.join("lots.prj"), PRJ).unwrap();
                write_street(d);
            },
            expect: "class = \"warning\"\nbuilt = 0\nmessage = \"`height` = `1e9` is not a wall height\"\n",
        },
        Case {
            name: "dem_with_an_undeclared_nodata_value",
            make: |d| {
                good_town(d);
                let grid = "ncols 4\nnrows 4\nxllcorner -22040\nyllcorner -110040\ncellsize 40\n\
                            12 12 12 12\n12 -3.4028235e38 12 12\n12 12 12 12\n12 12 12 1e300\n";
                std::fs::write(d.join("dem.asc"), grid).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"2 cell(s) hold a number no ground has\"\n",
        },
    ]
}
