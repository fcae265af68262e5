//! `[input] overrides` (issue 61): the per-lot edits the workbench keeps beside a parameter
//! file, read by `build` like any input.

mod common;

use common::*;

/// A parameter file `p.toml` naming `p.overrides.csv` beside it, with `rows` after its header.
fn params_with(dir: &std::path::Path, rows: &str) -> String {
    std::fs::write(
        dir.join("p.overrides.csv"),
        format!("lot,field,value\n{rows}"),
    )
    .unwrap();
    let p = dir.join("p.toml");
    std::fs::write(&p, "[input]\noverrides = \"p.overrides.csv\"\n").unwrap();
    p.display().to_string()
}

#[test]
fn an_override_changes_one_lot_and_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let before = build_ok(
        &fixture("kyoto-small"),
        &dir.path().join("before"),
        &["--quiet"],
    );
    // Lot 5 is a sangai in the table: the override makes it a hiraya; lot 7 becomes an
    // estate; a later row for lot 7's district wins over an earlier one.
    let params = params_with(
        dir.path(),
        "5,mtype,hiraya\n7,use,buke\n7,district,a\n7,district,b\n",
    );
    // Run from elsewhere: the file is found beside the parameter file.
    let after = build_ok(
        &fixture("kyoto-small"),
        &dir.path().join("after"),
        &["--quiet", "--params", &params],
    );
    let count = |r: &serde_json::Value, k: &str, v: &str| r["counts"][k][v].as_u64().unwrap_or(0);
    assert_eq!(
        count(&after, "by_type", "sangai") + 1,
        count(&before, "by_type", "sangai")
    );
    assert_eq!(
        count(&after, "lots_by_use", "buke"),
        count(&before, "lots_by_use", "buke") + 1
    );
    assert_eq!(
        after["counts"]["machiya"].as_u64().unwrap() + 1,
        before["counts"]["machiya"].as_u64().unwrap()
    );
    let tables = after["tables"].as_array().unwrap();
    let t = tables
        .iter()
        .find(|t| t["file"] == "p.overrides.csv")
        .expect("the overrides are listed as a table");
    assert_eq!(
        (t["rows"].as_u64(), t["matched"].as_u64()),
        (Some(4), Some(4))
    );
    // The manifest names the file by its name and fingerprint, not the person's directory.
    let m = read_json(&dir.path().join("after/manifest.json"));
    let named = m["params"]["input"]["overrides"].as_str().unwrap();
    assert!(named.contains("p.overrides.csv"), "{named}");
    assert!(!named.contains(&*dir.path().to_string_lossy()), "{named}");
    // A build without overrides publishes its parameters as it always did.
    let m = read_json(&dir.path().join("before/manifest.json"));
    assert!(m["params"].get("input").is_none());
}

#[test]
fn a_bad_override_stops_the_build_naming_its_row() {
    for (rows, says) in [
        (
            "5,mtype,hiraya\nnope,mtype,hiraya\n",
            "row 3: no lot has the id `nope`",
        ),
        ("5,use,castle\n", "row 2: `castle` is not a lot use"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let params = params_with(dir.path(), rows);
        let out = dir.path().join("out");
        let o = edo_city()
            .arg("build")
            .arg(fixture("kyoto-small"))
            .args(["--quiet", "--params", &params, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains("p.overrides.csv") && err.contains(says),
            "{err}"
        );
        assert!(!out.exists(), "nothing written");
    }
}
