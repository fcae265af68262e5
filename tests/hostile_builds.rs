//! Files from another build and paths a user types, made as an attacker or a slip would make
//! them (issue 57): a shard manifest that lists `../planted.sh`, a FIFO or a 4 GiB sparse
//! file where a tile or model was, shards that disagree, leaves whose declared lengths were
//! edited, a GeoPackage target that names an input or a manifest, another build's
//! `plan.gpkg` whose `lots` is an endless query, a FIFO as the designs file. Each is refused
//! with exit 2 naming what is wrong, under a memory limit and within a deadline (a hang or an
//! abort fails), and nothing outside the output is written.

mod common;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use common::{build_ok, fixture, read_json};
use serde_json::Value;

/// Runs edo-city with `args` under a 3 GiB address-space limit; its exit code and stderr.
/// Panics if it has not ended within two minutes (it hung).
fn limited<S: AsRef<OsStr>>(args: &[S]) -> (Option<i32>, String) {
    let bin = assert_cmd::cargo::cargo_bin("edo-city");
    let mut line = format!("ulimit -v 3145728; exec '{}'", bin.display());
    for a in args {
        line += &format!(" '{}'", a.as_ref().to_string_lossy().replace('\'', "'\\''"));
    }
    let mut child = std::process::Command::new("sh")
        .args(["-c", &line])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status.code(), err);
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("edo-city {line} hung");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Asserts a refusal: exit 2 with `says` in its error.
fn refused<S: AsRef<OsStr>>(args: &[S], says: &str) {
    let (code, err) = limited(args);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains(says), "`{says}` not in: {err}");
}

fn mkfifo(path: &Path) {
    let _ = std::fs::remove_file(path);
    assert!(std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap()
        .success());
}

fn write_json(path: &Path, v: &Value) {
    std::fs::write(path, serde_json::to_vec_pretty(v).unwrap()).unwrap();
}

/// `{path, bytes, sha256}` of `bytes` as a manifest lists a file.
fn listed(path: &str, bytes: &[u8]) -> Value {
    serde_json::json!({
        "path": path,
        "bytes": bytes.len(),
        "sha256": edo_city::output::sha256_hex(bytes),
    })
}

/// A town with grown trees (shared models) built as two shards in directories far apart.
fn shards(top: &Path) -> (PathBuf, PathBuf, PathBuf) {
    let town = top.join("town");
    common::edo_city()
        .args([
            "synth",
            town.to_str().unwrap(),
            "--lots",
            "300",
            "--seed",
            "5",
        ])
        .assert()
        .success();
    let params = top.join("trees.toml");
    std::fs::write(&params, "[trees]\nstyle = \"lsystem\"\nper_ha = 200.0\n").unwrap();
    let (a, b) = (top.join("a"), top.join("deep/er/b"));
    for (out, shard) in [(&a, "1/2"), (&b, "2/2")] {
        let p = params.to_str().unwrap();
        common::run_ok(&town, out, &["--quiet", "--params", p, "--shard", shard]);
    }
    (a, b.clone(), b.join("manifest.shard-2-of-2.json"))
}

#[test]
fn merge_writes_only_inside_its_build_and_refuses_files_and_shards_it_cannot_trust() {
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path();
    let (a, b, manifest) = shards(top);
    let good = read_json(&manifest);
    let merge = [OsStr::new("merge"), a.as_os_str(), b.as_os_str()];

    // A tile listing a file beside the shard, with its true length and sha256.
    let script = b"#!/bin/sh\necho planted\n";
    std::fs::write(top.join("deep/er/planted.sh"), script).unwrap();
    let mut m = good.clone();
    m["tiles"][0]["models"] = serde_json::json!([listed("../planted.sh", script)]);
    write_json(&manifest, &m);
    refused(&merge, "`../planted.sh`, which no build writes");
    assert!(
        !top.join("planted.sh").exists(),
        "written beside the target"
    );
    assert!(!a.join("manifest.json").exists(), "the target as it was");

    // A shared model swapped for a FIFO, or for a link to /dev/zero.
    write_json(&manifest, &good);
    let model_of = |m: &Value| -> String {
        (m["tiles"].as_array().unwrap().iter())
            .flat_map(|t| t["models"].as_array().into_iter().flatten())
            .next()
            .expect("a shard with a shared model")["path"]
            .as_str()
            .unwrap()
            .to_string()
    };
    let model = model_of(&good);
    let bytes = std::fs::read(b.join(&model)).unwrap();
    mkfifo(&b.join(&model));
    refused(&merge, "not a regular file");
    std::fs::remove_file(b.join(&model)).unwrap();
    std::os::unix::fs::symlink("/dev/zero", b.join(&model)).unwrap();
    refused(&merge, "not a regular file");
    std::fs::remove_file(b.join(&model)).unwrap();
    std::fs::write(b.join(&model), &bytes).unwrap();

    // A tile made a sparse 4 GiB file: refused by its size, nothing read.
    let tile = good["tiles"][0]["glb"]["path"]
        .as_str()
        .unwrap()
        .to_string();
    let tile_bytes = std::fs::read(b.join(&tile)).unwrap();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(b.join(&tile))
        .unwrap();
    f.set_len(4 << 30).unwrap();
    drop(f);
    refused(&merge, "but it holds 4294967296");
    std::fs::write(b.join(&tile), &tile_bytes).unwrap();

    // A shared model both shards list, grown otherwise in one of them (its manifest made
    // to agree with its own copy): the shards disagree.
    let first = read_json(&a.join("manifest.shard-1-of-2.json"));
    let shared = model_of(&first);
    let mut other = std::fs::read(a.join(&shared)).unwrap();
    other[0] ^= 0xff;
    let kept = std::fs::read(b.join(&shared)).ok();
    std::fs::create_dir_all(b.join(&shared).parent().unwrap()).unwrap();
    std::fs::write(b.join(&shared), &other).unwrap();
    let mut m = good.clone();
    m["tiles"][0]["models"] = serde_json::json!([listed(&shared, &other)]);
    write_json(&manifest, &m);
    refused(
        &merge,
        &format!("shards 1/2 and 2/2 disagree on `{shared}`"),
    );
    match kept {
        Some(bytes) => std::fs::write(b.join(&shared), bytes).unwrap(),
        None => std::fs::remove_file(b.join(&shared)).unwrap(),
    }

    // A shard of another version of the program.
    let mut m = good.clone();
    m["version"] = "0.0.0-other".into();
    write_json(&manifest, &m);
    refused(&merge, "written by edo-city 0.0.0-other");

    // Put back, the shards merge.
    write_json(&manifest, &good);
    let (code, err) = limited(&merge);
    assert_eq!(code, Some(0), "{err}");
    assert!(a.join("manifest.json").is_file());
}

/// The GLB of `path` with its JSON chunk replaced by `edit(json)`, and the manifest of `out`
/// made to list the new bytes (as someone covering their tracks would).
fn edit_leaf(out: &Path, path: &str, edit: impl Fn(&mut Value)) {
    let bytes = std::fs::read(out.join(path)).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let mut json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    edit(&mut json);
    let mut text = serde_json::to_vec(&json).unwrap();
    text.resize(text.len().next_multiple_of(4), b' ');
    let rest = &bytes[20 + json_len..];
    let mut glb = bytes[..12].to_vec();
    glb.extend((text.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&text);
    glb.extend(rest);
    let total = glb.len() as u32;
    glb[8..12].copy_from_slice(&total.to_le_bytes());
    std::fs::write(out.join(path), &glb).unwrap();
    let mut m = read_json(&out.join("manifest.json"));
    for t in m["tiles"].as_array_mut().unwrap() {
        if t["glb"]["path"] == path {
            t["glb"] = listed(path, &glb);
        }
    }
    write_json(&out.join("manifest.json"), &m);
}

#[test]
fn leaves_whose_declared_lengths_were_edited_are_refused_not_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let input = fixture("kyoto-small");
    build_ok(&input, &out, &["--quiet", "--no-plan"]);
    let m = read_json(&out.join("manifest.json"));
    let tiles = m["tiles"].as_array().unwrap();
    assert!(tiles.len() >= 2);
    let leaf = tiles[0]["glb"]["path"].as_str().unwrap().to_string();
    let other = tiles[1]["id"].as_str().unwrap().to_string();
    let again = |says: &str| {
        let args = [
            OsStr::new("build"),
            input.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
            OsStr::new("--quiet"),
            OsStr::new("--no-plan"),
            OsStr::new("--tiles"),
            OsStr::new(&other),
        ];
        refused(&args, says);
    };
    let original = std::fs::read(out.join(&leaf)).unwrap();
    let original_manifest = std::fs::read(out.join("manifest.json")).unwrap();
    edit_leaf(&out, &leaf, |j| {
        j["buffers"][0]["byteLength"] = 100_000_000_000u64.into()
    });
    again("declares 100000000000 bytes");
    std::fs::write(out.join(&leaf), &original).unwrap();
    std::fs::write(out.join("manifest.json"), &original_manifest).unwrap();
    edit_leaf(&out, &leaf, |j| {
        j["extensions"]["EXT_structural_metadata"]["propertyTables"][0]["count"] =
            10_000_000_000u64.into()
    });
    again("claims 10000000000 rows");
}

#[test]
fn geopackages_go_nowhere_a_command_reads_and_over_no_other_kind_of_file() {
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path();
    let input = top.join("in");
    common::copy_fixture("kyoto-small", &input);
    let lots = std::fs::read(input.join("lots.shp")).unwrap();
    let check = |target: &Path, says: &str| {
        let args = [OsStr::new("check"), input.as_os_str(), OsStr::new("--gpkg")];
        let mut args: Vec<&OsStr> = args.to_vec();
        args.push(target.as_os_str());
        refused(&args, says);
    };
    check(&input.join("lots.shp"), "inside the input directory");
    assert_eq!(std::fs::read(input.join("lots.shp")).unwrap(), lots);

    let (a, b) = (top.join("a"), top.join("b"));
    build_ok(&input, &a, &["--quiet"]);
    build_ok(&input, &b, &["--quiet"]);
    let manifest = std::fs::read(a.join("manifest.json")).unwrap();
    let compare = |flag: &str, target: &Path, says: &str| {
        let args = [
            OsStr::new("compare"),
            a.as_os_str(),
            b.as_os_str(),
            OsStr::new(flag),
            target.as_os_str(),
        ];
        refused(&args, says);
    };
    compare("--gpkg", &a.join("manifest.json"), "inside build A");
    compare("--gpkg", &b.join("plan.gpkg"), "inside build B");
    compare("--plan", &a.join("plan.png"), "inside build A");
    assert_eq!(std::fs::read(a.join("manifest.json")).unwrap(), manifest);
    let notes = top.join("notes.txt");
    std::fs::write(&notes, "a historian's notes").unwrap();
    compare("--gpkg", &notes, "exists and is not a GeoPackage");
    compare("--plan", &notes, "exists and is not a PNG image");
    assert_eq!(
        std::fs::read_to_string(&notes).unwrap(),
        "a historian's notes"
    );

    // B's plan.gpkg with `lots` an endless recursive query: refused before it runs.
    {
        let c = rusqlite::Connection::open(b.join("plan.gpkg")).unwrap();
        c.execute_batch(
            "DROP TABLE lots; CREATE VIEW lots AS WITH RECURSIVE n(x) AS (SELECT 1 UNION ALL \
             SELECT x + 1 FROM n) SELECT x AS fid, 'a' AS id, x AS record, NULL AS geom, \
             'hiraya' AS type, NULL AS kura, NULL AS status, 0 AS trees FROM n ORDER BY x;",
        )
        .unwrap();
    }
    compare(
        "--gpkg",
        &top.join("diff.gpkg"),
        "its `lots` is not a table",
    );
    assert!(!top.join("diff.gpkg").exists());
}

#[test]
fn a_fifo_for_a_designs_file_is_refused_not_waited_on() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("designs.json");
    mkfifo(&fifo);
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[garden]\ndesigns = \"designs.json\"\n").unwrap();
    let input = fixture("kyoto-small");
    let out = dir.path().join("out");
    for cmd in ["build", "check"] {
        let mut args = vec![OsStr::new(cmd), input.as_os_str()];
        if cmd == "build" {
            args.extend([OsStr::new("--out"), out.as_os_str()]);
        }
        args.extend([OsStr::new("--params"), params.as_os_str()]);
        refused(&args, "is not a regular file");
    }
    assert!(!out.exists(), "nothing written");
}
