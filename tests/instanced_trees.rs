//! Grown trees in the GLB tiles by instancing (`EXT_mesh_gpu_instancing`, issue 40): every
//! grown tree of a tile is an instance of its variant's model, with its own metadata row
//! (`tree_<id>`, its lot), standing where `placements.csv` and the OBJ's copies have it: the
//! model moved by each instance lands on the OBJ's `trees_grown` vertices. The GLB holds no
//! copies, nor the model: each variant is one file, `tiles/models/<species>_<k>.bin`, that
//! every tile planting it references and lists in the manifest.

mod common;

use std::collections::{HashMap, HashSet};

use common::glb::{accessor_floats, glb_json, shared_floats, strings};
use common::{build_ok, synth};

/// `v` rotated by the unit quaternion `q` (x, y, z, w).
fn rotate(q: &[f32], v: [f64; 3]) -> [f64; 3] {
    let (x, y, z, w) = (q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64);
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let c1 = cross([x, y, z], v);
    let c2 = cross([x, y, z], c1);
    [0, 1, 2].map(|k| v[k] + 2.0 * w * c1[k] + 2.0 * c2[k])
}

/// The vertices of object `name` of an OBJ tile (output frame, metres).
fn obj_vertices(obj: &str, name: &str) -> Vec<[f64; 3]> {
    let mut all = Vec::new();
    let mut mine = Vec::new();
    let mut current = String::new();
    for line in obj.lines() {
        if let Some(rest) = line.strip_prefix("o ") {
            current = rest.to_string();
        } else if let Some(rest) = line.strip_prefix("v ") {
            let p: Vec<f64> = rest
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            all.push([p[0], p[1], p[2]]);
            if current == name {
                mine.push([p[0], p[1], p[2]]);
            }
        }
    }
    mine
}

#[test]
fn each_grown_tree_is_an_instance_with_its_row_where_the_obj_has_its_copy() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 600, 3);
    let params = dir.path().join("trees.toml");
    std::fs::write(
        &params,
        "[trees]\nstyle = \"lsystem\"\nper_ha = 300.0\nmax_tile_bytes = 20000000\n[output]\nglb_compression = \"none\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let r = build_ok(
        &town,
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let grown = r["trees"]["by_lod"]["lod1"].as_u64().unwrap();
    assert!(grown > 50, "{}", r["trees"]);

    // placements.csv: id -> (x, y, z) in the output frame.
    let csv = std::fs::read_to_string(out.join("species/placements.csv")).unwrap();
    let placed: HashMap<String, [f64; 3]> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let n = |i: usize| f[i].parse::<f64>().unwrap();
            (f[0].to_string(), [n(4), n(5), n(6)])
        })
        .collect();

    let mut instances = 0u64;
    let mut models: HashSet<String> = HashSet::new();
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    for t in manifest["tiles"].as_array().unwrap() {
        let id = t["id"].as_str().unwrap();
        let bytes = std::fs::read(out.join(format!("tiles/{id}.glb"))).unwrap();
        let g = glb_json(&bytes);
        let names = strings(&bytes, &g, "name");
        let lots = strings(&bytes, &g, "lot");
        let obj = std::fs::read_to_string(out.join(format!("tiles/{id}.obj"))).unwrap();
        // The OBJ's copies, on a 1 cm grid (each vertex in its cell and the ones around).
        let copies = obj_vertices(&obj, "trees_grown");
        let mut grid: HashSet<[i64; 3]> = HashSet::new();
        for p in &copies {
            let c = p.map(|v| (v * 100.0).floor() as i64);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        grid.insert([c[0] + dx, c[1] + dy, c[2] + dz]);
                    }
                }
            }
        }
        let nodes = g["nodes"].as_array().cloned().unwrap_or_default();
        assert!(
            nodes.iter().all(|n| n["name"] != "trees_grown"),
            "{id}: the copies are not in the GLB"
        );
        let mut shift: Option<[f64; 3]> = None;
        for n in nodes {
            let Some(e) = n["extensions"].get("EXT_mesh_gpu_instancing") else {
                continue;
            };
            assert_eq!(n["extras"]["kind"], "trees");
            let a = &e["attributes"];
            let tr = accessor_floats(&bytes, &g, &a["TRANSLATION"]);
            let ro = accessor_floats(&bytes, &g, &a["ROTATION"]);
            let sc = accessor_floats(&bytes, &g, &a["SCALE"]);
            let ids = accessor_floats(&bytes, &g, &a["_FEATURE_ID_0"]);
            let f = &n["extensions"]["EXT_instance_features"]["featureIds"][0];
            assert_eq!(f["featureCount"].as_u64().unwrap() as usize, tr.len());
            let mesh = &g["meshes"][n["mesh"].as_u64().unwrap() as usize];
            let tiles = out.join("tiles");
            let model: Vec<Vec<f32>> = mesh["primitives"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(|p| shared_floats(&tiles, &g, &p["attributes"]["POSITION"]))
                .collect();
            // The variant's file, listed with the tile.
            let file = format!("tiles/models/{}.bin", mesh["name"].as_str().unwrap());
            assert!(
                t["models"].as_array().is_some(),
                "{id}: the manifest lists no models with it"
            );
            models.insert(file);
            for i in 0..tr.len() {
                instances += 1;
                let row = ids[i][0] as usize;
                let tree = names[row].strip_prefix("tree_").expect("a tree's row");
                let at = placed[tree];
                // Its foot where placements.csv has it, up to the tile's centre.
                let d = [0, 1, 2].map(|k| at[k] - tr[i][k] as f64);
                let s = *shift.get_or_insert(d);
                assert!(
                    (0..3).all(|k| (d[k] - s[k]).abs() < 0.002),
                    "{id} {tree}: {d:?} vs {s:?}"
                );
                assert!(!lots[row].is_empty(), "{tree} names its lot");
                // The model moved by the instance lands on the OBJ's copy.
                for p in model.iter().step_by(7) {
                    let v = [0, 1, 2].map(|k| p[k] as f64 * sc[i][k] as f64);
                    let r = rotate(&ro[i], v);
                    let w = [0, 1, 2].map(|k| r[k] + tr[i][k] as f64 + s[k]);
                    let c = w.map(|v| (v * 100.0).floor() as i64);
                    assert!(grid.contains(&c), "{id} {tree}: {w:?} is on no OBJ vertex");
                }
            }
        }
    }
    assert_eq!(instances, grown, "every grown tree is an instance");
    // Each variant's model is one file for the whole city, listed by the tiles that draw it.
    let listed: HashSet<String> = (manifest["tiles"].as_array().unwrap().iter())
        .flat_map(|t| t["models"].as_array().cloned().unwrap_or_default())
        .map(|f| f["path"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(listed, models);
    let on_disk = std::fs::read_dir(out.join("tiles/models")).unwrap().count();
    assert_eq!(on_disk, models.len(), "no other file in tiles/models");
}

/// The shared models are part of the city as its tiles are: shards in separate directories
/// merged, and a tile rebuilt with `--tiles` (its model deleted first), give the full build's
/// files byte for byte; a build without variants leaves no model behind.
#[test]
fn shared_models_follow_shards_merge_and_single_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 300, 5);
    let params = dir.path().join("trees.toml");
    std::fs::write(&params, "[trees]\nstyle = \"lsystem\"\nper_ha = 200.0\n").unwrap();
    let p = params.to_str().unwrap();
    let full = dir.path().join("full");
    build_ok(&town, &full, &["--quiet", "--params", p]);
    let models = common::all_files(&full.join("tiles/models"));
    assert!(models.len() > 3, "{} models", models.len());
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for (out, shard) in [(&a, "1/2"), (&b, "2/2")] {
        common::run_ok(&town, out, &["--quiet", "--params", p, "--shard", shard]);
    }
    common::edo_city()
        .arg("merge")
        .arg(&a)
        .arg(&b)
        .assert()
        .success();
    common::assert_same_tree(&full, &a);
    // One tile again, its first model gone: written back, the same bytes.
    let manifest = common::read_json(&full.join("manifest.json"));
    let tile = (manifest["tiles"].as_array().unwrap().iter())
        .find(|t| t["models"].as_array().is_some_and(|m| !m.is_empty()))
        .unwrap();
    let model = tile["models"][0]["path"].as_str().unwrap();
    std::fs::remove_file(full.join(model)).unwrap();
    let id = tile["id"].as_str().unwrap();
    build_ok(&town, &full, &["--quiet", "--params", p, "--tiles", id]);
    assert_eq!(
        common::all_files(&full.join("tiles/models")),
        models,
        "{model} written back"
    );
    // Without variants no tile names a model: the directory goes.
    std::fs::write(
        &params,
        "[trees]\nstyle = \"lsystem\"\nper_ha = 200.0\nvariants = 0\n",
    )
    .unwrap();
    build_ok(&town, &full, &["--quiet", "--params", p, "--force"]);
    assert!(!full.join("tiles/models").exists());
}
