//! plan.gpkg, `check --gpkg` and `compare --gpkg` as GDAL reads them: Debian's `ogrinfo`
//! and `gdalsrsinfo` (gdal-bin) and GDAL's GeoPackage validator (python3-gdal), installed by
//! scripts/ci-deps.sh.

mod common;

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use common::{build_ok, edo_city, fixture, read_json, read_lots};

/// Runs a GDAL tool and returns what it printed; a missing tool fails with what to run.
fn gdal(tool: &str, args: &[&str]) -> String {
    let o = Command::new(tool).args(args).output().unwrap_or_else(|e| {
        panic!("{tool} cannot be run ({e}): run `bash scripts/ci-deps.sh` (Debian gdal-bin)")
    });
    assert!(
        o.status.success(),
        "{tool} {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !err.contains("ERROR") && !err.contains("Warning"),
        "{tool} {args:?} complained: {err}"
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Each layer's feature count, as `ogrinfo -so -al` lists them.
fn counts(gpkg: &Path) -> BTreeMap<String, usize> {
    let text = gdal("ogrinfo", &["-so", "-al", "-ro", gpkg.to_str().unwrap()]);
    let mut out = BTreeMap::new();
    let mut layer = String::new();
    for line in text.lines() {
        if let Some(name) = line.strip_prefix("Layer name: ") {
            layer = name.trim().to_string();
        } else if let Some(n) = line.strip_prefix("Feature Count: ") {
            out.insert(layer.clone(), n.trim().parse().unwrap());
        }
    }
    out
}

/// The rows of an SQL query over a package: one map of field -> value per feature.
fn rows(gpkg: &Path, sql: &str) -> Vec<BTreeMap<String, String>> {
    let text = gdal(
        "ogrinfo",
        &["-ro", "-q", gpkg.to_str().unwrap(), "-sql", sql],
    );
    let mut out: Vec<BTreeMap<String, String>> = Vec::new();
    for line in text.lines() {
        if line.starts_with("OGRFeature(") {
            out.push(BTreeMap::new());
        } else if let (Some(row), Some((k, v))) = (out.last_mut(), line.split_once(" = ")) {
            let key = k.trim().split(' ').next().unwrap_or_default().to_string();
            row.insert(key, v.trim().to_string());
        } else if let (Some(row), Some(wkt)) = (out.last_mut(), line.trim().strip_prefix("POLYGON"))
        {
            row.insert("geom".into(), wkt.trim().to_string());
        }
    }
    out
}

/// `edo-city compare a b --gpkg out`.
fn compare_gpkg(a: &Path, b: &Path, out: &Path) -> std::process::Output {
    edo_city()
        .arg("compare")
        .arg(a)
        .arg(b)
        .arg("--gpkg")
        .arg(out)
        .output()
        .unwrap()
}

/// GDAL's own check of a GeoPackage against the standard's requirements.
fn validate(gpkg: &Path) {
    let script = "/usr/lib/python3/dist-packages/osgeo_utils/samples/validate_gpkg.py";
    let o = Command::new("/usr/bin/python3")
        .arg(script)
        .arg(gpkg)
        .output()
        .expect("python3 runs");
    assert!(
        o.status.success() && o.stdout.is_empty() && o.stderr.is_empty(),
        "{script} (Debian python3-gdal, from scripts/ci-deps.sh) on {}: {}{}",
        gpkg.display(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn count_where(r: &serde_json::Value, layer: &str) -> usize {
    r["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|k| k["layer"] == layer)
        .count()
}

#[test]
fn every_layer_opens_in_gdal_with_the_reports_counts() {
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("out");
    let r = build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let gpkg = out.join("plan.gpkg");
    validate(&gpkg);
    let n = counts(&gpkg);
    let layers: Vec<&str> = n.keys().map(String::as_str).collect();
    assert_eq!(
        layers,
        [
            "fences",
            "frontages",
            "gardens",
            "gates",
            "halls",
            "houses",
            "kura",
            "landmarks",
            "layer_styles",
            "lots",
            "people",
            "skipped",
            "tiles",
            "trees"
        ]
    );
    let c = &r["counts"];
    let get = |k: &str| c[k].as_u64().unwrap() as usize;
    // Every lot read is a feature: read = built + skipped + lots of other uses.
    let lots = |status: &str| {
        rows(
            &gpkg,
            &format!("SELECT count(*) AS n FROM lots WHERE status = '{status}'"),
        )[0]["n"]
            .parse::<usize>()
            .unwrap()
    };
    assert_eq!(n["lots"], get("lots") + count_where(&r, "lots"));
    assert_eq!(lots("built"), get("machiya"));
    assert_eq!(lots("skipped"), count_where(&r, "lots"));
    assert_eq!(lots("no house"), get("lots") - get("machiya"));
    assert_eq!(n["houses"], get("machiya") + get("footprints"));
    assert_eq!(n["frontages"], n["houses"]);
    assert_eq!(n["tiles"], get("tiles"));
    assert_eq!(n["skipped"], get("skipped"));
    assert_eq!(n["gates"], get("gates"));
    assert_eq!(n["people"], get("people"));
    assert_eq!(n["trees"], get("trees"));
    assert_eq!(n["gardens"], r["gardens"].as_array().unwrap().len());
    assert_eq!(n["halls"], r["halls"].as_array().unwrap().len());
    let placed = rows(
        &gpkg,
        "SELECT count(*) AS n FROM kura WHERE status = 'placed'",
    );
    assert_eq!(placed[0]["n"].parse::<usize>().unwrap(), get("kura"));
    // Every spatial index is whole (SQLite's own check), and a box query through it finds
    // what a scan of the geometries finds.
    for layer in n.keys().filter(|l| *l != "layer_styles") {
        let sql = format!("SELECT rtreecheck('rtree_{layer}_geom') AS c");
        assert_eq!(rows(&gpkg, &sql)[0]["c"], "ok", "{layer}");
    }
    let spat = gdal(
        "ogrinfo",
        &[
            "-ro",
            "-q",
            gpkg.to_str().unwrap(),
            "lots",
            "-spat",
            "-22950",
            "-109900",
            "-22900",
            "-109850",
        ],
    );
    let scan = rows(
        &gpkg,
        "SELECT count(*) AS n FROM lots WHERE ST_MaxX(geom) >= -22950 AND ST_MinX(geom) <= -22900 \
         AND ST_MaxY(geom) >= -109900 AND ST_MinY(geom) <= -109850",
    );
    let found = spat.matches("OGRFeature(lots)").count();
    assert!(found > 10, "{found}");
    assert_eq!(found.to_string(), scan[0]["n"]);
    // Each of the twelve spatial layers styled, as QGIS stores styles.
    assert_eq!(n["layer_styles"], 13);
    // A placed garden carries its fitness and the five rule scores.
    let g = &rows(&gpkg, "SELECT * FROM gardens WHERE placed = 1")[0];
    for rule in [
        "centre",
        "triangles",
        "opposition",
        "adjacency",
        "axis",
        "fitness",
    ] {
        assert!(g[rule].parse::<f64>().unwrap() >= 0.0, "{rule}: {g:?}");
    }
}

#[test]
fn the_srs_is_the_output_crs_and_a_lot_round_trips_within_a_millimetre() {
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet", "--no-plan"]);
    let gpkg = out.join("plan.gpkg");
    let prj = fixture("kyoto-small").join("lots.prj");
    let ours = gdal("gdalsrsinfo", &["-o", "proj4", gpkg.to_str().unwrap()]);
    let theirs = gdal("gdalsrsinfo", &["-o", "proj4", prj.to_str().unwrap()]);
    assert_eq!(ours.trim(), theirs.trim());
    assert!(ours.contains("+proj=tmerc"), "{ours}");
    let shp = read_lots(&fixture("kyoto-small").join("lots.shp"));
    let mut checked = 0;
    for row in rows(&gpkg, "SELECT id, geom FROM lots ORDER BY fid LIMIT 40") {
        let (_, _, lot) = &shp[&row["id"]];
        let wkt = row["geom"].trim_matches(|c| c == '(' || c == ')');
        for pair in wkt.split(',') {
            let v: Vec<f64> = pair
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            let near = lot
                .exterior()
                .0
                .iter()
                .map(|c| (c.x - v[0]).hypot(c.y - v[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(near < 0.001, "lot {}: {pair} is {near} m off", row["id"]);
            checked += 1;
        }
    }
    assert!(checked >= 160, "{checked} vertices");
}

#[test]
fn the_plan_is_the_same_bytes_for_any_thread_count() {
    let work = tempfile::tempdir().unwrap();
    let (a, b) = (work.path().join("a"), work.path().join("b"));
    build_ok(&fixture("kyoto-small"), &a, &["--quiet", "-j", "1"]);
    build_ok(&fixture("kyoto-small"), &b, &["--quiet", "-j", "3"]);
    let read = |d: &Path| std::fs::read(d.join("plan.gpkg")).unwrap();
    assert!(
        read(&a) == read(&b),
        "plan.gpkg differs between -j 1 and -j 3"
    );
    // Built again without gpkg, the directory keeps no plan.gpkg of the earlier build.
    build_ok(
        &fixture("kyoto-small"),
        &a,
        &["--quiet", "--format", "obj", "--force"],
    );
    assert!(!a.join("plan.gpkg").exists());
    let leftovers: Vec<_> = std::fs::read_dir(&a)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("gpkg"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn check_writes_each_problem_where_it_is() {
    let work = tempfile::tempdir().unwrap();
    // A repeated id: the problem is drawn at the second record's own outline, not at the
    // first lot of that id.
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input/duplicate_id");
    let gpkg = work.path().join("problems.gpkg");
    let o = edo_city()
        .arg("check")
        .arg(&case)
        .arg("--gpkg")
        .arg(&gpkg)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "problems found");
    assert!(String::from_utf8_lossy(&o.stdout).contains("problems.gpkg"));
    validate(&gpkg);
    let found = rows(&gpkg, "SELECT * FROM problems");
    assert_eq!(found.len(), 1, "{found:?}");
    let p = &found[0];
    assert!(p["reason"].starts_with("duplicate id"), "{p:?}");
    // The shapefile's records of that id, in order: the first was built, the second is the
    // problem, drawn at its own outline.
    let mut reader = shapefile::Reader::from_path(case.join("lots.shp")).unwrap();
    let outlines: Vec<String> = reader
        .iter_shapes_and_records()
        .map(|r| r.unwrap())
        .filter(|(_, rec)| {
            matches!(rec.get("id"), Some(dbase::FieldValue::Character(Some(s))) if s.trim() == p["id"])
                || matches!(rec.get("id"), Some(dbase::FieldValue::Numeric(Some(n))) if format!("{}", *n as i64) == p["id"])
        })
        .map(|(shape, _)| match shape {
            shapefile::Shape::Polygon(poly) => {
                let q = poly.rings()[0].points()[0];
                format!("{} {}", q.x, q.y)
            }
            _ => panic!("lots are polygons"),
        })
        .collect();
    assert_eq!(outlines.len(), 2, "{outlines:?}");
    assert!(outlines[0] != outlines[1]);
    assert!(p["geom"].contains(&outlines[1]), "{p:?} {outlines:?}");
    assert!(!p["geom"].contains(&outlines[0]), "{p:?} {outlines:?}");
    assert!(p["record"] != "0" && p["record"] != "(null)", "{p:?}");
    // The fixture: its one problem (a table row without a lot) has no place.
    let gpkg = work.path().join("fixture.gpkg");
    let o = edo_city()
        .arg("check")
        .arg(fixture("kyoto-small"))
        .arg("--gpkg")
        .arg(&gpkg)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let n = counts(&gpkg);
    assert_eq!(n["problems"], 1);
    assert_eq!(n["warnings"], 0);
    validate(&gpkg);
}

#[test]
fn compare_writes_the_lots_and_tiles_two_hypotheses_disagree_on() {
    let work = tempfile::tempdir().unwrap();
    let (a, b) = (work.path().join("a"), work.path().join("b"));
    build_ok(&fixture("kyoto-small"), &a, &["--quiet", "--no-plan"]);
    let params = work.path().join("no-avoidance.toml");
    std::fs::write(&params, "[kura]\ncollision = false\n").unwrap();
    let pb = params.to_str().unwrap();
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "--no-plan", "--params", pb],
    );
    let diff = work.path().join("diff.gpkg");
    let o = compare_gpkg(&a, &b, &diff);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    validate(&diff);
    let ra = read_json(&a.join("report.json"));
    let rb = read_json(&b.join("report.json"));
    let kura = |r: &serde_json::Value| r["counts"]["kura"].as_u64().unwrap() as usize;
    // Without avoidance every colliding kura is built: exactly those lots differ.
    let lots = rows(&diff, "SELECT * FROM lots");
    assert_eq!(lots.len(), kura(&rb) - kura(&ra));
    for l in &lots {
        assert_eq!(l["differs"], "kura", "{l:?}");
        assert_eq!(
            (l["kura_a"].as_str(), l["kura_b"].as_str()),
            ("refused", "placed")
        );
        assert!(l.contains_key("geom"), "{l:?}");
    }
    let c: serde_json::Value = serde_json::from_slice(
        &edo_city()
            .arg("compare")
            .arg(&a)
            .arg(&b)
            .arg("--json")
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    let tiles = rows(&diff, "SELECT * FROM tiles");
    assert_eq!(tiles.len(), c["tiles"]["differ"].as_array().unwrap().len());
    assert!(tiles
        .iter()
        .all(|t| t["difference"] == "differ" && t.contains_key("geom")));
    // A build without plan.gpkg is named, with what to do; nothing is written.
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "--format", "obj,glb", "--force"],
    );
    let none = work.path().join("none.gpkg");
    let o = compare_gpkg(&a, &b, &none);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("plan.gpkg") && err.contains("gpkg among its formats"),
        "{err}"
    );
    assert!(!none.exists());
}

#[test]
fn houses_generation_could_not_build_are_marked_in_lots_and_houses() {
    let dir = tempfile::tempdir().unwrap();
    let (out, r) = common::build_with_failing_template(dir.path());
    let gpkg = out.join("plan.gpkg");
    let failed = r["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|k| k["layer"] == "lots" && !k["reason"].as_str().unwrap().starts_with("its "))
        .count();
    assert!(failed > 0);
    let one = |sql: &str| rows(&gpkg, sql)[0]["n"].parse::<usize>().unwrap();
    assert_eq!(
        one("SELECT count(*) AS n FROM lots WHERE status = 'skipped'"),
        failed
    );
    assert_eq!(
        one("SELECT count(*) AS n FROM houses WHERE built = 0"),
        failed
    );
    assert_eq!(
        one("SELECT count(*) AS n FROM lots WHERE status = 'built'"),
        r["counts"]["machiya"].as_u64().unwrap() as usize
    );
    let nan = one("SELECT count(*) AS n FROM houses WHERE built = 0 AND reason LIKE '%is NaN%'");
    assert!(nan > 0 && nan < failed, "{nan} of {failed}");
    validate(&gpkg);
}

#[test]
fn compare_reads_builds_of_a_broken_input() {
    // A repeated id: plan.gpkg holds two lots of that id (the one built, the record
    // skipped); the difference keeps one row for it.
    let work = tempfile::tempdir().unwrap();
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input/duplicate_id");
    let (a, b) = (work.path().join("a"), work.path().join("b"));
    build_ok(&case, &a, &["--quiet", "--no-plan"]);
    // Every lot too shallow for a house in B.
    let params = work.path().join("deep.toml");
    std::fs::write(&params, "[machiya]\nmin_depth = 100.0\n").unwrap();
    build_ok(
        &case,
        &b,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let twice = rows(
        &a.join("plan.gpkg"),
        "SELECT status FROM lots WHERE id = '2' ORDER BY fid",
    );
    let status: Vec<&str> = twice.iter().map(|r| r["status"].as_str()).collect();
    assert_eq!(
        status,
        ["built", "skipped"],
        "the first built, the repeat skipped"
    );
    let diff = work.path().join("diff.gpkg");
    let o = compare_gpkg(&a, &b, &diff);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    validate(&diff);
    let lots = rows(&diff, "SELECT * FROM lots ORDER BY id");
    let ids: Vec<&str> = lots.iter().map(|l| l["id"].as_str()).collect();
    assert_eq!(ids, ["1", "2", "3"]);
    for l in &lots {
        assert!(l["differs"].contains("house"), "{l:?}");
        assert_eq!(
            (l["house_a"].as_str(), l["house_b"].as_str()),
            ("built", "skipped")
        );
    }
}
