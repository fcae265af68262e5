//! The viewer in a real browser: two hypotheses of the example town served by `edo-city
//! serve`, opened in Debian's chromium by playwright-core (`viewer/test/browser.mjs`): ready,
//! nothing failed, roofs and plaster drawn, a click on a known house shows its lot id, and the
//! hypothesis switch keeps the camera and changes the picture. Chromium and the npm packages
//! come from `make viewer-deps` (scripts/viewer-deps.sh).

mod common;

use std::path::Path;
use std::process::Command;

use common::{build_ok, read_json};

#[test]
fn the_viewer_shows_the_city_names_a_clicked_house_and_switches_hypotheses() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("edo"), dir.path().join("other-seed"));
    // The example town with HTML in its lots' district and its links' titles: the viewer
    // shows both as text (browser.mjs looks for the elements they would make).
    let town = dir.path().join("town");
    common::copy_fixture("kyoto-small", &town);
    with_html_in_attributes(&town);
    build_ok(&town, &a, &["--quiet", "--no-plan"]);
    let params = dir.path().join("seed.toml");
    std::fs::write(&params, "seed = 7\n").unwrap();
    build_ok(
        &town,
        &b,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );

    // The largest house of the first build, and a point on its roof.
    let m = read_json(&a.join("manifest.json"));
    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
    ];
    let objects = common::build_objects(&a);
    let house = objects
        .iter()
        .filter(|o| o.name.starts_with("machiya_"))
        .max_by_key(|o| o.vertices.len())
        .unwrap();
    let n = house.vertices.len() as f64;
    let east = house.vertices.iter().map(|v| v[0]).sum::<f64>() / n - origin[0];
    let north = house.vertices.iter().map(|v| v[1]).sum::<f64>() / n - origin[1];
    let up = house.vertices.iter().map(|v| v[2]).fold(f64::MIN, f64::max);
    let lot = house.name.trim_start_matches("machiya_");
    let house_file = dir.path().join("house.json");
    std::fs::write(
        &house_file,
        serde_json::json!({"lot": lot, "east": east, "north": north, "up": up}).to_string(),
    )
    .unwrap();

    let mut serve = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve.args(["serve", "--port", "0"]).arg(&a).arg(&b);
    let (server, url) = common::start_server(serve);

    let (out, text) =
        common::run_browser_script("browser.mjs", &[url.as_ref(), house_file.as_os_str()], &[]);
    drop(server);
    eprintln!("viewer measurements: {out}");
    assert_eq!(out["clicked"]["lot"], lot, "{text}");
    assert_eq!(out["clicked"]["kind"], "machiya");
    // Walking stands the eye 1.6 m over the tiles' ground.
    let (g, eye) = (
        out["walk"]["ground"].as_f64().unwrap(),
        out["walk"]["eye"].as_f64().unwrap(),
    );
    assert!((eye - g - 1.6).abs() < 0.05, "{text}");
    assert_eq!(out["hypotheses"], serde_json::json!(["edo", "other-seed"]));
    // window.edoCity.stats: the first view's draw calls, triangles, tiles and bytes.
    let stats = &out["stats"];
    let n = |k: &str| stats[k].as_f64().unwrap_or(-1.0);
    // Tiles with content: the leaves and their parents (the levels of detail).
    let parents = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["path"].as_str().unwrap().starts_with("tiles/lod/"))
        .count();
    let tiles = (m["tiles"].as_array().unwrap().len() + parents) as f64;
    assert!(n("drawCalls") >= 1.0 && n("triangles") >= 1000.0, "{stats}");
    assert!(
        n("tilesLoaded") >= 1.0 && n("tilesLoaded") <= tiles,
        "{stats}"
    );
    assert!(n("fps") > 0.0, "{stats}");
    // More than the tileset (the tiles came), no more than both builds' files.
    let bytes = |dir: &Path| -> u64 {
        common::all_files(dir)
            .values()
            .map(|b| b.len() as u64)
            .sum()
    };
    let tileset = std::fs::metadata(a.join("tileset.json")).unwrap().len() as f64;
    assert!(n("bytesFetched") > tileset + 10_000.0, "{stats}");
    assert!(
        n("bytesFetched") <= (bytes(&a) + bytes(&b)) as f64,
        "{stats}"
    );
}

/// Writes `<b id=inj>x</b>` into every lot's `district` (the DBF's fourth field, 20 bytes
/// from byte 41 of a record) and an `<img>` into every link's title.
fn with_html_in_attributes(town: &Path) {
    let dbf = town.join("lots.dbf");
    let mut b = std::fs::read(&dbf).unwrap();
    let count = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
    let header = u16::from_le_bytes([b[8], b[9]]) as usize;
    let len = u16::from_le_bytes([b[10], b[11]]) as usize;
    assert_eq!(
        &b[32 + 3 * 32..32 + 3 * 32 + 8],
        b"district",
        "the field's place"
    );
    for r in 0..count {
        let at = header + r * len + 41;
        b[at..at + 20].copy_from_slice(format!("{:<20}", "<b id=inj>x</b>").as_bytes());
    }
    std::fs::write(&dbf, b).unwrap();
    let links = town.join("links.csv");
    let text = std::fs::read_to_string(&links).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for line in lines.iter_mut().skip(1) {
        if let Some((id, rest)) = line.split_once(',') {
            *line = format!("{id},<img id=inj2 src=x onerror=window.pwned=1>{rest}");
        }
    }
    std::fs::write(&links, lines.join("\n") + "\n").unwrap();
}
