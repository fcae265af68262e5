//! The corpus of broken inputs in `tests/bad_input/`: one small input directory per case,
//! with `expect.toml` saying what edo-city must make of it. `make bad-input` rewrites the
//! committed corpus from this file (tests/bad_input.rs checks it is up to date).
//!
//! Every case is a three-lot town on one street (lots `1`, `2`, `3`, 5 m x 25 m, in JGD2011
//! zone VI), damaged in one way.

use std::path::Path;

use dbase::{FieldName, FieldValue, Record, TableWriterBuilder};
use shapefile::{Point, Polygon, PolygonRing, Polyline};

/// The good town's lots: id and ring (counter-clockwise).
pub(super) fn good_lots() -> Vec<(String, Vec<[f64; 2]>)> {
    (0..3)
        .map(|i| {
            let x = -22_000.0 + 10.0 * i as f64;
            let y = -110_000.0;
            (
                (i + 1).to_string(),
                vec![[x, y], [x + 5.0, y], [x + 5.0, y + 25.0], [x, y + 25.0]],
            )
        })
        .collect()
}

pub(super) const PRJ: &str =
    "PROJCS[\"JGD2011 / Japan Plane Rectangular CS VI\",GEOGCS[\"JGD2011\",\
DATUM[\"Japanese_Geodetic_Datum_2011\",SPHEROID[\"GRS 1980\",6378137,298.257222101]],\
PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],\
PARAMETER[\"latitude_of_origin\",36],PARAMETER[\"central_meridian\",136],\
PARAMETER[\"scale_factor\",0.9999],PARAMETER[\"false_easting\",0],PARAMETER[\"false_northing\",0],\
UNIT[\"metre\",1]]";

pub(super) fn name(n: &str) -> FieldName {
    FieldName::try_from(n).unwrap()
}

pub(super) fn ring(r: &[[f64; 2]]) -> Vec<Point> {
    // Shapefile outer rings are clockwise: write ours reversed, closed.
    let mut pts: Vec<Point> = r.iter().rev().map(|p| Point::new(p[0], p[1])).collect();
    if let Some(first) = pts.first().copied() {
        pts.push(first);
    }
    pts
}

/// A lots layer: each feature an id (text), a `use`, and one or more rings (outer, then
/// holes); `.cpg` UTF-8 and the zone VI `.prj`.
pub(super) fn write_lots(dir: &Path, lots: &[(String, &str, Vec<PolygonRing<Point>>)]) {
    let table = TableWriterBuilder::new()
        .add_character_field(name("id"), 12)
        .add_character_field(name("use"), 10);
    let mut w = shapefile::Writer::from_path(dir.join("lots.shp"), table).unwrap();
    for (id, lot_use, rings) in lots {
        let mut rec = Record::default();
        rec.insert("id".into(), FieldValue::Character(Some(id.clone())));
        rec.insert(
            "use".into(),
            FieldValue::Character(Some(lot_use.to_string())),
        );
        w.write_shape_and_record(&Polygon::with_rings(rings.clone()), &rec)
            .unwrap();
    }
    drop(w);
    edo_city::synth::stamp_dbf_date(&dir.join("lots.dbf")).unwrap();
    std::fs::write(dir.join("lots.cpg"), "UTF-8").unwrap();
    std::fs::write(dir.join("lots.prj"), PRJ).unwrap();
}

pub(super) fn simple(
    lots: Vec<(String, Vec<[f64; 2]>)>,
) -> Vec<(String, &'static str, Vec<PolygonRing<Point>>)> {
    lots.into_iter()
        .map(|(id, r)| (id, "machiya", vec![PolygonRing::Outer(ring(&r))]))
        .collect()
}

pub(super) fn write_street(dir: &Path) {
    let table = TableWriterBuilder::new()
        .add_character_field(name("id"), 4)
        .add_numeric_field(name("width"), 6, 2);
    let mut w = shapefile::Writer::from_path(dir.join("streets.shp"), table).unwrap();
    let mut rec = Record::default();
    rec.insert("id".into(), FieldValue::Character(Some("s1".into())));
    rec.insert("width".into(), FieldValue::Numeric(Some(8.0)));
    let line = Polyline::new(vec![
        Point::new(-22_050.0, -110_004.0),
        Point::new(-21_900.0, -110_004.0),
    ]);
    w.write_shape_and_record(&line, &rec).unwrap();
    drop(w);
    edo_city::synth::stamp_dbf_date(&dir.join("streets.dbf")).unwrap();
    std::fs::write(dir.join("streets.cpg"), "UTF-8").unwrap();
    std::fs::write(dir.join("streets.prj"), PRJ).unwrap();
}

/// The good town plus one extra lot.
pub(super) fn town_with(dir: &Path, extra: (String, Vec<[f64; 2]>)) {
    let mut lots = good_lots();
    lots.push(extra);
    write_lots(dir, &simple(lots));
    write_street(dir);
}

pub(super) fn good_town(dir: &Path) {
    write_lots(dir, &simple(good_lots()));
    write_street(dir);
}

/// A strip lot of the good town's shape at `x` metres east of the first.
pub(super) fn strip(x: f64) -> Vec<[f64; 2]> {
    let (x, y) = (-22_000.0 + x, -110_000.0);
    vec![[x, y], [x + 5.0, y], [x + 5.0, y + 25.0], [x, y + 25.0]]
}

fn points(dir: &Path, file: &str, pts: &[(&str, [f64; 2])]) {
    let table = TableWriterBuilder::new().add_character_field(name("id"), 8);
    let mut w = shapefile::Writer::from_path(dir.join(file), table).unwrap();
    for (id, p) in pts {
        let mut rec = Record::default();
        rec.insert("id".into(), FieldValue::Character(Some(id.to_string())));
        w.write_shape_and_record(&Point::new(p[0], p[1]), &rec)
            .unwrap();
    }
    drop(w);
    edo_city::synth::stamp_dbf_date(&dir.join(file).with_extension("dbf")).unwrap();
    std::fs::write(dir.join(file).with_extension("prj"), PRJ).unwrap();
}

/// A workbook with a fixed creation time, so the file is the same every time it is made.
pub(super) fn workbook() -> rust_xlsxwriter::Workbook {
    let mut book = rust_xlsxwriter::Workbook::new();
    let date = rust_xlsxwriter::ExcelDateTime::from_ymd(2000, 1, 1).unwrap();
    book.set_properties(&rust_xlsxwriter::DocProperties::new().set_creation_datetime(&date));
    book
}

/// One case: its name, how to make its input, and its `expect.toml`.
pub struct Case {
    pub name: &'static str,
    pub make: fn(&Path),
    pub expect: &'static str,
}

/// Every case of the corpus.
pub fn cases() -> Vec<Case> {
    let mut all = base_cases();
    all.extend(super::corpus_ledger::cases());
    all
}

/// The first cases: damaged files, bad parameters, degenerate geometry.
fn base_cases() -> Vec<Case> {
    vec![
        // ---- errors: exit code 2, nothing written -------------------------------------
        Case {
            name: "truncated_shp",
            make: |d| {
                good_town(d);
                let p = d.join("lots.shp");
                let b = std::fs::read(&p).unwrap();
                std::fs::write(&p, &b[..150]).unwrap();
            },
            expect: "class = \"error\"\nmessage = \"lots.shp\"\n",
        },
        Case {
            name: "shx_mismatch",
            make: |d| {
                // The index of a one-lot layer next to the three-lot file.
                let tmp = d.join("one");
                std::fs::create_dir_all(&tmp).unwrap();
                write_lots(&tmp, &simple(vec![good_lots().remove(0)]));
                good_town(d);
                std::fs::copy(tmp.join("lots.shx"), d.join("lots.shx")).unwrap();
                std::fs::remove_dir_all(&tmp).unwrap();
            },
            expect: "class = \"error\"\nmessage = \"the files do not belong together\"\n",
        },
        Case {
            name: "missing_dbf",
            make: |d| {
                good_town(d);
                std::fs::remove_file(d.join("lots.dbf")).unwrap();
            },
            expect: "class = \"error\"\nmessage = \"lots.dbf\"\n",
        },
        Case {
            name: "points_as_lots",
            make: |d| {
                write_street(d);
                points(d, "lots.shp", &[("1", [-22_000.0, -110_000.0])]);
            },
            expect: "class = \"error\"\nmessage = \"is a point; the lots layer must hold polygons\"\n",
        },
        Case {
            name: "people_as_polygons",
            make: |d| {
                good_town(d);
                std::fs::copy(d.join("lots.shp"), d.join("people.shp")).unwrap();
                std::fs::copy(d.join("lots.shx"), d.join("people.shx")).unwrap();
                std::fs::copy(d.join("lots.dbf"), d.join("people.dbf")).unwrap();
            },
            expect: "class = \"error\"\nmessage = \"the people layer must hold points\"\n",
        },
        Case {
            name: "xlsx_without_the_sheet",
            make: |d| {
                good_town(d);
                let mut book = workbook();
                let sheet = book.add_worksheet().set_name("Sheet1").unwrap();
                sheet.write(0, 0, "id").unwrap();
                sheet.write(0, 1, "mtype").unwrap();
                sheet.write(1, 0, "1").unwrap();
                sheet.write(1, 1, "hiraya").unwrap();
                book.save(d.join("lots.xlsx")).unwrap();
                std::fs::write(d.join("params.toml"), "[layers.lots]\nsheet = \"Lots\"\n").unwrap();
            },
            expect: "class = \"error\"\nmessage = \"Lots\"\nargs = [\"--params\", \"params.toml\"]\n",
        },
        Case {
            name: "params_unknown_key",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("params.toml"), "[machiya]\ndepht = 10.0\n").unwrap();
            },
            expect: "class = \"error\"\nmessage = \"depht\"\nargs = [\"--params\", \"params.toml\"]\n",
        },
        Case {
            name: "params_wrong_type",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("params.toml"), "tile_size = \"large\"\n").unwrap();
            },
            expect: "class = \"error\"\nmessage = \"line 1\"\nargs = [\"--params\", \"params.toml\"]\n",
        },
        Case {
            name: "params_negative_size",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("params.toml"), "[kura]\nwidth = -3.0\n").unwrap();
            },
            expect: "class = \"error\"\nmessage = \"`kura.width` must be a positive number\"\nargs = [\"--params\", \"params.toml\"]\n",
        },
        Case {
            name: "unwritable_output",
            make: good_town,
            expect: "class = \"error\"\nmessage = \"not-a-directory\"\nout = \"not-a-directory\"\n",
        },
        Case {
            name: "full_disk",
            make: good_town,
            expect: "class = \"error\"\nmessage = \"No space left on device\"\ndisk_bytes = 20000\n",
        },
        // ---- warnings: the feature skipped and reported, the rest built ---------------
        Case {
            name: "zero_area",
            make: |d| {
                let x = -21_970.0;
                town_with(d, ("flat".into(), vec![[x, -110_000.0], [x + 5.0, -110_000.0], [x + 9.0, -110_000.0]]));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"flat\"\nreason = \"no area\"\n",
        },
        Case {
            name: "fewer_than_three_vertices",
            make: |d| {
                town_with(d, ("two".into(), vec![[-21_970.0, -110_000.0], [-21_965.0, -110_000.0]]));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"two\"\nreason = \"distinct vertices\"\n",
        },
        Case {
            name: "duplicate_id",
            make: |d| town_with(d, ("2".into(), strip(30.0))),
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"2\"\nreason = \"duplicate id\"\n",
        },
        Case {
            name: "missing_id",
            make: |d| town_with(d, ("".into(), strip(30.0))),
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"record 3\"\nreason = \"no value in the id field\"\n",
        },
        Case {
            name: "nan_coordinate",
            make: |d| {
                let mut r = strip(30.0);
                r[1][0] = f64::NAN;
                town_with(d, ("nan".into(), r));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"nan\"\nreason = \"not a finite number\"\n",
        },
        Case {
            name: "inf_coordinate",
            make: |d| {
                let mut r = strip(30.0);
                r[2][1] = f64::INFINITY;
                town_with(d, ("inf".into(), r));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"inf\"\nreason = \"not a finite number\"\n",
        },
        Case {
            name: "absurd_coordinate",
            make: |d| {
                let mut r = strip(30.0);
                r[2][1] = 1.5e286;
                town_with(d, ("far".into(), r));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"far\"\nreason = \"from the CRS's origin\"\n",
        },
        Case {
            name: "degrees_with_a_metre_prj",
            make: |d| {
                let lots: Vec<(String, Vec<[f64; 2]>)> = (0..3)
                    .map(|i| {
                        let x = 135.76 + 0.0001 * i as f64;
                        (format!("{}", i + 1), vec![[x, 35.0], [x + 0.00005, 35.0], [x + 0.00005, 35.0002], [x, 35.0002]])
                    })
                    .collect();
                write_lots(d, &simple(lots));
                write_street(d);
            },
            expect: "class = \"warning\"\nmessage = \"like longitude/latitude in degrees\"\n",
        },
        Case {
            name: "missing_prj",
            make: |d| {
                good_town(d);
                std::fs::remove_file(d.join("lots.prj")).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"lots.shp: no .prj\"\n",
        },
        Case {
            name: "shift_jis_dbf_without_cpg",
            make: |d| {
                let table = TableWriterBuilder::with_encoding(dbase::encoding::EncodingRs::from(
                    encoding_rs::SHIFT_JIS,
                ))
                .add_character_field(name("id"), 12)
                .add_character_field(name("mtype"), 20);
                let mut w = shapefile::Writer::from_path(d.join("lots.shp"), table).unwrap();
                for (id, r) in good_lots() {
                    let mut rec = Record::default();
                    rec.insert("id".into(), FieldValue::Character(Some(id)));
                    rec.insert("mtype".into(), FieldValue::Character(Some("平屋".into())));
                    let poly = Polygon::new(PolygonRing::Outer(ring(&r)));
                    w.write_shape_and_record(&poly, &rec).unwrap();
                }
                drop(w);
                edo_city::synth::stamp_dbf_date(&d.join("lots.dbf")).unwrap();
                // No code page in the DBF header either (byte 29), as old files have it.
                let dbf = d.join("lots.dbf");
                let mut b = std::fs::read(&dbf).unwrap();
                b[29] = 0;
                std::fs::write(&dbf, b).unwrap();
                std::fs::write(d.join("lots.prj"), PRJ).unwrap();
                write_street(d);
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"shift_jis\"\n",
        },
        Case {
            name: "table_unknown_id",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,mtype\n1,hiraya\n99,sangai\n").unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots table\"\nid = \"99\"\nreason = \"no lot has this id\"\n",
        },
        Case {
            name: "table_wrong_type",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,ground\n1,high\n2,3.5\n").unwrap();
                std::fs::write(d.join("params.toml"), "[layers.lots.fields]\nground = \"ground\"\n").unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"is not a number\"\nargs = [\"--params\", \"params.toml\"]\n",
        },
        Case {
            name: "table_empty_cells",
            make: |d| {
                good_town(d);
                std::fs::write(d.join("lots.csv"), "id,mtype,district\n1,,\n2,sangai,\n3,,east\n").unwrap();
            },
            expect: "class = \"ok\"\nbuilt = 3\n",
        },
        Case {
            name: "dem_not_covering_the_lots",
            make: |d| {
                good_town(d);
                let grid = "ncols 2\nnrows 2\nxllcorner -22010\nyllcorner -110010\ncellsize 10\n\
                            NODATA_value -9999\n1 2\n3 4\n";
                std::fs::write(d.join("dem.asc"), grid).unwrap();
            },
            expect: "class = \"warning\"\nbuilt = 3\nmessage = \"outside the DEM\"\n",
        },
        Case {
            name: "point_inside_a_house",
            make: |d| {
                good_town(d);
                points(d, "trees.shp", &[("t1", [-21_997.5, -109_998.0]), ("t2", [-22_030.0, -109_990.0])]);
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"trees\"\nid = \"t1\"\nreason = \"inside a building\"\n",
        },
        // ---- supported, not rejected --------------------------------------------------
        Case {
            name: "polygon_with_a_hole",
            make: |d| {
                let mut lots = simple(good_lots());
                let (x, y) = (-21_970.0, -110_000.0);
                lots.push((
                    "court".into(),
                    "machiya",
                    vec![
                        PolygonRing::Outer(ring(&[[x, y], [x + 12.0, y], [x + 12.0, y + 30.0], [x, y + 30.0]])),
                        PolygonRing::Inner(
                            [[x + 4.0, y + 14.0], [x + 8.0, y + 14.0], [x + 8.0, y + 18.0], [x + 4.0, y + 18.0]]
                                .iter()
                                .map(|p| Point::new(p[0], p[1]))
                                .chain(std::iter::once(Point::new(x + 4.0, y + 14.0)))
                                .collect(),
                        ),
                    ],
                ));
                write_lots(d, &lots);
                write_street(d);
            },
            expect: "class = \"ok\"\nbuilt = 4\n",
        },
        Case {
            name: "multipolygon",
            make: |d| {
                let mut lots = simple(good_lots());
                lots.push((
                    "twin".into(),
                    "machiya",
                    vec![PolygonRing::Outer(ring(&strip(30.0))), PolygonRing::Outer(ring(&strip(40.0)))],
                ));
                write_lots(d, &lots);
                write_street(d);
            },
            expect: "class = \"ok\"\nbuilt = 5\n",
        },
        Case {
            name: "self_intersecting",
            make: |d| {
                let s = strip(30.0);
                town_with(d, ("bowtie".into(), vec![s[0], s[2], s[1], s[3]]));
            },
            expect: "class = \"warning\"\nbuilt = 3\n[[skipped]]\nlayer = \"lots\"\nid = \"bowtie\"\nreason = \"crosses itself\"\n",
        },
    ]
}
