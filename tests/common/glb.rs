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
    assert_eq!(a["componentType"], 5126, "a float accessor");
    let n = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        t => panic!("type {t}"),
    };
    let view = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let stride = view["byteStride"].as_u64().unwrap_or(4 * n as u64) as usize;
    let bytes = view_bytes(glb, json, &a["bufferView"]);
    let start = a["byteOffset"].as_u64().unwrap_or(0) as usize;
    (0..a["count"].as_u64().unwrap() as usize)
        .map(|i| {
            (0..n)
                .map(|k| {
                    let o = start + i * stride + 4 * k;
                    f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap())
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
