//! The binary half of a GLB: one BIN buffer of views, each 8-byte aligned (the structural
//! metadata extension asks 8 for its tables; vertex data needs 4), and the accessors over
//! them, collected as glTF JSON.

use serde_json::{json, Value};

/// `ELEMENT_ARRAY_BUFFER` / `ARRAY_BUFFER` targets.
pub const INDICES: u32 = 34963;
/// Vertex attributes.
pub const VERTICES: u32 = 34962;

/// The BIN chunk being built, with its views and accessors.
#[derive(Default)]
pub struct Buffer {
    /// The bytes.
    pub bin: Vec<u8>,
    /// `bufferViews`.
    pub views: Vec<Value>,
    /// `accessors`.
    pub accessors: Vec<Value>,
}

impl Buffer {
    /// Appends `bytes` as a view (with `target`, if any); returns its index.
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(8) {
            self.bin.push(0);
        }
        let mut v = json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
        });
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// A float accessor of `n`-component elements (`SCALAR`, `VEC2`, `VEC3`), with `min`
    /// and `max` when asked (positions must have them).
    pub fn floats(&mut self, data: &[f32], n: usize, bounds: bool) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(VERTICES));
        let kind = match n {
            1 => "SCALAR",
            2 => "VEC2",
            3 => "VEC3",
            _ => "VEC4",
        };
        let mut a = json!({
            "bufferView": view,
            "componentType": 5126,
            "count": data.len() / n,
            "type": kind,
        });
        if bounds {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            for e in data.chunks_exact(n) {
                for k in 0..n {
                    lo[k] = lo[k].min(e[k]);
                    hi[k] = hi[k].max(e[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// The index accessor: u16 while the vertices fit, else u32.
    pub fn indices(&mut self, idx: &[u32], vertices: usize) -> usize {
        let (bytes, ctype): (Vec<u8>, u32) = if vertices <= u16::MAX as usize {
            (
                idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
                5123,
            )
        } else {
            (idx.iter().flat_map(|&i| i.to_le_bytes()).collect(), 5125)
        };
        let view = self.view(&bytes, Some(INDICES));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": ctype,
            "count": idx.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

/// The GLB container: header, JSON chunk (space-padded) and BIN chunk (zero-padded).
pub fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).expect("glTF JSON serialises");
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_are_aligned_and_the_container_adds_up() {
        let mut b = Buffer::default();
        b.view(&[1, 2, 3], None);
        let second = b.view(&[4], None);
        assert_eq!(b.views[second]["byteOffset"], 8);
        let out = glb(&json!({"asset": {"version": "2.0"}}), &b.bin);
        assert_eq!(&out[0..4], b"glTF");
        let total = u32::from_le_bytes(out[8..12].try_into().unwrap()) as usize;
        assert_eq!(total, out.len());
        let jlen = u32::from_le_bytes(out[12..16].try_into().unwrap()) as usize;
        assert_eq!(jlen % 4, 0);
        assert_eq!(&out[20 + jlen + 4..20 + jlen + 8], b"BIN\0");
    }

    #[test]
    fn indices_widen_past_u16() {
        let mut b = Buffer::default();
        let a = b.indices(&[0, 1, 2], 3);
        assert_eq!(b.accessors[a]["componentType"], 5123);
        let a = b.indices(&[0, 1, 70_000], 70_001);
        assert_eq!(b.accessors[a]["componentType"], 5125);
    }
}
