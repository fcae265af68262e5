//! `edo-city garden`: the report's keys and numbers, the same bytes for the same seed, an
//! OBJ every client reads, and an interactive run driven by a script breeding from its picks.

mod common;

use common::{edo_city, read_json};

fn garden(dir: &std::path::Path, name: &str, extra: &[&str]) -> serde_json::Value {
    let obj = dir.join(format!("{name}.obj"));
    let rep = dir.join(format!("{name}.json"));
    let out = edo_city()
        .args([
            "garden",
            "--population",
            "30",
            "-o",
            obj.to_str().unwrap(),
            "--report",
            rep.to_str().unwrap(),
        ])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    read_json(&rep)
}

#[test]
fn a_garden_reports_its_rules_stones_and_history() {
    let dir = tempfile::tempdir().unwrap();
    let r = garden(
        dir.path(),
        "g",
        &[
            "--seed",
            "3",
            "--generations",
            "15",
            "--width",
            "25",
            "--depth",
            "10",
        ],
    );
    let w = &r["weights"];
    for (name, v) in [
        ("centre", 1.54),
        ("triangles", 1.32),
        ("opposition", 0.53),
        ("adjacency", 2.0),
        ("axis", 1.22),
    ] {
        assert_eq!(w[name], v, "{name}");
        assert!(r["rule_scores"][name].as_f64().unwrap() >= 0.0);
    }
    let history: Vec<f64> = r["fitness_history"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(history.len(), 16);
    assert!(history.windows(2).all(|p| p[1] >= p[0]), "{history:?}");
    let stones = r["stones"].as_array().unwrap();
    assert_eq!(stones.len(), 15);
    for st in stones {
        let (x, y, size) = (
            st["x"].as_f64().unwrap(),
            st["y"].as_f64().unwrap(),
            st["size"].as_f64().unwrap(),
        );
        assert!(
            x - size / 2.0 >= -1e-9 && x + size / 2.0 <= 25.0 + 1e-9,
            "{st}"
        );
        assert!(
            y - size / 2.0 >= -1e-9 && y + size / 2.0 <= 10.0 + 1e-9,
            "{st}"
        );
        assert!(["shin", "soe", "tai", "other"].contains(&st["role"].as_str().unwrap()));
    }
    assert!(r["zipf"]["slope"].as_f64().unwrap() < 0.0);
    assert!(
        r["viewpoint"]["y"].as_f64().unwrap() < 0.0,
        "the veranda is outside the garden"
    );
    // The OBJ loads with its textures; every stone is an object of its own.
    let (models, materials) = tobj::load_obj(
        dir.path().join("g.obj"),
        &tobj::LoadOptions {
            triangulate: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(
        models
            .iter()
            .filter(|m| m.name.starts_with("stone_garden_"))
            .count(),
        15
    );
    assert!(materials.unwrap().iter().any(|m| m.name == "gravel_raked"));
}

#[test]
fn the_same_seed_gives_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    garden(&a, "g", &["--seed", "5", "--generations", "5"]);
    garden(&b, "g", &["--seed", "5", "--generations", "5"]);
    assert!(std::fs::read(a.join("g.obj")).unwrap() == std::fs::read(b.join("g.obj")).unwrap());
    assert_eq!(
        std::fs::read(a.join("g.json")).unwrap(),
        std::fs::read(b.join("g.json")).unwrap()
    );
}

#[test]
fn an_interactive_run_breeds_from_the_picked_candidates() {
    let dir = tempfile::tempdir().unwrap();
    let sheet = dir.path().join("sheet.png");
    let rep = dir.path().join("i.json");
    let run = |picks: &str| {
        let out = edo_city()
            .args([
                "garden",
                "--interactive",
                "--seed",
                "2",
                "--generations",
                "3",
                "--population",
                "20",
            ])
            .args([
                "--sheet",
                sheet.to_str().unwrap(),
                "--report",
                rep.to_str().unwrap(),
            ])
            .write_stdin(picks)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        (String::from_utf8(out.stderr).unwrap(), read_json(&rep))
    };
    // Always picking the worst shown candidate, against letting the GA choose.
    let (asked, picked) = run("8\n8\n8\n");
    assert_eq!(asked.matches("pick favourites").count(), 3, "{asked}");
    assert!(asked.contains("generation 1: candidates drawn in"));
    assert!(sheet.exists());
    let (_, unattended) = run("\n\n\n");
    assert_ne!(
        picked["stones"], unattended["stones"],
        "the picks changed the breeding"
    );
    // A bad pick is named and ignored; the end of input lets the rest run unattended.
    let (asked, _) = run("99 x\n");
    assert!(
        asked.contains("`99` is not a candidate") && asked.contains("`x` is not a candidate"),
        "{asked}"
    );
}

#[test]
fn temples_get_gardens_clear_of_buildings_with_trees_and_people_kept_out() {
    use edo_city::analyse::obstacles::Obstacles;
    use geo::Contains;
    let dir = tempfile::tempdir().unwrap();
    common::synth(dir.path(), 3000, 4);
    let params = edo_city::params::Params::default();
    let data = edo_city::input::read_dataset(dir.path(), &params).expect("reads");
    let catalog = edo_city::templates::Catalog::load(None).unwrap();
    let plan = edo_city::analyse::analyse(&data, &params, &catalog, "lots.shp", &|_| {});
    let temples = data
        .lots
        .iter()
        .filter(|l| l.lot_use.name() == "jisha")
        .count();
    assert!(temples > 0);
    assert_eq!(
        plan.garden_reports.len(),
        temples,
        "one entry per temple lot"
    );
    let obstacles = Obstacles::new(
        plan.houses.values().flatten(),
        plan.fences.values().flatten(),
        &catalog,
        &params,
    );
    let gardens: Vec<_> = plan.gardens.values().flatten().collect();
    assert!(!gardens.is_empty());
    for g in &gardens {
        let lot = data.lots.iter().find(|l| l.id == g.lot).unwrap();
        let ring = g.outline();
        for (k, q) in ring.iter().enumerate() {
            let r = ring[(k + 1) % 4];
            for t in [0.0, 0.25, 0.5, 0.75] {
                let p = geo_types::Coord {
                    x: q.x + (r.x - q.x) * t,
                    y: q.y + (r.y - q.y) * t,
                };
                assert!(
                    lot.outline.contains(&geo::Point(p)),
                    "{}: the garden leaves its lot",
                    g.lot
                );
                assert!(
                    !obstacles.hit(p, params.garden.clearance - 1e-6),
                    "{}: the garden meets a building or wall",
                    g.lot
                );
            }
        }
        assert!(g.size[0].min(g.size[1]) >= params.garden.min_size);
        assert_eq!(g.stones.len(), 15);
        let mut poly: Vec<geo_types::Coord<f64>> = ring.clone();
        poly.push(ring[0]);
        let outline = geo_types::Polygon::new(poly.into(), vec![]);
        for b in plan.billboards.values().flatten() {
            assert!(
                !outline.contains(&geo::Point(b.at)),
                "{} stands in the garden of {}",
                b.id,
                g.lot
            );
        }
    }
    for r in &plan.garden_reports {
        assert!(r.placed || !r.reason.is_empty(), "{r:?}");
    }
}
