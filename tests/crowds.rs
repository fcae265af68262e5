//! Street crowds (`people.motion = "boids"`): the people walk as a crowd through the street
//! network (tests/crowd_clip.rs tests the clip); at time 0 they stand on the street, apart
//! and out of buildings, keep the density of section 4.4 on average, and the report gives
//! each street's and district's order parameters. Tiles and clips are byte-identical for any
//! thread count and for `--tiles`.

mod common;

use std::path::Path;

use common::{all_files, build_ok, fixture, read_json, synth};
use edo_city::geom::segment::segment_distance_2;
use edo_city::model::{BillboardKind, PlannedBillboard};
use edo_city::params::Params;

fn boids_params(dir: &Path) -> String {
    let p = dir.join("boids.toml");
    std::fs::write(&p, "[people]\nmotion = \"boids\"\nper_100m = 12.0\n").unwrap();
    p.display().to_string()
}

fn people(dir: &Path, params: &Params) -> (edo_city::model::Dataset, Vec<PlannedBillboard>) {
    let data = edo_city::input::read_dataset(dir, params).expect("reads");
    let catalog = edo_city::templates::Catalog::load(None).unwrap();
    let plan = edo_city::analyse::analyse(&data, params, &catalog, "lots.shp", &|_| {});
    let people = plan
        .billboards
        .values()
        .flatten()
        .filter(|b| b.kind == BillboardKind::Person)
        .cloned()
        .collect();
    (data, people)
}

#[test]
fn walkers_stay_on_their_street_apart_and_out_of_the_lots_at_the_same_density() {
    let dir = tempfile::tempdir().unwrap();
    synth(dir.path(), 1500, 5);
    let text = std::fs::read_to_string(boids_params(dir.path())).unwrap();
    let walk = Params::from_toml_str(&text, "boids.toml").unwrap();
    let scatter = Params::from_toml_str("[people]\nper_100m = 12.0\n", "scatter.toml").unwrap();
    let (data, walkers) = people(dir.path(), &walk);
    let (_, scattered) = people(dir.path(), &scatter);
    assert!(walkers.len() > 200, "{} walkers", walkers.len());
    let ratio = walkers.len() as f64 / scattered.len() as f64;
    assert!(
        (0.85..=1.1).contains(&ratio),
        "{} walkers, {} scattered",
        walkers.len(),
        scattered.len()
    );
    // They moved: most are not where the process put them.
    let moved = walkers
        .iter()
        .filter(|w| {
            scattered
                .iter()
                .find(|s| s.id == w.id)
                .is_none_or(|s| s.at != w.at)
        })
        .count();
    assert!(
        moved * 2 > walkers.len(),
        "{moved} of {} moved",
        walkers.len()
    );
    let margin = walk.people.edge_margin;
    for w in &walkers {
        let dist = data
            .streets
            .iter()
            .flat_map(|s| s.line.lines().map(move |l| (s, l)))
            .map(|(s, l)| {
                segment_distance_2(w.at.into(), l.start.into(), l.end.into()).sqrt() - s.width / 2.0
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            dist <= -margin + 1e-6,
            "{} is {dist} m past the street's edge",
            w.id
        );
        assert!(
            !data
                .lots
                .iter()
                .any(|l| geo::Contains::contains(&l.outline, &w.at)),
            "{} stands in a lot",
            w.id
        );
        assert!(w.facing.is_finite());
    }
    for (i, a) in walkers.iter().enumerate() {
        for b in &walkers[i + 1..] {
            let d = (a.at.x - b.at.x).hypot(a.at.y - b.at.y);
            assert!(
                d >= walk.people.min_spacing - 1e-9,
                "{} and {} {d} m apart",
                a.id,
                b.id
            );
        }
    }
}

#[test]
fn the_report_gives_each_street_and_district_its_order_parameters() {
    let out = tempfile::tempdir().unwrap();
    let params = boids_params(out.path());
    let r = build_ok(
        &fixture("kyoto-small"),
        &out.path().join("out"),
        &["--quiet", "--no-plan", "--params", &params],
    );
    let c = &r["crowds"];
    let streets = c["streets"].as_array().unwrap();
    assert!(!streets.is_empty());
    for s in streets {
        for k in ["lambda1", "lambda2", "lambda3"] {
            let v = s[k].as_f64().unwrap();
            assert!((-1.0..=1.0).contains(&v), "{s}");
            assert!(s["mean"][k].as_f64().unwrap().is_finite(), "{s}");
        }
        assert!(s["agents"].as_u64().unwrap() > 0);
        assert!(s["street"].as_str().unwrap().contains('/'));
    }
    let districts = c["by_district"].as_object().unwrap();
    let agents: u64 = streets.iter().map(|s| s["agents"].as_u64().unwrap()).sum();
    assert_eq!(
        districts
            .values()
            .map(|d| d["agents"].as_u64().unwrap())
            .sum::<u64>(),
        agents
    );
    // A scatter build has no crowds key at all.
    let plain = build_ok(
        &fixture("kyoto-small"),
        &out.path().join("plain"),
        &["--quiet", "--no-plan"],
    );
    assert!(plain.get("crowds").is_none());
}

#[test]
fn crowds_are_byte_identical_for_any_thread_count_and_for_single_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let params = boids_params(dir.path());
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    build_ok(
        &fixture("kyoto-small"),
        &a,
        &["--quiet", "-j", "1", "--params", &params],
    );
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "-j", "2", "--params", &params],
    );
    let tiles = |d: &Path| {
        all_files(d)
            .into_iter()
            .filter(|(k, _)| k.starts_with("tiles/") || k.starts_with("crowds/"))
            .collect::<Vec<_>>()
    };
    assert_eq!(tiles(&a), tiles(&b));
    assert!(
        tiles(&a).iter().any(|(k, _)| k.starts_with("crowds/")),
        "the walkers' clips are compared too"
    );
    let m = read_json(&a.join("manifest.json"));
    let id = m["tiles"][0]["id"].as_str().unwrap().to_string();
    let before = tiles(&a);
    std::fs::remove_file(a.join(format!("tiles/{id}.obj"))).unwrap();
    build_ok(
        &fixture("kyoto-small"),
        &a,
        &["--quiet", "--tiles", &id, "--params", &params],
    );
    assert_eq!(tiles(&a), before, "the tile regenerated alone is the same");
}

#[test]
fn a_district_that_scatters_keeps_its_people_where_the_process_put_them() {
    let dir = tempfile::tempdir().unwrap();
    synth(dir.path(), 1500, 5);
    let text = "[people]\nmotion = \"boids\"\nper_100m = 12.0\n[district.\"中京\"]\npeople_motion = \"scatter\"\n";
    let mixed = Params::from_toml_str(text, "mixed.toml").unwrap();
    let scatter = Params::from_toml_str("[people]\nper_100m = 12.0\n", "scatter.toml").unwrap();
    let (_, walkers) = people(dir.path(), &mixed);
    let (_, scattered) = people(dir.path(), &scatter);
    let still = |w: &PlannedBillboard| scattered.iter().any(|s| s.id == w.id && s.at == w.at);
    let central: Vec<_> = walkers
        .iter()
        .filter(|w| w.district.as_deref() == Some("中京"))
        .collect();
    let others: Vec<_> = walkers
        .iter()
        .filter(|w| w.district.as_deref() != Some("中京"))
        .collect();
    assert!(!central.is_empty() && !others.is_empty());
    assert!(central.iter().all(|w| still(w)), "中京 scatters");
    assert!(
        others.iter().filter(|w| still(w)).count() * 2 < others.len(),
        "the rest walk"
    );
    // A misspelt motion is refused naming the key.
    let e = Params::from_toml_str("[district.x]\npeople_motion = \"flock\"\n", "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("district.x.people_motion"), "{e}");
}

#[test]
fn compare_shows_the_crowds_of_two_hypotheses_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let busy = dir.path().join("busy.toml");
    std::fs::write(&busy, "[people]\nmotion = \"boids\"\nper_100m = 20.0\n").unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    build_ok(
        &fixture("kyoto-small"),
        &a,
        &[
            "--quiet",
            "--no-plan",
            "--params",
            &boids_params(dir.path()),
        ],
    );
    build_ok(
        &fixture("kyoto-small"),
        &b,
        &["--quiet", "--no-plan", "--params", busy.to_str().unwrap()],
    );
    let o = common::edo_city()
        .arg("compare")
        .arg(&a)
        .arg(&b)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success());
    let c: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = c["crowds"].as_array().unwrap();
    assert!(!rows.is_empty());
    let walkers = |k: usize| {
        rows.iter()
            .map(|r| r["agents"][k].as_u64().unwrap())
            .sum::<u64>()
    };
    assert!(
        walkers(1) > walkers(0),
        "20 per 100 m walk more than 12: {rows:?}"
    );
    let text = common::edo_city()
        .arg("compare")
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&text.stdout).contains("crowds (mean over the clip)"));
}
