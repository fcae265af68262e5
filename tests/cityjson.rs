//! The city as a CityJSON 2.0 model (issue 60): `--format ...,cityjson` writes
//! `city.city.jsonl`, which CityJSON's official validator (cjval) passes with no error and no
//! warning, which holds every building the report counts once with its lot, the walls,
//! gates, ground, streets and gardens, the grown trees as instances of one template per
//! variant; the same bytes for any thread count, `--tiles`, and shards merged.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::cityjson::{objects, read, validate};
use common::{build_ok, fixture, read_json};
use serde_json::Value;

const FORMATS: &str = "obj,glb,gpkg,cityjson";

fn assert_valid(path: &Path) -> usize {
    let v = validate(path);
    assert!(v.errors.is_empty(), "{}", v.errors.join("\n"));
    assert!(v.warnings.is_empty(), "{}", v.warnings.join("\n"));
    v.features
}

/// The types of a model's city objects, counted.
fn types(features: &[Value]) -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    for (_, o) in objects(features) {
        *out.entry(o["type"].as_str().unwrap().to_string())
            .or_default() += 1;
    }
    out
}

/// The validator of these tests finds what cjval finds: a feature's index past its own
/// vertices, a surface not closed, an unknown semantic type, a city object twice.
#[test]
fn the_validator_finds_broken_features() {
    let dir = tempfile::tempdir().unwrap();
    let header = r#"{"type":"CityJSON","version":"2.0","transform":{"scale":[0.001,0.001,0.001],"translate":[0,0,0]},"CityObjects":{},"vertices":[]}"#;
    let good = |id: &str, last: u32| {
        format!(
            r#"{{"type":"CityJSONFeature","id":"{id}","CityObjects":{{"{id}":{{"type":"CityFurniture","geometry":[{{"type":"MultiSurface","lod":"2","boundaries":[[[0,1,{last}]]]}}]}}}},"vertices":[[0,0,0],[1000,0,0],[0,1000,0]]}}"#
        )
    };
    let file = dir.path().join("m.city.jsonl");
    let write = |lines: &[String]| {
        std::fs::write(&file, format!("{header}\n{}\n", lines.join("\n"))).unwrap();
        validate(&file)
    };
    let ok = write(&[good("a", 2), good("b", 2)]);
    assert!(
        ok.errors.is_empty() && ok.warnings.is_empty(),
        "{:?}",
        ok.errors
    );
    assert_eq!(ok.features, 2);
    // Index 3 of a feature with three vertices: the next feature's first vertex once the
    // two are one document, yet wrong.
    assert!(!write(&[good("a", 3), good("b", 2)]).errors.is_empty());
    assert!(!write(&[good("a", 2), good("a", 2)]).errors.is_empty());
    let unknown = good("c", 2).replace("CityFurniture", "Teahouse");
    assert!(!write(&[good("a", 2), unknown]).errors.is_empty());
    let twice = good("d", 2).replace("[1000,0,0]", "[0,0,0]");
    let v = write(&[twice]);
    assert!(!v.errors.is_empty() || !v.warnings.is_empty());
}

#[test]
fn the_example_town_is_a_valid_city_model_holding_every_building_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let report = build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--format", FORMATS],
    );
    let file = out.join("city.city.jsonl");
    let n = assert_valid(&file);
    let (header, features) = read(&file);
    assert_eq!(features.len(), n);
    assert_eq!(
        (header["type"].as_str(), header["version"].as_str()),
        (Some("CityJSON"), Some("2.0"))
    );
    assert_eq!(
        header["transform"]["scale"],
        serde_json::json!([0.001, 0.001, 0.001])
    );
    // The fixture's .prj names JGD2011 zone VI without an AUTHORITY: found by its name.
    assert_eq!(
        header["metadata"]["referenceSystem"],
        "https://www.opengis.net/def/crs/EPSG/0/6674"
    );
    let hypothesis = header["metadata"]["identifier"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        hypothesis.starts_with("edo-city/") && hypothesis.ends_with("/seed-1"),
        "{hypothesis}"
    );

    // Every building the report counts, once, with its lot.
    let c = &report["counts"];
    let halls = (report["halls"].as_array().into_iter().flatten())
        .filter(|h| h["placed"] == true)
        .count() as u64;
    let built = c["machiya"].as_u64().unwrap()
        + c["footprints"].as_u64().unwrap()
        + c["kura"].as_u64().unwrap()
        + halls;
    let all = objects(&features);
    let buildings: Vec<&(String, Value)> = all
        .iter()
        .filter(|(_, o)| o["type"] == "Building")
        .collect();
    assert_eq!(buildings.len() as u64, built, "{c}");
    let mut ids: Vec<&String> = buildings.iter().map(|(id, _)| id).collect();
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), buildings.len(), "each once");
    for (id, b) in &buildings {
        let a = &b["attributes"];
        assert!(a["lot"].is_string(), "{id}: {a}");
        assert!(a["record"].is_u64(), "{id}: {a}");
        assert!(a["measuredHeight"].as_f64().unwrap() > 2.0, "{id}: {a}");
        assert!(a["storeysAboveGround"].as_u64().unwrap() >= 1, "{id}: {a}");
        assert!(a["roofType"].is_string(), "{id}: {a}");
        let lods: Vec<&str> = (b["geometry"].as_array().unwrap().iter())
            .map(|g| g["lod"].as_str().unwrap())
            .collect();
        assert_eq!(lods, ["1", "2"], "{id}: an LoD1 block and the LoD2 model");
    }
    // A machiya: a closed body (a Solid) with roofs, walls and its ground, its pent roof an
    // installation; its street named.
    let (id, house) = buildings
        .iter()
        .find(|(id, _)| id.starts_with("machiya_"))
        .unwrap();
    let lod2 = &house["geometry"][1];
    assert_eq!(lod2["type"], "Solid", "{id}");
    let surfaces: Vec<&str> = (lod2["semantics"]["surfaces"].as_array().unwrap().iter())
        .map(|s| s["type"].as_str().unwrap())
        .collect();
    for s in ["RoofSurface", "WallSurface", "GroundSurface"] {
        assert!(surfaces.contains(&s), "{id}: {surfaces:?}");
    }
    assert!(house["attributes"]["street"].is_string(), "{id}");
    let children = house["children"].as_array().unwrap();
    let hisashi = format!("{id}-hisashi");
    assert!(
        children.iter().any(|c| c == hisashi.as_str()),
        "{children:?}"
    );
    let (_, inst) = all.iter().find(|(k, _)| *k == hisashi).unwrap();
    assert_eq!(inst["type"], "BuildingInstallation");
    assert_eq!(inst["parents"][0], id.as_str());

    // Walls and gates, ground, streets, the temple's rock garden; no people.
    let t = types(&features);
    for ty in ["CityFurniture", "LandUse", "Road", "PlantCover"] {
        assert!(t.contains_key(ty), "{t:?}");
    }
    let walls = (all.iter())
        .filter(|(_, o)| o["attributes"]["function"] == "wall")
        .count();
    assert!(walls > 0, "{t:?}");
    assert!(!all.iter().any(|(id, _)| id.starts_with("people")));
    let m = read_json(&out.join("manifest.json"));
    let listed = m["files"].as_array().unwrap();
    assert!(listed.iter().any(|f| f["path"] == "city.city.jsonl"));

    // cjio, a client of the format, reads it: its info gives the buildings the report counts
    // and the CRS.
    let info = cjio_info(&file);
    assert!(info.contains(&format!("Building ({built})")), "{info}");
    assert!(info.contains("EPSG = 6674"), "{info}");
    assert!(info.contains("CityJSON version = 2.0"), "{info}");
}

/// `cjio stdin info` of a CityJSONSeq (cjio in target/cjio-venv: `make cityjson-deps`).
fn cjio_info(file: &Path) -> String {
    let target = std::env::var("CARGO_TARGET_DIR").map_or_else(
        |_| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"),
        std::path::PathBuf::from,
    );
    let cjio = target.join("cjio-venv/bin/cjio");
    assert!(
        cjio.exists(),
        "{} is missing: run `make cityjson-deps`",
        cjio.display()
    );
    let o = std::process::Command::new(cjio)
        .args(["stdin", "info"])
        .stdin(std::fs::File::open(file).unwrap())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A 300-lot synth town in `dir/town` and parameters that grow its trees from their
/// grammars, dense enough for every variant to be planted.
fn grown_tree_town(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let town = dir.join("town");
    common::synth(&town, 300, 5);
    let params = dir.join("trees.toml");
    std::fs::write(&params, "[trees]\nstyle = \"lsystem\"\nper_ha = 200.0\n").unwrap();
    (town, params)
}

#[test]
fn grown_trees_are_instances_of_one_template_per_variant() {
    let dir = tempfile::tempdir().unwrap();
    let (town, params) = grown_tree_town(dir.path());
    let out = dir.path().join("out");
    let p = params.to_str().unwrap();
    build_ok(
        &town,
        &out,
        &["--quiet", "--params", p, "--format", FORMATS],
    );
    let file = out.join("city.city.jsonl");
    assert_valid(&file);
    let (header, features) = read(&file);
    let templates = header["geometry-templates"]["templates"]
        .as_array()
        .unwrap();
    assert!(templates.len() > 1, "{}", templates.len());
    let trees: Vec<Value> = (objects(&features).into_iter())
        .filter(|(_, o)| o["type"] == "SolitaryVegetationObject")
        .map(|(_, o)| o)
        .filter(|o| o["geometry"][0]["type"] == "GeometryInstance")
        .collect();
    assert!(trees.len() > 10, "{}", trees.len());
    let mut used = std::collections::BTreeSet::new();
    for t in &trees {
        let k = t["geometry"][0]["template"].as_u64().unwrap() as usize;
        assert!(k < templates.len());
        used.insert(k);
        assert!(t["attributes"]["species"].is_string());
    }
    assert_eq!(used.len(), templates.len(), "every template drawn");
}

/// `[output] cityjson_textures = true`: textured surfaces name the library's images (files
/// the build wrote) with a coordinate for each corner; the model stays valid; without it, no
/// texture is named.
#[test]
fn textures_are_named_when_asked_and_valid() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("textures.toml");
    std::fs::write(&params, "[output]\ncityjson_textures = true\n").unwrap();
    let out = dir.path().join("out");
    let p = params.to_str().unwrap();
    let args = ["--quiet", "--params", p, "--format", "cityjson"];
    build_ok(&fixture("kyoto-small"), &out, &args);
    let file = out.join("city.city.jsonl");
    assert_valid(&file);
    let (_, features) = read(&file);
    let mut textured = 0;
    for f in &features {
        let Some(images) = f["appearance"]["textures"].as_array() else {
            continue;
        };
        let uvs = f["appearance"]["vertices-texture"].as_array().unwrap();
        for t in images {
            let image = t["image"].as_str().unwrap();
            assert!(image.starts_with("tiles/textures/"), "{image}");
            assert!(out.join(image).is_file(), "{image} is written");
        }
        for (_, o) in f["CityObjects"].as_object().unwrap() {
            for g in o["geometry"].as_array().into_iter().flatten() {
                let Some(values) = g["texture"]["visual"]["values"].as_array() else {
                    continue;
                };
                // A solid's surfaces are one shell deeper.
                let surfaces = match g["type"].as_str() {
                    Some("Solid") => values[0].as_array().unwrap(),
                    _ => values,
                };
                let rings = match g["type"].as_str() {
                    Some("Solid") => g["boundaries"][0].as_array().unwrap(),
                    _ => g["boundaries"].as_array().unwrap(),
                };
                assert_eq!(surfaces.len(), rings.len());
                for (s, r) in surfaces.iter().zip(rings) {
                    let ring = s[0].as_array().unwrap();
                    if ring[0].is_null() {
                        continue;
                    }
                    textured += 1;
                    assert!((ring[0].as_u64().unwrap() as usize) < images.len());
                    assert_eq!(ring.len() - 1, r[0].as_array().unwrap().len());
                    assert!(ring[1..]
                        .iter()
                        .all(|k| (k.as_u64().unwrap() as usize) < uvs.len()));
                }
            }
        }
    }
    assert!(textured > 1000, "{textured} textured surfaces");
    // The same town without it: colours only (and the same as before the key existed).
    // (Its summary says where the model is.)
    let plain = dir.path().join("plain");
    let o = common::edo_city()
        .arg("build")
        .arg(fixture("kyoto-small"))
        .arg("--out")
        .arg(&plain)
        .args(["--format", "cityjson"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("in 3D GIS: ") && said.contains("city.city.jsonl"),
        "{said}"
    );
    let text = std::fs::read_to_string(plain.join("city.city.jsonl")).unwrap();
    assert!(!text.contains("\"texture\""));
    assert!(text.contains("\"diffuseColor\""));
}

/// Builds `town` into `out` with `extra` flags, the model's formats and parameters `p`.
fn build(town: &Path, out: &Path, p: &str, extra: &[&str]) {
    let mut args = vec!["--quiet", "--params", p, "--format", FORMATS];
    args.extend(extra);
    common::run_ok(town, out, &args);
}

#[test]
fn the_model_is_the_same_bytes_for_any_thread_count_single_tiles_and_merged_shards() {
    let dir = tempfile::tempdir().unwrap();
    let (town, params) = grown_tree_town(dir.path());
    let p = params.to_str().unwrap();
    let (one, two) = (dir.path().join("j1"), dir.path().join("j2"));
    build(&town, &one, p, &["-j", "1"]);
    build(&town, &two, p, &["-j", "2"]);
    let model = |d: &Path| std::fs::read(d.join("city.city.jsonl")).unwrap();
    assert_eq!(model(&one), model(&two));
    // One tile again, its fragment and a template gone: the same file.
    let m = read_json(&two.join("manifest.json"));
    let tile = &m["tiles"][0];
    std::fs::remove_file(two.join(tile["cityjson"]["path"].as_str().unwrap())).unwrap();
    if let Some(t) = (tile["models"].as_array().into_iter().flatten())
        .find(|f| f["path"].as_str().unwrap().starts_with("tiles/templates/"))
    {
        std::fs::remove_file(two.join(t["path"].as_str().unwrap())).unwrap();
    }
    build(&town, &two, p, &["--tiles", tile["id"].as_str().unwrap()]);
    assert_eq!(model(&one), model(&two));
    // Shards in two directories, merged.
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    build(&town, &a, p, &["--shard", "1/2"]);
    build(&town, &b, p, &["--shard", "2/2"]);
    common::edo_city()
        .arg("merge")
        .arg(&a)
        .arg(&b)
        .assert()
        .success();
    assert_eq!(model(&one), model(&a));
}

/// The real sets (their cut in a clone without ../shared) validate too.
#[test]
fn real_towns_are_valid_city_models() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (set, example) in [
        ("chino_plateau_devpermit", "chino"),
        ("osaka_plateau", "osaka"),
    ] {
        let full = repo.join("../shared/data/real").join(set);
        let dir = match full.is_dir() {
            true => full,
            false => repo.join("fixtures/real").join(set),
        };
        let work = tempfile::tempdir().unwrap();
        let params = repo.join("params/examples").join(format!("{example}.toml"));
        let out = work.path().join("out");
        let report = build_ok(
            &dir,
            &out,
            &[
                "--quiet",
                "--params",
                params.to_str().unwrap(),
                "--format",
                "obj,cityjson",
            ],
        );
        let file = out.join("city.city.jsonl");
        assert_valid(&file);
        let (_, features) = read(&file);
        let buildings = types(&features).get("Building").copied().unwrap_or(0) as u64;
        let c = &report["counts"];
        let landmarks = report["landmarks"]["placed"]
            .as_array()
            .map_or(0, |p| p.len()) as u64;
        assert_eq!(
            buildings,
            c["machiya"].as_u64().unwrap()
                + c["footprints"].as_u64().unwrap()
                + c["kura"].as_u64().unwrap()
                + landmarks,
            "{set}: {c}"
        );
    }
}

#[test]
fn a_model_that_cannot_be_written_is_named_not_the_output_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o_dir");
    std::fs::create_dir_all(out.join("city.city.jsonl")).unwrap();
    let o = common::build_cmd(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--format", "cityjson"],
    )
    .output()
    .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains(&format!(
            "cannot write {}",
            out.join("city.city.jsonl").display()
        )),
        "{err}"
    );
}
