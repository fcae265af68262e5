//! Grown trees (seeds 003 and 001): `edo-city lsystem` gives the seed's examples,
//! `edo-city tree` grows and meshes each species with its numbers, and in the city
//! (`trees.style`) every tree stands inside its lot with its crown clear of buildings, a
//! tile's grown trees stay within `trees.max_tile_bytes`, and the build is byte-identical
//! for any thread count and for `--tiles`.

mod common;

use std::path::Path;

use common::{all_files, build_ok, edo_city, load_tile, read_json, synth};
use edo_city::analyse::obstacles::{boundary_distance, Obstacles};
use edo_city::model::BillboardKind;
use edo_city::params::Params;

fn stdout_of(args: &[&str]) -> String {
    let out = edo_city().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn stderr_of_failure(args: &[&str]) -> String {
    let out = edo_city().args(args).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{args:?} should fail");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn lsystem_prints_the_seeds_strings() {
    for (n, len) in [(1, 31), (2, 112), (3, 355)] {
        let s = stdout_of(&[
            "lsystem",
            "--preset",
            "fffa",
            "--generations",
            &n.to_string(),
            "--string",
        ]);
        assert_eq!(s.trim_end().chars().count(), len, "n = {n}");
    }
    let s = stdout_of(&[
        "lsystem",
        "--axiom",
        "A",
        "--rule",
        "A=F+FA",
        "--angle",
        "20",
        "--generations",
        "2",
        "--string",
    ]);
    assert_eq!(s.trim_end(), "F+FF+FA");
    let s = stdout_of(&["lsystem", "--preset", "koch", "--generations", "3"]);
    assert!(s.contains("64 segments"), "{s}");
}

#[test]
fn lsystem_writes_a_mesh_and_a_figure() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("fffa.obj");
    let svg = dir.path().join("koch.svg");
    stdout_of(&["lsystem", "--preset", "fffa", "-o", obj.to_str().unwrap()]);
    let (models, _) = tobj::load_obj(
        &obj,
        &tobj::LoadOptions {
            triangulate: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(models[0].mesh.indices.len() / 3 > 100);
    assert!(dir.path().join("textures/bark.png").exists());
    stdout_of(&[
        "lsystem",
        "--preset",
        "koch",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(text.matches("<line").count(), 256);
}

#[test]
fn lsystem_errors_name_the_rule_the_column_and_the_limit() {
    let e = stderr_of_failure(&[
        "lsystem",
        "--axiom",
        "A",
        "--rule",
        "A=F[+A",
        "--generations",
        "2",
    ]);
    assert!(
        e.contains("rule 1") && e.contains("column 4") && e.contains("never closed"),
        "{e}"
    );
    let e = stderr_of_failure(&[
        "lsystem",
        "--preset",
        "fffa",
        "--generations",
        "12",
        "--max-symbols",
        "10000",
    ]);
    assert!(
        e.contains("max_symbols = 10000") && e.contains("fewer generations"),
        "{e}"
    );
    let e = stderr_of_failure(&["lsystem", "--axiom", "A(1)", "--rule", "A(l)=F(l*k)"]);
    assert!(e.contains("unknown parameter `k`"), "{e}");
}

fn species_names() -> Vec<String> {
    stdout_of(&["tree"])
        .lines()
        .map(|l| l.split_whitespace().next().unwrap().to_string())
        .collect()
}

#[test]
fn every_species_grows_three_lods_with_its_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let names = species_names();
    assert!(names.len() >= 9, "{names:?}");
    for want in [
        "matsu",
        "momiji",
        "yanagi",
        "sakura",
        "sugi",
        "take",
        "kusu",
        "matsu_kaze",
        "shidare_zakura",
    ] {
        assert!(names.iter().any(|n| n == want), "{want} missing");
    }
    for name in &names {
        for seed in ["1", "2"] {
            let report = dir.path().join(format!("{name}-{seed}.json"));
            stdout_of(&[
                "tree",
                "--species",
                name,
                "--seed",
                seed,
                "--report",
                report.to_str().unwrap(),
            ]);
            let r = read_json(&report);
            let tri = |k: usize| r["lods"][k]["triangles"].as_f64().unwrap();
            let ratio = tri(1) / tri(0);
            assert!(
                (0.15..=0.45).contains(&ratio),
                "{name} seed {seed}: LOD1/LOD0 = {ratio:.2}"
            );
            assert_eq!(
                tri(2),
                8.0,
                "{name}: LOD2 is two crossed double-sided quads"
            );
            for key in ["height", "crown_width"] {
                assert!(r[key].as_f64().unwrap() > 0.5, "{name}: {key}");
            }
            assert!(
                r["lods"][0]["bytes"].as_u64().unwrap() > r["lods"][1]["bytes"].as_u64().unwrap()
            );
        }
    }
}

#[test]
fn a_tree_is_the_same_bytes_for_the_same_seed_whatever_lod_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let run = |lod: &str, name: &str| {
        let sub = dir.path().join(name);
        std::fs::create_dir_all(&sub).unwrap();
        let obj = sub.join("t.obj");
        let rep = sub.join("t.json");
        stdout_of(&[
            "tree",
            "--species",
            "sakura",
            "--seed",
            "3",
            "--lod",
            lod,
            "-o",
            obj.to_str().unwrap(),
            "--report",
            rep.to_str().unwrap(),
        ]);
        (std::fs::read(obj).unwrap(), read_json(&rep))
    };
    let (a, ra) = run("0", "a");
    let (b, _) = run("0", "b");
    let (c, rc) = run("1", "c");
    assert!(a == b, "the same seed gives the same bytes");
    assert!(a != c, "LOD1 is another mesh");
    assert_eq!(
        ra["lods"], rc["lods"],
        "LOD0 does not depend on the LOD asked for"
    );
}

#[test]
fn a_colonized_tree_reports_its_groups() {
    let dir = tempfile::tempdir().unwrap();
    let rep = dir.path().join("kusu.json");
    stdout_of(&[
        "tree",
        "--species",
        "kusu",
        "--seed",
        "1",
        "--report",
        rep.to_str().unwrap(),
    ]);
    let r = read_json(&rep);
    assert_eq!(r["method"], "colonization");
    let reasons = ["all_killed", "none_in_range", "stalled", "max_iter"];
    assert!(reasons.contains(&r["stop"].as_str().unwrap()));
    let groups = r["groups"].as_array().unwrap();
    let names: Vec<&str> = groups.iter().map(|g| g["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["trunk", "branches", "roots"]);
    // One tree: one node more than edges (the groups' sum counted shared stem edges twice).
    assert_eq!(
        r["nodes"].as_u64().unwrap(),
        r["edges"].as_u64().unwrap() + 1
    );
    for g in groups {
        assert_eq!(
            g["nodes"].as_u64().unwrap(),
            g["edges"].as_u64().unwrap() + 1
        );
        assert!(reasons.contains(&g["stop"].as_str().unwrap()));
        for key in ["iterations", "points_left", "step", "influence", "kill"] {
            assert!(g[key].is_number(), "{key}");
        }
    }
    assert_eq!(r["step"], 0.5);
}

#[test]
fn a_broken_species_file_is_an_error_at_its_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let trees = dir.path().join("trees");
    std::fs::create_dir_all(&trees).unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("templates/trees/sakura.toml"),
    )
    .unwrap()
    .replace("\"A:0.6=[&(45)F!A]", "\"A:0.6=[&(45)F!A");
    std::fs::write(trees.join("sakura.toml"), &text).unwrap();
    let line = text.lines().position(|l| l.contains("A:0.6=")).unwrap() + 1;
    let e = stderr_of_failure(&[
        "tree",
        "--species",
        "sakura",
        "--templates",
        dir.path().to_str().unwrap(),
    ]);
    assert!(e.contains(&format!("sakura.toml:{line}:")), "{e}");
    assert!(e.contains("never closed") || e.contains("closed by"), "{e}");
}

fn style(dir: &Path, style: &str, extra: &str) -> String {
    let p = dir.join(format!("{style}.toml"));
    std::fs::write(&p, format!("[trees]\nstyle = \"{style}\"\n{extra}")).unwrap();
    p.display().to_string()
}

#[test]
fn every_grown_tree_stands_in_its_lot_with_its_crown_clear_of_buildings() {
    let dir = tempfile::tempdir().unwrap();
    synth(dir.path(), 1200, 7);
    for s in ["lsystem", "colonization"] {
        let text = std::fs::read_to_string(style(dir.path(), s, "")).unwrap();
        let params = Params::from_toml_str(&text, "style.toml").unwrap();
        let data = edo_city::input::read_dataset(dir.path(), &params).expect("reads");
        let catalog = edo_city::templates::Catalog::load(None).unwrap();
        let plan = edo_city::analyse::analyse(&data, &params, &catalog, "lots.shp", &|_| {});
        let obstacles = Obstacles::new(
            plan.houses.values().flatten(),
            plan.fences.values().flatten(),
            &catalog,
            &params,
        );
        let clearance = params.trees.clearance;
        let mut grown = 0;
        for b in plan
            .billboards
            .values()
            .flatten()
            .filter(|b| b.kind == BillboardKind::Tree)
        {
            let form = b
                .tree
                .as_ref()
                .expect("every tree of a grown style has a species");
            assert_eq!(catalog.species[&form.species].method, s);
            assert!(form.grown);
            grown += 1;
            assert!((0.4..=1.0).contains(&form.squeeze), "{}", form.squeeze);
            assert!(b.height >= edo_city::analyse::trees::MIN_HEIGHT);
            let lot = data
                .lots
                .iter()
                .find(|l| Some(&l.id) == form.lot.as_ref())
                .expect("a lot");
            let edge = boundary_distance(b.at, &lot.outline);
            assert!(
                edge + 1e-9 >= form.crown + clearance,
                "{}: crown {} edge {edge}",
                b.id,
                form.crown
            );
            assert!(
                !obstacles.hit(b.at, form.crown + clearance),
                "{}: crown reaches a building",
                b.id
            );
        }
        assert!(grown > 50, "{s}: {grown}");
    }
}

/// The bytes of object `name` in an OBJ file.
fn object_bytes(obj: &[u8], name: &str) -> usize {
    let text = std::str::from_utf8(obj).unwrap();
    let start = format!("o {name}\n");
    let Some(from) = text.find(&start) else {
        return 0;
    };
    let rest = &text[from + start.len()..];
    start.len() + rest.find("\no ").map_or(rest.len(), |k| k + 1)
}

#[test]
fn grown_trees_keep_the_tile_budget_and_the_same_bytes_for_any_threads_and_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 1500, 3);
    // Dense estates and a small budget: the temples' tiles hold hundreds of trees.
    let params = style(
        dir.path(),
        "lsystem",
        "per_ha = 300.0\nmax_tile_bytes = 400000\n",
    );
    let one = dir.path().join("one");
    let two = dir.path().join("two");
    let r = build_ok(
        &town,
        &one,
        &["--quiet", "--params", &params, "--threads", "1"],
    );
    build_ok(
        &town,
        &two,
        &["--quiet", "--params", &params, "--threads", "2"],
    );
    let (a, b) = (all_files(&one), all_files(&two));
    a.iter()
        .filter(|(k, _)| !k.ends_with("report.json") && !k.ends_with("manifest.json"))
        .for_each(|(k, v)| {
            assert_eq!(Some(v), b.get(k), "{k} differs between 1 and 2 threads");
        });
    let trees = &r["trees"];
    assert!(trees["by_lod"]["lod1"].as_u64().unwrap() > 20, "{trees}");
    assert!(
        trees["by_lod"]["billboard"].as_u64().unwrap() > 0,
        "the budget bites: {trees}"
    );
    let mut crowded = 0;
    for (name, bytes) in a
        .iter()
        .filter(|(k, _)| k.starts_with("tiles/") && k.ends_with(".obj"))
    {
        let grown = object_bytes(bytes, "trees_grown");
        assert!(grown <= 400_000, "{name}: {grown} bytes of grown trees");
        let all = grown + object_bytes(bytes, "trees");
        let id = name.trim_start_matches("tiles/").trim_end_matches(".obj");
        assert_eq!(
            trees["tile_bytes"][id].as_u64().unwrap_or(0) as usize,
            all,
            "{id}"
        );
        crowded += usize::from(bytes.windows(12).filter(|w| *w == b"o trees_grow").count() > 0);
    }
    assert!(crowded > 0);
    // Placements: one row per tree of a species, and each species' LOD0 loads.
    let csv = String::from_utf8(a["species/placements.csv"].clone()).unwrap();
    let rows = csv.lines().count() - 1;
    let by_species: u64 = trees["by_lod"]
        .as_object()
        .unwrap()
        .values()
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(rows as u64, by_species);
    assert!(csv.starts_with("id,tile,species,lot,x,y,z,rotation,scale,squeeze,style,variant\n"));
    // Every grown tree is one of its species' 8 variants (trees.variants' default), and
    // each variant a tree is has its mesh in species/.
    let mut variants = std::collections::BTreeSet::new();
    for row in csv.lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        assert_eq!(f[10], "lsystem", "{row}");
        let k: u32 = f[11]
            .parse()
            .unwrap_or_else(|_| panic!("no variant: {row}"));
        assert!(k < 8, "{row}");
        variants.insert((f[2].to_string(), k));
    }
    assert!(variants.len() > 8, "{variants:?}");
    for (species, k) in &variants {
        let name = format!("species/{species}_{k}.obj");
        assert!(a.contains_key(&name), "{name}");
        let (models, _) = tobj::load_obj(one.join(&name), &tobj::LoadOptions::default()).unwrap();
        assert!(
            !models.is_empty() && !models[0].mesh.indices.is_empty(),
            "{name}"
        );
    }
    for species in trees["by_species"].as_object().unwrap().keys() {
        let obj = one.join(format!("species/{species}.obj"));
        let (models, _) = tobj::load_obj(
            &obj,
            &tobj::LoadOptions {
                triangulate: true,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(!models.is_empty(), "{species}");
    }
    // Every tile still loads with its textures.
    let origin = [
        r["origin"][0].as_f64().unwrap_or(0.0),
        r["origin"][1].as_f64().unwrap_or(0.0),
    ];
    let first = r["tiles"][0]["id"].as_str().unwrap().to_string();
    load_tile(&one.join(format!("tiles/{first}.obj")), origin);
    // One tile again, alone: the same bytes.
    let before = a[&format!("tiles/{first}.obj")].clone();
    build_ok(
        &town,
        &one,
        &["--quiet", "--params", &params, "--tiles", &first],
    );
    assert_eq!(
        std::fs::read(one.join(format!("tiles/{first}.obj"))).unwrap(),
        before
    );
}

#[test]
fn trees_variants_zero_grows_every_tree_its_own_and_too_many_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 300, 3);
    let own = style(dir.path(), "lsystem", "per_ha = 300.0\nvariants = 0\n");
    let out = dir.path().join("own");
    build_ok(&town, &out, &["--quiet", "--no-plan", "--params", &own]);
    let csv = std::fs::read_to_string(out.join("species/placements.csv")).unwrap();
    assert!(csv.lines().count() > 10, "{csv}");
    for row in csv.lines().skip(1) {
        assert!(
            row.ends_with(",lsystem,"),
            "no variant with variants = 0: {row}"
        );
    }
    let names: Vec<String> = std::fs::read_dir(out.join("species"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().all(|n| !n.contains('_')),
        "no variant meshes: {names:?}"
    );
    // The same town with variants: other trees (a variant's branches, not each its own).
    let with = dir.path().join("with");
    let eight = style(dir.path(), "lsystem", "per_ha = 300.0\n");
    let _ = std::fs::rename(&eight, dir.path().join("eight.toml"));
    build_ok(
        &town,
        &with,
        &[
            "--quiet",
            "--no-plan",
            "--params",
            dir.path().join("eight.toml").to_str().unwrap(),
        ],
    );
    let tile = |d: &Path| {
        let mut v: Vec<_> = std::fs::read_dir(d.join("tiles"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "obj"))
            .collect();
        v.sort();
        v.iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect::<Vec<_>>()
    };
    assert_ne!(tile(&out), tile(&with));

    let bad = style(dir.path(), "lsystem", "variants = 5000\n");
    let e = stderr_of_failure(&["build", town.to_str().unwrap(), "--params", &bad]);
    assert!(e.contains("trees.variants") && e.contains("1024"), "{e}");
}

#[test]
fn a_species_field_of_the_points_names_each_trees_species() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 400, 2);
    // One point per lot centroid of the first estate lots, naming kusu or an unknown species.
    let lots = common::read_lots(&town.join("lots.shp"));
    let mut ids: Vec<&String> = lots.keys().collect();
    ids.sort();
    let mut w = shapefile::Writer::from_path(
        town.join("trees.shp"),
        dbase::TableWriterBuilder::new()
            .add_character_field("id".try_into().unwrap(), 10)
            .add_character_field("species".try_into().unwrap(), 20),
    )
    .unwrap();
    for (n, id) in ids.iter().take(40).enumerate() {
        use geo::Centroid;
        let c = lots[*id].2.centroid().unwrap();
        let mut rec = dbase::Record::default();
        rec.insert(
            "id".into(),
            dbase::FieldValue::Character(Some(format!("t{n}"))),
        );
        let sp = if n % 2 == 0 { "kusu" } else { "oak" };
        rec.insert(
            "species".into(),
            dbase::FieldValue::Character(Some(sp.into())),
        );
        w.write_shape_and_record(&shapefile::Point::new(c.x(), c.y()), &rec)
            .unwrap();
    }
    drop(w);
    let out = dir.path().join("out");
    let params = style(dir.path(), "lsystem", "");
    let r = build_ok(&town, &out, &["--quiet", "--params", &params]);
    let csv = std::fs::read_to_string(out.join("species/placements.csv")).unwrap();
    assert!(
        csv.lines().skip(1).any(|l| l.contains(",kusu,")),
        "named kusu are planted"
    );
    let warned = r["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w["message"].as_str().unwrap().contains("species `oak`"));
    assert!(warned, "an unknown species is warned about");
    for a in r["accounting"].as_array().unwrap() {
        assert_eq!(a["unaccounted"], 0, "{a}");
    }
}

/// A colonized species in `dir/trees/` whose branches fill the hull `file` with `points`.
fn hull_species(dir: &Path, file: &str, points: usize) {
    let trees = dir.join("trees");
    std::fs::create_dir_all(&trees).unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("templates/trees/kusu.toml"),
    )
    .unwrap()
    .replace("name = \"kusu\"", "name = \"shaped\"")
    .replace(
        "envelope = { shape = \"ellipsoid\", center = [0.0, 0.0, 12.5], radii = [10.0, 10.0, 7.0] }",
        &format!("envelope = {{ shape = \"hull\", file = \"{file}\" }}"),
    )
    .replace("points = 2000", &format!("points = {points}"));
    assert!(text.contains("\"hull\""));
    // Without its roots, whose 12 m spread would hide the crown's width.
    let roots = text
        .find("[[colonization.group]]\nname = \"roots\"")
        .unwrap();
    let text = format!(
        "{}{}",
        &text[..roots],
        &text[text.find("[roots]").unwrap()..]
    );
    std::fs::write(trees.join("shaped.toml"), text).unwrap();
}

/// An OBJ (y up) of a box from `lo` to `hi`, twelve triangles wound outward.
fn box_obj(lo: [f64; 3], hi: [f64; 3]) -> String {
    let mut s = String::new();
    for i in 0..8 {
        let c = |k: usize| if i >> k & 1 == 1 { hi[k] } else { lo[k] };
        s += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    for f in [
        "1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6",
    ] {
        s += &format!("f {f}\n");
    }
    s
}

#[test]
fn a_hull_crown_grows_inside_it_and_a_hull_with_no_volume_or_outside_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let templates = dir.path().join("tpl");
    let trees = templates.join("trees");
    std::fs::create_dir_all(&trees).unwrap();
    std::fs::write(
        trees.join("crown.obj"),
        box_obj([-4.0, 7.0, -3.0], [4.0, 13.0, 3.0]),
    )
    .unwrap();
    let grow = |extra: &[&str]| {
        let mut args = vec!["tree", "--species", "shaped", "--templates"];
        args.push(templates.to_str().unwrap());
        args.extend(extra);
        edo_city().args(&args).output().unwrap()
    };
    hull_species(&templates, "crown.obj", 3000);
    let rep = dir.path().join("r.json");
    let o = grow(&["--report", rep.to_str().unwrap(), "--height", "13"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = read_json(&rep);
    // Grown to the box's own top (13 m, OBJ y is up), the crown reaches the box's corners
    // (5 m from the axis) and its leaves' clusters (1.6 m), not kusu's 10 m dome.
    let width = r["crown_width"].as_f64().unwrap();
    assert!((8.0..=2.0 * (5.0 + 1.6)).contains(&width), "{r}");
    assert_eq!(
        r["nodes"].as_u64().unwrap(),
        r["edges"].as_u64().unwrap() + 1
    );

    // 10,001 triangles in one plane, 50,000 points: refused when read (ran for minutes).
    let mut flat = String::from("v 0 5 0\n");
    for i in 0..10_002 {
        flat += &format!(
            "v {} 5 {}\n",
            (i as f64 * 0.7).sin() * 5.0,
            (i as f64 * 1.3).cos() * 5.0
        );
    }
    for i in 2..10_003 {
        flat += &format!("f 1 {i} {}\n", i + 1);
    }
    std::fs::write(trees.join("flat.obj"), flat).unwrap();
    hull_species(&templates, "flat.obj", 50_000);
    let e = String::from_utf8(grow(&[]).stderr).unwrap();
    assert!(e.contains("flat.obj") && e.contains("no volume"), "{e}");

    // Named outside the species' folder, by `..`, absolutely, or as a device: refused, and
    // nothing is told of what lies outside.
    std::fs::write(dir.path().join("secret.obj"), box_obj([0.0; 3], [1.0; 3])).unwrap();
    std::os::unix::fs::symlink(dir.path().join("secret.obj"), trees.join("link.obj")).unwrap();
    let names = [
        "link.obj",
        "../../secret.obj",
        "../../nothing.obj",
        "/dev/zero",
        "/etc/passwd",
        "nothing.obj",
    ];
    for name in names {
        hull_species(&templates, name, 100);
        let o = grow(&[]);
        assert_eq!(o.status.code(), Some(2), "{name}");
        let e = String::from_utf8(o.stderr).unwrap();
        assert!(e.contains(name), "{name}: {e}");
        let want = if name == "nothing.obj" {
            "does not exist"
        } else {
            "outside the folder"
        };
        assert!(e.contains(want), "{name}: {e}");
    }
}
