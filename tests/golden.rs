//! Golden outputs: the example town's every tile (sha256 of its OBJ, MTL and GLB), the
//! levels of detail above them and `tileset.json`, and its whole report.json, committed in `tests/golden/`. A template or rule that changes the geometry
//! by accident fails here; a change made on purpose is accepted with
//! `EDO_CITY_BLESS=1 cargo test --test golden` and shows in the diff of `tests/golden/`
//! (resvg keeps its reference images the same way).

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::{edo_city, read_json};

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// What a build of `fixtures/<name>` is, as the golden file keeps it: per tile the sha256 of
/// each file, and the report with the machine's absolute input path left out.
fn snapshot(name: &str, extra: &[&str]) -> serde_json::Value {
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("out");
    // Run from fixtures/ with a relative input, so the report's file names are the same on
    // every machine.
    let o = edo_city()
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures"))
        .args(["build", name, "--out"])
        .arg(&out)
        .args(["--quiet", "--no-plan"])
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let manifest = read_json(&out.join("manifest.json"));
    let mut tiles = BTreeMap::new();
    for t in manifest["tiles"].as_array().unwrap() {
        let mut files = BTreeMap::new();
        for kind in ["obj", "mtl", "glb"] {
            let f = &t[kind];
            files.insert(kind.to_string(), f["sha256"].clone());
            files.insert(format!("{kind}_bytes"), f["bytes"].clone());
        }
        tiles.insert(t["id"].as_str().unwrap().to_string(), files);
    }
    // The levels of detail above the tiles (tileset.json's parents): made from the tiles'
    // bytes, pinned with them.
    let mut lod = BTreeMap::new();
    for f in manifest["files"].as_array().unwrap() {
        let path = f["path"].as_str().unwrap();
        if path.starts_with("tiles/lod/") || path == "tileset.json" {
            lod.insert(path.to_string(), f["sha256"].clone());
        }
    }
    let mut report = read_json(&out.join("report.json"));
    report["input"] = serde_json::Value::String(format!("fixtures/{name}"));
    serde_json::json!({ "tiles": tiles, "lod": lod, "report": report })
}

/// Compares a snapshot with its golden file, or writes it with `EDO_CITY_BLESS=1`.
fn check(golden: &str, now: serde_json::Value) {
    let path = golden_dir().join(golden);
    let text = serde_json::to_string_pretty(&now).unwrap() + "\n";
    if std::env::var_os("EDO_CITY_BLESS").is_some() {
        std::fs::create_dir_all(golden_dir()).unwrap();
        std::fs::write(&path, &text).unwrap();
        return;
    }
    let before = std::fs::read_to_string(&path).unwrap_or_default();
    if before == text {
        return;
    }
    let old: serde_json::Value = serde_json::from_str(&before).unwrap_or_default();
    let changed_tiles: Vec<&String> = now["tiles"]
        .as_object()
        .unwrap()
        .keys()
        .filter(|id| old["tiles"][id.as_str()] != now["tiles"][id.as_str()])
        .collect();
    let first_line = before
        .lines()
        .zip(text.lines())
        .position(|(a, b)| a != b)
        .map_or(before.lines().count().min(text.lines().count()) + 1, |i| {
            i + 1
        });
    panic!(
        "the build differs from {} (tiles changed: {changed_tiles:?}; first differing line \
         {first_line}). If the change is intended, run `EDO_CITY_BLESS=1 cargo test --test \
         golden` and commit tests/golden/ with it",
        path.display()
    );
}

#[test]
fn the_example_town_is_its_golden_output() {
    check("kyoto-small.json", snapshot("kyoto-small", &[]));
}

#[test]
fn the_example_town_without_kura_avoidance_is_its_golden_output() {
    // A second hypothesis, so that the kura rule's effect on the tiles is pinned too.
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("no-avoidance.toml");
    std::fs::write(&params, "[kura]\ncollision = false\n").unwrap();
    let now = snapshot("kyoto-small", &["--params", params.to_str().unwrap()]);
    check("kyoto-small-no-avoidance.json", now);
}
