//! Reading a GLB the build wrote, in tests: its JSON chunk, a plain view's bytes, an
//! accessor's floats, a property table's string column.

use serde_json::Value;

/// The JSON chunk of a GLB.
pub fn glb_json(bytes: &[u8]) -> Value {
    assert_eq!(&bytes[0..4], b"glTF");
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    serde_json::from_slice(&bytes[20..20 + len]).unwrap()
}

/// The bytes of one (plain, uncompressed) view of a GLB, the view given by its index.
pub fn view_bytes<'a>(glb: &'a [u8], json: &Value, view: &Value) -> &'a [u8] {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let bin = &glb[20 + len + 8..];
    let v = &json["bufferViews"][view.as_u64().unwrap() as usize];
    assert_eq!(v["buffer"], 0, "the view is plain");
    let o = v["byteOffset"].as_u64().unwrap_or(0) as usize;
    &bin[o..o + v["byteLength"].as_u64().unwrap() as usize]
}

/// The values of a float accessor (of a plain GLB), element by element.
pub fn accessor_floats(glb: &[u8], json: &Value, accessor: &Value) -> Vec<Vec<f32>> {
    let a = &json["accessors"][accessor.as_u64().unwrap() as usize];
    floats_in(view_bytes(glb, json, &a["bufferView"]), json, a)
}

/// The values of an accessor (floats or shorts) of a plain GLB in `tiles` whose view is in an external
/// buffer (a shared model, `models/<name>.bin`), element by element.
pub fn shared_floats(tiles: &std::path::Path, json: &Value, accessor: &Value) -> Vec<Vec<f32>> {
    let a = &json["accessors"][accessor.as_u64().unwrap() as usize];
    let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let b = &json["buffers"][v["buffer"].as_u64().unwrap() as usize];
    let uri = b["uri"].as_str().expect("an external buffer");
    let file = std::fs::read(tiles.join(uri)).unwrap();
    assert_eq!(
        file.len() as u64,
        b["byteLength"].as_u64().unwrap(),
        "{uri}"
    );
    let o = v["byteOffset"].as_u64().unwrap_or(0) as usize;
    floats_in(
        &file[o..o + v["byteLength"].as_u64().unwrap() as usize],
        json,
        a,
    )
}

/// The values of accessor `a` over its view's `bytes` as floats: floats, or shorts as their
/// values (positions on a grid, `KHR_mesh_quantization`).
fn floats_in(bytes: &[u8], json: &Value, a: &Value) -> Vec<Vec<f32>> {
    let size = match a["componentType"].as_u64().unwrap() {
        5126 => 4,
        5122 => 2,
        t => panic!("component type {t}"),
    };
    let n = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        t => panic!("type {t}"),
    };
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let stride = view["byteStride"].as_u64().unwrap_or(size * n as u64) as usize;
    let start = a["byteOffset"].as_u64().unwrap_or(0) as usize;
    (0..a["count"].as_u64().unwrap() as usize)
        .map(|i| {
            (0..n)
                .map(|k| {
                    let o = start + i * stride + size as usize * k;
                    match size {
                        4 => f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()),
                        _ => f32::from(i16::from_le_bytes(bytes[o..o + 2].try_into().unwrap())),
                    }
                })
                .collect()
        })
        .collect()
}

/// The strings of a string column of a GLB's property table.
pub fn strings(glb: &[u8], json: &Value, key: &str) -> Vec<String> {
    let t = &json["extensions"]["EXT_structural_metadata"]["propertyTables"][0];
    let p = &t["properties"][key];
    if p.is_null() {
        // No row has one: the column is left out.
        return vec![String::new(); t["count"].as_u64().unwrap() as usize];
    }
    let values = view_bytes(glb, json, &p["values"]);
    let offsets: Vec<usize> = view_bytes(glb, json, &p["stringOffsets"])
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as usize)
        .collect();
    offsets
        .windows(2)
        .map(|w| String::from_utf8(values[w[0]..w[1]].to_vec()).unwrap())
        .collect()
}

/// The data of each buffer of a plain GLB at `path`: the BIN chunk, or the external file a
/// buffer's URI names beside it (a shared model, `models/<name>.bin`).
pub fn buffers(path: &std::path::Path, glb: &gltf::Gltf) -> Vec<Vec<u8>> {
    glb.buffers()
        .map(|b| match b.source() {
            gltf::buffer::Source::Bin => glb.blob.clone().unwrap_or_default(),
            gltf::buffer::Source::Uri(uri) => {
                std::fs::read(path.parent().unwrap().join(uri)).unwrap()
            }
        })
        .collect()
}
