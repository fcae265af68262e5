//! The level-of-detail budget of the first view (issue 40), in counts, not times: a synthetic
//! town with every feature on (grown trees, walking people), 60 m tiles so the tileset has
//! two levels over its leaves, served by `edo-city serve` and opened in Debian's chromium
//! (`viewer/test/first-view.mjs`, 1280 x 720). The overview of the whole town must come from
//! the parent tiles alone, within the budget of bytes, draw calls and triangles: a
//! change that breaks the levels of detail (a parent without content, an error too small, a
//! leaf fetched for the overview) fails here. Then, up close, a click on a grown tree (an
//! instance of its variant, `EXT_mesh_gpu_instancing`) names that tree and its lot.

mod common;

use std::process::Command;

use common::{build_ok, read_json};

/// The budget for the first overview of a whole city.
const MAX_BYTES: f64 = 15.0e6;
const MAX_DRAW_CALLS: f64 = 150.0;
const MAX_TRIANGLES: f64 = 400_000.0;

#[test]
fn the_first_overview_comes_from_the_parents_within_the_budget() {
    let dir = tempfile::tempdir().unwrap();
    let (town, out) = (dir.path().join("town"), dir.path().join("out"));
    common::synth(&town, 1500, 1);
    let params = dir.path().join("every-feature.toml");
    std::fs::write(
        &params,
        "tile_size = 60.0\n[trees]\nstyle = \"lsystem\"\n[people]\nmotion = \"boids\"\n",
    )
    .unwrap();
    build_ok(
        &town,
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let m = read_json(&out.join("manifest.json"));
    let parents: Vec<&str> = m["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["path"].as_str())
        .filter(|p| p.starts_with("tiles/lod/"))
        .collect();
    let levels = parents
        .iter()
        .filter_map(|p| p.trim_start_matches("tiles/lod/").split('_').next())
        .collect::<std::collections::BTreeSet<_>>();
    assert!(levels.len() >= 2, "two levels over the leaves: {parents:?}");

    // The tallest grown tree (an instance of its variant in its tile's GLB), 4 m up its
    // crown: a click there must name it.
    let csv = std::fs::read_to_string(out.join("species/placements.csv")).unwrap();
    let tree = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>())
        .filter(|f| !f[11].is_empty())
        .max_by(|a, b| {
            a[8].parse::<f64>()
                .unwrap()
                .total_cmp(&b[8].parse().unwrap())
        })
        .expect("grown trees");
    let at = |i: usize| tree[i].parse::<f64>().unwrap();
    let click = dir.path().join("tree.json");
    std::fs::write(
        &click,
        serde_json::json!({"east": at(4), "north": -at(6), "up": at(5) + 4.0}).to_string(),
    )
    .unwrap();

    let mut serve = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve.args(["serve", "--port", "0"]).arg(&out);
    let (server, url) = common::start_server(serve);
    let (got, text) = common::run_browser_script(
        "first-view.mjs",
        &[url.as_ref()],
        &[("CLICK", click.as_os_str())],
    );
    drop(server);
    eprintln!("first view: {}", got["overview"]);
    assert_eq!(got["errors"], serde_json::json!([]), "{text}");

    // Only parents: every tile fetched is one of the build's files under tiles/lod/.
    let glbs: Vec<&str> = got["fetched"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|p| p.as_str())
        .filter(|p| p.ends_with(".glb"))
        .map(|p| p.splitn(4, '/').nth(3).unwrap_or(p))
        .collect();
    assert!(!glbs.is_empty(), "{text}");
    for g in &glbs {
        assert!(parents.contains(g), "the overview fetched a leaf: {g}");
    }

    let stats = &got["overview"];
    let n = |k: &str| stats[k].as_f64().unwrap_or(-1.0);
    assert!(n("tilesLoaded") >= 1.0, "{stats}");
    assert!(n("triangles") >= 1000.0, "the overview is drawn: {stats}");
    assert!(
        n("drawCalls") >= 1.0 && n("drawCalls") <= MAX_DRAW_CALLS,
        "{stats}"
    );
    assert!(n("triangles") <= MAX_TRIANGLES, "{stats}");
    assert!(n("bytesFetched") <= MAX_BYTES, "{stats}");
    // And within what the parents, the textures and the tileset weigh together (each
    // fetched at most a few times: parents share the cut-out textures).
    let on_disk: u64 = common::all_files(&out)
        .iter()
        .filter(|(p, _)| {
            p.starts_with("tiles/lod/") || p.starts_with("tiles/textures/") || p.ends_with(".json")
        })
        .map(|(_, b)| b.len() as u64)
        .sum();
    assert!(
        n("bytesFetched") <= 2.0 * on_disk as f64,
        "{stats} vs {on_disk} bytes"
    );

    // The trees' toggle reaches the parents: their trees (a node of kind `trees`) go with
    // their triangles, and come back.
    let toggle = &got["toggle"];
    let f = |k: &str, v: &str| toggle[k][v].as_f64().unwrap();
    assert!(f("on", "treeNodesShown") >= 1.0, "{toggle}");
    assert_eq!(f("off", "treeNodesShown"), 0.0, "{toggle}");
    assert!(
        f("off", "triangles") < f("on", "triangles")
            && toggle["off"]["hash"] != toggle["on"]["hash"],
        "{toggle}"
    );
    assert_eq!(toggle["again"], toggle["on"], "{toggle}");

    // Up close, the tree is an instance of its variant, and a click names its own row.
    assert!(
        got["picked"]["instance"].is_u64(),
        "an instance was clicked: {text}"
    );
    let clicked = &got["clicked"];
    assert_eq!(clicked["kind"], "trees", "{clicked}");
    assert_eq!(clicked["name"], format!("tree_{}", tree[0]), "{clicked}");
    assert_eq!(clicked["lot"], tree[3].as_str(), "{clicked}");
}
