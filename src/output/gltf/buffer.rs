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
    /// Pads the buffer to the next view's 8-byte boundary; returns where the view starts.
    fn align(&mut self) -> usize {
        let start = self.bin.len().next_multiple_of(8);
        self.bin.resize(start, 0);
        start
    }

    /// Records the bytes from `start` to the end as a view (with `target`, if any); returns
    /// its index.
    fn close_view(&mut self, start: usize, target: Option<u32>) -> usize {
        let mut v = json!({
            "buffer": 0,
            "byteOffset": start,
            "byteLength": self.bin.len() - start,
        });
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.views.push(v);
        self.views.len() - 1
    }

    /// Appends `bytes` as a view (with `target`, if any); returns its index.
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let start = self.align();
        self.bin.extend_from_slice(bytes);
        self.close_view(start, target)
    }

    /// Appends `data` little-endian as a view, written straight into the buffer (a tile's
    /// vertices are most of its bytes; each copy of them was measured).
    fn numbers<T: Copy, const N: usize>(
        &mut self,
        data: &[T],
        bytes: impl Fn(T) -> [u8; N],
        target: Option<u32>,
    ) -> usize {
        let start = self.align();
        self.bin.resize(start + N * data.len(), 0);
        for (out, &x) in self.bin[start..].chunks_exact_mut(N).zip(data) {
            out.copy_from_slice(&bytes(x));
        }
        self.close_view(start, target)
    }

    /// A float accessor of `n`-component elements (`SCALAR`, `VEC2`, `VEC3`), with `min`
    /// and `max` when asked (positions must have them).
    pub fn floats(&mut self, data: &[f32], n: usize, bounds: bool) -> usize {
        let view = self.numbers(data, f32::to_le_bytes, Some(VERTICES));
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

    /// A unit-vector accessor (normals) quantized to normalized bytes (`KHR_mesh_quantization`):
    /// 4 bytes a vertex (x, y, z and a pad, as vertex attributes align to 4) instead of 12.
    /// A byte step is 1/127: under half a degree, which flat-shaded walls and roofs cannot
    /// show; the shaders normalize the normal again.
    pub fn unit_vectors(&mut self, data: &[f32]) -> usize {
        let q = |x: f32| ((x.clamp(-1.0, 1.0) * 127.0).round() as i8).to_le_bytes()[0];
        let packed: Vec<[u8; 4]> = data
            .chunks_exact(3)
            .map(|v| [q(v[0]), q(v[1]), q(v[2]), 0])
            .collect();
        let view = self.numbers(&packed, |b| b, Some(VERTICES));
        self.views[view]["byteStride"] = json!(4);
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": 5120,
            "normalized": true,
            "count": packed.len(),
            "type": "VEC3",
        }));
        self.accessors.len() - 1
    }

    /// The index accessor: u16 while the vertices fit, else u32.
    pub fn indices(&mut self, idx: &[u32], vertices: usize) -> usize {
        let (view, ctype) = if vertices <= u16::MAX as usize {
            let view = self.numbers(idx, |i| (i as u16).to_le_bytes(), Some(INDICES));
            (view, 5123)
        } else {
            (self.numbers(idx, u32::to_le_bytes, Some(INDICES)), 5125)
        };
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": ctype,
            "count": idx.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

/// A GLB file in two pieces, written one after the other: the header with the JSON chunk and
/// the BIN chunk's header, then the BIN bytes (not copied into one buffer with the head: they
/// are most of a tile).
pub struct Glb {
    /// Header, JSON chunk, BIN chunk header.
    pub head: Vec<u8>,
    /// The BIN chunk's bytes, zero-padded to 4.
    pub bin: Vec<u8>,
}

impl Glb {
    /// The file's pieces in order.
    pub fn parts(&self) -> [&[u8]; 2] {
        [&self.head, &self.bin]
    }
}

/// The GLB container: header, JSON chunk (space-padded) and BIN chunk (zero-padded).
pub fn glb(json: &Value, mut bin: Vec<u8>) -> Glb {
    let mut j = serde_json::to_vec(json).expect("glTF JSON serialises");
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + j.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut head = Vec::with_capacity(28 + j.len());
    head.extend_from_slice(b"glTF");
    head.extend_from_slice(&2u32.to_le_bytes());
    head.extend_from_slice(&(total as u32).to_le_bytes());
    head.extend_from_slice(&(j.len() as u32).to_le_bytes());
    head.extend_from_slice(b"JSON");
    head.extend_from_slice(&j);
    if !bin.is_empty() {
        head.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        head.extend_from_slice(b"BIN\0");
    }
    Glb { head, bin }
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
        let out = glb(&json!({"asset": {"version": "2.0"}}), b.bin)
            .parts()
            .concat();
        assert_eq!(&out[0..4], b"glTF");
        let total = u32::from_le_bytes(out[8..12].try_into().unwrap()) as usize;
        assert_eq!(total, out.len());
        let jlen = u32::from_le_bytes(out[12..16].try_into().unwrap()) as usize;
        assert_eq!(jlen % 4, 0);
        assert_eq!(&out[20 + jlen + 4..20 + jlen + 8], b"BIN\0");
    }

    #[test]
    fn normals_become_padded_normalized_bytes() {
        let mut b = Buffer::default();
        let a = b.unit_vectors(&[0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.6, 0.8, 0.0]);
        let acc = &b.accessors[a];
        assert_eq!(
            (&acc["componentType"], &acc["normalized"], &acc["count"]),
            (&json!(5120), &json!(true), &json!(3))
        );
        let view = acc["bufferView"].as_u64().unwrap() as usize;
        assert_eq!(b.views[view]["byteStride"], 4);
        assert_eq!(b.views[view]["byteLength"], 12);
        let q = |v: i8| v.to_le_bytes()[0];
        assert_eq!(
            b.bin,
            [0, 0, q(127), 0, q(-127), 0, 0, 0, q(76), q(102), 0, 0]
        );
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
