//! The binary half of a GLB: one BIN buffer of views, each 8-byte aligned (the structural
//! metadata extension asks 8 for its tables; vertex data needs 4), and the accessors over
//! them, collected as glTF JSON.
//!
//! With meshopt on, vertex and index views are `EXT_meshopt_compression` views: their
//! compressed bytes are in the BIN buffer and the view itself points into buffer 1, a
//! fallback buffer with no data that the decoder fills (the extension's layout for files
//! that require it). The metadata's views stay plain: they are small, and three.js' metadata
//! plugin reads them straight from the buffer.

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
    /// Vertex and index views compressed by meshopt.
    pub meshopt: bool,
    /// The decoded size of the compressed views: the fallback buffer's `byteLength`.
    pub fallback: usize,
    /// External buffers (shared models, see [`super::models`]): URI and length, numbered
    /// after the BIN chunk and the fallback buffer.
    pub externals: Vec<(String, usize)>,
}

/// meshopt's two codecs, as `EXT_meshopt_compression` names them.
#[derive(Clone, Copy)]
enum Mode {
    /// The vertex codec over elements of a fixed size.
    Attributes,
    /// The index codec over triangles.
    Triangles,
}

impl Buffer {
    /// An empty buffer whose vertex and index views are compressed when `meshopt` is set.
    pub fn new(meshopt: bool) -> Buffer {
        Buffer {
            meshopt,
            ..Buffer::default()
        }
    }

    /// The glTF `buffers`: the BIN chunk, the fallback buffer when a view was compressed
    /// (or an external buffer needs index 1 to be it), then the external buffers.
    pub fn buffers_json(&self) -> Value {
        let mut out = vec![json!({"byteLength": self.bin.len().next_multiple_of(4)})];
        if self.fallback > 0 || (self.meshopt && !self.externals.is_empty()) {
            out.push(json!({
                "byteLength": self.fallback.max(4),
                "extensions": {"EXT_meshopt_compression": {"fallback": true}},
            }));
        }
        for (uri, length) in &self.externals {
            out.push(json!({"uri": uri, "byteLength": length}));
        }
        json!(out)
    }

    /// The index of the external buffer `uri` (`length` bytes), added at first use. With
    /// meshopt on, index 1 is the fallback buffer, written even if no view of the tile's own
    /// was compressed.
    pub fn external(&mut self, uri: &str, length: usize) -> usize {
        let first = if self.meshopt { 2 } else { 1 };
        let k = match self.externals.iter().position(|(u, _)| u == uri) {
            Some(k) => k,
            None => {
                self.externals.push((uri.to_string(), length));
                self.externals.len() - 1
            }
        };
        first + k
    }

    /// Room for `length` decoded bytes in the fallback buffer; returns their offset.
    pub fn reserve_fallback(&mut self, length: usize) -> usize {
        let offset = self.fallback.next_multiple_of(8);
        self.fallback = offset + length;
        offset
    }

    /// Whether a view was compressed (and the file needs `EXT_meshopt_compression`).
    pub fn compressed(&self) -> bool {
        self.fallback > 0 || (self.meshopt && !self.externals.is_empty())
    }

    /// Stores `raw` (`count` elements of `stride` bytes) compressed as a view of the fallback
    /// buffer; `None` (nothing stored) if meshopt refuses it, and the caller stores it plain.
    /// `indices` are the same data as numbers when `mode` is [`Mode::Triangles`].
    fn compressed_view(
        &mut self,
        raw: &[u8],
        stride: usize,
        mode: Mode,
        indices: &[u32],
        target: Option<u32>,
    ) -> Option<usize> {
        let count = raw.len() / stride;
        let encoded = match mode {
            Mode::Attributes => encode_attributes(raw, stride)?,
            Mode::Triangles => {
                let vertices = indices.iter().max().map_or(0, |&m| m as usize + 1);
                meshopt::encoding::encode_index_buffer(indices, vertices).ok()?
            }
        };
        let start = self.align();
        self.bin.extend_from_slice(&encoded);
        let offset = self.reserve_fallback(raw.len());
        let mut v = json!({
            "buffer": 1,
            "byteOffset": offset,
            "byteLength": raw.len(),
            "extensions": {"EXT_meshopt_compression": {
                "buffer": 0,
                "byteOffset": start,
                "byteLength": encoded.len(),
                "byteStride": stride,
                "count": count,
                "mode": match mode { Mode::Attributes => "ATTRIBUTES", Mode::Triangles => "TRIANGLES" },
            }},
        });
        if let Some(t) = target {
            v["target"] = json!(t);
            // Only vertex attribute views have a stride of their own (animation data not).
            if let Mode::Attributes = mode {
                v["byteStride"] = json!(stride);
            }
        }
        self.views.push(v);
        Some(self.views.len() - 1)
    }

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

    /// Appends vertex attributes `data` little-endian as a view, `N` bytes an element,
    /// compressed when meshopt is on.
    fn attributes<T: Copy, const N: usize>(
        &mut self,
        data: &[T],
        bytes: impl Fn(T) -> [u8; N],
    ) -> usize {
        self.elements(data, bytes, Some(VERTICES))
    }

    /// Appends animation data (a sampler's times, positions or rotations), `N` bytes an
    /// element, as a view with no target, compressed by meshopt's vertex codec when meshopt
    /// is on (as gltfpack stores animation).
    pub fn animation<T: Copy, const N: usize>(
        &mut self,
        data: &[T],
        bytes: impl Fn(T) -> [u8; N],
    ) -> usize {
        self.elements(data, bytes, None)
    }

    /// Elements of `N` bytes as a view with `target`, through meshopt's vertex codec when
    /// meshopt is on (plain if it refuses them).
    fn elements<T: Copy, const N: usize>(
        &mut self,
        data: &[T],
        bytes: impl Fn(T) -> [u8; N],
        target: Option<u32>,
    ) -> usize {
        if self.meshopt && !data.is_empty() {
            let raw: Vec<u8> = data.iter().flat_map(|&x| bytes(x)).collect();
            if let Some(v) = self.compressed_view(&raw, N, Mode::Attributes, &[], target) {
                return v;
            }
        }
        self.numbers(data, bytes, target)
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

    /// Adds an accessor; returns its index.
    pub fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// A float accessor of `n`-component elements (`SCALAR`, `VEC2`, `VEC3`), with `min`
    /// and `max` when asked (positions must have them).
    pub fn floats(&mut self, data: &[f32], n: usize, bounds: bool) -> usize {
        let view = match n {
            1 => self.attributes(data, f32::to_le_bytes),
            2 => self.attributes(pairs(data), |v| flat::<2, 8>(v.map(f32::to_le_bytes))),
            3 => self.attributes(triples(data), |v| flat::<3, 12>(v.map(f32::to_le_bytes))),
            _ => self.numbers(data, f32::to_le_bytes, Some(VERTICES)),
        };
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
        self.accessor(a)
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
        let view = self.attributes(&packed, |b| b);
        self.views[view]["byteStride"] = json!(4);
        self.accessor(json!({
            "bufferView": view,
            "componentType": 5120,
            "normalized": true,
            "count": packed.len(),
            "type": "VEC3",
        }))
    }

    /// A position accessor of shorts (`KHR_mesh_quantization`; the node's scale makes them
    /// metres): 8 bytes a vertex (x, y, z and a pad, as vertex attributes align to 4).
    pub fn short_positions(&mut self, data: &[[i16; 3]]) -> usize {
        let packed: Vec<[i16; 4]> = data.iter().map(|p| [p[0], p[1], p[2], 0]).collect();
        let view = self.attributes(&packed, |p| {
            let mut b = [0u8; 8];
            for (k, v) in p.iter().enumerate() {
                b[2 * k..2 * k + 2].copy_from_slice(&v.to_le_bytes());
            }
            b
        });
        self.views[view]["byteStride"] = json!(8);
        let lo = [0, 1, 2].map(|k| data.iter().map(|p| p[k]).min().unwrap_or(0));
        let hi = [0, 1, 2].map(|k| data.iter().map(|p| p[k]).max().unwrap_or(0));
        self.accessor(json!({
            "bufferView": view,
            "componentType": 5122,
            "count": data.len(),
            "type": "VEC3",
            "min": lo,
            "max": hi,
        }))
    }

    /// A vertex colour accessor (`COLOR_0`): linear RGBA as normalized unsigned bytes, which
    /// core glTF allows; 4 bytes a vertex.
    pub fn colours(&mut self, data: &[[u8; 4]]) -> usize {
        let view = self.attributes(data, |b| b);
        self.views[view]["byteStride"] = json!(4);
        self.accessor(json!({
            "bufferView": view,
            "componentType": 5121,
            "normalized": true,
            "count": data.len(),
            "type": "VEC4",
        }))
    }

    /// A skinned primitive's `JOINTS_0` and `WEIGHTS_0` accessors (in that order): each vertex
    /// follows one joint wholly (a walker's figure moves as one body), so its joints are
    /// that joint and three unused zeros, unsigned bytes, and its weights 1, 0, 0, 0. The
    /// weights are floats: CesiumJS 1.145 read normalized byte weights as 255, drawing each
    /// walker 255 times its size; a tile's walkers are a few hundred vertices, and alike
    /// weights compress to next to nothing.
    pub fn joints(&mut self, joints: &[f32]) -> (usize, usize) {
        let j: Vec<[u8; 4]> = joints.iter().map(|&j| [j as u8, 0, 0, 0]).collect();
        let view = self.attributes(&j, |b| b);
        self.views[view]["byteStride"] = json!(4);
        let joints_accessor = self.accessor(json!({
            "bufferView": view,
            "componentType": 5121,
            "count": j.len(),
            "type": "VEC4",
        }));
        let w = vec![[1.0f32, 0.0, 0.0, 0.0]; joints.len()];
        let view = self.attributes(&w, |v| flat::<4, 16>(v.map(f32::to_le_bytes)));
        self.views[view]["byteStride"] = json!(16);
        let weights = self.accessor(json!({
            "bufferView": view,
            "componentType": 5126,
            "count": w.len(),
            "type": "VEC4",
        }));
        (joints_accessor, weights)
    }

    /// The index accessor: u16 while the vertices fit, else u32.
    pub fn indices(&mut self, idx: &[u32], vertices: usize) -> usize {
        let short = vertices <= u16::MAX as usize;
        let compressed = (self.meshopt && !idx.is_empty() && idx.len().is_multiple_of(3))
            .then(|| {
                let raw: Vec<u8> = if short {
                    idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect()
                } else {
                    idx.iter().flat_map(|&i| i.to_le_bytes()).collect()
                };
                let stride = if short { 2 } else { 4 };
                self.compressed_view(&raw, stride, Mode::Triangles, idx, Some(INDICES))
            })
            .flatten();
        let (view, ctype) = match (compressed, short) {
            (Some(v), true) => (v, 5123),
            (Some(v), false) => (v, 5125),
            (None, true) => (
                self.numbers(idx, |i| (i as u16).to_le_bytes(), Some(INDICES)),
                5123,
            ),
            (None, false) => (self.numbers(idx, u32::to_le_bytes, Some(INDICES)), 5125),
        };
        self.accessor(json!({
            "bufferView": view,
            "componentType": ctype,
            "count": idx.len(),
            "type": "SCALAR",
        }))
    }
}

/// meshopt's vertex codec over `raw`, elements of `stride` bytes (4, 8, 12 or 16 here); `None`
/// for another stride or if the codec refuses.
fn encode_attributes(raw: &[u8], stride: usize) -> Option<Vec<u8>> {
    fn encode<const N: usize>(raw: &[u8]) -> Option<Vec<u8>> {
        let (elements, rest) = raw.as_chunks::<N>();
        if !rest.is_empty() {
            return None;
        }
        meshopt::encoding::encode_vertex_buffer(elements).ok()
    }
    match stride {
        4 => encode::<4>(raw),
        8 => encode::<8>(raw),
        12 => encode::<12>(raw),
        16 => encode::<16>(raw),
        _ => None,
    }
}

/// `data` as pairs (its length is even: two coordinates a vertex).
fn pairs(data: &[f32]) -> &[[f32; 2]] {
    data.as_chunks::<2>().0
}

/// `data` as triples.
fn triples(data: &[f32]) -> &[[f32; 3]] {
    data.as_chunks::<3>().0
}

/// `N` arrays of 4 bytes as one array.
fn flat<const N: usize, const M: usize>(parts: [[u8; 4]; N]) -> [u8; M] {
    let mut out = [0u8; M];
    for (o, b) in out.chunks_exact_mut(4).zip(parts.iter()) {
        o.copy_from_slice(b);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::glb::container::glb;

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
    fn each_vertex_follows_its_one_joint_wholly() {
        let mut b = Buffer::default();
        let (j, w) = b.joints(&[0.0, 3.0, 31.0]);
        let view =
            |a: usize| b.views[b.accessors[a]["bufferView"].as_u64().unwrap() as usize].clone();
        let bytes = |a: usize| {
            let v = view(a);
            let (o, n) = (
                v["byteOffset"].as_u64().unwrap() as usize,
                v["byteLength"].as_u64().unwrap() as usize,
            );
            b.bin[o..o + n].to_vec()
        };
        assert_eq!(b.accessors[j]["componentType"], 5121);
        assert_eq!(bytes(j), [0, 0, 0, 0, 3, 0, 0, 0, 31, 0, 0, 0]);
        // Float weights (CesiumJS misread normalized bytes), 1 on the first joint only.
        assert_eq!(b.accessors[w]["componentType"], 5126);
        assert!(b.accessors[w].get("normalized").is_none());
        let weights: Vec<f32> = bytes(w)
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(weights, [1.0, 0.0, 0.0, 0.0].repeat(3));
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

    /// The view's compressed bytes and its extension object.
    fn compressed_of(b: &Buffer, view: usize) -> (&[u8], &Value) {
        let e = &b.views[view]["extensions"]["EXT_meshopt_compression"];
        let start = e["byteOffset"].as_u64().unwrap() as usize;
        let len = e["byteLength"].as_u64().unwrap() as usize;
        (&b.bin[start..start + len], e)
    }

    #[test]
    fn compressed_views_decode_to_the_plain_bytes_with_the_codec_versions_the_extension_reads() {
        let positions: Vec<f32> = (0..300).map(|i| (i % 17) as f32 * 0.25).collect();
        let idx: Vec<u32> = (0..99).map(|i| (i * 7) % 100).collect();
        let mut plain = Buffer::new(false);
        let mut packed = Buffer::new(true);
        for b in [&mut plain, &mut packed] {
            b.floats(&positions, 3, true);
            b.indices(&idx, 100);
        }
        assert!(!plain.compressed() && packed.compressed());
        // Vertex codec version 0 (0xa0) is the one EXT_meshopt_compression defines;
        // index codec 0xe0 | version.
        let (bytes, e) = compressed_of(&packed, 0);
        assert_eq!(
            (bytes[0], &e["mode"], &e["byteStride"]),
            (0xa0, &json!("ATTRIBUTES"), &json!(12))
        );
        let decoded: Vec<[u8; 12]> = meshopt::encoding::decode_vertex_buffer(bytes, 100).unwrap();
        assert_eq!(decoded.concat(), plain.bin[..1200]);
        let (bytes, e) = compressed_of(&packed, 1);
        assert_eq!(
            (bytes[0] & 0xf0, &e["mode"], &e["count"]),
            (0xe0, &json!("TRIANGLES"), &json!(99))
        );
        // The index codec may rotate a triangle's corners (its winding kept).
        let decoded: Vec<u16> = meshopt::encoding::decode_index_buffer(bytes, 99).unwrap();
        let rotated = |t: &[u16]| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        };
        let expected: Vec<[u16; 3]> = idx
            .iter()
            .map(|&i| i as u16)
            .collect::<Vec<_>>()
            .chunks(3)
            .map(rotated)
            .collect();
        let got: Vec<[u16; 3]> = decoded.chunks(3).map(rotated).collect();
        assert_eq!(got, expected);
        // The views point into the fallback buffer, 8-byte aligned, as long as the plain ones.
        assert_eq!(packed.views[1]["buffer"], 1);
        assert_eq!(packed.views[1]["byteOffset"], 1200);
        assert_eq!(packed.views[1]["byteLength"], plain.views[1]["byteLength"]);
        assert_eq!(packed.fallback, 1398);
        assert_eq!(
            packed.buffers_json()[1]["extensions"]["EXT_meshopt_compression"]["fallback"],
            true
        );
        // The accessors are the same but for where their views are.
        assert_eq!(packed.accessors, plain.accessors);
        assert!(
            packed.bin.len() < plain.bin.len() / 2,
            "{} {}",
            packed.bin.len(),
            plain.bin.len()
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
