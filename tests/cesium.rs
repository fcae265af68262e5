//! The build in CesiumJS (issue 40): the example town served by `edo-city serve`, opened at
//! `/viewer/cesium.html` in Debian's chromium by `viewer/test/cesium.mjs` (CesiumJS from npm,
//! pinned by viewer/package-lock.json; no Cesium ion token, no imagery, no request leaving
//! the server). The tileset loads with no error, its centre lands at the longitude and
//! latitude proj gives the centre's map point, and a pick in the middle of the picture reads
//! an object's metadata row.

mod common;

use std::path::Path;
use std::process::Command;

use common::{build_ok, read_json};

#[test]
fn cesium_loads_the_tileset_where_proj_puts_it_and_reads_its_metadata() {
    let viewer = Path::new(env!("CARGO_MANIFEST_DIR")).join("viewer");
    assert!(
        viewer.join("node_modules/cesium").is_dir(),
        "CesiumJS is missing: run `make viewer-deps`"
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("edo");
    build_ok(
        &common::fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan"],
    );

    let mut serve = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve.args(["serve", "--port", "0"]).arg(&out);
    let (server, url) = common::start_server(serve);
    let (got, text) = common::run_browser_script("cesium.mjs", &[url.as_ref()], &[]);
    drop(server);
    eprintln!("cesium: {got}");
    assert!(got["tilesLoaded"].as_u64().unwrap() >= 1, "{text}");

    // The centre of the root's box, a map point, where proj puts it (within 1 m: Cesium's
    // bounding sphere is the box's centre, up to its height over the frame's tangent plane).
    let m = read_json(&out.join("manifest.json"));
    let tileset = read_json(&out.join("tileset.json"));
    let b = &tileset["root"]["boundingVolume"]["box"];
    let map = geo_types::Coord {
        x: m["origin"][0].as_f64().unwrap() + b[0].as_f64().unwrap(),
        y: m["origin"][1].as_f64().unwrap() + b[1].as_f64().unwrap(),
    };
    let crs = edo_city::input::crs::Crs::from_user(m["crs"].as_str().unwrap()).unwrap();
    let wgs84 =
        edo_city::input::crs::Crs::from_user("+proj=longlat +datum=WGS84 +no_defs").unwrap();
    let mut truth = [map];
    edo_city::input::crs::reproject(&mut truth, &crs, &wgs84).unwrap();
    let (lon, lat) = (
        got["centre"][0].as_f64().unwrap(),
        got["centre"][1].as_f64().unwrap(),
    );
    let metres_per_degree = 111_320.0;
    let dx = (lon - truth[0].x) * metres_per_degree * lat.to_radians().cos();
    let dy = (lat - truth[0].y) * metres_per_degree;
    assert!(
        dx.hypot(dy) < 1.0,
        "centre at {lon}, {lat}; proj: {:?} ({:.2} m off)",
        truth[0],
        dx.hypot(dy)
    );

    // Cesium reads the metadata: the object in the middle of the picture has its row.
    let picked = &got["picked"];
    assert!(picked.is_object(), "nothing picked: {text}");
    assert!(
        picked["kind"].as_str().is_some_and(|k| !k.is_empty()),
        "{picked}"
    );
}

/// Walkers (a skinned crowd and its clip) and instanced grown trees in CesiumJS: the example
/// town's leaves all load (a screen-space error of 1 pixel) with no error, and the middle of
/// the overview is the town, not a walker: with normalized short rotations in the clip,
/// CesiumJS drew every walker hundreds of metres tall over the town.
#[test]
fn cesium_draws_the_walkers_and_instanced_trees_of_the_leaves() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(
        &params,
        "[trees]\nstyle = \"lsystem\"\n[people]\nmotion = \"boids\"\n",
    )
    .unwrap();
    let out = dir.path().join("edo");
    build_ok(
        &common::fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let leaves = read_json(&out.join("manifest.json"))["tiles"]
        .as_array()
        .unwrap()
        .len() as u64;
    let mut serve = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve.args(["serve", "--port", "0"]).arg(&out);
    let (server, url) = common::start_server(serve);
    let (got, text) = common::run_browser_script(
        "cesium.mjs",
        &[url.as_ref(), "-".as_ref(), "1".as_ref()],
        &[],
    );
    drop(server);
    assert_eq!(got["errors"], serde_json::json!([]), "{text}");
    assert!(got["tilesLoaded"].as_u64().unwrap() >= leaves, "{text}");
    assert_ne!(got["picked"]["kind"], "people", "{text}");
    assert!(got["picked"]["lot"].is_string(), "{text}");
}
