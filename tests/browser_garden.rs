//! The garden designer in a real browser (issue 42): the example town served by `edo-city
//! serve --designs`, opened in Debian's chromium by playwright-core (`viewer/test/garden.mjs`):
//! a click on the temple's garden offers "design", two candidates are picked (by clicking
//! their pictures) for three generations, each pick changing the next generation, a second
//! session with the same picks gets the same answers, and the candidate standing in place is
//! kept. A page of another origin then tries to open a session and keep over the design
//! (issue 57): nothing it sends changes the file. The town is rebuilt into the same
//! directory with the designs file while the server runs; reloaded, the viewer's garden is
//! the kept one, and its stones are in the tiles.

mod common;

use std::process::Command;

use common::{build_ok, fixture, read_json};
use edo_city::model::design::Design;

/// Runs `viewer/test/garden.mjs <url> <args>`; its JSON line.
fn garden_mjs(url: &str, args: &[&str]) -> serde_json::Value {
    let mut all: Vec<&std::ffi::OsStr> = vec![url.as_ref()];
    all.extend(args.iter().map(std::ffi::OsStr::new));
    common::run_browser_script("garden.mjs", &all, &[]).0
}

#[test]
fn a_visitor_designs_the_temple_garden_keeps_it_and_finds_it_in_the_rebuilt_city() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("edo");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet", "--no-plan"]);
    let designs = dir.path().join("designs.json");
    let mut serve = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve
        .args(["serve", "--port", "0", "--designs"])
        .arg(&designs)
        .arg(&out);
    let (server, url) = common::start_server(serve);

    let designed = garden_mjs(&url, &["design", "343"]);
    assert_eq!(designed["clicked"]["lot"], "343", "{designed}");
    assert_eq!(designed["shown"], 9);
    assert_eq!(designed["generations"].as_array().unwrap().len(), 4);
    let kept = &designed["kept"]["kept"];
    assert_eq!(kept["lot"], "343");
    assert_eq!(kept["kept"], 1, "the candidate standing in place");
    // Compared as designs: the browser's JSON writes 0.0 as 0.
    let design = |v: &serde_json::Value| -> Design { serde_json::from_value(v.clone()).unwrap() };
    let file = read_json(&designs);
    assert_eq!(design(&file["designs"][0]), design(kept));

    // Another origin's page: blind POSTs are sent but refused, the token cannot be read, a
    // JSON POST never leaves the browser (its preflight is not granted).
    let before = std::fs::read(&designs).unwrap();
    let attacked = garden_mjs(&url, &["attack", "343"]);
    assert_eq!(std::fs::read(&designs).unwrap(), before, "{attacked}");
    assert!(
        attacked["token"].as_str().unwrap().starts_with("failed"),
        "{attacked}"
    );
    assert!(
        attacked["json"].as_str().unwrap().starts_with("failed"),
        "{attacked}"
    );
    assert_eq!(attacked["keeps"].as_array().unwrap().len(), 80);

    // Rebuilt where it was, with the design, while the server runs (--force: the
    // parameters differ from the build's there).
    let params = dir.path().join("params.toml");
    std::fs::write(&params, "[garden]\ndesigns = \"designs.json\"\n").unwrap();
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &[
            "--quiet",
            "--no-plan",
            "--force",
            "--params",
            params.to_str().unwrap(),
        ],
    );
    let checked = garden_mjs(&url, &["check", "343"]);
    drop(server);
    let g = &checked["garden"];
    assert_eq!(g["built_from_design"], true, "{checked}");
    let got: Vec<[f64; 4]> = serde_json::from_value(g["stones"].clone()).unwrap();
    assert_eq!(
        got,
        design(kept).stone_rows(),
        "the kept stones, to the bit"
    );
    assert!(checked["stone_nodes"].as_u64().unwrap() > 0, "{checked}");
}
