//! The workbench in a real browser (issue 61): the example town served by `edo-city serve
//! --edit`, opened in Debian's chromium by playwright-core (`viewer/test/workbench.mjs`). A
//! lot's type and a parameter of the panel are changed; only the tiles they change are
//! rebuilt, the lot is outlined and the picture there changes; the house clicked shows its
//! new type in the lot editor; undo restores the bytes. Then the edits are saved, and a CLI
//! build of the saved file equals what was served. A page of another origin cannot edit.

mod common;

use std::process::Command;

use common::{assert_same_tree, build_ok, fixture};

fn workbench_mjs(url: &str, args: &[&str]) -> serde_json::Value {
    let mut all: Vec<&std::ffi::OsStr> = vec![url.as_ref()];
    all.extend(args.iter().map(std::ffi::OsStr::new));
    common::run_browser_script("workbench.mjs", &all, &[]).0
}

#[test]
fn a_visitor_changes_a_lot_and_a_parameter_undoes_them_and_saves_a_hypothesis() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("edo");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let initial = common::tile_hashes(&out, &["glb"]);
    let params = dir.path().join("hyp.toml");
    let mut serve = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve
        .args(["serve", "--port", "0", "--edit"])
        .arg(&params)
        .arg("--input")
        .arg(fixture("kyoto-small"))
        .arg(&out);
    let (server, url) = common::start_server(serve);

    let shots = std::env::var_os("EDO_CITY_SHOTS");
    let mut args = vec!["edit", "5", "hiraya"];
    let shot_dir = shots.as_ref().map(|s| s.to_string_lossy().into_owned());
    if let Some(s) = &shot_dir {
        args.push(s);
    }
    let e = workbench_mjs(&url, &args);
    assert_eq!(e["errors"], serde_json::json!([]), "{e}");
    assert_eq!(e["params"].as_u64().map(|n| n > 100), Some(true), "{e}");
    // The lot's edit rebuilt its tile alone, outlined it, and the house clicked says so.
    assert_eq!(e["lot"]["changedTiles"].as_array().unwrap().len(), 1, "{e}");
    assert_eq!(
        e["changedLots"],
        serde_json::json!([{"lot": "5", "differs": "type"}])
    );
    assert!(e["outlines"].as_u64().unwrap() >= 2, "{e}");
    assert_eq!(e["clicked"]["lot"], "5", "{e}");
    assert_eq!(e["clicked"]["mtype"], "hiraya", "{e}");
    assert_eq!(e["editor"]["value"], "hiraya", "{e}");
    // The panel's parameter rebuilt some tiles, not every one, and is marked changed.
    let gap = e["gap"]["changedTiles"].as_array().unwrap().len();
    assert!(gap >= 1 && gap < initial.len(), "{e}");
    assert_eq!(e["marked"], serde_json::json!(["kura.gap"]), "{e}");
    // Undone: the bytes of the first build, and the picture at the lot changed back.
    assert_eq!(common::tile_hashes(&out, &["glb"]), initial);
    assert_ne!(e["pictures"]["after"], e["pictures"]["undone"], "{e}");
    assert_eq!(e["redoAfterUndo"], 2);
    assert_eq!(e["againstSelf"], 0, "{e}");

    let s = workbench_mjs(&url, &["save", "5", "hiraya"]);
    assert_eq!(s["errors"], serde_json::json!([]), "{s}");
    // Another site's 300 token requests beside the page locked it out of nothing.
    assert_eq!(s["flood"], 300, "{s}");
    assert!(
        !s["gap"]["changedTiles"].as_array().unwrap().is_empty(),
        "{s}"
    );
    assert_eq!(s["saved"]["saved"], true, "{s}");
    assert_eq!(s["status"]["saved"], true, "{s}");

    // Another origin's page: its blind POSTs and its JSON POST change nothing.
    let before = std::fs::read(&params).unwrap();
    let a = workbench_mjs(&url, &["attack"]);
    assert!(a["token"].as_str().unwrap().starts_with("failed"), "{a}");
    assert!(a["json"].as_str().unwrap().starts_with("failed"), "{a}");
    drop(server);
    assert_eq!(std::fs::read(&params).unwrap(), before, "{a}");

    // The saved hypothesis, built by the CLI: what the browser was shown.
    let cli = dir.path().join("cli");
    build_ok(
        &fixture("kyoto-small"),
        &cli,
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    assert_same_tree(&out, &cli);
}
