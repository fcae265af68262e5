//! `edo-city serve OUT --edit PARAMS.toml` (issue 61) over HTTP, as the viewer talks to it:
//! the parameters listed from the defaults, a lot and a parameter edited (only the tiles
//! they change rebuilt), a refused value and an unknown lot answered with the build's own
//! message and taken back, undo restoring the bytes, a stale page refused, save writing the
//! person's files, and a CLI build of the saved file giving what was served.

mod common;

use common::designer::{ask, error, post_to as post, serve_edit};
use common::*;
use serde_json::{json, Value};

/// Waits for the server's first build (every tile, to know what each is made from).
fn settled(port: u16) -> Value {
    for _ in 0..600 {
        let (_, s) = ask(port, "GET", "/api/edit/status", "");
        if s["busy"] == false && s["revision"].as_u64() >= Some(1) {
            return s;
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    panic!("the first build did not end");
}

#[test]
fn a_hypothesis_is_edited_undone_saved_and_built_again_by_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let initial = tile_hashes(&out, &["obj", "glb"]);
    let params = dir.path().join("hyp.toml");
    std::fs::write(&params, "# my hypothesis\nseed = 1\n").unwrap();
    let (server, port) = serve_edit(dir.path(), &[&out], &params);
    let first = settled(port);
    assert_eq!(
        tile_hashes(&out, &["obj", "glb"]),
        initial,
        "the same parameters rebuild the same tiles"
    );

    // The parameters, from the one place they are defined.
    let (status, list) = ask(port, "GET", "/api/params", "");
    assert_eq!(status, 200);
    let list = list.as_array().unwrap();
    let gap = list.iter().find(|p| p["key"] == "kura.gap").unwrap();
    assert_eq!(gap["section"], "kura");
    assert_eq!(gap["allowed"]["max"], 1000.0);
    assert!(gap["doc"].as_str().unwrap().contains("courtyard"));
    let seed = list.iter().find(|p| p["key"] == "seed").unwrap();
    assert_eq!(seed["set"], true);

    let (_, t) = ask(port, "GET", "/api/token", "");
    let token = t["token"].as_str().unwrap().to_string();
    // Lot 9 becomes a sangai: its tile, and only its tile, is rebuilt.
    let (status, lot) = post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "9", "field": "mtype", "value": "sangai", "base": first["requested"]}),
    );
    assert_eq!(status, 200, "{lot}");
    let changed: Vec<String> = serde_json::from_value(lot["changedTiles"].clone()).unwrap();
    assert_eq!(changed.len(), 1, "{lot}");
    let now = tile_hashes(&out, &["obj", "glb"]);
    let differ: Vec<&String> = (initial.iter().zip(&now))
        .filter(|(a, b)| a != b)
        .map(|(a, _)| &a.0)
        .collect();
    assert!(
        differ.iter().all(|id| **id == changed[0]),
        "{differ:?} {changed:?}"
    );
    let (_, s) = ask(port, "GET", "/api/edit/status", "");
    let lots = s["changedLots"].as_array().unwrap();
    assert!(
        lots.iter()
            .any(|l| l["lot"] == "9" && l["differs"] == "type"),
        "{s}"
    );

    // A value the build refuses, an unknown lot: its message, and nothing changed.
    let (status, e) = error(post(
        port,
        &token,
        "/api/edit/set",
        json!({"key": "kura.gap", "value": -1}),
    ));
    assert_eq!(status, 422);
    assert!(e.contains("`kura.gap` must be from 0 to 1000"), "{e}");
    let (status, e) = error(post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "no-such-lot", "field": "mtype", "value": "sangai"}),
    ));
    assert_eq!(status, 422);
    assert!(e.contains("no lot has the id `no-such-lot`"), "{e}");
    assert_eq!(tile_hashes(&out, &["obj", "glb"]), now);
    // A page that saw an older revision.
    let (status, _) = error(post(
        port,
        &token,
        "/api/edit/set",
        json!({"key": "seed", "value": 2, "base": 1}),
    ));
    assert_eq!(status, 409);

    // Undo restores the bytes; redo brings the edit back.
    let (status, _) = post(port, &token, "/api/edit/undo", json!({}));
    assert_eq!(status, 200);
    assert_eq!(tile_hashes(&out, &["obj", "glb"]), initial);
    let (status, _) = post(port, &token, "/api/edit/redo", json!({}));
    assert_eq!(status, 200);
    assert_eq!(tile_hashes(&out, &["obj", "glb"]), now);

    // A parameter, then save: the person's file keeps their comment.
    let (status, _) = post(
        port,
        &token,
        "/api/edit/set",
        json!({"key": "kura.gap", "value": 3.0}),
    );
    assert_eq!(status, 200);
    let (status, saved) = post(port, &token, "/api/edit/save", json!({}));
    assert_eq!(status, 200, "{saved}");
    drop(server);
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(text.starts_with("# my hypothesis\nseed = 1\n"), "{text}");
    assert!(text.contains("overrides = \"hyp.overrides.csv\""), "{text}");
    let rows = std::fs::read_to_string(dir.path().join("hyp.overrides.csv")).unwrap();
    assert_eq!(rows, "lot,field,value\n9,mtype,sangai\n");
    let log = std::fs::read_to_string(dir.path().join("hyp.history.jsonl")).unwrap();
    assert_eq!(log.lines().count(), 3, "{log}");

    // What was served is what the CLI builds from the saved file.
    let cli = dir.path().join("cli");
    build_ok(
        &fixture("kyoto-small"),
        &cli,
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    assert_same_tree(&out, &cli);
}

#[test]
fn a_server_without_edit_lists_the_parameters_and_refuses_edits() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--format", "glb"],
    );
    let (_server, port) = common::designer::serve(dir.path(), &out, None);
    let (status, list) = ask(port, "GET", "/api/params", "");
    assert_eq!(status, 200);
    assert!(list.as_array().unwrap().len() > 100);
    let (status, state) = ask(port, "GET", "/api/edit/state", "");
    assert_eq!((status, state["enabled"].clone()), (200, json!(false)));
    let (_, t) = ask(port, "GET", "/api/token", "");
    let token = t["token"].as_str().unwrap();
    let (status, e) = error(post(
        port,
        token,
        "/api/edit/set",
        json!({"key": "seed", "value": 2}),
    ));
    assert_eq!(status, 403);
    assert!(e.contains("--edit"), "{e}");
}

#[test]
fn the_hypothesis_is_never_kept_inside_the_input_or_the_build() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("town");
    copy_fixture("kyoto-small", &input);
    let out = dir.path().join("out");
    build_ok(&input, &out, &["--quiet", "--format", "glb"]);
    // A file of the input named as the parameter file is named as such, not read as TOML.
    for params in [
        input.join("hyp.toml"),
        out.join("hyp.toml"),
        input.join("lots.shp"),
    ] {
        let o = edo_city()
            .args(["serve", "--port", "0", "--edit"])
            .arg(&params)
            .arg("--input")
            .arg(&input)
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("would be written inside"), "{err}");
    }
    // A parameter file beside them whose overrides name the lots' table in the input.
    let params = dir.path().join("hyp.toml");
    std::fs::write(&params, "[input]\noverrides = \"town/lots.csv\"\n").unwrap();
    let o = edo_city()
        .args(["serve", "--port", "0", "--edit"])
        .arg(&params)
        .arg("--input")
        .arg(&input)
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("its overrides") && err.contains("inside the input"),
        "{err}"
    );
}

#[test]
fn the_outlines_compare_against_another_served_hypothesis() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    // Another hypothesis: lot 9 a sangai.
    std::fs::write(
        dir.path().join("b.overrides.csv"),
        "lot,field,value\n9,mtype,sangai\n",
    )
    .unwrap();
    let b = dir.path().join("b.toml");
    std::fs::write(&b, "[input]\noverrides = \"b.overrides.csv\"\n").unwrap();
    let other = dir.path().join("other");
    build_ok(
        &fixture("kyoto-small"),
        &other,
        &["--quiet", "--params", b.to_str().unwrap()],
    );
    let (_server, port) = serve_edit(dir.path(), &[&out, &other], &dir.path().join("hyp.toml"));
    settled(port);
    let (status, c) = ask(port, "GET", "/api/edit/compare?h=1", "");
    assert_eq!(status, 200, "{c}");
    let lots = c["changedLots"].as_array().unwrap();
    assert_eq!(lots.len(), 1, "{c}");
    assert_eq!(
        (lots[0]["lot"].as_str(), lots[0]["differs"].as_str()),
        (Some("9"), Some("type"))
    );
    assert!(lots[0]["ring"].as_array().unwrap().len() >= 4);
    let (status, c) = ask(port, "GET", "/api/edit/compare?h=0", "");
    assert_eq!(
        (status, c["changedLots"].as_array().map(Vec::len)),
        (200, Some(0))
    );
    assert_eq!(ask(port, "GET", "/api/edit/compare?h=7", "").0, 404);
    assert_eq!(ask(port, "GET", "/api/edit/compare?h=x", "").0, 400);
}

#[test]
fn a_kept_draw_survives_a_reroll() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let params = dir.path().join("hyp.toml");
    std::fs::write(&params, "[trees]\nper_ha_machiya = 200.0\n").unwrap();
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    settled(port);
    let before = plan_trees(&out);
    assert!(before.len() > 100);
    let (_, t) = ask(port, "GET", "/api/token", "");
    let token = t["token"].as_str().unwrap().to_string();
    let (status, a) = post(
        port,
        &token,
        "/api/edit/lock",
        json!({"section": "trees", "keep": true}),
    );
    assert_eq!(status, 200, "{a}");
    let (_, state) = ask(port, "GET", "/api/edit/state", "");
    assert_eq!(state["locks"], json!(["trees"]));
    let (status, r) = post(port, &token, "/api/edit/reroll", json!({}));
    assert_eq!(status, 200, "{r}");
    assert!(!r["changedTiles"].as_array().unwrap().is_empty(), "{r}");
    assert_eq!(plan_trees(&out), before, "the trees kept their draw");
    // Let go: the next reroll draws them again.
    post(
        port,
        &token,
        "/api/edit/lock",
        json!({"section": "trees", "keep": false}),
    );
    let (status, _) = post(port, &token, "/api/edit/reroll", json!({}));
    assert_eq!(status, 200);
    assert_ne!(plan_trees(&out), before);
    let (status, e) = error(post(
        port,
        &token,
        "/api/edit/lock",
        json!({"section": "roofs", "keep": true}),
    ));
    assert_eq!(status, 400);
    assert!(e.contains("`roofs` draws from no seed of its own"), "{e}");
}
