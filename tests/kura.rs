//! Kura (section 4.2): candidates, placement inside the lot, the collision avoidance of Fig.7,
//! Table 2 in the report, and independence from tiles and order.

mod common;

use std::path::Path;

use common::{build_objects, build_ok, distance_to_lot, edo_city, read_json, synth};
use edo_city::synth::{write_blocks, write_lots, SynthLot};
use geo_types::{Coord, LineString, Polygon};

fn lot(id: u64, ring: Vec<[f64; 2]>) -> SynthLot {
    SynthLot {
        id,
        ring,
        lot_use: "machiya",
        mtype: "平屋",
        district: "",
        gate: "",
    }
}

/// The paper's case: two wide, deep lots back to back whose shared back line is not square
/// to their streets, so their provisional plots (rectangles square to each frontage) overlap
/// by a sliver although the lots do not. Lot 3 stands alone on the same street: no collision.
fn back_to_back(dir: &Path) -> Vec<SynthLot> {
    let lots = vec![
        lot(1, vec![[0.0, 0.0], [10.0, 0.0], [10.0, 31.0], [0.0, 29.0]]),
        lot(
            2,
            vec![[0.0, 29.0], [10.0, 31.0], [10.0, 60.0], [0.0, 60.0]],
        ),
        lot(
            3,
            vec![[30.0, 0.0], [40.0, 0.0], [40.0, 28.0], [30.0, 28.0]],
        ),
    ];
    write_lots(&dir.join("lots.shp"), &lots).unwrap();
    let block = vec![[-10.0, 0.0], [60.0, 0.0], [60.0, 60.0], [-10.0, 60.0]];
    write_blocks(&dir.join("blocks.shp"), &[block]).unwrap();
    lots
}

fn polygon(ring: &[[f64; 2]]) -> Polygon<f64> {
    let mut pts: Vec<Coord<f64>> = ring.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
    pts.push(pts[0]);
    Polygon::new(LineString(pts), vec![])
}

/// kura_<id> objects of a build and their vertices (map metres).
fn kura_objects(out: &Path) -> Vec<(String, Vec<[f64; 3]>)> {
    let mut out_objects = Vec::new();
    for o in build_objects(out) {
        if let Some(id) = o.name.strip_prefix("kura_") {
            out_objects.push((id.to_string(), o.vertices));
        }
    }
    out_objects
}

#[test]
fn back_to_back_lots_collide_and_lose_their_kura_unless_avoidance_is_off() {
    let dir = tempfile::tempdir().unwrap();
    let lots = back_to_back(dir.path());

    let with = dir.path().join("with");
    let r = build_ok(dir.path(), &with, &["--quiet", "--no-plan"]);
    let t2 = &r["table2"];
    assert_eq!(t2["machiya"], 3);
    assert_eq!(t2["kura_candidates"], 3);
    assert_eq!(t2["kura_without_avoidance"], 3);
    assert_eq!(t2["kura_with_avoidance"], 1, "{t2}");
    assert_eq!(r["counts"]["kura"], 1);
    let built: Vec<String> = kura_objects(&with).into_iter().map(|k| k.0).collect();
    assert_eq!(
        built,
        ["3"],
        "only the lot with no neighbour behind keeps its kura"
    );

    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[kura]\ncollision = false\n").unwrap();
    let without = dir.path().join("without");
    let r = build_ok(
        dir.path(),
        &without,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    assert_eq!(
        r["counts"]["kura"], 3,
        "the paper's 'without avoidance' column"
    );
    assert_eq!(
        r["table2"]["kura_with_avoidance"], 1,
        "the table is the same either way"
    );
    // Even without avoidance a kura never leaves its lot: each is cut to its own lot's
    // inner width, so the two back-to-back kura stand on opposite sides.
    for (id, vertices) in kura_objects(&without) {
        let l = &lots[id.parse::<usize>().unwrap() - 1];
        let poly = polygon(&l.ring);
        for v in vertices {
            assert!(
                distance_to_lot(&poly, v[0], v[1]) <= 0.002,
                "kura {id}: {v:?} outside"
            );
        }
    }
}

#[test]
fn table2_is_in_the_report_per_district_and_beside_the_paper() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 1500, 4);
    let city = dir.path().join("city");
    let run = edo_city()
        .args([
            "build",
            town.to_str().unwrap(),
            "--out",
            city.to_str().unwrap(),
            "--no-plan",
        ])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        text.contains("Table 2") && text.contains("16664") && text.contains("9.4 %"),
        "{text}"
    );
    let r = read_json(&city.join("report.json"));
    let t2 = &r["table2"];
    let n = |v: &serde_json::Value| v.as_u64().unwrap();
    assert_eq!(n(&t2["machiya"]), n(&r["counts"]["machiya"]));
    assert!(n(&t2["kura_candidates"]) >= n(&t2["kura_without_avoidance"]));
    assert!(n(&t2["kura_without_avoidance"]) >= n(&t2["kura_with_avoidance"]));
    assert!(n(&t2["kura_with_avoidance"]) > 0);
    assert_eq!(n(&t2["kura_with_avoidance"]), n(&r["counts"]["kura"]));
    let ratio = n(&t2["kura_with_avoidance"]) as f64 / n(&t2["machiya"]) as f64;
    assert!((t2["ratio_with"].as_f64().unwrap() - ratio).abs() < 1e-4);
    assert_eq!(t2["paper"]["kura_with_avoidance"], 2824);
    // Per district, the counts add up to the whole.
    let districts = t2["by_district"].as_object().unwrap();
    assert!(districts.len() >= 2, "{districts:?}");
    for key in [
        "machiya",
        "kura_candidates",
        "kura_without_avoidance",
        "kura_with_avoidance",
    ] {
        let sum: u64 = districts.values().map(|d| n(&d[key])).sum();
        assert_eq!(sum, n(&t2[key]), "{key}");
    }
}

#[test]
fn kura_do_not_depend_on_tiles_or_threads() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 1200, 11);
    let full = dir.path().join("full");
    build_ok(&town, &full, &["--quiet", "--no-plan", "-j", "2"]);
    let m = read_json(&full.join("manifest.json"));
    let tiles: Vec<String> = m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect();
    assert!(tiles.len() >= 4);
    // Every tile built alone, one thread, into a copy: the same bytes, so the same kura.
    let single = dir.path().join("single");
    build_ok(&town, &single, &["--quiet", "--no-plan", "-j", "1"]);
    for t in &tiles {
        build_ok(
            &town,
            &single,
            &["--quiet", "--no-plan", "-j", "1", "--tiles", t],
        );
    }
    let mut kura_total = 0;
    for t in m["tiles"].as_array().unwrap() {
        let p = t["obj"]["path"].as_str().unwrap();
        assert_eq!(
            std::fs::read(full.join(p)).unwrap(),
            std::fs::read(single.join(p)).unwrap(),
            "{p}"
        );
        kura_total += t["stats"]["kura"].as_u64().unwrap();
    }
    assert!(kura_total > 0);
}
