//! The crowds' looping clip (issue 41): walkers walk the street network (round corners, in
//! groups, at people's pace, apart), the clip ends where it starts, `crowds/<tile>.csv` holds
//! every key, the GLB's animation moves each walker's node through the same places (read
//! from the file, and played by three.js in Debian's chromium), and bad `[crowd]` values are
//! refused naming the key.

mod common;

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use common::glb::{accessor_floats, glb_json};
use common::{build_ok, edo_city, fixture, read_json, synth};

/// One CSV row: t, x, y, z, heading (degrees).
type Key = [f64; 5];

/// Every walker's keys and group, from every `crowds/*.csv` of a build.
fn clips(out: &Path) -> (BTreeMap<String, Vec<Key>>, HashMap<String, String>) {
    let (mut keys, mut groups) = (BTreeMap::new(), HashMap::new());
    let m = read_json(&out.join("manifest.json"));
    for t in m["tiles"].as_array().unwrap() {
        let Some(path) = t["crowds"]["path"].as_str() else {
            continue;
        };
        let mut r = csv::Reader::from_path(out.join(path)).unwrap();
        assert_eq!(
            r.headers().unwrap().iter().collect::<Vec<_>>(),
            ["t", "id", "x", "y", "z", "heading", "group"]
        );
        for row in r.records() {
            let row = row.unwrap();
            let f = |k: usize| row[k].parse::<f64>().unwrap();
            keys.entry(row[1].to_string())
                .or_insert_with(Vec::new)
                .push([f(0), f(2), f(3), f(4), f(5)]);
            groups.insert(row[1].to_string(), row[6].to_string());
        }
    }
    (keys, groups)
}

fn quantile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

#[test]
fn walkers_loop_round_corners_in_groups_at_peoples_pace_and_apart() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 1500, 5);
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[people]\nmotion = \"boids\"\nper_100m = 12.0\n").unwrap();
    let out = dir.path().join("out");
    build_ok(
        &town,
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let (keys, groups) = clips(&out);
    assert!(keys.len() > 200, "{} walkers", keys.len());
    let data = edo_city::input::read_dataset(
        &town,
        &edo_city::params::Params::from_toml_str("", "x").unwrap(),
    )
    .unwrap();
    let (mut paces, mut steps, mut corners) = (Vec::new(), Vec::new(), 0);
    for (id, k) in &keys {
        // 60 s in keys of 0.5 s; the last key is the first (the clip loops without a jump).
        assert_eq!(k.len(), 121, "{id}");
        assert_eq!(k[120][1..], k[0][1..], "{id} does not come back");
        assert!((k[120][0] - 60.0).abs() < 1e-9);
        let d: Vec<f64> = k
            .windows(2)
            .map(|w| (w[1][1] - w[0][1]).hypot(w[1][2] - w[0][2]) / 0.5)
            .collect();
        paces.push(d.iter().sum::<f64>() / d.len() as f64);
        steps.extend(d);
        // The streets it walks along (the nearest centreline at each key): two or more is a
        // walker that turned a corner.
        let streets: std::collections::BTreeSet<&str> = k
            .iter()
            .step_by(4)
            .map(|p| {
                data.streets
                    .iter()
                    .map(|s| {
                        let d = s
                            .line
                            .lines()
                            .map(|l| {
                                edo_city::geom::segment::segment_distance_2(
                                    [p[1], p[2]],
                                    l.start.into(),
                                    l.end.into(),
                                )
                            })
                            .fold(f64::INFINITY, f64::min);
                        (d, s.id.as_str())
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .unwrap()
                    .1
            })
            .collect();
        corners += usize::from(streets.len() > 1);
    }
    // People's pace: 1.0-1.6 m/s over the clip (pedestrians.md), few steps out of it.
    let (lo, hi) = (quantile(paces.clone(), 0.0), quantile(paces.clone(), 1.0));
    assert!(lo >= 0.9 && hi <= 1.6, "paces {lo:.2} to {hi:.2} m/s");
    let p99 = quantile(steps.clone(), 0.99);
    assert!(p99 <= 1.8, "1 % of steps faster than {p99:.2} m/s");
    assert!(
        corners * 10 > keys.len(),
        "{corners} of {} walkers turned a corner",
        keys.len()
    );
    // Apart: at every tenth key, the share of walkers with someone nearer than
    // people.min_spacing (0.8 m).
    let ids: Vec<&String> = keys.keys().collect();
    let (mut near, mut seen) = (0usize, 0usize);
    for k in (0..121).step_by(10) {
        for (i, a) in ids.iter().enumerate() {
            let p = keys[*a][k];
            seen += 1;
            near += usize::from(ids.iter().enumerate().any(|(j, b)| {
                let q = keys[*b][k];
                j != i && (p[1] - q[1]).hypot(p[2] - q[2]) < 0.8
            }));
        }
    }
    assert!(
        near * 20 < seen,
        "{near} of {seen} walker-keys had someone nearer than 0.8 m"
    );
    // Groups stay together: each member within 2.5 m of its group's centre at 95 % of keys.
    let mut by_group: HashMap<&str, Vec<&String>> = HashMap::new();
    for id in &ids {
        by_group.entry(groups[*id].as_str()).or_default().push(id);
    }
    let mut spread = Vec::new();
    for members in by_group.values().filter(|m| m.len() > 1) {
        #[allow(clippy::needless_range_loop)] // k is a time: every member at it
        for k in 0..121 {
            let n = members.len() as f64;
            let cx = members.iter().map(|m| keys[*m][k][1]).sum::<f64>() / n;
            let cy = members.iter().map(|m| keys[*m][k][2]).sum::<f64>() / n;
            for m in members {
                spread.push((keys[*m][k][1] - cx).hypot(keys[*m][k][2] - cy));
            }
        }
    }
    assert!(!spread.is_empty(), "no group of two or more");
    let p95 = quantile(spread, 0.95);
    assert!(p95 <= 2.5, "group members {p95:.2} m from their centre");
}

/// A walker's node in a tile's GLB and the times and places of its translation keys.
fn node_clip(glb: &[u8], json: &serde_json::Value, person: &str) -> Vec<(f32, [f32; 3])> {
    let nodes = json["nodes"].as_array().unwrap();
    let node = nodes
        .iter()
        .position(|n| n["extras"]["person"] == person)
        .expect("the walker's node");
    let clip = &json["animations"][0];
    assert_eq!(clip["name"], "crowd");
    let ch = clip["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["target"]["node"] == node && c["target"]["path"] == "translation")
        .unwrap();
    let s = &clip["samplers"][ch["sampler"].as_u64().unwrap() as usize];
    assert_eq!(s["interpolation"], "LINEAR");
    // Every output is floats: CesiumJS read normalized short rotations as raw integers.
    for c in clip["channels"].as_array().unwrap() {
        let s = &clip["samplers"][c["sampler"].as_u64().unwrap() as usize];
        let output = &json["accessors"][s["output"].as_u64().unwrap() as usize];
        assert_eq!(output["componentType"], 5126, "{c}");
    }
    let times = accessor_floats(glb, json, &s["input"]);
    let at = accessor_floats(glb, json, &s["output"]);
    times
        .iter()
        .zip(at)
        .map(|(t, p)| (t[0], [p[0], p[1], p[2]]))
        .collect()
}

/// The example town with walkers, its GLB uncompressed (Blender 3.4 and the validator read
/// no meshopt), built into `dir/out`.
fn walking_town(dir: &Path) -> std::path::PathBuf {
    let params = dir.join("p.toml");
    std::fs::write(
        &params,
        "[people]\nmotion = \"boids\"\nper_100m = 12.0\n[output]\nglb_compression = \"none\"\n",
    )
    .unwrap();
    let out = dir.join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    out
}

#[test]
fn the_glb_clip_moves_each_walker_through_its_csv_places_in_the_file_and_in_three_js() {
    let dir = tempfile::tempdir().unwrap();
    let out = walking_town(dir.path());
    let (keys, _) = clips(&out);
    // Khronos' validator reads the animation (uncompressed here) without an error or warning.
    common::validate_glbs(&out);
    let m = read_json(&out.join("manifest.json"));
    let tile = m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["crowds"].is_object() && t["glb"].is_object())
        .unwrap();
    let glb = std::fs::read(out.join(tile["glb"]["path"].as_str().unwrap())).unwrap();
    let json = glb_json(&glb);
    // Each walker of the tile's CSV has a node, and the people_walking copies are not drawn.
    let csv = std::fs::read_to_string(out.join(tile["crowds"]["path"].as_str().unwrap())).unwrap();
    let in_tile: std::collections::BTreeSet<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    let nodes: Vec<&serde_json::Value> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n["extras"]["person"].is_string())
        .collect();
    assert_eq!(nodes.len(), in_tile.len());
    // ... a joint of one skin (at most 32 a skin), drawn by a skinned mesh of the skin's
    // figures: a draw call per skin and material, not per walker.
    let skins = json["skins"].as_array().unwrap();
    assert_eq!(skins.len(), in_tile.len().div_ceil(32), "{skins:?}");
    let mut joints: Vec<u64> = skins
        .iter()
        .flat_map(|s| s["joints"].as_array().unwrap())
        .map(|j| j.as_u64().unwrap())
        .collect();
    assert!(skins
        .iter()
        .all(|s| s["joints"].as_array().unwrap().len() <= 32));
    joints.sort_unstable();
    let persons: Vec<u64> = (json["nodes"].as_array().unwrap().iter().enumerate())
        .filter(|(_, n)| n["extras"]["person"].is_string())
        .map(|(i, n)| {
            assert!(n.get("mesh").is_none(), "{n}");
            i as u64
        })
        .collect();
    assert_eq!(joints, persons);
    let skinned: Vec<&serde_json::Value> = (json["nodes"].as_array().unwrap().iter())
        .filter(|n| n.get("skin").is_some())
        .collect();
    assert_eq!(skinned.len(), skins.len());
    for n in skinned {
        let mesh = &json["meshes"][n["mesh"].as_u64().unwrap() as usize];
        for p in mesh["primitives"].as_array().unwrap() {
            assert!(p["attributes"]["JOINTS_0"].is_u64() && p["attributes"]["WEIGHTS_0"].is_u64());
        }
    }
    assert!(json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .all(|n| n["name"] != "people_walking"));
    // Between any two kept keys a walker's node moves as far as its CSV says, and its clip
    // ends where it starts.
    let mut checked = 0;
    let (mut person, mut pair) = (String::new(), (0.0, 0.0));
    for id in &in_tile {
        let clip = node_clip(&glb, &json, id);
        assert_eq!(clip.first().unwrap().1, clip.last().unwrap().1, "{id}");
        assert!((clip.last().unwrap().0 - 60.0).abs() < 1e-4);
        let k = &keys[*id];
        let key = |t: f32| k[(t as f64 / 0.5).round() as usize];
        for w in clip.windows(2) {
            let (a, b) = (w[0], w[1]);
            let node = (b.1[0] - a.1[0]).hypot(b.1[2] - a.1[2]) as f64;
            let (ka, kb) = (key(a.0), key(b.0));
            let csv = (kb[1] - ka[1]).hypot(kb[2] - ka[2]);
            assert!(
                (node - csv).abs() < 0.003,
                "{id} {a:?} {b:?}: {node} vs {csv}"
            );
            checked += 1;
            if node > 3.0 && person.is_empty() {
                person = id.to_string();
                pair = (a.0 as f64, b.0 as f64);
            }
        }
    }
    assert!(checked > 100 && !person.is_empty(), "{checked}");
    // three.js' GLTFLoader in the viewer plays the same clip: the node at the two times.
    let mut serve = std::process::Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    serve.args(["serve", "--port", "0"]).arg(&out);
    let (server, url) = common::start_server(serve);
    let k = &keys[&person];
    let east_north = (
        k[0][1] - m["origin"][0].as_f64().unwrap(),
        k[0][2] - m["origin"][1].as_f64().unwrap(),
    );
    let (got, text) = common::run_browser_script(
        "crowd.mjs",
        &[
            url.as_ref(),
            person.as_ref(),
            east_north.0.to_string().as_ref(),
            east_north.1.to_string().as_ref(),
            pair.0.to_string().as_ref(),
            pair.1.to_string().as_ref(),
        ],
        &[],
    );
    drop(server);
    assert_eq!(got["errors"], serde_json::json!([]), "{text}");
    assert_eq!(got["duration"], 60.0, "{text}");
    assert!(got["walkers"].as_u64().unwrap() > 0);
    let (a, b) = (&got["first"]["at"], &got["second"]["at"]);
    let f = |v: &serde_json::Value, i: usize| v[i].as_f64().unwrap();
    let moved = (f(b, 0) - f(a, 0)).hypot(f(b, 2) - f(a, 2));
    let (ka, kb) = (
        k[(pair.0 / 0.5).round() as usize],
        k[(pair.1 / 0.5).round() as usize],
    );
    let expected = (kb[1] - ka[1]).hypot(kb[2] - ka[2]);
    assert!(
        (moved - expected).abs() < 0.01,
        "three.js moved {person} {moved} m from {}s to {}s, the CSV {expected} m: {text}",
        pair.0,
        pair.1
    );
    assert_eq!(got["picked"], person.as_str(), "{text}");
    assert_eq!(got["paused_held"], true, "{text}");
    assert_eq!(got["played_on"], true, "{text}");
    // The street clicked there charts its stretch's crowd: lambda1-3 each second, 0-59 s.
    let chart = &got["chart"];
    assert_eq!(chart["points"], 60, "{text}");
    assert_eq!(chart["canvas"], true, "{text}");
    let r = read_json(&out.join("report.json"));
    assert!(r["crowds"]["streets"]
        .as_array()
        .unwrap()
        .iter()
        .any(|s| s["street"] == chart["street"]));
}

/// Debian's Blender on tests/blender/clip.py: its JSON line (every `person_<id>` object's
/// world place and yaw at each of `times`). Blender, like rustc, stalls under the libfaketime
/// that scripts/test-future.sh preloads (recursive clock_gettime in its allocator): it runs
/// on the real clock, as the browser does; it only reads the file a build wrote.
fn blender_clip(glb: &Path, times: &[f64], home: &Path) -> serde_json::Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/blender/clip.py");
    assert!(
        Path::new("/usr/bin/blender").exists(),
        "Debian's blender is missing: run `make blender-deps`"
    );
    // `timeout`: a hung Blender fails the test instead of holding the suite.
    let o = std::process::Command::new("timeout")
        .args(["300", "/usr/bin/blender", "-b", "--factory-startup"])
        .args(["--python-exit-code", "1", "--python"])
        .arg(&script)
        .arg("--")
        .arg(glb)
        .args(times.iter().map(|t| t.to_string()))
        .env_remove("LD_PRELOAD")
        .env_remove("FAKETIME")
        .env("HOME", home)
        .env("BLENDER_USER_CONFIG", home)
        .env("BLENDER_USER_SCRIPTS", home)
        .output()
        .expect("blender runs");
    let text = common::succeeded(&o);
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("EDO_CITY_JSON "))
        .unwrap_or_else(|| panic!("no EDO_CITY_JSON line: {text}"));
    serde_json::from_str(line).unwrap()
}

/// The difference of two angles in radians, folded into 0..=pi.
fn angle_between(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}

#[test]
fn blenders_gltf_importer_plays_the_same_clip_as_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let out = walking_town(dir.path());
    let (keys, _) = clips(&out);
    let m = read_json(&out.join("manifest.json"));
    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
    ];
    let mut walkers = 0;
    let mut turned = 0;
    // Every tile with walkers, each walker at every key of its CSV (every 0.5 s, 0-60 s).
    for tile in m["tiles"].as_array().unwrap() {
        let Some(csv) = tile["crowds"]["path"].as_str() else {
            continue;
        };
        let text = std::fs::read_to_string(out.join(csv)).unwrap();
        let in_tile: std::collections::BTreeSet<&str> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(1).unwrap())
            .collect();
        let glb = out.join(tile["glb"]["path"].as_str().unwrap());
        // A tile's GLB is about its centre (the tileset's transform puts it in place).
        let centre = [
            origin[0] + tile["centre"][0].as_f64().unwrap(),
            origin[1] + tile["centre"][1].as_f64().unwrap(),
        ];
        let times: Vec<f64> = keys[*in_tile.first().unwrap()]
            .iter()
            .map(|k| k[0])
            .collect();
        assert_eq!(times.len(), 121);
        let got = blender_clip(&glb, &times, dir.path());
        // The importer's clock: 24 frames a second, time 0 at frame 0.
        assert_eq!(got["fps"], 24.0, "{got}");
        let at = got["at"].as_object().unwrap();
        assert_eq!(
            at.keys().map(String::as_str).collect::<Vec<_>>(),
            in_tile.iter().copied().collect::<Vec<_>>(),
            "one Blender object or bone per walker of {csv}"
        );
        for (id, places) in at {
            let k = &keys[id];
            let places = places.as_array().unwrap();
            assert_eq!(places.len(), k.len());
            for (p, key) in places.iter().zip(k) {
                let f = |i: usize| p[i].as_f64().unwrap();
                // Blender turns glTF's Y up into Z up: x east, y north of the tile's
                // centre. Within the 2 cm the clip's thinning allows, and the CSV's mm.
                let off = (f(0) - (key[1] - centre[0])).hypot(f(1) - (key[2] - centre[1]));
                assert!(
                    off < 0.025,
                    "{id} at {} s: Blender {:?}, CSV {key:?}",
                    key[0],
                    p
                );
                assert!((f(2) - key[3]).abs() < 0.025, "{id} at {} s: {p:?}", key[0]);
                // Its yaw about Z is the CSV's heading (the thinning's 0.02 rad, nlerp).
                let yaw = angle_between(f(3), key[4].to_radians());
                assert!(
                    yaw < 0.03,
                    "{id} at {} s: yaw {} vs heading {}",
                    key[0],
                    f(3),
                    key[4]
                );
            }
            if angle_between(k[0][4].to_radians(), k[k.len() / 2][4].to_radians()) > 0.5 {
                turned += 1;
            }
            walkers += 1;
        }
    }
    assert!(
        walkers > 100 && turned > 10,
        "{walkers} walkers, {turned} turned"
    );
}

#[test]
fn bad_clip_lengths_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for (text, key) in [
        ("[crowd]\nduration = 1e9\n", "crowd.duration"),
        ("[crowd]\nduration = 0.0\n", "crowd.duration"),
        ("[crowd]\ndt = 0.001\n", "crowd.dt"),
        ("[crowd]\nduration = 3600.0\ndt = 0.1\n", "crowd.dt"),
        ("[crowd]\nstraight = -1.0\n", "crowd.straight"),
    ] {
        let p = dir.path().join("bad.toml");
        std::fs::write(&p, format!("[people]\nmotion = \"boids\"\n{text}")).unwrap();
        let o = edo_city()
            .arg("build")
            .arg(fixture("kyoto-small"))
            .arg("--out")
            .arg(dir.path().join("out"))
            .args(["--quiet", "--params", p.to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(key), "{text}: {err}");
    }
}

#[test]
fn a_street_asked_for_more_walkers_than_it_holds_is_thinned_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("busy.toml");
    std::fs::write(
        &p,
        "[people]\nmotion = \"boids\"\nper_100m = 200.0\nmin_spacing = 0.3\nedge_margin = 3.0\n",
    )
    .unwrap();
    let r = build_ok(
        &fixture("kyoto-small"),
        &dir.path().join("out"),
        &["--quiet", "--no-plan", "--params", p.to_str().unwrap()],
    );
    let warnings = r["warnings"].to_string();
    assert!(warnings.contains("walkers thinned"), "{warnings}");
}
