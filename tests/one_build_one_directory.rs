//! One build in one directory, and nothing lost between runs: the output-directory lock,
//! merges checked against their shards, `--tiles` never stamping new parameters on old tiles,
//! a build that would write nothing never deleting an earlier one, `synth` and `init` that
//! never overwrite or wander (issue 17).

mod common;

use std::path::Path;

use common::{all_files, build_ok, edo_city, fixture, read_json, synth};

/// `edo-city build input --out out args... --params params`.
fn build_with(input: &Path, out: &Path, args: &[&str], params: &Path) -> std::process::Output {
    edo_city()
        .arg("build")
        .arg(input)
        .arg("--out")
        .arg(out)
        .args(args)
        .arg("--params")
        .arg(params)
        .output()
        .unwrap()
}

fn stderr_of(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_second_run_into_a_locked_directory_refuses_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // Another run holds the directory (the lock is the one every run takes).
    let held = edo_city::output::lock::OutLock::acquire(&out).unwrap();
    let o = edo_city()
        .args(["build"])
        .arg(fixture("kyoto-small"))
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr_of(&o));
    assert!(
        stderr_of(&o).contains("in use by another edo-city run"),
        "{}",
        stderr_of(&o)
    );
    assert!(!out.join("manifest.json").exists());
    assert!(!out.join("tiles").exists(), "nothing written");
    drop(held);
    // Released (as a killed process releases it), the same command builds.
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let files = all_files(&out);
    assert!(
        files.keys().all(|f| !f.contains(".edo-city.lock")),
        "the lock file goes with its run"
    );
}

#[test]
fn a_lock_file_left_by_a_killed_run_does_not_block() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // A killed run leaves its file (with its pid) but not its lock: the OS lock died with it.
    std::fs::write(out.join(edo_city::output::lock::LOCK_FILE), "4194303").unwrap();
    build_ok(&fixture("kyoto-small"), &out, &["--quiet", "--no-plan"]);
}

#[test]
fn two_hypotheses_started_together_never_mix_in_one_directory() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 3000, 4);
    let other = dir.path().join("other.toml");
    std::fs::write(&other, "seed = 99\n").unwrap();
    let out = dir.path().join("out");
    for _ in 0..3 {
        let _ = std::fs::remove_dir_all(&out);
        let spawn = |params: Option<&Path>| {
            let mut c = std::process::Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
            c.arg("build")
                .arg(&town)
                .arg("--out")
                .arg(&out)
                .args(["--quiet", "--no-plan"]);
            if let Some(p) = params {
                c.arg("--params").arg(p);
            }
            c.stderr(std::process::Stdio::piped()).spawn().unwrap()
        };
        let (a, b) = (spawn(None), spawn(Some(&other)));
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        let ok = [a.status.success(), b.status.success()];
        // However they interleave, exactly one succeeds: the other finds the directory
        // locked, or (starting after the first finished) holding another hypothesis.
        assert_eq!(
            ok.iter().filter(|s| **s).count(),
            1,
            "a: {}\nb: {}",
            stderr_of(&a),
            stderr_of(&b)
        );
        // The directory holds exactly the winner's build: every file of its manifest is
        // there with its size and hash, and no other tile is.
        let m = read_json(&out.join("manifest.json"));
        let listed: std::collections::BTreeSet<String> = m["tiles"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|t| [&t["obj"], &t["mtl"], &t["glb"]])
            // The levels of detail above the tiles, among the build's files.
            .chain(
                m["files"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .filter(|f| f["path"].as_str().unwrap().starts_with("tiles/")),
            )
            .map(|f| {
                let path = f["path"].as_str().unwrap().to_string();
                let bytes = std::fs::read(out.join(&path)).unwrap();
                assert_eq!(bytes.len() as u64, f["bytes"].as_u64().unwrap(), "{path}");
                assert_eq!(edo_city::output::sha256_hex(&bytes), f["sha256"], "{path}");
                path
            })
            .collect();
        let on_disk: std::collections::BTreeSet<String> = all_files(&out)
            .into_keys()
            .filter(|f| f.starts_with("tiles/") && !f.starts_with("tiles/textures/"))
            .collect();
        assert_eq!(listed, on_disk);
    }
}

/// A town built in two shards into `a` and `b`.
fn two_shards(town: &Path, a: &Path, b: &Path) {
    for (dir, shard) in [(a, "1/2"), (b, "2/2")] {
        let o = edo_city()
            .arg("build")
            .arg(town)
            .arg("--out")
            .arg(dir)
            .args(["--quiet", "--shard", shard])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr_of(&o));
    }
}

#[test]
fn merge_checks_every_shard_file_and_writes_nothing_when_one_is_cut_short() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 800, 2);
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    two_shards(&town, &a, &b);
    let m = read_json(&b.join("manifest.shard-2-of-2.json"));
    let tile = m["tiles"][0]["obj"]["path"].as_str().unwrap().to_string();
    let bytes = std::fs::read(b.join(&tile)).unwrap();
    std::fs::write(b.join(&tile), &bytes[..bytes.len() / 2]).unwrap();
    let o = edo_city().arg("merge").arg(&a).arg(&b).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let e = stderr_of(&o);
    assert!(
        e.contains("cut short or changed") && e.contains(&tile),
        "{e}"
    );
    assert!(!a.join("manifest.json").exists(), "no merged manifest");
    assert!(!a.join(&tile).exists(), "nothing copied");

    // A missing tile is named as missing, not as a file that cannot be written.
    std::fs::remove_file(b.join(&tile)).unwrap();
    let o = edo_city().arg("merge").arg(&a).arg(&b).output().unwrap();
    let e = stderr_of(&o);
    assert!(
        e.contains("cannot be read") && e.contains("run that shard again"),
        "{e}"
    );

    // Restored, the merge works, from another working directory too (the shards' manifests
    // name the input by its absolute path).
    std::fs::write(b.join(&tile), &bytes).unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let o = edo_city()
        .current_dir(elsewhere.path())
        .arg("merge")
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(a.join("plan.png").exists());
    // The merged manifest, published with the city, names the input alone (issue 39).
    assert_eq!(
        read_json(&a.join("manifest.json"))["input"]["input"],
        town.file_name().unwrap().to_str().unwrap()
    );
    let abs = town.canonicalize().unwrap().display().to_string();
    for f in ["manifest.json", "report.json"] {
        let text = std::fs::read_to_string(a.join(f)).unwrap();
        assert!(!text.contains(&abs), "{f} names {abs}");
    }
}

#[test]
fn merge_of_two_builds_names_the_parameter_that_differs() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 400, 2);
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    two_shards(&town, &a, &b);
    let p = dir.path().join("p.toml");
    std::fs::write(&p, "seed = 5\n").unwrap();
    let o = build_with(&town, &b, &["--quiet", "--shard", "2/2", "--force"], &p);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let o = edo_city().arg("merge").arg(&a).arg(&b).output().unwrap();
    let e = stderr_of(&o);
    assert!(e.contains("the parameter `seed` differs"), "{e}");
    // Shards of one seed in two formats (OBJ here, GLB there) are two builds too.
    let none = dir.path().join("none.toml");
    std::fs::write(&none, "").unwrap();
    let o = build_with(
        &town,
        &b,
        &["--quiet", "--shard", "2/2", "--force", "--format", "glb"],
        &none,
    );
    assert!(o.status.success(), "{}", stderr_of(&o));
    let o = build_with(
        &town,
        &a,
        &["--quiet", "--shard", "1/2", "--force", "--format", "obj"],
        &none,
    );
    assert!(o.status.success(), "{}", stderr_of(&o));
    let o = edo_city().arg("merge").arg(&a).arg(&b).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let e = stderr_of(&o);
    assert!(e.contains("`output.formats` differs"), "{e}");
}

#[test]
fn tiles_with_force_never_stamps_new_parameters_on_old_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let before = all_files(&out);
    let p = dir.path().join("p.toml");
    std::fs::write(&p, "seed = 5\n").unwrap();
    let m = read_json(&out.join("manifest.json"));
    let tile = m["tiles"][0]["id"].as_str().unwrap().to_string();
    let o = build_with(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--force", "--tiles", &tile],
        &p,
    );
    assert_eq!(o.status.code(), Some(2));
    let e = stderr_of(&o);
    assert!(e.contains("even with --force") && e.contains("seed"), "{e}");
    assert_eq!(all_files(&out), before, "the build is as it was");
}

/// What a `--force` rebuild with other parameters, killed half way, leaves: the earlier
/// manifest, some tiles of the new parameters, and the mark a build keeps while it writes.
fn half_written(out: &Path, other: &Path, tile: &str) {
    std::fs::write(out.join(".edo-city.writing"), b"").unwrap();
    let name = format!("tiles/{tile}.obj");
    std::fs::copy(other.join(&name), out.join(&name)).unwrap();
}

#[test]
fn tiles_over_a_directory_a_killed_run_left_half_written_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let other = dir.path().join("other");
    let p = dir.path().join("p.toml");
    std::fs::write(&p, "seed = 5\n").unwrap();
    let none = dir.path().join("none.toml");
    std::fs::write(&none, "").unwrap();
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let o = build_with(&fixture("kyoto-small"), &other, &["--quiet"], &p);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let ids: Vec<String> = read_json(&out.join("manifest.json"))["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect();
    assert!(ids.len() >= 2, "two tiles at least: {ids:?}");
    let (left, asked) = (&ids[0], &ids[1]);
    let whole = all_files(&out);
    let differs = whole[&format!("tiles/{left}.obj")]
        != std::fs::read(other.join(format!("tiles/{left}.obj"))).unwrap();
    assert!(differs, "seed 5 builds another {left}");

    // A tile of seed 5 under a manifest of seed 1: refused, naming the file, nothing written.
    half_written(&out, &other, left);
    let before = all_files(&out);
    let o = build_with(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--tiles", asked],
        &none,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr_of(&o));
    let e = stderr_of(&o);
    assert!(
        e.contains("half-written") && e.contains(&format!("tiles/{left}.obj")),
        "{e}"
    );
    assert!(e.contains("without --tiles"), "says what to do: {e}");
    assert_eq!(all_files(&out), before, "nothing written");

    // The whole city built again: the mark is gone and the build is the first one.
    let o = build_with(&fixture("kyoto-small"), &out, &["--quiet"], &none);
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(!out.join(".edo-city.writing").exists());
    assert_eq!(all_files(&out), whole);

    // A run killed before it changed anything: every file agrees, so --tiles goes on.
    std::fs::write(out.join(".edo-city.writing"), b"").unwrap();
    let o = build_with(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--tiles", asked],
        &none,
    );
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(!out.join(".edo-city.writing").exists());
    assert_eq!(all_files(&out), whole);
}

#[test]
fn tiles_into_another_hypothesis_are_refused_before_the_input_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    common::copy_fixture("kyoto-small", &town);
    let out = dir.path().join("out");
    build_ok(&town, &out, &["--quiet"]);
    let m = read_json(&out.join("manifest.json"));
    let tile = m["tiles"][0]["id"].as_str().unwrap().to_string();
    // Lots that no longer read: a run that read them would name them; the refusal comes
    // first (at a million lots a minute of reading and analysis earlier).
    std::fs::write(town.join("lots.shp"), b"not a shapefile").unwrap();
    let p = dir.path().join("p.toml");
    std::fs::write(&p, "seed = 5\n").unwrap();
    let o = build_with(&town, &out, &["--quiet", "--tiles", &tile], &p);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr_of(&o);
    assert!(
        e.contains("--tiles only rewrites") && e.contains("seed"),
        "{e}"
    );
}

#[test]
fn an_empty_tile_id_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let o = edo_city()
        .arg("build")
        .arg(fixture("kyoto-small"))
        .arg("--out")
        .arg(&out)
        .args(["--quiet", "--tiles", "1108_760,,1109_760"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr_of(&o).contains("a tile id is empty"),
        "{}",
        stderr_of(&o)
    );
}

#[test]
fn a_build_that_reads_no_lots_leaves_the_earlier_build_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet"]);
    let before = all_files(&out);
    let p = dir.path().join("none.toml");
    std::fs::write(&p, "[layers.lots]\nfile = \"\"\n").unwrap();
    let o = edo_city()
        .arg("build")
        .arg(fixture("kyoto-small"))
        .arg("--out")
        .arg(&out)
        .args(["--quiet", "--force", "--params"])
        .arg(&p)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr_of(&o).contains("it was left as it was"),
        "{}",
        stderr_of(&o)
    );
    assert_eq!(all_files(&out), before);
}

#[test]
fn plan_and_compare_of_a_directory_without_a_build_say_so() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        vec!["plan".to_string(), dir.path().display().to_string()],
        vec![
            "compare".to_string(),
            dir.path().display().to_string(),
            dir.path().display().to_string(),
        ],
    ] {
        let o = edo_city().args(&args).output().unwrap();
        assert_eq!(o.status.code(), Some(2));
        let e = stderr_of(&o);
        assert!(
            e.contains("holds no finished build") && !e.contains("--tiles"),
            "{e}"
        );
    }
}

#[test]
fn compare_plan_of_builds_on_other_grids_refuses_instead_of_a_huge_image() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    build_ok(&fixture("kyoto-small"), &a, &["--quiet", "--no-plan"]);
    let p = dir.path().join("p.toml");
    // Any other size is another grid (1 m tiles, once used here, took 2 of CI's minutes to
    // build; the refusal comes before any image whatever the sizes).
    std::fs::write(&p, "tile_size = 100.0\n").unwrap();
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "--no-plan", "--params", p.to_str().unwrap()],
    );
    let png = dir.path().join("diff.png");
    let o = edo_city()
        .arg("compare")
        .arg(&a)
        .arg(&b)
        .arg("--plan")
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr_of(&o).contains("other tile sizes"),
        "{}",
        stderr_of(&o)
    );
    assert!(!png.exists());
}

#[test]
fn synth_never_writes_over_a_users_directory() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("mine");
    std::fs::create_dir_all(&data).unwrap();
    std::fs::write(data.join("lots.csv"), "id,mtype\n1,sangai\n").unwrap();
    let o = edo_city()
        .arg("synth")
        .arg(&data)
        .args(["--lots", "20"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr_of(&o).contains("is not empty"), "{}", stderr_of(&o));
    assert_eq!(all_files(&data).len(), 1, "nothing written");
    edo_city()
        .arg("synth")
        .arg(&data)
        .args(["--lots", "20", "--force"])
        .assert()
        .success();
    assert!(data.join("lots.shp").exists());
    for lots in ["0", "10000001"] {
        let o = edo_city()
            .arg("synth")
            .arg(dir.path().join(format!("t{lots}")))
            .args(["--lots", lots])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2));
        assert!(
            stderr_of(&o).contains("--lots must be from 1 to"),
            "{}",
            stderr_of(&o)
        );
    }
}

#[cfg(unix)]
#[test]
fn init_follows_no_link_and_its_printed_command_builds() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    common::copy_fixture("kyoto-small", &data);
    let sub = data.join("sub");
    std::fs::create_dir_all(&sub).unwrap();
    std::os::unix::fs::symlink("..", sub.join("up")).unwrap();
    std::os::unix::fs::symlink("/", data.join("root")).unwrap();
    let params = dir.path().join("guess.toml");
    let o = edo_city()
        .arg("init")
        .arg(&data)
        .arg("-o")
        .arg(&params)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(text.contains("lots.shp"), "{text}");
    assert!(!text.contains("up/"), "the loop was not walked: {text}");
    let said = String::from_utf8_lossy(&o.stdout).into_owned() + &stderr_of(&o);
    let line = said
        .lines()
        .find(|l| l.trim_start().starts_with("edo-city build"))
        .unwrap_or_else(|| panic!("no command printed: {said}"));
    // The printed command, run as printed (from the directory the user was in).
    let words: Vec<&str> = line.split_whitespace().skip(1).collect();
    let out = dir.path().join("out");
    let o = edo_city()
        .current_dir(dir.path())
        .args(&words)
        .output()
        .unwrap();
    assert!(o.status.success(), "`{line}`: {}", stderr_of(&o));
    assert!(out.join("plan.png").exists(), "`{line}` builds into out/");
}

/// A `--force` rebuild over an earlier build leaves the directory a build into an empty one
/// makes, byte for byte: no temporary, and none of the earlier build's files it has no more.
#[test]
fn a_rebuild_over_an_earlier_build_leaves_what_a_fresh_build_does() {
    let dir = tempfile::tempdir().unwrap();
    let (over, fresh) = (dir.path().join("over"), dir.path().join("fresh"));
    let p = dir.path().join("seed.toml");
    std::fs::write(&p, "seed = 2\n").unwrap();
    build_ok(&fixture("kyoto-small"), &over, &["--quiet"]);
    let o = build_with(&fixture("kyoto-small"), &over, &["--quiet", "--force"], &p);
    assert!(o.status.success(), "{}", stderr_of(&o));
    let o = build_with(&fixture("kyoto-small"), &fresh, &["--quiet"], &p);
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(
        all_files(&over).keys().all(|f| !f.contains(".tmp-")),
        "no temporary left"
    );
    common::assert_same_tree(&over, &fresh);
}
