//! Mapping other people's data onto edo-city's: value maps, constants, PolygonZ ground,
//! projections, shapes that cannot be lots.

mod common;

use common::*;
use predicates::prelude::*;
use shapefile::{PointZ, PolygonRing, PolygonZ};

fn write_params(dir: &std::path::Path, text: &str) -> String {
    let p = dir.join("p.toml");
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn a_value_map_turns_codes_into_uses() {
    let dir = tempfile::tempdir().unwrap();
    // Map the fixture's use "machiya" to "buke": no town lots are left to build.
    let params = write_params(dir.path(), "[layers.lots.values.use]\nmachiya = \"buke\"\n");
    let r = build_ok(
        &fixture("kyoto-small"),
        &dir.path().join("out"),
        &["--quiet", "--params", &params],
    );
    assert_eq!(r["counts"]["machiya"], 0);
    // The fixture's 398 town lots join its one samurai lot; its temple lot stays a temple.
    assert_eq!(r["counts"]["lots_by_use"]["buke"], 399);
    assert_eq!(r["counts"]["lots_by_use"]["jisha"], 1);
    assert!(r["counts"]["lots_by_use"].get("machiya").is_none());
}

#[test]
fn a_constant_fills_a_field_the_data_does_not_have() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    std::fs::remove_file(dir.path().join("lots.csv")).unwrap();
    let params = write_params(
        dir.path(),
        "[layers.lots.fields]\nmtype = \"kind\"\n[layers.lots.constants]\nmtype = \"三階\"\n",
    );
    let r = build_ok(
        dir.path(),
        &dir.path().join("out"),
        &["--quiet", "--params", &params],
    );
    let machiya = r["counts"]["machiya"].as_u64().unwrap();
    assert!(machiya > 300);
    assert_eq!(r["counts"]["by_type"]["sangai"], machiya);
    // The missing field is named in a warning.
    assert!(r["warnings"].to_string().contains("no field `kind`"));
}

/// One square PolygonZ lot at elevation 50 m, facing a street, in its own directory.
fn polygonz_town(dir: &std::path::Path) {
    let ring: Vec<PointZ> = [(0.0, 0.0), (0.0, 30.0), (6.0, 30.0), (6.0, 0.0), (0.0, 0.0)]
        .iter()
        .map(|(x, y)| PointZ::new(*x, *y, 50.0 + y / 100.0, 0.0))
        .collect();
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(dbase::FieldName::try_from("id").unwrap(), 10);
    let mut w = shapefile::Writer::from_path(dir.join("lots.shp"), table).unwrap();
    let mut rec = dbase::Record::default();
    rec.insert("id".into(), dbase::FieldValue::Character(Some("z1".into())));
    w.write_shape_and_record(&PolygonZ::new(PolygonRing::Outer(ring)), &rec)
        .unwrap();
    drop(w);
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(dbase::FieldName::try_from("id").unwrap(), 10);
    let mut w = shapefile::Writer::from_path(dir.join("streets.shp"), table).unwrap();
    let mut rec = dbase::Record::default();
    rec.insert("id".into(), dbase::FieldValue::Character(Some("s".into())));
    let line = shapefile::Polyline::new(vec![
        shapefile::Point::new(-20.0, -4.0),
        shapefile::Point::new(30.0, -4.0),
    ]);
    w.write_shape_and_record(&line, &rec).unwrap();
}

#[test]
fn polygonz_lots_stand_on_their_lowest_z() {
    let dir = tempfile::tempdir().unwrap();
    polygonz_town(dir.path());
    let out = dir.path().join("out");
    let r = build_ok(dir.path(), &out, &["--quiet"]);
    assert_eq!(r["counts"]["machiya"], 1);
    // Layers without .prj are reported as assumed.
    assert!(r["warnings"].to_string().contains("no .prj"));
    let tile = &read_json(&out.join("manifest.json"))["tiles"][0]["obj"]["path"];
    let text = std::fs::read_to_string(out.join(tile.as_str().unwrap())).unwrap();
    let heights: Vec<f64> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|v| v.split(' ').nth(1).unwrap().parse().unwrap())
        .collect();
    let lowest = heights.iter().copied().fold(f64::MAX, f64::min);
    assert_eq!(lowest, 50.0, "the floor is the lowest Z of the lot");
    assert!(heights.iter().all(|h| *h >= 50.0));
}

#[test]
fn a_multipatch_lots_layer_is_refused_with_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    polygonz_town(dir.path());
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(dbase::FieldName::try_from("id").unwrap(), 10);
    let mut w = shapefile::Writer::from_path(dir.path().join("lots.shp"), table).unwrap();
    let mut rec = dbase::Record::default();
    rec.insert("id".into(), dbase::FieldValue::Character(Some("m".into())));
    let patch = shapefile::Multipatch::new(shapefile::Patch::TriangleStrip(vec![
        PointZ::new(0.0, 0.0, 0.0, 0.0),
        PointZ::new(1.0, 0.0, 0.0, 0.0),
        PointZ::new(0.0, 1.0, 1.0, 0.0),
    ]));
    w.write_shape_and_record(&patch, &rec).unwrap();
    drop(w);
    build_cmd(dir.path(), &dir.path().join("out"), &[])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("MultiPatch").and(predicate::str::contains("Polygon")));
}

#[test]
fn lon_lat_without_prj_is_recognised_as_degrees() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    // Move the fixture to degrees near Kyoto (a crude affine map is enough) and drop the .prj
    // files: the numbers alone must tell the tool they are degrees.
    let town = edo_city::synth::make_town(60, 1, edo_city::synth::Profile::Grid);
    let to_deg = |p: [f64; 2]| {
        [
            135.75 + (p[0] + 23_000.0) / 91_000.0,
            35.0 + (p[1] + 110_000.0) / 111_000.0,
        ]
    };
    let lots: Vec<_> = town
        .lots
        .iter()
        .map(|l| edo_city::synth::SynthLot {
            ring: l.ring.iter().map(|p| to_deg(*p)).collect(),
            ..l.clone()
        })
        .collect();
    for f in std::fs::read_dir(dir.path()).unwrap() {
        std::fs::remove_file(f.unwrap().path()).unwrap();
    }
    edo_city::synth::write_lots(&dir.path().join("lots.shp"), &lots).unwrap();
    let blocks: Vec<Vec<[f64; 2]>> = town
        .blocks
        .iter()
        .map(|b| b.iter().map(|p| to_deg(*p)).collect())
        .collect();
    edo_city::synth::write_blocks(&dir.path().join("blocks.shp"), &blocks).unwrap();
    std::fs::remove_file(dir.path().join("lots.prj")).unwrap();
    std::fs::remove_file(dir.path().join("blocks.prj")).unwrap();
    let r = build_ok(dir.path(), &dir.path().join("out"), &["--quiet"]);
    assert!(
        r["warnings"].to_string().contains("longitude/latitude"),
        "{}",
        r["warnings"]
    );
    assert!(
        r["crs"].as_str().unwrap().contains("+proj=utm +zone=53"),
        "{}",
        r["crs"]
    );
    assert_eq!(r["counts"]["machiya"], 60);
}
