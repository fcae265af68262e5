//! Broken features from many hands: each is skipped with its reason and id, the rest of the
//! city is built. (The layer-level errors are in input_errors.rs and robustness.rs.)

mod common;

use std::path::Path;

use common::*;
use predicates::prelude::*;

/// Writes lots.shp (ids as text, so an empty id can be written) and one street along y = -4.
fn town(dir: &Path, lots: &[(&str, Vec<(f64, f64)>)]) {
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(dbase::FieldName::try_from("id").unwrap(), 12);
    let mut w = shapefile::Writer::from_path(dir.join("lots.shp"), table).unwrap();
    for (id, ring) in lots {
        let mut pts: Vec<shapefile::Point> = ring
            .iter()
            .rev()
            .map(|(x, y)| shapefile::Point::new(*x, *y))
            .collect();
        if let Some(first) = pts.first().copied() {
            pts.push(first);
        }
        let mut rec = dbase::Record::default();
        rec.insert(
            "id".into(),
            dbase::FieldValue::Character(Some(id.to_string())),
        );
        let poly = shapefile::Polygon::new(shapefile::PolygonRing::Outer(pts));
        w.write_shape_and_record(&poly, &rec).unwrap();
    }
    drop(w);
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(dbase::FieldName::try_from("id").unwrap(), 4);
    let mut w = shapefile::Writer::from_path(dir.join("streets.shp"), table).unwrap();
    let mut rec = dbase::Record::default();
    rec.insert("id".into(), dbase::FieldValue::Character(Some("s".into())));
    let line = shapefile::Polyline::new(vec![
        shapefile::Point::new(-50.0, -4.0),
        shapefile::Point::new(5000.0, -4.0),
    ]);
    w.write_shape_and_record(&line, &rec).unwrap();
}

/// A lot: its id, its ring, and the reason it must be skipped for (None = built).
type Case = (&'static str, Vec<(f64, f64)>, Option<&'static str>);

fn strip(x: f64) -> Vec<(f64, f64)> {
    vec![(x, 0.0), (x + 5.0, 0.0), (x + 5.0, 25.0), (x, 25.0)]
}

#[test]
fn each_broken_lot_is_skipped_with_its_reason_and_the_rest_built() {
    let dir = tempfile::tempdir().unwrap();
    let mut many = Vec::new();
    // A million-vertex lot: a 5 m x 25 m strip whose back edge wiggles in a million steps.
    many.push((10.0, 0.0));
    many.push((15.0, 0.0));
    let n = 1_000_000;
    for i in 0..=n {
        let x = 15.0 - 5.0 * i as f64 / n as f64;
        many.push((x, 25.0 + 0.001 * ((i % 2) as f64)));
    }
    let cases: Vec<Case> = vec![
        ("ok-1", strip(0.0), None),
        ("ok-2", strip(100.0), None),
        ("dup", strip(200.0), None),
        ("dup", strip(300.0), Some("duplicate id")),
        ("", strip(400.0), Some("no value in the id field")),
        (
            "nan",
            vec![(500.0, 0.0), (f64::NAN, 0.0), (505.0, 25.0), (500.0, 25.0)],
            Some("not a finite number"),
        ),
        (
            "inf",
            vec![(600.0, 0.0), (f64::INFINITY, 0.0), (605.0, 25.0)],
            Some("not a finite number"),
        ),
        (
            "two-points",
            vec![(700.0, 0.0), (705.0, 0.0)],
            Some("distinct vertices"),
        ),
        (
            "flat",
            vec![(800.0, 0.0), (805.0, 0.0), (810.0, 0.0)],
            Some("no area"),
        ),
        // Self-intersecting (a bow tie): built or skipped, never a crash.
        (
            "bowtie",
            vec![(900.0, 0.0), (905.0, 25.0), (905.0, 0.0), (900.0, 25.0)],
            None,
        ),
        // One kilometre deep: the house stays machiya.depth deep.
        (
            "deep",
            vec![
                (1000.0, 0.0),
                (1006.0, 0.0),
                (1006.0, 1000.0),
                (1000.0, 1000.0),
            ],
            None,
        ),
        ("million", many, None),
    ];
    let lots: Vec<(&str, Vec<(f64, f64)>)> =
        cases.iter().map(|(id, r, _)| (*id, r.clone())).collect();
    town(dir.path(), &lots);
    let out = dir.path().join("out");
    let r = build_ok(dir.path(), &out, &["--quiet"]);
    let skipped = r["skipped"].as_array().unwrap();
    for (id, _, reason) in &cases {
        let Some(reason) = reason else { continue };
        let hit = skipped.iter().any(|s| {
            let sid = s["id"].as_str().unwrap();
            let matches_id = if id.is_empty() {
                sid.starts_with("record ")
            } else {
                sid == *id
            };
            matches_id && s["reason"].as_str().unwrap().contains(reason)
        });
        assert!(hit, "lot `{id}` not skipped for `{reason}`: {skipped:#?}");
    }
    for s in skipped {
        assert!(s["file"].as_str().unwrap().ends_with("lots.shp"), "{s}");
    }
    let built: Vec<String> = std::fs::read_dir(out.join("tiles"))
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .flat_map(|t| {
            t.lines()
                .filter_map(|l| l.strip_prefix("o ").map(String::from))
                .collect::<Vec<_>>()
        })
        .collect();
    for id in ["ok-1", "ok-2", "dup", "deep", "million"] {
        assert!(
            built.contains(&format!("machiya_{id}")),
            "{id} not built: {built:?}"
        );
    }
    // The 1 km deep lot's house is machiya.depth (12 m) deep, not 1 km.
    let deep = std::fs::read_dir(out.join("tiles"))
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .find(|t| t.contains("o machiya_deep\n"))
        .unwrap();
    let start = deep.find("o machiya_deep\n").unwrap();
    let zs: Vec<f64> = deep[start..]
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with("o "))
        .filter_map(|l| l.strip_prefix("v "))
        .map(|v| v.split(' ').nth(2).unwrap().parse().unwrap())
        .collect();
    let span =
        zs.iter().copied().fold(f64::MIN, f64::max) - zs.iter().copied().fold(f64::MAX, f64::min);
    assert!(span < 13.5, "house depth {span} m (pent roof included)");
}

#[test]
fn an_unwritable_output_directory_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("not-a-dir");
    std::fs::write(&blocker, "a file where the output directory should go").unwrap();
    build_cmd(&fixture("kyoto-small"), &blocker.join("out"), &[])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("not-a-dir"));
}
