//! The browser's formats: GLB tiles and the 3D Tiles tileset. Its structure (boxes hold
//! their content and their children, geometric error 0 at the leaves and growing to the
//! root), its placement on the globe (a house corner lands where proj puts it), `--format`,
//! and Khronos' glTF-Validator on every GLB (npm, installed by `make viewer-deps`).

mod common;

use std::path::Path;

use common::glb::{glb_json, strings};
use common::{build_ok, fixture, read_json};
use edo_city::output::tiles3d::globe::{geodetic, Affine};
use serde_json::Value;

/// Builds the example town into `out` (quiet, no plan) with `extra` flags.
fn build_example(out: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["--quiet", "--no-plan"];
    args.extend_from_slice(extra);
    build_ok(&fixture("kyoto-small"), out, &args)
}

/// A JSON array of numbers.
fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A column-major 4x4 transform as an affine map.
fn affine(m: &Value) -> Affine {
    let v = floats(m);
    Affine {
        cols: [[v[0], v[1], v[2]], [v[4], v[5], v[6]], [v[8], v[9], v[10]]],
        t: [v[12], v[13], v[14]],
    }
}

/// Is `p` inside the box `b` (centre and three axis-aligned half-axes), to `eps`?
fn inside(b: &Value, p: [f64; 3], eps: f64) -> bool {
    let b = floats(b);
    let half = [b[3], b[7], b[11]];
    (0..3).all(|k| (p[k] - b[k]).abs() <= half[k] + eps)
}

/// The corners of a box.
fn corners(b: &Value) -> Vec<[f64; 3]> {
    let b = floats(b);
    (0..8)
        .map(|i| {
            let s = |k: usize| if i >> k & 1 == 0 { -1.0 } else { 1.0 };
            [b[0] + s(0) * b[3], b[1] + s(1) * b[7], b[2] + s(2) * b[11]]
        })
        .collect()
}

/// Walks the tree: every child's box (through its transform) inside its parent's, leaf
/// errors 0 and inner ones larger than their children's; returns the leaves with their
/// transform relative to the root.
fn walk(node: &Value, to_root: Affine, leaves: &mut Vec<(Value, Affine)>) {
    let here = match node.get("transform") {
        Some(t) => to_root.then(&affine(t)),
        None => to_root,
    };
    let Some(children) = node.get("children").and_then(|c| c.as_array()) else {
        assert!(
            !node["content"]["uri"]
                .as_str()
                .unwrap()
                .starts_with("tiles/lod/"),
            "a leaf is a tile, not a level of detail"
        );
        assert_eq!(node["geometricError"], 0.0, "a leaf's error is 0");
        assert!(node["content"]["uri"].as_str().unwrap().ends_with(".glb"));
        leaves.push((node.clone(), here));
        return;
    };
    let e = node["geometricError"].as_f64().unwrap();
    for c in children {
        assert!(
            c["geometricError"].as_f64().unwrap() < e,
            "errors grow to the root"
        );
        let ct = c.get("transform").map(affine).unwrap_or(Affine::IDENTITY);
        for p in corners(&c["boundingVolume"]["box"]) {
            assert!(
                inside(&node["boundingVolume"]["box"], ct.apply(p), 1e-6),
                "a child's box leaves its parent's"
            );
        }
        walk(c, here, leaves);
    }
}

#[test]
fn the_tileset_holds_every_tile_and_places_a_house_where_proj_does() {
    let out = tempfile::tempdir().unwrap();
    let report = build_example(out.path(), &[]);
    let manifest = read_json(&out.path().join("manifest.json"));
    assert_eq!(manifest["formats"], serde_json::json!(["obj", "glb"]));
    assert!(manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f["path"] == "tileset.json"));
    let tileset = read_json(&out.path().join("tileset.json"));
    assert_eq!(tileset["asset"]["version"], "1.1");
    let root = &tileset["root"];
    assert_eq!(root["refine"], "REPLACE");
    let mut leaves = Vec::new();
    walk(root, Affine::IDENTITY, &mut leaves);
    let tiles = manifest["tiles"].as_array().unwrap();
    assert_eq!(leaves.len(), tiles.len(), "one leaf per tile");
    assert_eq!(report["tiles"][0]["glb_bytes"], tiles[0]["glb"]["bytes"]);

    // Every vertex of every GLB lies in its leaf's box (glTF y-up turned z-up as 3D Tiles
    // does: (x, y, z) -> (x, -z, y)), its shorts placed by its node's translation and scale
    // (within half a step of the millimetres the box was made from).
    for (leaf, _) in &leaves {
        let uri = leaf["content"]["uri"].as_str().unwrap();
        let g = glb_json(&std::fs::read(out.path().join(uri)).unwrap());
        for node in g["nodes"].as_array().unwrap() {
            let Some(mesh) = node["mesh"].as_u64() else {
                continue;
            };
            assert!(
                node.get("skin").is_none(),
                "no walkers in the example's build"
            );
            assert!(
                node["extensions"].is_null(),
                "no grown trees in the example's build"
            );
            let t = floats(&node["translation"]);
            let sc = floats(&node["scale"])[0];
            let mesh = &g["meshes"][mesh as usize];
            for p in mesh["primitives"].as_array().unwrap() {
                let a = &g["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
                assert_eq!(a["componentType"], 5122, "{uri}: shorts");
                for m in [&a["min"], &a["max"]] {
                    let v = floats(m);
                    let v = [0, 1, 2].map(|k| t[k] + sc * v[k]);
                    assert!(
                        inside(&leaf["boundingVolume"]["box"], [v[0], -v[2], v[1]], sc),
                        "{uri}: a vertex outside its box"
                    );
                }
                let ext = &p["extensions"]["EXT_mesh_features"]["featureIds"][0];
                assert_eq!(ext["propertyTable"], 0);
                assert!(p["attributes"]["_FEATURE_ID_0"].is_u64());
            }
        }
        let table = &g["extensions"]["EXT_structural_metadata"]["propertyTables"][0];
        assert!(table["count"].as_u64().unwrap() > 0);
        for mat in g["materials"].as_array().unwrap() {
            assert_ne!(mat["alphaMode"], "BLEND");
            if mat["alphaMode"] == "MASK" {
                assert_eq!(mat["alphaCutoff"], 0.5);
                assert_eq!(mat["doubleSided"], true);
            }
        }
    }

    // A house's corner in the OBJ, through the tileset's transforms, lands at the longitude
    // and latitude proj gives its map point (within 5 cm).
    let origin = [
        manifest["origin"][0].as_f64().unwrap(),
        manifest["origin"][1].as_f64().unwrap(),
    ];
    let crs = edo_city::input::crs::Crs::from_user(manifest["crs"].as_str().unwrap()).unwrap();
    let wgs84 =
        edo_city::input::crs::Crs::from_user("+proj=longlat +datum=WGS84 +no_defs").unwrap();
    let objects = common::build_objects(out.path());
    let mut checked = 0;
    for t in tiles {
        let uri = t["glb"]["path"].as_str().unwrap();
        let (_, to_ecef) = leaves
            .iter()
            .find(|(l, _)| l["content"]["uri"] == uri)
            .unwrap();
        let centre = [
            t["centre"][0].as_f64().unwrap(),
            t["centre"][1].as_f64().unwrap(),
        ];
        let tile_objects =
            common::load_tile(&out.path().join(t["obj"]["path"].as_str().unwrap()), origin);
        let Some(house) = tile_objects.iter().find(|o| o.name.starts_with("machiya_")) else {
            continue;
        };
        for &[e, n, up] in house.vertices.iter().step_by(7).take(5) {
            let local = [e - origin[0] - centre[0], n - origin[1] - centre[1], up];
            let g = geodetic(to_ecef.apply(local));
            let mut truth = [geo_types::Coord { x: e, y: n }];
            edo_city::input::crs::reproject(&mut truth, &crs, &wgs84).unwrap();
            let metres_per_degree = 111_320.0;
            let dx = (g[0] - truth[0].x) * metres_per_degree * g[1].to_radians().cos();
            let dy = (g[1] - truth[0].y) * metres_per_degree;
            assert!(
                dx.hypot(dy) < 0.05,
                "{}: off by {:.3} m",
                house.name,
                dx.hypot(dy)
            );
            assert!((g[2] - up).abs() < 0.05, "height {} for {up}", g[2]);
            checked += 1;
        }
    }
    assert!(checked >= 10, "{checked} corners checked");
    assert!(!objects.is_empty());
}

#[test]
fn formats_are_chosen_and_a_city_without_a_crs_is_built_unplaced_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("glb");
    build_example(&glb, &["--format", "glb"]);
    let m = read_json(&glb.join("manifest.json"));
    assert!(m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .all(|t| t["obj"].is_null() && t["glb"].is_object()));
    assert!(!std::fs::read_dir(glb.join("tiles")).unwrap().any(|e| e
        .unwrap()
        .path()
        .extension()
        .is_some_and(|x| x == "obj")));
    let obj = dir.path().join("obj");
    build_example(&obj, &["--format", "obj"]);
    assert!(!obj.join("tileset.json").exists());
    let bad = common::edo_city()
        .args(["build", fixture("kyoto-small").to_str().unwrap(), "--out"])
        .arg(dir.path().join("bad"))
        .args(["--format", "obj,gltf"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown format `gltf`"));

    // The same town with no .prj anywhere: identity transform and a warning; placed again
    // with origin_lonlat.
    let town = dir.path().join("town");
    common::copy_fixture("kyoto-small", &town);
    for e in std::fs::read_dir(&town).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "prj") {
            std::fs::remove_file(p).unwrap();
        }
    }
    let unplaced = dir.path().join("unplaced");
    let r = build_ok(&town, &unplaced, &["--quiet", "--no-plan"]);
    let t = read_json(&unplaced.join("tileset.json"));
    assert_eq!(
        t["root"]["transform"],
        serde_json::json!([
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0
        ])
    );
    assert!(r["warnings"]
        .to_string()
        .contains("not placed on the globe"));
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "origin_lonlat = [135.7681, 35.0116, 40.0]\n").unwrap();
    let placed = dir.path().join("placed");
    let r = build_ok(
        &town,
        &placed,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    assert!(!r["warnings"]
        .to_string()
        .contains("not placed on the globe"));
    let t = read_json(&placed.join("tileset.json"));
    let root = affine(&t["root"]["transform"]);
    let g = geodetic(root.apply([0.0, 0.0, 0.0]));
    assert!(
        (g[0] - 135.7681).abs() < 1e-9
            && (g[1] - 35.0116).abs() < 1e-9
            && (g[2] - 40.0).abs() < 1e-3
    );
}

#[test]
fn every_glb_passes_the_khronos_validator() {
    let out = tempfile::tempdir().unwrap();
    // Houses, kura, walls, gates, people, trees and a garden: every kind the example has.
    build_example(out.path(), &["--format", "glb"]);
    common::validate_glbs(out.path());
}

#[test]
fn links_become_markers_and_a_malformed_address_is_skipped_with_its_record() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    common::copy_fixture("kyoto-small", &town);
    let mut csv = std::fs::read_to_string(town.join("links.csv")).unwrap();
    csv.push_str("3,A broken address,htp:/not a url,,-22700.0,-109800.0\n");
    std::fs::write(town.join("links.csv"), csv).unwrap();
    let out = dir.path().join("out");
    let r = build_ok(&town, &out, &["--quiet", "--no-plan"]);
    let links = read_json(&out.join("links.json"));
    let titles: Vec<&str> = links
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["title"].as_str().unwrap())
        .collect();
    assert_eq!(
        titles,
        ["Rakuchu rakugai-zu (Uesugi screens)", "Sanjo Ohashi"]
    );
    // links.csv's x, y are in the output CRS; links.json's are from the origin.
    let m = read_json(&out.join("manifest.json"));
    let ox = m["origin"][0].as_f64().unwrap();
    assert_eq!(links[0]["x"].as_f64().unwrap(), -22880.0 - ox);
    assert!(m["files"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f["path"] == "links.json"));
    let skipped = r["skipped"].as_array().unwrap();
    let bad = skipped
        .iter()
        .find(|s| s["layer"] == "links")
        .expect("the malformed link is listed");
    assert_eq!(
        (bad["id"].as_str(), bad["record"].as_u64()),
        (Some("3"), Some(2))
    );
    assert!(bad["reason"].as_str().unwrap().contains("htp:/not a url"));
    let ledger = r["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "links")
        .unwrap();
    assert_eq!(
        (ledger["read"].as_u64(), ledger["unaccounted"].as_u64()),
        (Some(3), Some(0))
    );
}

#[test]
fn obj_objects_by_kind_keep_every_face_in_a_few_objects() {
    let dir = tempfile::tempdir().unwrap();
    let each = dir.path().join("each");
    build_example(&each, &["--format", "obj"]);
    let params = dir.path().join("kind.toml");
    std::fs::write(&params, "[output]\nobj_objects = \"kind\"\n").unwrap();
    let kind = dir.path().join("kind");
    build_example(
        &kind,
        &["--format", "obj", "--params", params.to_str().unwrap()],
    );
    let (a, b) = (common::build_objects(&each), common::build_objects(&kind));
    let faces = |objs: &[common::ObjObject]| objs.iter().map(|o| o.vertices.len()).sum::<usize>();
    assert_eq!(faces(&a), faces(&b), "the same triangles");
    let names: std::collections::BTreeSet<&str> = b.iter().map(|o| o.name.as_str()).collect();
    assert!(names.len() < 12, "{names:?}");
    assert!(
        names.contains("machiya") && names.contains("kura"),
        "{names:?}"
    );
    let m = read_json(&kind.join("manifest.json"));
    let obj = kind.join(m["tiles"][0]["obj"]["path"].as_str().unwrap());
    let text = std::fs::read_to_string(obj).unwrap();
    let each_text =
        std::fs::read_to_string(each.join(m["tiles"][0]["obj"]["path"].as_str().unwrap())).unwrap();
    let runs = |t: &str| t.lines().filter(|l| l.starts_with("usemtl ")).count();
    assert!(
        runs(&text) * 10 < runs(&each_text),
        "{} vs {}",
        runs(&text),
        runs(&each_text)
    );
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[output]\nobj_objects = \"houses\"\n").unwrap();
    let o = common::edo_city()
        .args(["build", fixture("kyoto-small").to_str().unwrap(), "--out"])
        .arg(dir.path().join("x"))
        .args(["--params", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("obj_objects"));
}

/// Triangles of a GLB (every primitive's index count / 3).
fn triangles(json: &Value) -> u64 {
    (json["meshes"].as_array().unwrap().iter())
        .flat_map(|m| m["primitives"].as_array().unwrap().iter())
        .map(|p| {
            json["accessors"][p["indices"].as_u64().unwrap() as usize]["count"]
                .as_u64()
                .unwrap()
                / 3
        })
        .sum()
}

/// The levels of detail: every inner node has content of its own (`tiles/lod/`), with fewer
/// triangles than its leaves, a measured error above zero, its quantized vertices inside its
/// box, and a metadata row for every house below it, so a click on a distant house names
/// its lot; no people on it, standing or walking.
#[test]
fn parents_hold_the_city_coarser_and_still_name_every_lot() {
    let out = tempfile::tempdir().unwrap();
    // Small tiles: the example town spans a few levels.
    let params = out.path().join("p.toml");
    std::fs::write(
        &params,
        "tile_size = 60.0\n[output]\nglb_compression = \"none\"\n[people]\nmotion = \"boids\"\n",
    )
    .unwrap();
    let dir = out.path().join("o");
    build_example(
        &dir,
        &["--format", "glb", "--params", params.to_str().unwrap()],
    );
    let tileset = read_json(&dir.join("tileset.json"));
    assert!(
        tileset["extras"]["levels"].as_u64().unwrap() >= 2,
        "{}",
        tileset["extras"]
    );
    // (node, its leaves' GLB paths), for every inner node.
    fn inner(node: &Value, out: &mut Vec<(Value, Vec<String>)>) -> Vec<String> {
        let Some(children) = node.get("children").and_then(|c| c.as_array()) else {
            return vec![node["content"]["uri"].as_str().unwrap().to_string()];
        };
        let leaves: Vec<String> = children.iter().flat_map(|c| inner(c, out)).collect();
        out.push((node.clone(), leaves.clone()));
        leaves
    }
    let mut parents = Vec::new();
    inner(&tileset["root"], &mut parents);
    assert!(parents.len() >= 3, "{} parents", parents.len());
    for (node, leaves) in &parents {
        let uri = node["content"]["uri"].as_str().unwrap();
        assert!(uri.starts_with("tiles/lod/"), "{uri}");
        let e = node["geometricError"].as_f64().unwrap();
        assert!((0.5..100.0).contains(&e), "{uri}: error {e}");
        let bytes = std::fs::read(dir.join(uri)).unwrap();
        let g = glb_json(&bytes);
        let lots = strings(&bytes, &g, "lot");
        let names = strings(&bytes, &g, "name");
        let mut below = 0;
        for leaf in leaves {
            let lb = std::fs::read(dir.join(leaf)).unwrap();
            let lg = glb_json(&lb);
            below += triangles(&lg);
            for (name, lot) in strings(&lb, &lg, "name")
                .iter()
                .zip(strings(&lb, &lg, "lot"))
            {
                if name.starts_with("machiya_") {
                    assert!(
                        names.contains(name) && lots.contains(&lot),
                        "{uri}: house {name} of lot {lot} has no row"
                    );
                }
            }
        }
        let here = triangles(&g);
        assert!(
            here > 0 && here < below,
            "{uri}: {here} triangles against {below} below"
        );
        // A node per kind of object (so the viewer's kind toggles reach the parents), named
        // and marked as the leaves' nodes are; the houses among them. Each node's
        // translation and scale place its quantized positions in the box.
        let nodes = g["nodes"].as_array().unwrap();
        let kinds: Vec<&str> = nodes
            .iter()
            .map(|n| n["extras"]["kind"].as_str().unwrap())
            .collect();
        assert!(kinds.windows(2).all(|w| w[0] < w[1]), "{uri}: {kinds:?}");
        assert!(
            kinds.contains(&"machiya") && kinds.len() > 3,
            "{uri}: {kinds:?}"
        );
        // No people: neither standing nor walking (the leaves' skinned crowds).
        assert!(
            kinds
                .iter()
                .all(|k| *k != "people" && !k.starts_with("crowd")),
            "{uri}: {kinds:?}"
        );
        for n in nodes {
            assert_eq!(
                n["name"],
                format!("lod_{}", n["extras"]["kind"].as_str().unwrap())
            );
        }
        for n in nodes {
            let t = floats(&n["translation"]);
            let sc = floats(&n["scale"])[0];
            let mesh = &g["meshes"][n["mesh"].as_u64().unwrap() as usize];
            for p in mesh["primitives"].as_array().unwrap() {
                let a = &g["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
                for m in [&a["min"], &a["max"]] {
                    let v = floats(m);
                    let y_up = [t[0] + sc * v[0], t[1] + sc * v[1], t[2] + sc * v[2]];
                    assert!(
                        inside(
                            &node["boundingVolume"]["box"],
                            [y_up[0], -y_up[2], y_up[1]],
                            0.1
                        ),
                        "{uri}: a vertex outside its box"
                    );
                }
            }
        }
        assert!(
            g["materials"]
                .as_array()
                .unwrap()
                .iter()
                .all(|m| !m["name"].as_str().unwrap().starts_with("person")),
            "{uri}: people are left out"
        );
    }
}
