//! `[output] glb_compression`: the default `"meshopt"` tiles decode to exactly the
//! `"none"` tiles (the index codec may rotate a triangle's corners, keeping its winding),
//! are smaller, and the plain ones pass Khronos' glTF-Validator with their data checked
//! (the validator does not know `EXT_meshopt_compression` and skips compressed views).
//! A value that is neither is refused naming the key.

mod common;

use std::path::Path;

use common::{build_ok, edo_city, fixture, read_json};
use serde_json::Value;

/// The JSON chunk and the BIN chunk of a GLB.
fn chunks(bytes: &[u8]) -> (Value, &[u8]) {
    assert_eq!(&bytes[0..4], b"glTF");
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let bin = bytes.get(20 + len + 8..).unwrap_or(&[]);
    (json, bin)
}

/// The bytes of view `v` of a GLB: decoded when compressed. Triangles come back each
/// starting at its smallest index, so that rotations compare equal.
fn view_bytes(json: &Value, bin: &[u8], v: usize) -> Vec<u8> {
    let view = &json["bufferViews"][v];
    let Some(e) = view["extensions"].get("EXT_meshopt_compression") else {
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().unwrap() as usize;
        return bin[start..start + len].to_vec();
    };
    assert_eq!(e["buffer"], 0, "compressed bytes live in the BIN chunk");
    assert_eq!(
        view["buffer"], 1,
        "a compressed view points into the fallback buffer"
    );
    let start = e["byteOffset"].as_u64().unwrap() as usize;
    let src = &bin[start..start + e["byteLength"].as_u64().unwrap() as usize];
    let count = e["count"].as_u64().unwrap() as usize;
    let stride = e["byteStride"].as_u64().unwrap() as usize;
    let out: Vec<u8> = match (e["mode"].as_str().unwrap(), stride) {
        ("TRIANGLES", 2) => {
            let i: Vec<u16> = meshopt::encoding::decode_index_buffer(src, count).unwrap();
            i.iter().flat_map(|x| x.to_le_bytes()).collect()
        }
        ("TRIANGLES", 4) => {
            let i: Vec<u32> = meshopt::encoding::decode_index_buffer(src, count).unwrap();
            i.iter().flat_map(|x| x.to_le_bytes()).collect()
        }
        ("ATTRIBUTES", 4) => decode::<4>(src, count),
        ("ATTRIBUTES", 8) => decode::<8>(src, count),
        ("ATTRIBUTES", 12) => decode::<12>(src, count),
        other => panic!("unexpected compressed view {other:?}"),
    };
    assert_eq!(out.len(), view["byteLength"].as_u64().unwrap() as usize);
    out
}

/// One vertex of `N` bytes (the decoder asks `Default`, which `[u8; N]` lacks for any `N`).
#[derive(Clone, Copy)]
#[repr(transparent)]
struct Element<const N: usize>([u8; N]);

impl<const N: usize> Default for Element<N> {
    fn default() -> Self {
        Element([0; N])
    }
}

fn decode<const N: usize>(src: &[u8], count: usize) -> Vec<u8> {
    let v: Vec<Element<N>> = meshopt::encoding::decode_vertex_buffer(src, count).unwrap();
    v.into_iter().flat_map(|e| e.0).collect()
}

/// An index view's triangles, each rotated to start at its smallest index.
fn triangles(bytes: &[u8], width: usize) -> Vec<[u32; 3]> {
    let idx: Vec<u32> = bytes
        .chunks_exact(width)
        .map(|c| match width {
            2 => u16::from_le_bytes([c[0], c[1]]) as u32,
            _ => u32::from_le_bytes(c.try_into().unwrap()),
        })
        .collect();
    idx.chunks_exact(3)
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect()
}

fn build(out: &Path, compression: &str, dir: &Path) -> Value {
    let params = dir.join(format!("{compression}.toml"));
    std::fs::write(
        &params,
        format!("[output]\nformats = [\"glb\"]\nglb_compression = \"{compression}\"\n"),
    )
    .unwrap();
    build_ok(
        &fixture("kyoto-small"),
        out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    )
}

#[test]
fn meshopt_tiles_decode_to_the_plain_tiles_and_are_smaller() {
    let dir = tempfile::tempdir().unwrap();
    let (packed, plain) = (dir.path().join("meshopt"), dir.path().join("none"));
    build(&packed, "meshopt", dir.path());
    build(&plain, "none", dir.path());
    let manifest = read_json(&plain.join("manifest.json"));
    let (mut packed_bytes, mut plain_bytes, mut compared) = (0, 0, 0);
    for t in manifest["tiles"].as_array().unwrap() {
        let rel = t["glb"]["path"].as_str().unwrap();
        let a = std::fs::read(packed.join(rel)).unwrap();
        let b = std::fs::read(plain.join(rel)).unwrap();
        packed_bytes += a.len();
        plain_bytes += b.len();
        let ((ja, bin_a), (jb, bin_b)) = (chunks(&a), chunks(&b));
        assert_eq!(ja["accessors"], jb["accessors"], "{rel}");
        assert_eq!(ja["meshes"], jb["meshes"], "{rel}");
        assert_eq!(
            ja["extensionsRequired"],
            serde_json::json!(["KHR_mesh_quantization", "EXT_meshopt_compression"])
        );
        assert_eq!(
            jb["extensionsRequired"],
            serde_json::json!(["KHR_mesh_quantization"])
        );
        assert!(jb["bufferViews"].to_string().find("meshopt").is_none());
        let indices: Vec<(usize, usize)> = jb["accessors"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|a| a["componentType"] == 5123 || a["componentType"] == 5125)
            .map(|a| {
                let w = if a["componentType"] == 5123 { 2 } else { 4 };
                (a["bufferView"].as_u64().unwrap() as usize, w)
            })
            .collect();
        for v in 0..jb["bufferViews"].as_array().unwrap().len() {
            let (x, y) = (view_bytes(&ja, bin_a, v), view_bytes(&jb, bin_b, v));
            match indices.iter().find(|(i, _)| *i == v) {
                Some(&(_, w)) => assert_eq!(triangles(&x, w), triangles(&y, w), "{rel} view {v}"),
                None => assert!(x == y, "{rel} view {v} decodes to other bytes"),
            }
            compared += 1;
        }
    }
    assert!(compared > 100, "{compared} views compared");
    // Measured on the example: 0.53 of the plain bytes.
    assert!(
        packed_bytes * 10 < plain_bytes * 7,
        "meshopt {packed_bytes} bytes against {plain_bytes} plain"
    );
}

#[test]
fn plain_tiles_pass_the_khronos_validator_with_their_data_checked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("none");
    build(&out, "none", dir.path());
    common::validate_glbs(&out);
}

#[test]
fn an_unknown_compression_is_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[output]\nglb_compression = \"draco\"\n").unwrap();
    let o = edo_city()
        .args(["build", "--params", params.to_str().unwrap()])
        .arg(fixture("kyoto-small"))
        .arg("-o")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("output.glb_compression") && err.contains("draco"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists());
}
