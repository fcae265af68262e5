//! `EXT_meshopt_compression` in a glTF: our own GLB tiles are written so by default
//! (`output.glb_compression = "meshopt"`, and read back for the tileset's parents), and
//! gltfpack writes it in landmark models. A compressed
//! view's data is decoded by meshoptimizer's decoders (which are safe on any input: garbage
//! gives garbage, never a read out of bounds) into its fallback buffer, where the gltf
//! crate's reader then finds it as in any plain model. Filters are not undone: a filtered
//! view is refused with what to do.

use serde_json::Value;

/// The extension's name.
pub const EXTENSION: &str = "EXT_meshopt_compression";

/// Whether buffer `b` is a fallback buffer: no data of its own, filled by decoding.
pub fn is_fallback(b: &gltf::Buffer) -> bool {
    b.extension_value(EXTENSION)
        .and_then(|e| e.get("fallback"))
        .and_then(Value::as_bool)
        .unwrap_or(false)
}

/// At most 80 characters of a value read from a file, for a message.
fn excerpt(s: &str) -> String {
    match s.char_indices().nth(80) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

/// A compressed view's extension object, as numbers checked against the buffers.
struct Compressed {
    source: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    triangles: bool,
}

/// Reads view `v`'s extension; `Ok(None)` for a plain view.
fn compressed(v: &gltf::buffer::View, shown: &str) -> Result<Option<Compressed>, String> {
    let Some(e) = v.extension_value(EXTENSION) else {
        return Ok(None);
    };
    let bad = |what: &str| {
        format!(
            "{shown}: buffer view {}'s {EXTENSION} {what}: it is damaged",
            v.index()
        )
    };
    let num = |key: &str| {
        e.get(key)
            .and_then(Value::as_u64)
            .map(|n| n as usize)
            .ok_or_else(|| bad(&format!("has no `{key}`")))
    };
    let filter = e.get("filter").and_then(Value::as_str).unwrap_or("NONE");
    if filter != "NONE" {
        return Err(format!(
            "{shown}: buffer view {} is compressed with meshopt's {filter} filter, which is not \
             read: write the model without filters (gltfpack -noq, or edo-city's \
             output.glb_compression = \"none\")",
            v.index()
        ));
    }
    let mode = e.get("mode").and_then(Value::as_str).unwrap_or("");
    let triangles = match mode {
        "ATTRIBUTES" => false,
        "TRIANGLES" => true,
        other => {
            return Err(format!(
                "{shown}: buffer view {}'s {EXTENSION} mode `{}` is not read (ATTRIBUTES and \
                 TRIANGLES are)",
                v.index(),
                excerpt(other)
            ))
        }
    };
    let c = Compressed {
        source: e.get("buffer").and_then(Value::as_u64).unwrap_or(0) as usize,
        offset: e.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize,
        length: num("byteLength")?,
        stride: num("byteStride")?,
        count: num("count")?,
        triangles,
    };
    let strides: &[usize] = if triangles { &[2, 4] } else { &[4, 8, 12, 16] };
    if !strides.contains(&c.stride) || c.count.checked_mul(c.stride) != Some(v.length()) {
        return Err(bad(&format!(
            "stride {} and count {} do not fill the view's {} bytes (or the stride is not read)",
            c.stride,
            c.count,
            v.length()
        )));
    }
    Ok(Some(c))
}

/// Decodes every compressed view of `doc` into its place in `buffers` (the fallback buffers
/// were made zeroed at their declared length).
pub fn decode(
    doc: &gltf::Document,
    buffers: &mut [gltf::buffer::Data],
    shown: &str,
) -> Result<(), String> {
    for v in doc.views() {
        let Some(c) = compressed(&v, shown)? else {
            continue;
        };
        let damaged = || {
            format!(
                "{shown}: buffer view {}'s compressed data does not decode: it is damaged",
                v.index()
            )
        };
        let source = buffers
            .get(c.source)
            .and_then(|b| b.0.get(c.offset..c.offset.checked_add(c.length)?))
            .ok_or_else(damaged)?;
        let bytes = match (c.triangles, c.stride) {
            (true, 2) => meshopt::encoding::decode_index_buffer::<u16>(source, c.count)
                .map(|i| i.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>()),
            (true, _) => meshopt::encoding::decode_index_buffer::<u32>(source, c.count)
                .map(|i| i.iter().flat_map(|x| x.to_le_bytes()).collect()),
            (false, 4) => vertices::<4>(source, c.count),
            (false, 8) => vertices::<8>(source, c.count),
            (false, 12) => vertices::<12>(source, c.count),
            (false, _) => vertices::<16>(source, c.count),
        }
        .map_err(|_| damaged())?;
        let target = v.buffer().index();
        let slot = buffers
            .get_mut(target)
            .and_then(|b| b.0.get_mut(v.offset()..v.offset() + bytes.len()))
            .ok_or_else(damaged)?;
        slot.copy_from_slice(&bytes);
    }
    Ok(())
}

/// One vertex of `N` bytes, as the decoder writes it (the crate asks `Default`, which arrays
/// of any length do not have).
#[derive(Clone, Copy)]
#[repr(transparent)]
struct Element<const N: usize>([u8; N]);

impl<const N: usize> Default for Element<N> {
    fn default() -> Self {
        Element([0; N])
    }
}

/// meshopt's vertex decoder over `count` elements of `N` bytes.
fn vertices<const N: usize>(source: &[u8], count: usize) -> meshopt::Result<Vec<u8>> {
    meshopt::encoding::decode_vertex_buffer::<Element<N>>(source, count)
        .map(|v| v.into_iter().flat_map(|e| e.0).collect())
}
