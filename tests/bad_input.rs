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
    // A lot traced in 30,000 real steps (a 1 m zigzag simplification cannot remove): more
    // than `simplify.max_vertices`.
    let mut traced = vec![(1100.0, 0.0), (1105.0, 0.0)];
    for i in 0..30_000 {
        traced.push((1105.0 - 5.0 * i as f64 / 30_000.0, 25.0 + (i % 2) as f64));
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
        (
            "traced",
            traced,
            Some("more than `simplify.max_vertices` (20000)"),
        ),
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
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .map(|p| std::fs::read_to_string(p).unwrap())
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
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .map(|p| std::fs::read_to_string(p).unwrap())
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

/// Where the committed corpus lives.
fn corpus_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input")
}

/// Every file under `dir` (relative path -> bytes), `expect.toml` included.
fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    all_files(dir)
}

#[test]
fn the_committed_corpus_is_what_its_script_makes() {
    let fresh = tempfile::tempdir().unwrap();
    for case in common::corpus::cases() {
        let d = fresh.path().join(case.name);
        std::fs::create_dir_all(&d).unwrap();
        (case.make)(&d);
        std::fs::write(d.join("expect.toml"), case.expect).unwrap();
    }
    if std::env::var_os("EDO_CITY_WRITE_CORPUS").is_some() {
        let _ = std::fs::remove_dir_all(corpus_dir());
        for (rel, bytes) in tree(fresh.path()) {
            let p = corpus_dir().join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, bytes).unwrap();
        }
    }
    assert!(
        tree(fresh.path()) == tree(&corpus_dir()),
        "tests/bad_input differs from tests/common/corpus.rs: run `make bad-input`"
    );
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Expect {
    class: String,
    #[serde(default)]
    message: Option<String>,
    #[serde(default)]
    args: Vec<String>,
    #[serde(default)]
    built: Option<u64>,
    #[serde(default)]
    skipped: Vec<ExpectSkip>,
    /// The output directory's name (a file of that name is put there first).
    #[serde(default)]
    out: Option<String>,
    /// Simulate a disk that is full after this many bytes.
    #[serde(default)]
    disk_bytes: Option<u64>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ExpectSkip {
    layer: String,
    id: String,
    reason: String,
}

/// The file a skipped feature of `layer` must be reported in.
fn file_of(layer: &str) -> &'static str {
    match layer {
        "lots table" => "lots.csv",
        "trees" => "trees.shp",
        "people" => "people.shp",
        _ => "lots.shp",
    }
}

#[test]
fn every_broken_input_gets_its_class_of_message() {
    let mut cases: Vec<_> = std::fs::read_dir(corpus_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    cases.sort();
    assert!(
        cases.len() >= 25,
        "only {} cases in tests/bad_input",
        cases.len()
    );
    // Every case runs, two at a time (a build of a small case leaves a core idle); the
    // failures are listed together, in the cases' order.
    use rayon::prelude::*;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let failed: Vec<String> = pool.install(|| {
        cases
            .par_iter()
            .filter_map(|case| {
                std::panic::catch_unwind(|| run_case(case)).err().map(|e| {
                    match e.downcast_ref::<String>() {
                        Some(m) => m.clone(),
                        None => format!("{}: {:?}", case.display(), e.downcast_ref::<&str>()),
                    }
                })
            })
            .collect()
    });
    assert!(
        failed.is_empty(),
        "{} case(s) failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

/// Runs one case of the corpus and checks its `expect.toml`.
fn run_case(case: &Path) {
    {
        let name = case.file_name().unwrap().to_string_lossy().to_string();
        let expect: Expect =
            toml::from_str(&std::fs::read_to_string(case.join("expect.toml")).unwrap()).unwrap();
        let work = tempfile::tempdir().unwrap();
        for (rel, bytes) in tree(case) {
            let to = work.path().join(rel);
            std::fs::create_dir_all(to.parent().unwrap()).unwrap();
            std::fs::write(to, bytes).unwrap();
        }
        let out_name = expect.out.clone().unwrap_or_else(|| "out".into());
        let out = work.path().join(&out_name);
        if expect.out.is_some() {
            std::fs::write(&out, "a file where the output should go").unwrap();
        }
        let mut cmd = edo_city();
        cmd.current_dir(work.path())
            .args(["build", ".", "--out", &out_name, "--quiet"])
            .args(&expect.args);
        if let Some(b) = expect.disk_bytes {
            cmd.env("EDO_CITY_SIMULATE_DISK_BYTES", b.to_string());
        }
        let o = cmd.output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr).to_string();
        let code = o.status.code();
        match expect.class.as_str() {
            "error" => {
                assert_eq!(code, Some(2), "{name}: {stderr}");
                let m = expect.message.as_deref().unwrap();
                assert!(stderr.contains(m), "{name}: `{m}` not in: {stderr}");
                // Nothing written: no manifest, no tile, no temporary.
                if out.is_dir() {
                    let files = all_files(&out);
                    assert!(
                        files.keys().all(|f| f.starts_with("tiles/textures/")),
                        "{name}: wrote {:?}",
                        files.keys().collect::<Vec<_>>()
                    );
                } else if expect.out.is_some() {
                    assert!(out.is_file(), "{name}: the blocking file is gone");
                }
            }
            "warning" | "ok" => {
                assert_eq!(code, Some(0), "{name}: {stderr}");
                let r = read_json(&out.join("report.json"));
                if let Some(n) = expect.built {
                    assert_eq!(r["counts"]["machiya"], n, "{name}");
                }
                let skipped = r["skipped"].as_array().unwrap();
                for s in &expect.skipped {
                    let hit = skipped.iter().any(|k| {
                        k["layer"] == s.layer.as_str()
                            && k["id"] == s.id.as_str()
                            && k["reason"].as_str().unwrap().contains(&s.reason)
                            && k["file"].as_str().unwrap().ends_with(file_of(&s.layer))
                    });
                    assert!(
                        hit,
                        "{name}: no skip {} {} `{}`: {skipped:#?}",
                        s.layer, s.id, s.reason
                    );
                }
                // Every record read is built or listed as skipped.
                for a in r["accounting"].as_array().unwrap() {
                    assert_eq!(a["unaccounted"], 0, "{name}: {a}");
                }
                if let Some(m) = &expect.message {
                    let said = r["warnings"].to_string() + &r["skipped"].to_string();
                    assert!(said.contains(m.as_str()), "{name}: `{m}` not in {said}");
                }
                if expect.class == "ok" {
                    assert!(skipped.is_empty(), "{name}: {skipped:#?}");
                } else {
                    assert!(
                        !skipped.is_empty() || expect.message.is_some(),
                        "{name}: a warning case expects a skip or a message"
                    );
                }
                assert!(out.join("manifest.json").exists(), "{name}");
            }
            other => panic!("{name}: unknown class {other}"),
        }
    }
}
