//! The real layers of `../shared/data/real` (see its README), built with the example
//! parameter files of `params/examples/`. The data is read where it lies, never copied: the
//! full set in `../shared` when it is beside the repository, else its licence-clean cut in
//! `fixtures/real` (`scripts/cut_real.py`, `make real-cut`), on which every assertion here
//! holds the same (tested: the same tiles, byte for byte). Swellendam has no cut (its
//! licence, fixtures/real/README.md): its test runs where `../shared` is (CI).
//! Counts are pinned: a change that moves them must say why.

mod common;

use std::path::{Path, PathBuf};

use common::*;

/// The data set `set`: the full one when `../shared` is here, else its cut, else `None`
/// with a note saying why it is skipped.
fn real(set: &str) -> Option<PathBuf> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let full = repo.join("../shared/data/real").join(set);
    if full.is_dir() {
        return Some(full);
    }
    let cut = repo.join("fixtures/real").join(set);
    if cut.is_dir() {
        return Some(cut);
    }
    eprintln!(
        "skipping {set}: {} is not here, and the set has no cut in fixtures/real (see its \
         README)",
        full.display()
    );
    None
}

fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("params/examples")
        .join(format!("{name}.toml"))
        .display()
        .to_string()
}

fn build_example(set: &str, name: &str, out: &Path) -> Option<serde_json::Value> {
    let dir = real(set)?;
    let r = build_ok(&dir, out, &["--quiet", "--params", &example(name)]);
    // Every tile has its ground, real parcels and roads included.
    for t in r["tiles"].as_array().unwrap() {
        assert!(t["ground_bytes"].as_u64().unwrap() > 0, "{set}: {t}");
    }
    // Every record of every layer is built or listed as skipped.
    for a in r["accounting"].as_array().unwrap() {
        assert_eq!(a["unaccounted"], 0, "{set}: {a}");
        assert_eq!(
            a["read"].as_u64().unwrap(),
            r["layers"]
                .as_array()
                .unwrap()
                .iter()
                .find(|l| l["file"] == a["file"])
                .unwrap()["features"]
                .as_u64()
                .unwrap()
        );
    }
    Some(r)
}

#[test]
fn chino_parcels_with_widths_from_split_lines() {
    let out = tempfile::tempdir().unwrap();
    let Some(r) = build_example("chino_plateau_devpermit", "chino", out.path()) else {
        return;
    };
    // 217 parcels in, every one a town lot with a house (none is too shallow or degenerate)
    // but for the 9 where one of the 45 landmarks stands.
    assert_eq!(r["counts"]["lots"], 217);
    assert_eq!(r["counts"]["machiya"], 208);
    assert_eq!(r["counts"]["skipped"], 9, "{}", r["skipped"]);
    for s in r["skipped"].as_array().unwrap() {
        let reason = s["reason"].as_str().unwrap();
        assert!(reason.starts_with("displaced by landmark "), "{s}");
    }
    assert!(
        r["crs"].as_str().unwrap().contains("+lon_0=138.5"),
        "zone VIII kept"
    );
    let w = r["warnings"].to_string();
    assert!(w.contains("took their width from"), "{w}");
    // Shift_JIS district ids and lot numbers came through.
    assert_eq!(r["layers"][0]["encoding"], "Shift_JIS (.cpg)");
}

#[test]
fn osaka_footprints_stand_on_their_ground_at_their_height() {
    let out = tempfile::tempdir().unwrap();
    let Some(r) = build_example("osaka_plateau", "osaka", out.path()) else {
        return;
    };
    assert_eq!(r["counts"]["footprints_read"], 1600);
    // 33 footprints are shallower than machiya.min_depth (2 m) behind their frontage: sheds
    // and slivers of the PLATEAU footprints; each is listed with that reason (34 before
    // vertex generalisation, simplify.tolerance).
    assert_eq!(r["counts"]["footprints"], 1567);
    assert_eq!(r["counts"]["skipped"], 33);
    for s in r["skipped"].as_array().unwrap() {
        assert_eq!(s["layer"], "footprints");
        assert!(s["reason"].as_str().unwrap().contains("deep"), "{s}");
    }
    // The tallest building (WTC Cosmo Tower, lod1_h 276 m on its ground) is that tall.
    let manifest = read_json(&out.path().join("manifest.json"));
    let mut top: f64 = 0.0;
    for t in manifest["tiles"].as_array().unwrap() {
        let text =
            std::fs::read_to_string(out.path().join(t["obj"]["path"].as_str().unwrap())).unwrap();
        for line in text.lines().filter(|l| l.starts_with("v ")) {
            let y: f64 = line.split(' ').nth(2).unwrap().parse().unwrap();
            top = top.max(y);
        }
    }
    assert!((270.0..290.0).contains(&top), "highest vertex {top} m");
}

#[test]
fn osaka_lon_lat_reprojects_onto_the_zone_vi_copy() {
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let Some(ra) = build_example("osaka_plateau", "osaka", a.path()) else {
        return;
    };
    let rb = build_example("osaka_plateau", "osaka-lonlat", b.path()).unwrap();
    assert_eq!(rb["counts"]["footprints_read"], 1600);
    assert_eq!(ra["counts"]["footprints_read"], 1600);
    assert!(!ra["layers"][0]["reprojected"].as_bool().unwrap());
    assert!(rb["layers"][0]["reprojected"].as_bool().unwrap());
    let (ma, mb) = (
        read_json(&a.path().join("manifest.json")),
        read_json(&b.path().join("manifest.json")),
    );
    assert_eq!(ma["origin"], mb["origin"]);
    // Same footprints, same tiles; vertex for vertex within 2 mm (rounding to millimetres of
    // two slightly different inputs). Measured: none of 1,567 differ with vertex
    // generalisation on; without it 4 of 1,566 did (two picked another frontage edge in a
    // near tie of street distances, two rounded a short edge to another vertex count).
    let (mut same, mut compared) = (0, 0);
    for t in ma["tiles"].as_array().unwrap() {
        let path = t["obj"]["path"].as_str().unwrap();
        let objects = |dir: &Path| -> std::collections::HashMap<String, Vec<[f64; 3]>> {
            let text = std::fs::read_to_string(dir.join(path)).unwrap();
            let mut out = std::collections::HashMap::new();
            let mut cur = String::new();
            for line in text.lines() {
                if let Some(name) = line.strip_prefix("o ") {
                    cur = name.to_string();
                } else if let Some(v) = line.strip_prefix("v ") {
                    let mut it = v.split(' ').map(|x| x.parse::<f64>().unwrap());
                    let p = [it.next().unwrap(), it.next().unwrap(), it.next().unwrap()];
                    out.entry(cur.clone()).or_insert_with(Vec::new).push(p);
                }
            }
            out
        };
        let (oa, ob) = (objects(a.path()), objects(b.path()));
        for (name, va) in &oa {
            let Some(vb) = ob.get(name) else { continue };
            compared += 1;
            let close = va.len() == vb.len()
                && va
                    .iter()
                    .zip(vb)
                    .all(|(p, q)| (0..3).all(|i| (p[i] - q[i]).abs() <= 0.002));
            same += close as usize;
        }
    }
    assert!(compared >= 1560, "{compared}");
    assert!(
        compared - same <= 4,
        "{} of {compared} footprints differ",
        compared - same
    );
}

#[test]
fn kyoto_japanese_field_names_and_no_buildings() {
    let out = tempfile::tempdir().unwrap();
    let Some(r) = build_example("kyoto_plateau_related", "kyoto", out.path()) else {
        return;
    };
    assert_eq!(r["layers"][0]["role"], "streets");
    assert_eq!(r["layers"][0]["features"], 210);
    assert_eq!(r["counts"]["tiles"], 0);
    assert!(r["warnings"].to_string().contains("nothing to build"));

    // The layer's Japanese field names decode, and a full name finds its truncated field.
    let dir = real("kyoto_plateau_related").unwrap();
    let layer =
        edo_city::input::shp::read_layer(&dir.join("jgd2011_zone6_sjis/park.shp"), "").unwrap();
    let found = edo_city::input::fields::resolve_field(
        "所在地市区町村",
        &layer.fields,
        layer.text_encoding,
    );
    assert_eq!(found, Some("所在地市区"));
    assert!(layer.fields.iter().any(|f| f == "公園名"));
}

#[test]
fn swellendam_erven_and_buildings_from_two_utm_zones() {
    let out = tempfile::tempdir().unwrap();
    let Some(r) = build_example("swellendam_osm", "swellendam", out.path()) else {
        return;
    };
    // 6 multipart features with 984 rings: 551 outer rings and 433 holes. Each hole goes to
    // the outer ring around it (as GDAL reads them; the shapefile crate gives a hole to the
    // outer ring written before it, which made 3 extra polygons of holes that lie elsewhere):
    // 551 polygons, one of which has no area.
    assert_eq!(r["counts"]["lots"], 550);
    assert_eq!(r["accounting"][0]["read"], 6);
    assert_eq!(r["accounting"][0]["unaccounted"], 0);
    assert_eq!(r["counts"]["footprints_read"], 4708);
    let footprints = &r["layers"][1];
    assert_eq!(footprints["role"], "footprints");
    assert_eq!(
        footprints["reprojected"], true,
        "UTM 34S buildings into the erven's 33S"
    );
    // Every footprint is built. Of the 550 lots, 549 get a house; the other is a sliver
    // with no depth behind its frontage, and one more ring had no area at all: both are
    // listed with that reason.
    assert_eq!(r["counts"]["footprints"], 4708);
    assert_eq!(r["counts"]["machiya"], 549);
    // OSM values that are not numbers are counted, not silently replaced.
    let warnings = r["warnings"].to_string();
    assert!(
        warnings.contains("3 footprint(s) have a `building_l`"),
        "{warnings}"
    );
    assert_eq!(r["counts"]["skipped"], 2);
    for s in r["skipped"].as_array().unwrap() {
        assert_eq!(s["layer"], "lots");
        let reason = s["reason"].as_str().unwrap();
        assert!(reason.contains("no area") || reason.contains("deep"), "{s}");
    }
}

#[test]
fn chino_public_buildings_stand_as_landmarks() {
    let out = tempfile::tempdir().unwrap();
    let Some(r) = build_example("chino_plateau_devpermit", "chino", out.path()) else {
        return;
    };
    // 45 points in WGS84, each kind mapped to a model: all placed, in zone VIII metres
    // beside the parcels, whole in the tile named in the manifest.
    let l = &r["landmarks"];
    let placed = l["placed"].as_array().unwrap();
    assert_eq!(placed.len(), 45, "{}", l["skipped"]);
    assert_eq!(l["skipped"].as_array().unwrap().len(), 0);
    assert_eq!(l["displaced"].as_array().unwrap().len(), 9);
    let a = r["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "landmarks")
        .expect("the landmarks layer is in the ledger");
    assert_eq!(a["read"], 45);
    let names: Vec<&str> = placed.iter().map(|p| p["id"].as_str().unwrap()).collect();
    assert!(names.contains(&"茅野駅"), "{names:?}");
    let manifest = read_json(&out.path().join("manifest.json"));
    for p in placed {
        let b: Vec<f64> = p["bounds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        // Zone VIII (origin 138.5 E, 36 N): Chino lies 20-40 km west, within 10 km of 36 N.
        assert!((-40_000.0..-15_000.0).contains(&b[0]), "{p}");
        assert!((-10_000.0..10_000.0).contains(&b[1]), "{p}");
        assert!(b[5] - b[2] > 3.0 && b[5] - b[2] < 60.0, "{p}");
        // Its tile (the tile of its anchor) holds the middle of its box; tile bounds are
        // stated from the manifest's origin.
        let tile = p["tile"].as_str().unwrap();
        let t = manifest["tiles"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["id"] == tile)
            .unwrap_or_else(|| panic!("{tile} not in the manifest"));
        let tb: Vec<f64> = t["bounds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let o = &manifest["origin"];
        let cx = (b[0] + b[3]) / 2.0 - o[0].as_f64().unwrap();
        let cy = (b[1] + b[4]) / 2.0 - o[1].as_f64().unwrap();
        assert!(
            tb[0] <= cx && cx <= tb[3] && tb[1] <= cy && cy <= tb[4],
            "{p} in {t}"
        );
    }
}

#[test]
fn init_guesses_build_every_real_set() {
    for (set, built_min) in [
        ("chino_plateau_devpermit", 217),
        ("osaka_plateau", 1500),
        ("swellendam_osm", 5000),
        ("kyoto_plateau_related", 0),
    ] {
        let Some(dir) = real(set) else { continue };
        let work = tempfile::tempdir().unwrap();
        let params = work.path().join("guess.toml");
        edo_city()
            .arg("init")
            .arg(&dir)
            .arg("-o")
            .arg(&params)
            .assert()
            .success();
        let text = std::fs::read_to_string(&params).unwrap();
        assert!(text.contains("# Layers found:"), "{set}: {text}");
        let r = build_ok(
            &dir,
            &work.path().join("out"),
            &["--quiet", "--params", params.to_str().unwrap()],
        );
        let built =
            r["counts"]["machiya"].as_u64().unwrap() + r["counts"]["footprints"].as_u64().unwrap();
        assert!(
            built >= built_min,
            "{set}: {built} built with the guessed parameters"
        );
    }
}

#[test]
fn chino_parcels_take_the_town_area_holding_them() {
    let out = tempfile::tempdir().unwrap();
    let Some(r) = build_example("chino_plateau_devpermit", "chino", out.path()) else {
        return;
    };
    let by_district = r["counts"]["by_district"].as_object().unwrap();
    // f_district has 10 town areas (町丁); every house lies in one of them (the 217 parcels'
    // houses less the 9 where a landmark stands).
    assert_eq!(by_district.len(), 10, "{by_district:?}");
    assert!(by_district.contains_key("ちの上原"));
    let total: u64 = by_district.values().map(|v| v.as_u64().unwrap()).sum();
    assert_eq!(total, 208);
}
