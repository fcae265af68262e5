//! Rock gardens designed by a person and kept (issue 42): `edo-city serve --designs FILE`
//! answers the designer's API (`/api/gardens...`), a build with `[garden] designs` places a
//! kept design stone for stone, and bad input (unknown lots, picks out of range, stale
//! generations, garbage files, conflicting keeps, a read-only server) gets a clear error and
//! writes nothing.

mod common;

use std::path::Path;

use common::designer::{ask, ask_with, built, error, page, post, serve, USES};
use common::{build_objects, build_ok, fixture, read_json};
use serde_json::{json, Value};

/// The report's garden of `key`.
fn garden(report: &Value, key: &str) -> Value {
    report["gardens"]
        .as_array()
        .unwrap()
        .iter()
        .find(|g| g["key"] == key)
        .cloned()
        .unwrap_or_else(|| panic!("no garden {key}"))
}

#[test]
fn a_kept_design_survives_a_rebuild_stone_for_stone_and_other_gardens_stay_the_gas() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let before = read_json(&out.join("report.json"));
    let designs = dir.path().join("kept/designs.json");
    std::fs::create_dir(dir.path().join("kept")).unwrap();
    let (server, port) = serve(dir.path(), &out, Some(&designs));
    let tok = page(port);

    let (status, list) = ask(port, "GET", "/api/gardens", "");
    assert_eq!(status, 200, "{list}");
    let keys: Vec<&str> = list["gardens"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["lot"].as_str().unwrap())
        .collect();
    assert_eq!(keys, ["138", "343"]);
    assert_eq!(list["writable"], true);

    let (status, s) = post(port, &tok, "open", json!({"lot": "343"}));
    assert_eq!(status, 200, "{s}");
    let n = s["candidates"].as_array().unwrap().len();
    assert!((6..=9).contains(&n), "{n} candidates");
    let session = s["session"].as_str().unwrap().to_string();
    let mut g = 0;
    let mut last = s;
    for picks in [[0, 2], [1, 3], [0, 1]] {
        let (status, next) = post(
            port,
            &tok,
            "next",
            json!({"session": session, "generation": g, "picks": picks}),
        );
        assert_eq!(status, 200, "{next}");
        assert_ne!(
            next["candidates"], last["candidates"],
            "picks {picks:?} changed nothing"
        );
        g += 1;
        assert_eq!(next["generation"], g);
        last = next;
    }
    let (status, kept) = post(
        port,
        &tok,
        "keep",
        json!({"session": session, "generation": g, "candidate": 2}),
    );
    assert_eq!(status, 200, "{kept}");
    assert_eq!(kept["kept"]["stones"].as_array().unwrap().len(), 15);
    let file: Value = read_json(&designs);
    assert_eq!(file["edo_city_designs"], 1);
    assert_eq!(file["designs"][0]["lot"], "343");
    assert_eq!(file["designs"][0]["history"].as_array().unwrap().len(), 3);
    let kept_stones: Vec<Value> = last["candidates"][2]["stones"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| json!({"x": s["x"], "y": s["y"], "size": s["size"], "group": s["group"]}))
        .collect();
    assert_eq!(
        file["designs"][0]["stones"],
        Value::Array(kept_stones),
        "the file holds the candidate kept"
    );
    drop(server);

    // Rebuild with the designs file (relative to the parameter file, which lies elsewhere).
    let params = dir.path().join("kept/params.toml");
    std::fs::write(&params, format!("{USES}designs = \"designs.json\"\n")).unwrap();
    let again = dir.path().join("again");
    let report = build_ok(
        &fixture("kyoto-small"),
        &again,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let g343 = garden(&report, "343");
    assert_eq!(g343["kept"], true);
    let want: Vec<[f64; 4]> = file["designs"][0]["stones"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            [
                s["x"].as_f64().unwrap(),
                s["y"].as_f64().unwrap(),
                s["size"].as_f64().unwrap(),
                s["group"].as_f64().unwrap(),
            ]
        })
        .collect();
    let got: Vec<[f64; 4]> = serde_json::from_value(g343["layout"].clone()).unwrap();
    assert_eq!(got, want, "the kept stones, to the bit");
    // In the tiles: each stone of lot 343 lies where the design puts it.
    let (corner, angle) = (
        [
            g343["corner"][0].as_f64().unwrap(),
            g343["corner"][1].as_f64().unwrap(),
        ],
        g343["angle"].as_f64().unwrap(),
    );
    let objects = build_objects(&again);
    let stones: Vec<_> = objects
        .iter()
        .filter(|o| o.name.starts_with("stone_343_"))
        .collect();
    assert_eq!(stones.len(), want.len());
    for (k, s) in want.iter().enumerate() {
        let o = stones
            .iter()
            .find(|o| o.name.ends_with(&format!("_{k}")))
            .unwrap();
        let n = o.vertices.len() as f64;
        let cx = o.vertices.iter().map(|v| v[0]).sum::<f64>() / n;
        let cy = o.vertices.iter().map(|v| v[1]).sum::<f64>() / n;
        let (sn, cs) = angle.sin_cos();
        let ex = corner[0] + s[0] * cs - s[1] * sn;
        let ey = corner[1] + s[0] * sn + s[1] * cs;
        let d = (cx - ex).hypot(cy - ey);
        assert!(
            d < s[2] / 2.0,
            "stone {k} of the tiles is {d} m from the design's"
        );
    }
    // The garden without a design is the GA's, as before.
    assert_eq!(garden(&report, "138"), garden(&before, "138"));
    assert_ne!(
        garden(&report, "343")["layout"],
        garden(&before, "343")["layout"]
    );
    let account = report["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "designs")
        .cloned()
        .unwrap();
    assert_eq!(
        (
            account["read"].as_u64(),
            account["built"].as_u64(),
            account["file"].as_str()
        ),
        (Some(1), Some(1), Some("designs.json"))
    );
}

#[test]
fn bad_requests_get_a_clear_error_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let designs = dir.path().join("designs.json");
    let (server, port) = serve(dir.path(), &out, Some(&designs));
    let tok = page(port);

    let (status, e) = error(post(port, &tok, "open", json!({"lot": "nope"})));
    assert_eq!(status, 404);
    assert!(e.contains("no garden `nope`"), "{e}");
    let (status, e) = error(post(
        port,
        &tok,
        "open",
        json!({"lot": "343", "population": 1}),
    ));
    assert_eq!(status, 400);
    assert!(e.contains("population"), "{e}");
    let (status, e) = error(ask_with(
        port,
        &[("X-Edo-City-Token", &tok)],
        "POST",
        "/api/gardens/open",
        "{not json",
    ));
    assert_eq!(status, 400);
    assert!(e.contains("body"), "{e}");
    let (status, _) = ask(port, "GET", "/api/gardens/open", "");
    assert_eq!(status, 405);
    let (status, _) = ask(port, "GET", "/api/gardens?h=5", "");
    assert_eq!(status, 404);

    let (_, s) = post(port, &tok, "open", json!({"lot": "343"}));
    let id = s["session"].as_str().unwrap().to_string();
    let (status, e) = error(post(
        port,
        &tok,
        "next",
        json!({"session": id, "generation": 0, "picks": [0, 40]}),
    ));
    assert_eq!(status, 400);
    assert!(e.contains("pick 40 is out of range"), "{e}");
    let (status, e) = error(post(
        port,
        &tok,
        "next",
        json!({"session": id, "generation": 3, "picks": []}),
    ));
    assert_eq!(status, 409);
    assert!(e.contains("stale"), "{e}");
    let (status, e) = error(post(
        port,
        &tok,
        "undo",
        json!({"session": id, "generation": 0}),
    ));
    assert_eq!(status, 409);
    assert!(e.contains("nothing to undo"), "{e}");
    let (status, _) = error(post(
        port,
        &tok,
        "next",
        json!({"session": "999", "generation": 0}),
    ));
    assert_eq!(status, 404);
    let (status, e) = error(post(
        port,
        &tok,
        "keep",
        json!({"session": id, "generation": 0, "candidate": 9}),
    ));
    assert_eq!(status, 400, "{e}");
    assert!(!designs.exists(), "nothing written");

    // The same picks from the same start: the same answers.
    let (_, t) = post(port, &tok, "open", json!({"lot": "343"}));
    assert_eq!(t["candidates"], s["candidates"]);
    let (_, a) = post(
        port,
        &tok,
        "next",
        json!({"session": id, "generation": 0, "picks": [1, 4]}),
    );
    let (_, b) = post(
        port,
        &tok,
        "next",
        json!({"session": t["session"], "generation": 0, "picks": [1, 4]}),
    );
    assert_eq!(a["candidates"], b["candidates"]);

    // A garbage designs file is reported and left as it was.
    std::fs::write(&designs, "garbage").unwrap();
    let (status, e) = error(post(
        port,
        &tok,
        "keep",
        json!({"session": id, "generation": 1, "candidate": 0}),
    ));
    assert_eq!(status, 422);
    assert!(
        e.contains("not a designs file") && e.contains("nothing was written"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&designs).unwrap(), "garbage");
    std::fs::remove_file(&designs).unwrap();

    // Two visitors on one garden: the second keep would lose the first, and is refused.
    let (status, _) = post(
        port,
        &tok,
        "keep",
        json!({"session": id, "generation": 1, "candidate": 0}),
    );
    assert_eq!(status, 200);
    let first = std::fs::read(&designs).unwrap();
    let (status, e) = error(post(
        port,
        &tok,
        "keep",
        json!({"session": t["session"], "generation": 1, "candidate": 1}),
    ));
    assert_eq!(status, 409);
    assert!(e.contains("someone kept another design"), "{e}");
    assert_eq!(
        std::fs::read(&designs).unwrap(),
        first,
        "the first design is kept"
    );
    // The first visitor keeps again over their own design.
    let (status, _) = post(
        port,
        &tok,
        "keep",
        json!({"session": id, "generation": 1, "candidate": 2}),
    );
    assert_eq!(status, 200);
    drop(server);

    // Without --designs the designer is read-only.
    let (server, port) = serve(dir.path(), &out, None);
    let tok = page(port);
    let (_, s) = post(port, &tok, "open", json!({"lot": "138"}));
    let (status, e) = error(post(
        port,
        &tok,
        "keep",
        json!({"session": s["session"], "generation": 0, "candidate": 0}),
    ));
    assert_eq!(status, 403);
    assert!(e.contains("read-only"), "{e}");
    drop(server);

    // serve refuses to start on a designs file that is not one.
    std::fs::write(&designs, "{\"edo_city_designs\": 7, \"designs\": []}").unwrap();
    let o = common::edo_city()
        .args(["serve", "--port", "0", "--viewer"])
        .arg(dir.path().join("viewer"))
        .arg(&out)
        .arg("--designs")
        .arg(&designs)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("designs.json") && err.contains("format 7"),
        "{err}"
    );
}

#[test]
fn designs_that_no_longer_fit_or_have_no_garden_are_skipped_with_why() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let before = read_json(&out.join("report.json"));
    let g = garden(&before, "343");
    let stones: Vec<Value> = g["layout"]
        .as_array()
        .unwrap()
        .iter()
        .map(
            |s| json!({"x": s[0], "y": s[1], "size": s[2], "group": s[3].as_f64().unwrap() as u64}),
        )
        .collect();
    let design = |lot: &str, x0: f64| {
        let mut st = stones.clone();
        st[0]["x"] = json!(x0);
        json!({"lot": lot, "seed": 1, "size": [10.0, 25.0], "stones": st, "fitness": 1.0})
    };
    let file = json!({"edo_city_designs": 1, "designs": [
        design("343", 30.0),
        design("gone", 1.0),
        design("138", 1.0),
        {"lot": "138", "seed": 1, "size": [10.0, 25.0], "stones": [], "fitness": 1.0},
    ]});
    std::fs::write(dir.path().join("designs.json"), file.to_string()).unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(&params, format!("{USES}designs = \"designs.json\"\n")).unwrap();
    let report = build_ok(
        &fixture("kyoto-small"),
        &dir.path().join("b"),
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let skipped: Vec<&Value> = report["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["layer"] == "designs")
        .collect();
    let why = |record: u64| {
        skipped
            .iter()
            .find(|s| s["record"] == record)
            .map(|s| s["reason"].as_str().unwrap().to_string())
            .unwrap_or_else(|| panic!("record {record} not skipped: {skipped:?}"))
    };
    assert!(
        why(0).contains("no longer fits") && why(0).contains("stone 0"),
        "{}",
        why(0)
    );
    assert!(why(0).contains("the GA designed the garden instead"));
    assert!(why(1).contains("no garden of this build"), "{}", why(1));
    assert!(why(3).contains("0 stones"), "{}", why(3));
    assert_eq!(skipped.len(), 3);
    // 343 is the GA's again, as without a designs file; 138 is the kept one.
    assert_eq!(garden(&report, "343"), garden(&before, "343"));
    assert_eq!(garden(&report, "138")["kept"], true);

    // A designs file that is not one stops the build, naming it.
    std::fs::write(dir.path().join("designs.json"), "[1, 2").unwrap();
    let o = common::build_cmd(
        &fixture("kyoto-small"),
        &dir.path().join("c"),
        &["--quiet", "--params", params.to_str().unwrap()],
    )
    .output()
    .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("designs.json") && err.contains("not a designs file"),
        "{err}"
    );
    assert!(!dir.path().join("c/manifest.json").exists());
}

#[test]
fn a_changed_designs_file_reaches_a_regenerated_tile() {
    // `--tiles` reuses the cached analysis only when every file it read is the same: the
    // designs file is one of them, wherever the parameter file puts it.
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let g = garden(&read_json(&out.join("report.json")), "343");
    let design = |dx: f64| {
        let stones: Vec<Value> = g["layout"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let x = s[0].as_f64().unwrap() + if k == 5 { dx } else { 0.0 };
                json!({"x": x, "y": s[1], "size": s[2], "group": s[3].as_f64().unwrap() as u64})
            })
            .collect();
        json!({"edo_city_designs": 1, "designs": [
            {"lot": "343", "seed": 1, "size": g["size"], "stones": stones, "fitness": 1.0}
        ]})
        .to_string()
    };
    let kept = dir.path().join("kept");
    std::fs::create_dir(&kept).unwrap();
    std::fs::write(kept.join("designs.json"), design(0.3)).unwrap();
    let params = kept.join("p.toml");
    std::fs::write(&params, format!("{USES}designs = \"designs.json\"\n")).unwrap();
    // Run from the parameter file's directory, named relative to it: the case a key that
    // resolved the designs against the input directory got wrong.
    let _ = params;
    let build = |out: &Path, extra: &[&str]| {
        let o = common::build_cmd(&fixture("kyoto-small"), out, extra)
            .args(["--quiet", "--params", "p.toml"])
            .current_dir(&kept)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let partial = dir.path().join("partial");
    build(&partial, &[]);
    let tile = std::fs::read_dir(partial.join("tiles"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|f| {
            f.extension().is_some_and(|e| e == "obj")
                && std::fs::read_to_string(f).unwrap().contains("o stone_343_")
        })
        .unwrap();
    let id = tile.file_stem().unwrap().to_str().unwrap().to_string();
    let before = std::fs::read(&tile).unwrap();

    std::fs::write(kept.join("designs.json"), design(0.6)).unwrap();
    build(&partial, &["--tiles", &id]);
    let full = dir.path().join("full");
    build(&full, &[]);
    let (now, want) = (
        std::fs::read(&tile).unwrap(),
        std::fs::read(full.join("tiles").join(format!("{id}.obj"))).unwrap(),
    );
    assert!(now != before, "the regenerated tile has the new design");
    assert!(now == want, "and is the full build's");
}
