//! Landmark models that try to read outside the input, or to exhaust memory from a small file
//! (issue 39). Each is a skip with its record and reason, or a texture left out with a
//! warning; nothing from outside the input or model directory reaches the tiles, and no
//! warning tells whether an outside file exists.

mod common;

use std::path::{Path, PathBuf};

use common::{build_ok, copy_fixture, read_json};

/// A point of the fixture town, in the output CRS, where a small model stands clear of lots.
const AT: (f64, f64) = (-22600.0, -109600.0);

/// The fixture town in `tmp/in` with `rows` as its landmarks table and `tmp/models` as the
/// model directory; returns the parameter file.
fn town(tmp: &Path, rows: &[String]) -> PathBuf {
    let input = tmp.join("in");
    copy_fixture("kyoto-small", &input);
    let mut table = String::from("id,model,kind,x,y,rotation,scale,z\n");
    for r in rows {
        table += r;
        table.push('\n');
    }
    std::fs::write(input.join("landmarks.csv"), table).unwrap();
    let params = input.join("params.toml");
    std::fs::write(
        &params,
        format!(
            "[layers.landmarks]\nfile = \"landmarks.csv\"\n[landmarks]\nmodels_dir = {:?}\n\
             anchor = \"origin\"\n",
            tmp.join("models").display().to_string()
        ),
    )
    .unwrap();
    params
}

fn row(id: &str, model: &str) -> String {
    format!("{id},{model},,{},{},0,1,", AT.0, AT.1)
}

fn build(tmp: &Path, rows: &[String]) -> serde_json::Value {
    let params = town(tmp, rows);
    build_ok(
        &tmp.join("in"),
        &tmp.join("out"),
        &["--params", params.to_str().unwrap(), "--format", "obj,glb"],
    )
}

/// The reason a landmark was skipped (panics naming it when it was not).
fn why(report: &serde_json::Value, id: &str) -> String {
    let skipped = report["landmarks"]["skipped"].as_array().unwrap();
    skipped
        .iter()
        .find(|s| s["id"] == id)
        .unwrap_or_else(|| panic!("{id} not skipped: {skipped:?}"))["reason"]
        .as_str()
        .unwrap()
        .to_string()
}

fn placed(report: &serde_json::Value) -> Vec<String> {
    report["landmarks"]["placed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["id"].as_str().unwrap().to_string())
        .collect()
}

/// A small red PNG: the bytes a build must never publish.
fn secret_png(path: &Path) -> Vec<u8> {
    let img = image::RgbImage::from_pixel(4, 4, image::Rgb([200, 17, 17]));
    img.save(path).unwrap();
    std::fs::read(path).unwrap()
}

fn triangle_obj(mtl: &str) -> String {
    format!("mtllib {mtl}\nusemtl m\nv 0 0 0\nv 10 0 0\nv 0 10 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
}

#[test]
fn mtl_textures_outside_the_directories_are_left_out_and_their_existence_not_told() {
    let tmp = tempfile::tempdir().unwrap();
    let models = tmp.path().join("models");
    let outside = tmp.path().join("outside");
    std::fs::create_dir_all(&models).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    let secret = secret_png(&outside.join("secret.png"));
    let names = [
        ("abs", outside.join("secret.png").display().to_string()),
        (
            "absmissing",
            outside.join("absent.png").display().to_string(),
        ),
        ("up", "../outside/secret.png".to_string()),
        ("upmissing", "../outside/absent.png".to_string()),
        ("zero", "/dev/zero".to_string()),
    ];
    #[cfg(unix)]
    std::os::unix::fs::symlink(outside.join("secret.png"), models.join("link.png")).unwrap();
    let mut rows = Vec::new();
    for (name, texture) in names.iter().chain(&[("link", "link.png".to_string())]) {
        std::fs::write(
            models.join(format!("{name}.mtl")),
            format!("newmtl m\nKd 1 0 0\nmap_Kd {texture}\n"),
        )
        .unwrap();
        std::fs::write(
            models.join(format!("{name}.obj")),
            triangle_obj(&format!("{name}.mtl")),
        )
        .unwrap();
        rows.push(row(name, &format!("{name}.obj")));
    }
    let report = build(tmp.path(), &rows);
    let out = tmp.path().join("out");
    // Every model stands (its material keeps its colour) ...
    assert_eq!(placed(&report).len(), 6, "{}", report["landmarks"]);
    // ... and no texture file of the build holds the outside bytes.
    for entry in std::fs::read_dir(out.join("tiles/textures")).unwrap() {
        let p = entry.unwrap().path();
        assert_ne!(std::fs::read(&p).unwrap(), secret, "{}", p.display());
        assert!(!p.to_string_lossy().contains("secret"), "{}", p.display());
    }
    for glb in std::fs::read_dir(out.join("tiles")).unwrap() {
        let p = glb.unwrap().path();
        if p.extension().is_some_and(|e| e == "glb") {
            let bytes = std::fs::read(&p).unwrap();
            assert!(
                !bytes.windows(secret.len()).any(|w| w == secret),
                "{}",
                p.display()
            );
        }
    }
    // The warnings for an existing and a missing outside file read the same but for the name.
    let text = std::fs::read_to_string(out.join("report.json")).unwrap();
    let warnings: Vec<String> = read_json(&out.join("report.json"))["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.to_string())
        .collect();
    let about = |name: &str| -> String {
        warnings
            .iter()
            .find(|w| w.contains(name))
            .unwrap_or_else(|| panic!("no warning names {name}: {warnings:?}"))
            .replace(name, "NAME")
    };
    let abs = &names[0].1;
    let absent = &names[1].1;
    assert_eq!(about(abs), about(absent));
    assert!(about(abs).contains("outside"), "{}", about(abs));
    assert_eq!(
        about("../outside/secret.png"),
        about("../outside/absent.png")
    );
    assert!(about("/dev/zero").contains("outside"));
    assert!(about("link.png").contains("outside"));
    assert!(text.contains("outside"));
}

/// A glTF of one triangle whose buffer is `uri` (36 bytes declared).
fn gltf_with_buffer(uri: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},
"buffers":[{{"uri":{uri:?},"byteLength":36}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[10,10,0]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

/// One triangle of 10 m as 36 little-endian f32 bytes.
fn triangle_bin() -> Vec<u8> {
    [0f32, 0., 0., 10., 0., 0., 0., 10., 0.]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect()
}

#[test]
fn gltf_buffers_outside_by_scheme_or_undecodable_are_skipped_with_their_record() {
    let tmp = tempfile::tempdir().unwrap();
    let models = tmp.path().join("models");
    let outside = tmp.path().join("outside");
    std::fs::create_dir_all(&models).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(outside.join("x.bin"), triangle_bin()).unwrap();
    std::fs::write(models.join("ok.bin"), triangle_bin()).unwrap();
    let file_uri = format!("file://{}", outside.join("x.bin").display());
    let cases = [
        ("ok", "ok.bin".to_string()),
        ("up", "../outside/x.bin".to_string()),
        ("fileuri", file_uri),
        ("zero", "file:///dev/zero".to_string()),
        ("devzero", "/dev/zero".to_string()),
        ("stdin", "/dev/stdin".to_string()),
        ("badpercent", "%FF%FE.bin".to_string()),
        ("web", "https://example.org/x.bin".to_string()),
    ];
    let mut rows = Vec::new();
    for (name, uri) in &cases {
        std::fs::write(models.join(format!("{name}.gltf")), gltf_with_buffer(uri)).unwrap();
        rows.push(row(name, &format!("{name}.gltf")));
    }
    let report = build(tmp.path(), &rows);
    assert_eq!(placed(&report), vec!["ok".to_string()]);
    assert!(
        why(&report, "up").contains("outside"),
        "{}",
        why(&report, "up")
    );
    for id in ["fileuri", "zero", "web"] {
        let w = why(&report, id);
        assert!(w.contains("scheme") || w.contains("outside"), "{id}: {w}");
    }
    for id in ["devzero", "stdin"] {
        let w = why(&report, id);
        assert!(w.contains("outside"), "{id}: {w}");
    }
    assert!(
        why(&report, "badpercent").contains("UTF-8")
            || why(&report, "badpercent").contains("does not exist"),
        "{}",
        why(&report, "badpercent")
    );
}

#[test]
fn declared_sizes_node_repeats_and_triangle_counts_are_checked_before_allocating() {
    let tmp = tempfile::tempdir().unwrap();
    let models = tmp.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    std::fs::write(models.join("ok.bin"), triangle_bin()).unwrap();
    std::fs::write(models.join("ok.gltf"), gltf_with_buffer("ok.bin")).unwrap();
    // A sparse accessor that claims 3e8 (and 1e11) elements in 600 bytes.
    for (name, count) in [("sparse", 300_000_000u64), ("sparse11", 100_000_000_000)] {
        let g = gltf_with_buffer("ok.bin").replace(
            r#""count":3,"type":"VEC3","#,
            &format!(
                r#""count":{count},"type":"VEC3","sparse":{{"count":{count},"indices":{{"bufferView":0,"componentType":5125}},"values":{{"bufferView":0}}}},"#
            ),
        );
        std::fs::write(models.join(format!("{name}.gltf")), g).unwrap();
    }
    // Nodes as a DAG: 40 levels of two nodes, each naming both of the next: 2^40 placements.
    let levels = 40;
    let mut nodes = Vec::new();
    for level in 0..levels {
        for _ in 0..2 {
            if level + 1 < levels {
                let (a, b) = (2 * (level + 1), 2 * (level + 1) + 1);
                nodes.push(format!(r#"{{"children":[{a},{b}]}}"#));
            } else {
                nodes.push(r#"{"mesh":0}"#.to_string());
            }
        }
    }
    let dag = gltf_with_buffer("ok.bin").replace(
        r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#,
        &format!(
            r#""nodes":[{}],"scenes":[{{"nodes":[0,1]}}]"#,
            nodes.join(",")
        ),
    );
    assert!(dag.len() < 6000);
    std::fs::write(models.join("dag.gltf"), dag).unwrap();
    // One node naming 1,000 children, each naming the same 1,000 again: the stack itself.
    let wide: Vec<String> = (0..1000).map(|i| (i + 1).to_string()).collect();
    let wide = wide.join(",");
    let mut nodes = vec![format!(r#"{{"children":[{wide}]}}"#)];
    for _ in 0..1000 {
        nodes.push(r#"{"mesh":0}"#.to_string());
    }
    let fan = gltf_with_buffer("ok.bin").replace(
        r#""nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#,
        &format!(
            r#""nodes":[{}],"scenes":[{{"nodes":[{}]}}]"#,
            nodes.join(","),
            vec!["0"; 200].join(",")
        ),
    );
    std::fs::write(models.join("fan.gltf"), fan).unwrap();
    // An OBJ of 1,000,001 triangles (8 MB): over the model limit, refused before tobj reads it.
    let mut big = String::from("v 0 0 0\nv 10 0 0\nv 0 10 0\n");
    big.reserve(8_000_010);
    for _ in 0..1_000_001 {
        big += "f 1 2 3\n";
    }
    std::fs::write(models.join("big.obj"), big).unwrap();
    let rows: Vec<String> = [
        "ok.gltf",
        "sparse.gltf",
        "sparse11.gltf",
        "dag.gltf",
        "fan.gltf",
        "big.obj",
    ]
    .iter()
    .map(|m| row(m.split('.').next().unwrap(), m))
    .collect();
    let report = build(tmp.path(), &rows);
    assert_eq!(
        placed(&report),
        vec!["ok".to_string()],
        "{}",
        report["landmarks"]
    );
    for id in ["sparse", "sparse11"] {
        assert!(
            why(&report, id).contains("too large to place"),
            "{}",
            why(&report, id)
        );
    }
    for id in ["dag", "fan"] {
        assert!(
            why(&report, id).contains("places more than"),
            "{}",
            why(&report, id)
        );
    }
    assert!(
        why(&report, "big").contains("triangles"),
        "{}",
        why(&report, "big")
    );
}

#[test]
fn landmark_triangles_are_budgeted_per_tile_with_the_rest_skipped() {
    let tmp = tempfile::tempdir().unwrap();
    let models = tmp.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    // 600,000 triangles: under the model limit; two at one point pass the tile's budget.
    let mut obj = String::from("v 0 0 0\nv 10 0 0\nv 0 10 0\n");
    for _ in 0..600_000 {
        obj += "f 1 2 3\n";
    }
    std::fs::write(models.join("heavy.obj"), obj).unwrap();
    let rows = vec![row("first", "heavy.obj"), row("second", "heavy.obj")];
    let report = build(tmp.path(), &rows);
    assert_eq!(placed(&report), vec!["first".to_string()]);
    let w = why(&report, "second");
    assert!(
        w.contains("past 1000000") && w.contains("holds 600000"),
        "{w}"
    );
    // The ledger closes: both read, one built, one skipped.
    let lm = report["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "landmarks")
        .unwrap();
    assert_eq!(
        (lm["built"].as_u64(), lm["skipped"].as_u64()),
        (Some(1), Some(1))
    );
}

/// A glTF of one triangle whose positions are an `EXT_meshopt_compression` view: the
/// compressed bytes in `compressed.bin`, the view in a fallback buffer of `fallback` bytes,
/// with `ext` added to the view's extension object.
fn meshopt_gltf(compressed_len: usize, fallback: u64, ext: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},
"extensionsUsed":["EXT_meshopt_compression"],"extensionsRequired":["EXT_meshopt_compression"],
"buffers":[{{"uri":"compressed.bin","byteLength":{compressed_len}}},
  {{"byteLength":{fallback},"extensions":{{"EXT_meshopt_compression":{{"fallback":true}}}}}}],
"bufferViews":[{{"buffer":1,"byteLength":36,"byteStride":12,"extensions":{{"EXT_meshopt_compression":
  {{"buffer":0,"byteLength":{compressed_len},"byteStride":12,"count":3,"mode":"ATTRIBUTES"{ext}}}}}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[10,10,0]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

#[test]
fn meshopt_compressed_models_are_decoded_and_damaged_ones_skipped_with_why() {
    let tmp = tempfile::tempdir().unwrap();
    let models = tmp.path().join("models");
    std::fs::create_dir_all(&models).unwrap();
    let triangle: Vec<[u8; 12]> = triangle_bin()
        .chunks(12)
        .map(|c| c.try_into().unwrap())
        .collect();
    let packed = meshopt::encoding::encode_vertex_buffer(&triangle).unwrap();
    std::fs::write(models.join("compressed.bin"), &packed).unwrap();
    let n = packed.len();
    let cases = [
        ("ok", meshopt_gltf(n, 36, "")),
        ("filtered", meshopt_gltf(n, 36, r#","filter":"OCTAHEDRAL""#)),
        ("huge", meshopt_gltf(n, 1 << 40, "")),
        (
            "short",
            meshopt_gltf(n, 36, "").replace(r#""count":3"#, r#""count":2"#),
        ),
    ];
    let mut rows = Vec::new();
    for (name, text) in &cases {
        std::fs::write(models.join(format!("{name}.gltf")), text).unwrap();
        rows.push(row(name, &format!("{name}.gltf")));
    }
    // Garbage where the compressed bytes should be.
    std::fs::write(models.join("garbage.bin"), vec![0xa0; n]).unwrap();
    std::fs::write(
        models.join("garbage.gltf"),
        meshopt_gltf(n, 36, "").replace("compressed.bin", "garbage.bin"),
    )
    .unwrap();
    rows.push(row("garbage", "garbage.gltf"));
    let report = build(tmp.path(), &rows);
    assert_eq!(placed(&report), vec!["ok".to_string()]);
    assert!(why(&report, "filtered").contains("OCTAHEDRAL filter"));
    assert!(
        why(&report, "huge").contains("more than"),
        "{}",
        why(&report, "huge")
    );
    assert!(
        why(&report, "short").contains("damaged"),
        "{}",
        why(&report, "short")
    );
    let g = why(&report, "garbage");
    assert!(
        g.contains("does not decode") || g.contains("damaged"),
        "{g}"
    );
}
