//! Landmarks (`layers.landmarks`): models placed from their own files. The fixture town gets
//! the five-storey pagoda our own `template` command exported as OBJ; it lands whole in the
//! tile of its point with its materials and textures under prefixed names, displaces the
//! house under it, and is listed in the report; every error case is a skip with its record.

mod common;

use std::path::{Path, PathBuf};

use common::{build_ok, copy_fixture, fixture, read_json};

/// The fixture's lot 1 (a machiya, about 21 m across): its middle, output CRS.
const LOT_1: (f64, f64) = (-22985.4, -109989.6);

fn models() -> PathBuf {
    fixture("landmark-models")
}

/// The fixture town with `landmarks.csv` holding `rows` (after the header) and a parameter
/// file pointing at it; returns the parameter file.
fn town(dir: &Path, rows: &str, extra: &str) -> PathBuf {
    copy_fixture("kyoto-small", dir);
    std::fs::write(
        dir.join("landmarks.csv"),
        format!("id,model,kind,x,y,rotation,scale,z\n{rows}"),
    )
    .unwrap();
    let params = dir.join("params.toml");
    std::fs::write(
        &params,
        format!(
            "[layers.landmarks]\nfile = \"landmarks.csv\"\n[landmarks]\nmodels_dir = {:?}\n{extra}",
            models().display().to_string()
        ),
    )
    .unwrap();
    params
}

#[test]
fn the_pagoda_lands_whole_in_its_tile_and_displaces_the_house_under_it() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    let (x, y) = LOT_1;
    let params = town(
        &input,
        &format!("pagoda,goju-no-to.obj,,{x},{y},30,1,\n"),
        "",
    );
    let out = tmp.path().join("out");
    let report = build_ok(
        &input,
        &out,
        &["--params", params.to_str().unwrap(), "--format", "obj,glb"],
    );
    let l = &report["landmarks"];
    assert_eq!(l["placed"].as_array().unwrap().len(), 1, "{l}");
    let placed = &l["placed"][0];
    assert_eq!(placed["id"], "pagoda");
    let tile = placed["tile"].as_str().unwrap().to_string();
    // Its box: about 13 m across (turned 30 degrees: wider), 29.2 m tall, around its point.
    let b: Vec<f64> = placed["bounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!((b[5] - b[2] - 29.179).abs() < 0.01, "{b:?}");
    assert!(b[0] < x && x < b[3] && b[1] < y && y < b[4], "{b:?}");
    assert!(b[3] - b[0] > 13.0 && b[3] - b[0] < 19.0, "{b:?}");
    // The house of lot 1 is not built: displaced and skipped with why.
    let displaced = l["displaced"].as_array().unwrap();
    assert!(
        displaced.iter().any(|d| d["kind"] == "machiya"
            && d["id"] == "1"
            && d["landmark"] == "pagoda"
            && d["reason"]
                .as_str()
                .unwrap()
                .contains("overlaps the landmark's footprint")),
        "{displaced:?}"
    );
    let skipped = report["skipped"].as_array().unwrap();
    assert!(skipped.iter().any(|s| s["id"] == "1"
        && s["reason"]
            .as_str()
            .unwrap()
            .contains("displaced by landmark pagoda")));
    // Whole in its tile, with its materials under prefixed names and their textures.
    let obj = std::fs::read_to_string(out.join(format!("tiles/{tile}.obj"))).unwrap();
    assert!(obj.contains("o landmark_pagoda\n"));
    assert!(!obj.contains("o machiya_1\n"));
    assert!(obj.contains("usemtl lm_goju-no-to_kawara_roof\n"));
    let mtl = std::fs::read_to_string(out.join(format!("tiles/{tile}.mtl"))).unwrap();
    assert!(mtl.contains("newmtl lm_goju-no-to_kawara_roof\n"));
    assert!(mtl.contains("map_Kd textures/lm_goju-no-to_kawara.png"));
    assert!(out
        .join("tiles/textures/lm_goju-no-to_kawara.png")
        .is_file());
    assert!(out.join("tiles/textures/kawara.png").is_file());
    // Other tiles' MTL is the library's alone.
    let manifest = read_json(&out.join("manifest.json"));
    for t in manifest["tiles"].as_array().unwrap() {
        let id = t["id"].as_str().unwrap();
        let has = t["stats"]["landmarks"]
            .as_array()
            .is_some_and(|a| !a.is_empty());
        assert_eq!(has, id == tile, "{id}");
        if id != tile {
            let mtl = std::fs::read_to_string(out.join(format!("tiles/{id}.mtl"))).unwrap();
            assert!(!mtl.contains("lm_"), "{id}");
        }
    }
    assert!(manifest["textures"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f["path"]
            .as_str()
            .unwrap()
            .ends_with("lm_goju-no-to_kawara.png")));
    // The GLB names the landmark's materials and its image with its MIME type.
    let glb = std::fs::read(out.join(format!("tiles/{tile}.glb"))).unwrap();
    let text = String::from_utf8_lossy(&glb);
    assert!(text.contains("lm_goju-no-to_kawara_roof") && text.contains("\"landmark\""));
    // Its ledger closes.
    for a in report["accounting"].as_array().unwrap() {
        assert_eq!(a["unaccounted"], 0, "{a}");
    }
    let lm = report["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "landmarks")
        .unwrap();
    assert_eq!(lm["built"], 1);
    // Nothing else stands in its footprint: no other object's vertex inside its box's middle
    // third.
    let (cx, cy) = ((b[0] + b[3]) / 2.0, (b[1] + b[4]) / 2.0);
    let objects = common::load_tile(
        &out.join(format!("tiles/{tile}.obj")),
        [
            manifest["origin"][0].as_f64().unwrap(),
            manifest["origin"][1].as_f64().unwrap(),
        ],
    );
    for o in objects
        .iter()
        .filter(|o| !o.name.starts_with("landmark_") && o.name != "ground" && o.name != "streets")
    {
        for v in &o.vertices {
            assert!(
                (v[0] - cx).abs() > 3.0 || (v[1] - cy).abs() > 3.0,
                "{} at {v:?}",
                o.name
            );
        }
    }
    // The plan shows its footprint in the landmark colour (a plan without landmarks has
    // none of it).
    let landmark_pixels = |png: &Path| {
        let img = image::open(png).unwrap().to_rgb8();
        img.pixels()
            .filter(|p| p.0 == edo_city::output::plan::LANDMARK)
            .count()
    };
    assert!(landmark_pixels(&out.join("plan.png")) > 20);
    let plain = tmp.path().join("plain");
    build_ok(&fixture("kyoto-small"), &plain, &["--quiet"]);
    assert_eq!(landmark_pixels(&plain.join("plan.png")), 0);
}

#[test]
fn a_build_is_the_same_for_any_thread_count_and_tiles_rewrite_keeps_the_landmark() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    let (x, y) = LOT_1;
    let params = town(
        &input,
        &format!("pagoda,goju-no-to.obj,,{x},{y},0,1,\n"),
        "",
    );
    let p = params.to_str().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    build_ok(&input, &a, &["--params", p, "-j", "1"]);
    let report = build_ok(&input, &b, &["--params", p, "-j", "2"]);
    assert_eq!(common::all_files(&a), common::all_files(&b));
    let tile = report["landmarks"]["placed"][0]["tile"]
        .as_str()
        .unwrap()
        .to_string();
    let again = build_ok(&input, &b, &["--params", p, "--tiles", &tile]);
    assert_eq!(again["landmarks"], report["landmarks"]);
}

/// An OBJ of one triangle at `offset` metres east of its origin, `size` metres.
fn triangle_obj(dir: &Path, name: &str, offset: f64, size: f64) {
    std::fs::write(
        dir.join(name),
        format!(
            "v {offset} 0 0\nv {} 0 0\nv {offset} {size} 0\nf 1 2 3\n",
            offset + size
        ),
    )
    .unwrap();
}

#[test]
fn every_unusable_landmark_is_skipped_with_its_record_and_why() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    let models = tmp.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    triangle_obj(&models, "far.obj", 1000.0, 10.0);
    triangle_obj(&models, "ok.obj", 0.0, 10.0);
    std::fs::write(
        models.join("lines.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n",
    )
    .unwrap();
    std::fs::write(models.join("keep.fbx"), "Kaydara FBX Binary").unwrap();
    std::fs::write(models.join("broken.glb"), "glTF not really").unwrap();
    let (x, y) = (-22600.0, -109600.0);
    let rows = [
        format!("missing,nowhere.obj,,{x},{y},0,1,"),
        format!("fbx,keep.fbx,,{x},{y},0,1,"),
        format!("broken,broken.glb,,{x},{y},0,1,"),
        format!("nofaces,lines.obj,,{x},{y},0,1,"),
        format!("huge,ok.obj,,{x},{y},0,100,"),
        format!("tiny,ok.obj,,{x},{y},0,0.001,"),
        format!("tiniest,ok.obj,,{x},{y},0,1e-300,"),
        format!("hugest,ok.obj,,{x},{y},0,1e300,"),
        format!("far,far.obj,,{x},{y},0,1,"),
        format!("nokind,,castle,{x},{y},0,1,"),
        format!("badscale,ok.obj,,{x},{y},0,-2,"),
        format!("badrot,ok.obj,,{x},{y},north,1,"),
        format!("good,ok.obj,,{x},{y},0,1,"),
    ];
    let params = town(&input, &(rows.join("\n") + "\n"), "anchor = \"origin\"\n");
    // The models are in their own directory here.
    let text = std::fs::read_to_string(&params).unwrap().replace(
        &format!("{:?}", models_dir_str()),
        &format!("{:?}", models.display().to_string()),
    );
    std::fs::write(&params, text).unwrap();
    let out = tmp.path().join("out");
    let report = build_ok(&input, &out, &["--params", params.to_str().unwrap()]);
    let l = &report["landmarks"];
    let skipped = l["skipped"].as_array().unwrap();
    let why = |id: &str| -> String {
        skipped
            .iter()
            .find(|s| s["id"] == id)
            .unwrap_or_else(|| panic!("{id} not skipped: {skipped:?}"))["reason"]
            .as_str()
            .unwrap()
            .to_string()
    };
    assert!(
        why("missing").contains("does not exist"),
        "{}",
        why("missing")
    );
    assert!(why("fbx").contains("unsupported format"), "{}", why("fbx"));
    assert!(
        why("broken").contains("not a readable glTF"),
        "{}",
        why("broken")
    );
    assert!(why("nofaces").contains("no faces"), "{}", why("nofaces"));
    assert!(
        why("huge").contains("absurd scale") && why("huge").contains("over 500"),
        "{}",
        why("huge")
    );
    assert!(
        why("tiny").contains("absurd scale") && why("tiny").contains("under 0.1"),
        "{}",
        why("tiny")
    );
    // Every number in a reason is bounded in length (1e-300 once made 447 characters).
    for id in ["tiniest", "hugest"] {
        assert!(
            why(id).contains("absurd scale") && why(id).len() < 250,
            "{}",
            why(id)
        );
    }
    assert!(why("tiniest").contains("1e-300"), "{}", why("tiniest"));
    assert!(why("far").contains("from its point"), "{}", why("far"));
    assert!(
        why("nokind").contains("kind `castle` has no model"),
        "{}",
        why("nokind")
    );
    assert!(why("badscale").contains("above 0"), "{}", why("badscale"));
    assert!(why("badrot").contains("not a number"), "{}", why("badrot"));
    assert_eq!(skipped.len(), 12, "{skipped:?}");
    assert_eq!(l["placed"].as_array().unwrap().len(), 1);
    assert_eq!(l["placed"][0]["id"], "good");
    let lm = report["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "landmarks")
        .unwrap();
    assert_eq!(
        (
            lm["read"].as_u64(),
            lm["built"].as_u64(),
            lm["skipped"].as_u64(),
            lm["unaccounted"].as_u64()
        ),
        (Some(13), Some(1), Some(12), Some(0))
    );
}

fn models_dir_str() -> String {
    models().display().to_string()
}

#[test]
fn a_glb_of_our_own_is_a_landmark_too() {
    // A tile GLB the build wrote, read back through the gltf crate as a model.
    let tmp = tempfile::tempdir().unwrap();
    let first = tmp.path().join("first");
    let report = build_ok(&fixture("kyoto-small"), &first, &["--format", "glb"]);
    let tile = report["tiles"][0]["id"].as_str().unwrap().to_string();
    let models = tmp.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    std::fs::copy(
        first.join(format!("tiles/{tile}.glb")),
        models.join("block.glb"),
    )
    .unwrap();
    let input = tmp.path().join("in");
    let params = town(&input, "block,block.glb,,-22600,-109600,0,0.1,\n", "");
    let text = std::fs::read_to_string(&params).unwrap().replace(
        &format!("{:?}", models_dir_str()),
        &format!("{:?}", models.display().to_string()),
    );
    std::fs::write(&params, text).unwrap();
    let out = tmp.path().join("out");
    let r = build_ok(&input, &out, &["--params", params.to_str().unwrap()]);
    let placed = &r["landmarks"]["placed"];
    assert_eq!(placed.as_array().unwrap().len(), 1, "{}", r["landmarks"]);
    assert!(placed[0]["triangles"].as_u64().unwrap() > 1000);
    let b: Vec<f64> = placed[0]["bounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    // A tile is at most a few hundred metres; at 0.1 it is tens.
    assert!(b[3] - b[0] < 40.0 && b[3] - b[0] > 1.0, "{b:?}");
}

#[test]
fn rows_without_an_id_and_points_far_outside_the_city_are_skipped_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    let models = tmp.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    triangle_obj(&models, "ok.obj", 0.0, 10.0);
    let (x, y) = (-22600.0, -109600.0);
    let rows = [
        format!("good,ok.obj,,{x},{y},0,1,"),
        format!(",ok.obj,,{},{y},0,1,", x + 20.0),
        format!(",ok.obj,,{},{y},0,1,", x + 40.0),
        format!("farx,ok.obj,,5e7,{y},0,1,"),
        format!("fary,ok.obj,,{x},9e7,0,1,"),
        format!("huge,ok.obj,,1e300,{y},0,1,"),
        format!("nearby,ok.obj,,{},{y},0,1,", x - 1500.0),
    ];
    let params = town(&input, &(rows.join("\n") + "\n"), "anchor = \"origin\"\n");
    let text = std::fs::read_to_string(&params).unwrap().replace(
        &format!("{:?}", models_dir_str()),
        &format!("{:?}", models.display().to_string()),
    );
    std::fs::write(&params, text).unwrap();
    // A link far out, beside the fixture's two.
    let mut links = std::fs::read_to_string(input.join("links.csv")).unwrap();
    links.push_str("9,Far away,https://example.org/,,1e300,-109800.0\n");
    std::fs::write(input.join("links.csv"), links).unwrap();
    let out = tmp.path().join("out");
    let report = build_ok(&input, &out, &["--params", params.to_str().unwrap()]);
    let l = &report["landmarks"];
    let placed: Vec<&str> = l["placed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["id"].as_str().unwrap())
        .collect();
    let mut placed = placed;
    placed.sort();
    assert_eq!(placed, ["good", "nearby"], "{l}");
    let skipped = report["skipped"].as_array().unwrap();
    let reason = |layer: &str, id: &str| -> Vec<String> {
        skipped
            .iter()
            .filter(|s| s["layer"] == layer && s["id"] == id)
            .map(|s| s["reason"].as_str().unwrap().to_string())
            .collect()
    };
    // Both rows without an id are listed, with their spreadsheet rows.
    let no_id = reason("landmarks", "");
    assert_eq!(no_id.len(), 2, "{skipped:?}");
    assert!(no_id[0].contains("no `id`"), "{no_id:?}");
    for id in ["farx", "fary", "huge"] {
        let r = reason("landmarks", id);
        assert!(
            r.len() == 1 && (r[0].contains("outside the city") || r[0].contains("CRS's origin")),
            "{id}: {r:?}"
        );
    }
    let far_link = reason("links", "9");
    assert!(
        far_link.len() == 1 && far_link[0].contains("CRS's origin"),
        "{far_link:?}"
    );
    // Every row is accounted for, the manifest is written, and no tile lies far out.
    for a in report["accounting"].as_array().unwrap() {
        assert_eq!(a["unaccounted"], 0, "{a}");
    }
    let lm = report["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "landmarks")
        .unwrap();
    assert_eq!(
        (lm["read"].as_u64(), lm["built"].as_u64()),
        (Some(7), Some(2))
    );
    let manifest = read_json(&out.join("manifest.json"));
    let links = read_json(&out.join("links.json"));
    assert_eq!(links.as_array().unwrap().len(), 2);
    let tiles = manifest["tiles"].as_array().unwrap();
    let plain = build_ok(
        &fixture("kyoto-small"),
        &tmp.path().join("plain"),
        &["--quiet"],
    );
    assert!(tiles.len() <= plain["tiles"].as_array().unwrap().len() + 1);
}
