//! The workbench never loses a historian's work (issue 74), over HTTP as the viewer talks to
//! it: a first build that fails keeps the person's file; a save waits for the builds asked
//! for and writes only what built; edits made on a failing build are answered; the
//! overrides table changed by hand is never overwritten; the files the workbench owns and
//! paths outside the input are no parameters a page may set; a key of 30,000 parts is
//! refused, not a crash; a CLI build of OUT under the workbench is noticed; a flood of token
//! requests locks no page out; the largest seed rerolls; a formula in a cell is guarded.

mod common;

use std::path::{Path, PathBuf};
use std::time::Duration;

use common::designer::{ask, ask_with, error, page as token, post_to as post, serve_edit};
use common::*;
use serde_json::{json, Value};

/// Waits until no build runs and none is asked for; the status then.
fn idle(port: u16) -> Value {
    for _ in 0..1200 {
        let (_, s) = ask(port, "GET", "/api/edit/status", "");
        if s["busy"] == false && s["requested"].as_u64() >= Some(1) {
            return s;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("the builds did not end");
}

/// The example town built by the CLI with the parameter file `params` into `dir/name`
/// (GLB tiles): what a saved hypothesis gives.
fn cli_build(dir: &Path, name: &str, params: &Path) -> PathBuf {
    let out = dir.join(name);
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &[
            "--quiet",
            "--format",
            "glb",
            "--params",
            params.to_str().unwrap(),
        ],
    );
    out
}

/// The example town built once into `dir/out`, and a parameter file `dir/hyp.toml`.
fn town(dir: &Path, params: &str) -> (PathBuf, PathBuf) {
    let out = dir.join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--format", "glb"],
    );
    let p = dir.join("hyp.toml");
    std::fs::write(&p, params).unwrap();
    (out, p)
}

#[test]
fn a_failed_first_build_keeps_the_persons_hypothesis_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let text = "# my hypothesis: wider courtyards\nseed = 7\n\n[input]\noverrides = \
                \"hyp.overrides.csv\"\n\n[kura]\ngap = 2.5 # as the screen shows\n";
    let (out, params) = town(dir.path(), text);
    let rows = "lot,field,value\n9,mtype,sangai\n10,use,buke\nlost-lot,mtype,hiraya\n";
    let table = dir.path().join("hyp.overrides.csv");
    std::fs::write(&table, rows).unwrap();
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    let s = idle(port);
    assert!(
        s["error"].as_str().unwrap().contains("lost-lot"),
        "the first build fails on the lost lot: {s}"
    );
    // The panel shows the person's values, not the defaults.
    let (_, list) = ask(port, "GET", "/api/params", "");
    let seed = list
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["key"] == "seed")
        .unwrap();
    assert_eq!(seed["value"], 7, "{seed}");
    let token = token(port);
    let (status, e) = error(post(
        port,
        &token,
        "/api/edit/set",
        json!({"key": "kura.gap", "value": 3.0}),
    ));
    assert_eq!(status, 422, "{e}");
    let (status, saved) = post(port, &token, "/api/edit/save", json!({}));
    assert_eq!(status, 200, "{saved}");
    assert_eq!(saved["changes"], 0, "{saved}");
    assert_eq!(std::fs::read_to_string(&params).unwrap(), text);
    assert_eq!(std::fs::read_to_string(&table).unwrap(), rows);
    assert!(!dir.path().join("hyp.history.jsonl").exists());
}

#[test]
fn a_save_during_a_failing_edit_writes_only_what_built() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "seed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    let (status, _) = post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "9", "field": "mtype", "value": "sangai"}),
    );
    assert_eq!(status, 200);
    // A lot edit naming no lot, and a save 5 ms after it, while it builds.
    let failing = {
        let token = token.clone();
        std::thread::spawn(move || {
            post(
                port,
                &token,
                "/api/edit/lot",
                json!({"lot": "no-such-lot", "field": "mtype", "value": "sangai"}),
            )
        })
    };
    std::thread::sleep(Duration::from_millis(5));
    let (status, saved) = post(port, &token, "/api/edit/save", json!({}));
    assert_eq!(status, 200, "{saved}");
    assert_eq!(failing.join().unwrap().0, 422);
    let rows = std::fs::read_to_string(dir.path().join("hyp.overrides.csv")).unwrap();
    assert_eq!(rows, "lot,field,value\n9,mtype,sangai\n");
    // What was saved builds.
    let again = cli_build(dir.path(), "again", &params);
    assert!(again.join("manifest.json").is_file());
}

#[test]
fn edits_made_on_a_failing_build_are_answered_and_the_next_edit_builds() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "seed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    let edits: Vec<_> = [
        json!({"lot": "no-such-lot", "field": "mtype", "value": "sangai"}),
        json!({"lot": "9", "field": "use", "value": "buke"}),
        json!({"lot": "10", "field": "use", "value": "buke"}),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, body)| {
        let token = token.clone();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20 * i as u64));
            post(port, &token, "/api/edit/lot", body)
        })
    })
    .collect();
    // Every request is answered (none waits for a build that never comes).
    let answers: Vec<(u16, Value)> = edits.into_iter().map(|t| t.join().unwrap()).collect();
    assert_eq!(answers[0].0, 422, "{answers:?}");
    for (status, a) in &answers[1..] {
        assert!(*status == 200 || *status == 422, "{a}");
    }
    let s = idle(port);
    assert_eq!(s["busy"], false, "{s}");
    let (status, a) = post(
        port,
        &token,
        "/api/edit/set",
        json!({"key": "kura.gap", "value": 3.0}),
    );
    assert_eq!(status, 200, "{a}");
    assert_eq!(idle(port)["revision"], a["revision"]);
}

#[test]
fn a_row_added_to_the_table_by_hand_is_never_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "seed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "9", "field": "mtype", "value": "sangai"}),
    );
    assert_eq!(post(port, &token, "/api/edit/save", json!({})).0, 200);
    let table = dir.path().join("hyp.overrides.csv");
    let by_hand = "lot,field,value\n9,mtype,sangai\n10,use,buke\n";
    std::fs::write(&table, by_hand).unwrap();
    post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "11", "field": "mtype", "value": "hiraya"}),
    );
    let (status, e) = error(post(port, &token, "/api/edit/save", json!({})));
    assert_eq!(status, 409, "{e}");
    assert!(e.contains("hyp.overrides.csv changed on disk"), "{e}");
    assert_eq!(std::fs::read_to_string(&table).unwrap(), by_hand);
}

#[test]
fn a_page_sets_no_file_of_the_workbench_and_no_path_outside() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "seed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    let set = |key: &str, value: Value| {
        error(post(
            port,
            &token,
            "/api/edit/set",
            json!({"key": key, "value": value}),
        ))
    };
    let (status, e) = set("input.overrides", json!("/etc/passwd"));
    assert_eq!(status, 403, "{e}");
    assert!(e.contains("the workbench's own"), "{e}");
    for (key, value) in [
        ("machiya.templates", "/etc"),
        ("layers.lots.file", "/etc/passwd"),
        ("layers.lots.file", "../../lots.shp"),
        ("textures", "/usr/share"),
        ("garden.designs", "../elsewhere.json"),
    ] {
        let (status, e) = set(key, json!(value));
        assert_eq!(status, 403, "{key} = {value}: {e}");
        assert!(e.contains("must lie inside the input directory"), "{e}");
    }
    // A key of 30,000 dotted parts (58 KB), and a lock of such a section: refused, and the
    // server goes on.
    let deep = vec!["a"; 30_000].join(".");
    let (status, e) = set(&deep, json!(1));
    assert_eq!(status, 400, "{e}");
    assert!(e.len() < 300, "{e}");
    let (status, _) = error(post(
        port,
        &token,
        "/api/edit/lock",
        json!({"section": deep, "keep": true}),
    ));
    assert_eq!(status, 400);
    let (status, e) = set("kura.nope", json!(1));
    assert_eq!(status, 400, "{e}");
    assert_eq!(ask(port, "GET", "/api/edit/status", "").0, 200);
    // A path inside the input is a parameter like any other.
    let (status, a) = set("layers.lots.file", json!("lots.shp"));
    assert_eq!(status, 200, "{a}");
}

#[test]
fn a_cli_build_of_out_under_the_workbench_is_noticed() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "seed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let tiles = tile_hashes(&out, &["glb"]).len();
    let other = dir.path().join("seed2.toml");
    std::fs::write(&other, "seed = 2\n").unwrap();
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &[
            "--quiet",
            "--format",
            "glb",
            "--force",
            "--params",
            other.to_str().unwrap(),
        ],
    );
    let token = token(port);
    let (status, a) = post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "9", "field": "mtype", "value": "sangai"}),
    );
    assert_eq!(status, 200, "{a}");
    assert_eq!(a["changedTiles"].as_array().unwrap().len(), tiles, "{a}");
    let s = idle(port);
    assert!(s["notice"].as_str().unwrap().contains("another run"), "{s}");
    assert_eq!(post(port, &token, "/api/edit/save", json!({})).0, 200);
    let cli = cli_build(dir.path(), "cli", &params);
    assert_eq!(tile_hashes(&out, &["glb"]), tile_hashes(&cli, &["glb"]));
}

#[test]
fn a_flood_of_token_requests_locks_no_page_out() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "seed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    // Another site's `<img src>`: refused at once.
    let cross = [
        ("Sec-Fetch-Site", "cross-site"),
        ("Sec-Fetch-Dest", "image"),
    ];
    let (status, _) = ask_with(port, &cross, "GET", "/api/token", "");
    assert_eq!(status, 403);
    // Tokens asked for by anyone who may, as many as they like: the page's still works.
    for _ in 0..300 {
        ask(port, "GET", "/api/token", "");
    }
    let (status, a) = post(
        port,
        &token,
        "/api/edit/set",
        json!({"key": "kura.gap", "value": 3.0}),
    );
    assert_eq!(status, 200, "{a}");
}

#[test]
fn the_largest_seed_rerolls_and_a_formula_is_saved_as_text() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), &format!("seed = {}\n", i64::MAX));
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    let (status, a) = post(port, &token, "/api/edit/reroll", json!({}));
    assert_eq!(status, 200, "{a}");
    let formula = "=HYPERLINK(\"http://x.example\",\"x\")";
    let (status, a) = post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "9", "field": "district", "value": formula}),
    );
    assert_eq!(status, 200, "{a}");
    assert_eq!(post(port, &token, "/api/edit/save", json!({})).0, 200);
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(text.contains("seed = 0"), "{text}");
    let rows = std::fs::read_to_string(dir.path().join("hyp.overrides.csv")).unwrap();
    assert!(rows.contains("9,district,\"'=HYPERLINK"), "{rows}");
    // Read back as it went in: the build of the saved file is what was served.
    let cli = cli_build(dir.path(), "cli", &params);
    assert_eq!(tile_hashes(&out, &["glb"]), tile_hashes(&cli, &["glb"]));
}

#[test]
fn serve_reads_a_parameter_file_within_the_bound_build_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let big = format!("seed = 1\n{}", "# padding\n".repeat(1_700_000));
    let (out, params) = town(dir.path(), &big);
    let viewer = dir.path().join("viewer");
    std::fs::create_dir_all(viewer.join("node_modules/three")).unwrap();
    std::fs::write(viewer.join("index.html"), "<!doctype html>").unwrap();
    let o = edo_city()
        .args(["serve", "--port", "0", "--viewer"])
        .arg(&viewer)
        .arg("--edit")
        .arg(&params)
        .arg("--input")
        .arg(fixture("kyoto-small"))
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("hyp.toml") && err.contains("more than"),
        "{err}"
    );
    let b = build_cmd(
        &fixture("kyoto-small"),
        &dir.path().join("b"),
        &["--params"],
    )
    .arg(&params)
    .output()
    .unwrap();
    assert_eq!(b.status.code(), Some(2));
}

#[test]
fn a_save_that_fails_writes_nothing_and_the_next_save_goes_through() {
    let dir = tempfile::tempdir().unwrap();
    let (out, params) = town(dir.path(), "# mine\nseed = 1\n");
    let (_server, port) = serve_edit(dir.path(), &[&out], &params);
    idle(port);
    let token = token(port);
    post(
        port,
        &token,
        "/api/edit/lot",
        json!({"lot": "9", "field": "mtype", "value": "sangai"}),
    );
    // The log's name taken by a directory: the last write of the save fails.
    let log = dir.path().join("hyp.history.jsonl");
    std::fs::create_dir(&log).unwrap();
    let (status, e) = error(post(port, &token, "/api/edit/save", json!({})));
    assert_eq!(status, 500, "{e}");
    assert!(e.ends_with("nothing was saved"), "{e}");
    assert_eq!(
        std::fs::read_to_string(&params).unwrap(),
        "# mine\nseed = 1\n"
    );
    assert!(!dir.path().join("hyp.overrides.csv").exists());
    // Once the cause is gone: saved, not 409 about the workbench's own earlier try.
    std::fs::remove_dir(&log).unwrap();
    let (status, saved) = post(port, &token, "/api/edit/save", json!({}));
    assert_eq!(status, 200, "{saved}");
    assert!(std::fs::read_to_string(&params)
        .unwrap()
        .starts_with("# mine\nseed = 1\n"));
    assert_eq!(std::fs::read_to_string(&log).unwrap().lines().count(), 2);
}
