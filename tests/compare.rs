//! Two hypotheses of the same town, compared.

mod common;

use std::path::Path;

use common::*;

fn hypothesis(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("params/hypotheses")
        .join(format!("{name}.toml"))
        .display()
        .to_string()
}

#[test]
fn merchant_and_craftsman_towns_differ_where_their_parameters_do() {
    let work = tempfile::tempdir().unwrap();
    let (a, b) = (work.path().join("merchant"), work.path().join("craftsman"));
    build_ok(
        &fixture("kyoto-small"),
        &a,
        &["--quiet", "--params", &hypothesis("merchant-town")],
    );
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "--params", &hypothesis("craftsman-town")],
    );
    // The resolved parameters, not the `extends` line, are in the manifest.
    assert_eq!(
        read_json(&a.join("manifest.json"))["params"]["machiya"]["depth"],
        15.0
    );

    let out = edo_city()
        .args(["compare", "--json", "--plan"])
        .arg(work.path().join("diff.png"))
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let keys: Vec<&str> = c["params"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["key"].as_str().unwrap())
        .collect();
    assert!(
        keys.contains(&"machiya.depth") && keys.contains(&"type_mix.hiraya"),
        "{keys:?}"
    );
    assert!(!keys.contains(&"seed"));
    let row = |table: &str, name: &str| {
        c[table]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == name)
            .map(|r| (r["a"].as_u64().unwrap(), r["b"].as_u64().unwrap()))
            .unwrap()
    };
    let (hiraya_a, hiraya_b) = row("by_type", "hiraya");
    assert!(
        hiraya_b > 2 * hiraya_a,
        "craftsmen build more one-storey houses: {hiraya_a} vs {hiraya_b}"
    );
    assert_eq!(row("totals", "machiya"), (398, 398));
    // Types given in the data are the same in both; only drawn ones move.
    let (given_a, given_b) = row("totals", "type from data");
    assert_eq!(given_a, given_b);
    assert_eq!(c["tiles"]["differ"].as_array().unwrap().len(), 4);
    assert_eq!(c["tiles"]["same"], 0);
    let map = image::open(work.path().join("diff.png")).unwrap();
    assert!(map.width() >= 2 * 8 && map.height() > 40);

    // The same build against itself: nothing differs.
    let same = edo_city()
        .args(["compare"])
        .arg(&a)
        .arg(&a)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&same.stdout);
    assert!(
        text.contains("parameters: the same") && text.contains("4 identical, 0 differ"),
        "{text}"
    );
}

#[test]
fn kura_with_and_without_avoidance_compare_as_the_papers_table_2() {
    let work = tempfile::tempdir().unwrap();
    let (a, b) = (work.path().join("with"), work.path().join("without"));
    let off = work.path().join("off.toml");
    std::fs::write(&off, "[kura]\ncollision = false\n").unwrap();
    build_ok(&fixture("kyoto-small"), &a, &["--quiet", "--no-plan"]);
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "--no-plan", "--params", off.to_str().unwrap()],
    );
    let out = edo_city().arg("compare").arg(&a).arg(&b).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("kura.collision"), "{text}");
    assert!(text.contains("kura (Table 2)"), "{text}");
    let out = edo_city()
        .args(["compare", "--json"])
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let row = |table: &str, name: &str| {
        let r = c[table]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["name"] == name)
            .unwrap_or_else(|| panic!("{table}/{name}"))
            .clone();
        (r["a"].as_u64().unwrap(), r["b"].as_u64().unwrap())
    };
    let (with_a, with_b) = row("table2", "with avoidance");
    let (without_a, without_b) = row("table2", "without avoidance");
    assert_eq!(
        (with_a, without_a),
        (with_b, without_b),
        "the table is the same"
    );
    let (kura_a, kura_b) = row("totals", "kura");
    assert_eq!(kura_a, with_a, "A built the avoided set");
    assert_eq!(kura_b, without_b, "B built every kura that fits");
    assert!(kura_b > kura_a, "the fixture has colliding plots");
}
