//! Building part of a city: single tiles, shards and merge, and the output-directory guard.

mod common;

use std::path::Path;

use common::*;
use predicates::prelude::*;

#[test]
fn regenerated_tiles_are_byte_identical_to_a_full_build() {
    let work = tempfile::tempdir().unwrap();
    let (full, partial) = (work.path().join("full"), work.path().join("partial"));
    build_ok(&fixture("kyoto-small"), &full, &["--quiet"]);
    build_ok(&fixture("kyoto-small"), &partial, &["--quiet"]);
    let ids: Vec<String> = read_json(&full.join("manifest.json"))["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect();
    // Lose one tile, damage another, then regenerate just those two.
    std::fs::remove_file(partial.join(format!("tiles/{}.obj", ids[0]))).unwrap();
    std::fs::write(partial.join(format!("tiles/{}.obj", ids[1])), "damaged").unwrap();
    let before = std::fs::read(partial.join(format!("tiles/{}.obj", ids[2]))).unwrap();
    let list = format!("{},{}", ids[0], ids[1]);
    build_ok(
        &fixture("kyoto-small"),
        &partial,
        &["--quiet", "--tiles", &list],
    );
    assert_same_tree(&full, &partial);
    let after = std::fs::read(partial.join(format!("tiles/{}.obj", ids[2]))).unwrap();
    assert_eq!(before, after);
}

#[test]
fn an_unknown_tile_is_an_error_that_points_to_the_tiles_command() {
    let work = tempfile::tempdir().unwrap();
    build_ok(&fixture("kyoto-small"), work.path(), &["--quiet"]);
    build_cmd(&fixture("kyoto-small"), work.path(), &["--tiles", "1_1"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("1_1").and(predicate::str::contains("edo-city tiles")));
}

#[test]
fn the_union_of_shards_is_the_full_build() {
    let work = tempfile::tempdir().unwrap();
    let full = work.path().join("full");
    build_ok(&fixture("kyoto-small"), &full, &["--quiet"]);
    for n in 1..=3 {
        // All shards into one shared directory, as on a cluster's shared file system.
        let shared = work.path().join(format!("shared-{n}"));
        for i in 1..=n {
            let shard = format!("{i}/{n}");
            run_ok(
                &fixture("kyoto-small"),
                &shared,
                &["--quiet", "--shard", &shard],
            );
        }
        edo_city().arg("merge").arg(&shared).assert().success();
        assert_same_tree(&full, &shared);
    }
    // Shards in separate directories, merged into the first.
    let (a, b) = (work.path().join("a"), work.path().join("b"));
    run_ok(&fixture("kyoto-small"), &a, &["--quiet", "--shard", "1/2"]);
    run_ok(&fixture("kyoto-small"), &b, &["--quiet", "--shard", "2/2"]);
    edo_city().arg("merge").arg(&a).arg(&b).assert().success();
    assert_same_tree(&full, &a);
}

#[test]
fn merge_says_which_shards_are_missing() {
    let work = tempfile::tempdir().unwrap();
    run_ok(
        &fixture("kyoto-small"),
        work.path(),
        &["--quiet", "--shard", "2/3"],
    );
    edo_city()
        .arg("merge")
        .arg(work.path())
        .assert()
        .code(2)
        .stderr(predicate::str::contains("1/3, 3/3"));
}

#[test]
fn another_hypothesis_does_not_overwrite_a_build_without_force() {
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let before = all_files(&out);
    let params = work.path().join("h.toml");
    std::fs::write(&params, "[machiya]\ndepth = 9.0\n").unwrap();
    build_cmd(
        &fixture("kyoto-small"),
        &out,
        &["--params", params.to_str().unwrap()],
    )
    .assert()
    .code(2)
    .stderr(predicate::str::contains("machiya.depth").and(predicate::str::contains("--force")));
    assert_eq!(before, all_files(&out), "nothing was touched");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--force", "--params", params.to_str().unwrap()],
    );
    assert_eq!(
        read_json(&out.join("manifest.json"))["params"]["machiya"]["depth"],
        9.0
    );
}

#[test]
fn tiles_lists_ids_counts_and_bounds() {
    let out = edo_city()
        .arg("tiles")
        .arg(fixture("kyoto-small"))
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success());
    let tiles: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let tiles = tiles.as_array().unwrap();
    assert_eq!(tiles.len(), 4);
    let machiya: u64 = tiles.iter().map(|t| t["machiya"].as_u64().unwrap()).sum();
    assert_eq!(machiya, 398);
    let b = &tiles[0]["bounds"];
    assert_eq!(b[2].as_f64().unwrap() - b[0].as_f64().unwrap(), 250.0);
}

#[test]
fn a_mistyped_input_is_reported_as_such_even_into_an_existing_build() {
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    build_cmd(&work.path().join("kyoto-smal"), &out, &[])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("does not exist")
                .and(predicate::str::contains("another build").not()),
        );
}

#[test]
fn tiles_reuse_the_cached_analysis_only_for_the_same_input_and_parameters() {
    let work = tempfile::tempdir().unwrap();
    let (input, cache) = (work.path().join("in"), work.path().join("cache"));
    copy_fixture("kyoto-small", &input);
    let (full, out) = (work.path().join("full"), work.path().join("out"));
    // Runs a build with the given cache setting; its summary.
    let run = |out: &Path, extra: &[&str], cache: &Path| -> String {
        let o = build_cmd(&input, out, extra)
            .env("EDO_CITY_CACHE", cache)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let reused = |summary: &str| summary.contains("analysis   reused");
    run(&full, &["--quiet"], Path::new("off"));
    assert!(!reused(&run(&out, &[], &cache)));
    let plans: Vec<_> = std::fs::read_dir(&cache).unwrap().collect();
    assert_eq!(plans.len(), 1, "one cache file for the output directory");
    assert_eq!(
        all_files(&full).keys().collect::<Vec<_>>(),
        all_files(&out).keys().collect::<Vec<_>>(),
        "the cache is not in the output"
    );
    let id = read_json(&full.join("manifest.json"))["tiles"][0]["id"]
        .as_str()
        .unwrap()
        .to_string();
    let tile = out.join(format!("tiles/{id}.obj"));
    let tiles = ["--tiles", id.as_str()];

    std::fs::write(&tile, "damaged").unwrap();
    assert!(reused(&run(&out, &tiles, &cache)), "same input: reused");
    assert_same_tree(&full, &out);

    // A file only touched is the same input (the key is the content) ...
    let dbf = std::fs::File::options()
        .write(true)
        .open(input.join("lots.dbf"))
        .unwrap();
    dbf.set_modified(std::time::UNIX_EPOCH + std::time::Duration::from_secs(1_000_000_000))
        .unwrap();
    assert!(reused(&run(&out, &tiles, &cache)), "touched input: reused");
    assert_same_tree(&full, &out);
    // ... an edited one (the DBF header's date of last update, which changes no tile) is
    // analysed again, and that analysis cached.
    let mut bytes = std::fs::read(input.join("lots.dbf")).unwrap();
    bytes[1] = bytes[1].wrapping_add(1);
    std::fs::write(input.join("lots.dbf"), bytes).unwrap();
    std::fs::write(&tile, "damaged").unwrap();
    assert!(
        !reused(&run(&out, &tiles, &cache)),
        "edited input: analysed"
    );
    assert_same_tree(&full, &out);
    assert!(reused(&run(&out, &tiles, &cache)), "and cached again");

    // A damaged cache file is never read: the analysis runs.
    let plan = std::fs::read_dir(&cache)
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    let bytes = std::fs::read(&plan).unwrap();
    std::fs::write(&plan, &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(&tile, "damaged").unwrap();
    assert!(!reused(&run(&out, &tiles, &cache)));
    assert_same_tree(&full, &out);

    // EDO_CITY_CACHE=off: no cache read or written.
    std::fs::write(&tile, "damaged").unwrap();
    assert!(!reused(&run(&out, &tiles, Path::new("off"))));
    assert_same_tree(&full, &out);
}
