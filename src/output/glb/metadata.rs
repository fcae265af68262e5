//! Per-object metadata as `EXT_structural_metadata`: one class (`object`) and one property
//! table with a row per object of the tile, which the `_FEATURE_ID_0` vertex attribute of
//! `EXT_mesh_features` points into. Names and lots are strings (UTF-8 with UINT32 offsets);
//! the columns of few distinct values (kind, type, district, use, source) are ENUMs of the
//! tile's values, a byte or two a row (the strings of a parent tile over 35,000 objects took
//! 2.1 MB, the enums 0.2 MB); an empty value is the enum's `noData`, which readers give as
//! no value. `kura` is a BOOLEAN bitstream, least significant bit first.

use serde_json::{json, Map, Value};

use super::buffer::Buffer;
use crate::output::features::Feature;

/// The string properties, in table order, with what each holds.
const STRINGS: &[(&str, &str)] = &[
    ("name", "the object's name in the OBJ tile"),
    (
        "lot",
        "the lot (or footprint, fence line, garden polygon) it belongs to",
    ),
];

/// The enum properties, in table order, with what each holds.
pub const ENUMS: &[(&str, &str)] = &[
    (
        "kind",
        "machiya, footprint, kura, fence, gate, people, trees, garden, stone, ...",
    ),
    ("mtype", "the machiya type"),
    ("district", "the lot's district"),
    ("use", "the lot's use: machiya, buke, kuge, jisha, ..."),
    (
        "source",
        "the layer file it came from, relative to the input directory",
    ),
];

/// The name of an enum's value for an empty string.
pub const NO_VALUE: &str = "(none)";

/// The string of property `key` of `f`.
fn value<'a>(f: &'a Feature, key: &str) -> &'a str {
    match key {
        "name" => &f.name,
        "kind" => &f.kind,
        "lot" => &f.lot,
        "mtype" => &f.mtype,
        "district" => &f.district,
        "use" => &f.lot_use,
        _ => &f.source,
    }
}

/// The extension's top-level object for `features`, its tables written into `buf`.
pub fn structural_metadata(features: &[Feature], buf: &mut Buffer) -> Value {
    let mut class_props = Map::new();
    let mut table_props = Map::new();
    for (key, what) in STRINGS {
        class_props.insert(
            key.to_string(),
            json!({"type": "STRING", "description": what}),
        );
        let mut values = Vec::new();
        let mut offsets: Vec<u8> = Vec::with_capacity(4 * (features.len() + 1));
        offsets.extend_from_slice(&0u32.to_le_bytes());
        for f in features {
            values.extend_from_slice(value(f, key).as_bytes());
            offsets.extend_from_slice(&(values.len() as u32).to_le_bytes());
        }
        if values.is_empty() {
            // No object has one (a view may not be empty): the column is left out, which
            // the extension reads as "no value" for every row.
            continue;
        }
        let v = buf.view(&values, None);
        let o = buf.view(&offsets, None);
        table_props.insert(key.to_string(), json!({"values": v, "stringOffsets": o}));
    }
    let mut enums = Map::new();
    for (key, what) in ENUMS {
        // Values in sorted order after "no value": the same values give the same bytes.
        let mut names: Vec<&str> = features.iter().map(|f| value(f, key)).collect();
        names.sort_unstable();
        names.dedup();
        names.retain(|n| !n.is_empty());
        let wide = names.len() + 1 > 256;
        let mut bytes = Vec::with_capacity(features.len() * if wide { 2 } else { 1 });
        for f in features {
            let v = value(f, key);
            let i = match v.is_empty() {
                true => 0,
                false => names.binary_search(&v).map_or(0, |i| i + 1),
            };
            if wide {
                bytes.extend_from_slice(&(i as u16).to_le_bytes());
            } else {
                bytes.push(i as u8);
            }
        }
        let values: Vec<Value> = std::iter::once(NO_VALUE)
            .chain(names.iter().copied())
            .enumerate()
            .map(|(i, n)| json!({"name": n, "value": i}))
            .collect();
        enums.insert(
            key.to_string(),
            json!({"valueType": if wide { "UINT16" } else { "UINT8" }, "values": values}),
        );
        class_props.insert(
            key.to_string(),
            json!({"type": "ENUM", "enumType": key, "noData": NO_VALUE, "description": what}),
        );
        let v = buf.view(&bytes, None);
        table_props.insert(key.to_string(), json!({"values": v}));
    }
    class_props.insert(
        "kura".into(),
        json!({"type": "BOOLEAN", "description": "whether the lot has a kura in this tile"}),
    );
    let mut bits = vec![0u8; features.len().div_ceil(8).max(1)];
    for (i, f) in features.iter().enumerate() {
        if f.kura {
            bits[i / 8] |= 1 << (i % 8);
        }
    }
    let v = buf.view(&bits, None);
    table_props.insert("kura".into(), json!({"values": v}));
    json!({
        "schema": {
            "id": "edo_city",
            "enums": enums,
            "classes": {"object": {
                "description": "one object of the city: a house, a kura, a wall, a garden stone, the people or trees of a tile",
                "properties": class_props,
            }},
        },
        "propertyTables": [{
            "class": "object",
            "count": features.len(),
            "properties": table_props,
        }],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_and_booleans_are_laid_out_as_the_extension_reads_them() {
        let f = |name: &str, kura| Feature {
            name: name.into(),
            kura,
            ..Feature::default()
        };
        let mut buf = Buffer::default();
        let ext = structural_metadata(&[f("ab", false), f("c", true)], &mut buf);
        let t = &ext["propertyTables"][0];
        assert_eq!(t["count"], 2);
        let view = |i: &Value| {
            let v = &buf.views[i.as_u64().unwrap() as usize];
            let o = v["byteOffset"].as_u64().unwrap() as usize;
            &buf.bin[o..o + v["byteLength"].as_u64().unwrap() as usize]
        };
        assert_eq!(view(&t["properties"]["name"]["values"]), b"abc");
        assert_eq!(
            view(&t["properties"]["name"]["stringOffsets"]),
            [0u32, 2, 3]
                .iter()
                .flat_map(|x| x.to_le_bytes())
                .collect::<Vec<_>>()
        );
        assert_eq!(view(&t["properties"]["kura"]["values"]), [0b10]);
    }
}
