//! `edo-city synth --profile kyoto`: the town the benchmarks build has what real towns hold,
//! and the build makes all of it (walled estates with a gate and an omoya each, kura behind
//! about half the houses, repeated ids listed as skipped).

mod common;

use common::edo_city;

#[test]
fn the_kyoto_profile_builds_walled_estates_with_halls_kura_and_lists_repeated_ids() {
    let work = tempfile::tempdir().unwrap();
    let town = work.path().join("town");
    let said = edo_city()
        .args([
            "synth",
            "--lots",
            "2400",
            "--seed",
            "3",
            "--profile",
            "kyoto",
        ])
        .arg(&town)
        .output()
        .unwrap();
    assert!(said.status.success(), "{}", common::succeeded(&said));
    let said = String::from_utf8_lossy(&said.stdout).into_owned();
    let number_before = |what: &str| -> usize {
        let at = said
            .find(what)
            .unwrap_or_else(|| panic!("{what:?} in {said}"));
        let digits: String = said[..at]
            .trim_end()
            .chars()
            .rev()
            .take_while(|c| c.is_ascii_digit())
            .collect();
        digits.chars().rev().collect::<String>().parse().unwrap()
    };
    let estates = number_before("samurai estates");
    let repeated = number_before("records repeat the id");
    assert!(estates > 0 && repeated > 0, "{said}");

    let out = work.path().join("out");
    let built = common::build_cmd(&town, &out, &["--format", "obj", "--no-plan", "--timings"])
        .output()
        .unwrap();
    assert!(built.status.success(), "{}", common::succeeded(&built));
    // --timings gives each stage's wall time and how busy the cores were.
    let told = String::from_utf8_lossy(&built.stderr);
    let stages = (told.lines())
        .find_map(|l| l.strip_prefix("timings of the stages: "))
        .unwrap_or_else(|| panic!("no stage line in {told}"));
    for stage in ["read and analyse", "tiles", "whole-city files and report"] {
        let at = stages
            .find(&format!("{stage} "))
            .unwrap_or_else(|| panic!("{stages}"));
        let busy: f64 = stages[at..].split("cpu/wall ").nth(1).unwrap()[..4]
            .parse()
            .unwrap();
        assert!(busy > 0.0 && busy < 64.0, "{stages}");
    }
    let report = common::read_json(&out.join("report.json"));
    let counts = &report["counts"];
    // Every repeated id is listed, and nothing else is skipped.
    assert_eq!(counts["skipped"], repeated as u64, "{}", report["skipped"]);
    assert!(report["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .all(|s| s["reason"].as_str().unwrap().starts_with("duplicate id")));
    // Each estate built is walled on its four edges, one split by its gate, and holds its
    // omoya.
    let buke = counts["lots_by_use"]["buke"].as_u64().unwrap();
    let temples = counts["lots_by_use"]["jisha"].as_u64().unwrap_or(0);
    assert!(buke > 0 && buke <= estates as u64);
    assert_eq!(counts["gates"], buke + temples);
    assert_eq!(counts["fence_segments"], 5 * (buke + temples));
    let omoya = (report["halls"].as_array().unwrap().iter())
        .filter(|h| h["template"] == "omoya" && h["placed"] == true)
        .count() as u64;
    assert_eq!(omoya, buke);
    // A kura behind about half the houses, after collision avoidance.
    let (kura, machiya) = (
        counts["kura"].as_u64().unwrap() as f64,
        counts["machiya"].as_u64().unwrap() as f64,
    );
    assert!(
        (0.45..0.75).contains(&(kura / machiya)),
        "{kura} of {machiya}"
    );
}

#[test]
fn an_unknown_profile_is_refused_with_the_ones_there_are() {
    let work = tempfile::tempdir().unwrap();
    let o = edo_city()
        .args(["synth", "--profile", "edo"])
        .arg(work.path().join("t"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("grid") && err.contains("kyoto"), "{err}");
    assert!(!work.path().join("t").exists());
}
