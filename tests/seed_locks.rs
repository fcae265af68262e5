//! `[seeds]` (issue 61's seed lock): a section with a seed of its own keeps its draw when
//! `seed` changes, and only that section's: compared lot by lot as `compare --gpkg` does.

mod common;

use common::*;
use edo_city::output::gpkg::{lot_differences, plan_lots};

fn build_with(dir: &std::path::Path, name: &str, params: &str) -> std::path::PathBuf {
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, params).unwrap();
    let out = dir.join(name);
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--params", p.to_str().unwrap()],
    );
    out
}

#[test]
fn a_section_with_its_own_seed_keeps_its_draw_when_the_seed_changes() {
    let dir = tempfile::tempdir().unwrap();
    let a = build_with(
        dir.path(),
        "a",
        "seed = 1\n[trees]\nper_ha_machiya = 200.0\n",
    );
    let redrawn = build_with(
        dir.path(),
        "b",
        "seed = 2\n[trees]\nper_ha_machiya = 200.0\n",
    );
    let kept = build_with(
        dir.path(),
        "c",
        "seed = 2\n[seeds]\nmachiya = 1\ntrees = 1\n[trees]\nper_ha_machiya = 200.0\n",
    );
    let trees_only = build_with(
        dir.path(),
        "d",
        "seed = 2\n[seeds]\ntrees = 1\n[trees]\nper_ha_machiya = 200.0\n",
    );
    let lots = |d: &std::path::Path| plan_lots(d).unwrap();
    let (la, lb, lc, ld) = (lots(&a), lots(&redrawn), lots(&kept), lots(&trees_only));
    let aspects = |x, y| -> Vec<String> {
        lot_differences(x, y)
            .into_iter()
            .map(|d| d.differs)
            .collect()
    };
    let redraw = aspects(&la, &lb);
    assert!(redraw.iter().any(|d| d.contains("type")), "{redraw:?}");
    assert!(plan_trees(&a).len() > 100);
    assert_ne!(
        plan_trees(&a),
        plan_trees(&redrawn),
        "a new seed draws the trees again"
    );
    assert!(aspects(&la, &lc).is_empty(), "the types kept");
    assert_eq!(plan_trees(&a), plan_trees(&kept), "the trees kept");
    let d = aspects(&la, &ld);
    assert!(
        d.iter().any(|d| d.contains("type")),
        "the types drawn again: {d:?}"
    );
    assert_eq!(plan_trees(&a), plan_trees(&trees_only), "the trees kept");
    // An unknown section is refused naming the key.
    let p = dir.path().join("bad.toml");
    std::fs::write(&p, "[seeds]\nroofs = 3\n").unwrap();
    let o = edo_city()
        .args(["build", "--quiet", "--params"])
        .arg(&p)
        .arg(fixture("kyoto-small"))
        .arg("--out")
        .arg(dir.path().join("bad"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("`seeds.roofs`"), "{err}");
}
