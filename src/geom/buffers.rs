//! A glTF's buffers gathered within a budget, and every count it declares checked against
//! them before anything is allocated or read. A glTF is a few bytes of JSON that can declare
//! anything: a buffer `byteLength` of 1e11, an accessor of 1e10 elements, a compressed view
//! that decodes to more than its buffer holds. The gltf crate believes them; a landmark model
//! (`input::models`) and our own tiles read back for their parents (`output::tiles3d::lod`)
//! both come from files someone may have edited, so both read through this.

use std::borrow::Cow;

/// What a document may take: bytes of buffers (decoded ones included) and elements an
/// accessor may declare.
#[derive(Debug, Clone, Copy)]
pub struct Budget {
    /// Bytes of every buffer together.
    pub bytes: u64,
    /// Elements of any one accessor.
    pub elements: usize,
}

/// The document's buffers: the GLB's binary chunk, each external one as `fetch(uri, left)`
/// gives it (`left`: the bytes the budget has left), and each `EXT_meshopt_compression`
/// fallback buffer zeroed at its declared length, to be filled by [`super::meshopt::decode`].
/// Each holds at least what it declares, all together within `budget.bytes`, and every view
/// lies inside its buffer.
pub fn gather(
    g: &gltf::Gltf,
    budget: &Budget,
    shown: &str,
    mut fetch: impl FnMut(&str, u64) -> Result<Vec<u8>, String>,
) -> Result<Vec<gltf::buffer::Data>, String> {
    let too_much = || {
        format!(
            "{shown}: its buffers hold more than {} bytes: it is damaged, or too large to \
             place or read back",
            budget.bytes
        )
    };
    let mut blob = g.blob.as_deref().map(Cow::Borrowed);
    let mut total = 0u64;
    let mut out = Vec::new();
    for b in g.document.buffers() {
        let declared = b.length() as u64;
        let mut data = match b.source() {
            // Filled by decoding its compressed views; counted against the budget first.
            _ if super::meshopt::is_fallback(&b) => {
                if total.saturating_add(declared) > budget.bytes {
                    return Err(too_much());
                }
                vec![0; b.length()]
            }
            gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| {
                    format!(
                        "{shown}: buffer {} is the GLB's binary chunk, which is missing: it is \
                         damaged",
                        b.index()
                    )
                })?
                .into_owned(),
            gltf::buffer::Source::Uri(uri) => fetch(uri, budget.bytes.saturating_sub(total))?,
        };
        if (data.len() as u64) < declared {
            return Err(format!(
                "{shown}: buffer {} declares {declared} bytes and holds {}: it is damaged",
                b.index(),
                data.len()
            ));
        }
        total = total.saturating_add(data.len() as u64);
        if total > budget.bytes {
            return Err(too_much());
        }
        data.resize(data.len().next_multiple_of(4), 0);
        out.push(gltf::buffer::Data(data));
    }
    views_inside(&g.document, &out, shown)?;
    accessors_within(&g.document, budget, shown)?;
    Ok(out)
}

/// Refuses a view that reaches past its buffer: a compressed view is decoded into it, and
/// the decoder allocates what the view declares.
fn views_inside(
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    shown: &str,
) -> Result<(), String> {
    for v in doc.views() {
        let end = v.offset().checked_add(v.length());
        let room = buffers.get(v.buffer().index()).map_or(0, |b| b.0.len());
        if end.is_none_or(|e| e > room) {
            return Err(format!(
                "{shown}: buffer view {} reaches past its buffer ({} bytes at {}, of {room}): \
                 it is damaged",
                v.index(),
                v.length(),
                v.offset()
            ));
        }
    }
    Ok(())
}

/// Refuses accessors that declare more elements than the budget, none at all, or sparse
/// parts larger than their accessor: the crate would allocate, walk or underflow on them.
fn accessors_within(doc: &gltf::Document, budget: &Budget, shown: &str) -> Result<(), String> {
    for a in doc.accessors() {
        let sparse = a.sparse().map_or(0, |s| s.count());
        if a.count() == 0 || a.count() > budget.elements || sparse > a.count() {
            return Err(format!(
                "{shown}: accessor {} declares {} elements ({sparse} sparse), none or more than \
                 {} or than it has: it is damaged, or too large to place or read back",
                a.index(),
                a.count(),
                budget.elements
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GLB of `json` and a BIN chunk of `bin` bytes.
    fn glb(json: &str, bin: usize) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        j.resize(j.len().next_multiple_of(4), b' ');
        let bin = vec![0u8; bin.next_multiple_of(4)];
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend(((12 + 8 + j.len() + 8 + bin.len()) as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&j);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
        out
    }

    const BUDGET: Budget = Budget {
        bytes: 1 << 20,
        elements: 1000,
    };

    fn read(json: &str, bin: usize) -> Result<usize, String> {
        let g = gltf::Gltf::from_slice_without_validation(&glb(json, bin)).unwrap();
        gather(&g, &BUDGET, "t.glb", |uri, left| {
            Err(format!("{uri} asked with {left} left"))
        })
        .map(|b| b.len())
    }

    #[test]
    fn declared_sizes_are_checked_before_anything_is_allocated() {
        let asset = r#""asset":{"version":"2.0"}"#;
        let ok = format!(
            r#"{{{asset},"buffers":[{{"byteLength":12}}],"bufferViews":[{{"buffer":0,"byteLength":12}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3"}}]}}"#
        );
        assert_eq!(read(&ok, 12), Ok(1));
        // A buffer of 1e11 bytes declared: refused, not allocated.
        let huge = ok.replace(r#"{"byteLength":12}"#, r#"{"byteLength":100000000000}"#);
        assert!(read(&huge, 12)
            .unwrap_err()
            .contains("declares 100000000000"));
        // A fallback buffer of 1e11: past the budget before it is made.
        let fallback = format!(
            r#"{{{asset},"buffers":[{{"byteLength":100000000000,"extensions":{{"EXT_meshopt_compression":{{"fallback":true}}}}}}]}}"#
        );
        assert!(read(&fallback, 0)
            .unwrap_err()
            .contains("more than 1048576"));
        // A view past its buffer, an accessor of 1e10 or of no element.
        let view = ok.replace(
            r#""buffer":0,"byteLength":12"#,
            r#""buffer":0,"byteLength":4000"#,
        );
        assert!(read(&view, 12)
            .unwrap_err()
            .contains("reaches past its buffer"));
        let count = ok.replace(r#""count":1,"#, r#""count":10000000000,"#);
        assert!(read(&count, 12)
            .unwrap_err()
            .contains("10000000000 elements"));
        let none = ok.replace(r#""count":1,"#, r#""count":0,"#);
        assert!(read(&none, 12).unwrap_err().contains("0 elements"));
        // An external buffer is asked of the caller with what is left.
        let external = ok.replace(
            r#"{"byteLength":12}"#,
            r#"{"byteLength":12,"uri":"models/a.bin"}"#,
        );
        assert!(read(&external, 12)
            .unwrap_err()
            .contains("models/a.bin asked with 1048576 left"));
    }
}
