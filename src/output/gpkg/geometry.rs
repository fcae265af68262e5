//! The GeoPackage geometry blob (standard, section 2.1.3): a header (`GP`, version 0, flags,
//! the SRS id, the envelope) and the geometry as little-endian WKB, written by the georust
//! `wkb` crate.

use geo::BoundingRect;
use geo_types::Geometry;

/// Writes `g` as a GeoPackage blob into `out` (cleared first) and returns its envelope
/// `[min_x, max_x, min_y, max_y]`, or `None` for an empty geometry (written with the empty
/// flag and no envelope, as the standard asks).
pub fn encode(g: &Geometry<f64>, srs: i32, out: &mut Vec<u8>) -> Option<[f64; 4]> {
    out.clear();
    let rect = g.bounding_rect();
    let point = matches!(g, Geometry::Point(_));
    // Flags: bit 0 little-endian; bits 1-3 the envelope (1: x and y; 0: none, for points and
    // empty geometries, whose envelope is the point or nothing); bit 4 empty.
    let envelope = rect
        .filter(|_| !point)
        .map(|r| [r.min().x, r.max().x, r.min().y, r.max().y]);
    let empty = rect.is_none();
    let flags = 1u8 | if envelope.is_some() { 1 << 1 } else { 0 } | if empty { 1 << 4 } else { 0 };
    out.extend_from_slice(&[b'G', b'P', 0, flags]);
    out.extend_from_slice(&srs.to_le_bytes());
    if let Some(e) = envelope {
        for v in e {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    let options = wkb::writer::WriteOptions {
        endianness: wkb::Endianness::LittleEndian,
    };
    // Writing into a Vec cannot fail, and every geometry here has x and y only.
    if wkb::writer::write_geometry(out, g, &options).is_err() {
        out.truncate(8);
    }
    rect.map(|r| [r.min().x, r.max().x, r.min().y, r.max().y])
}

/// The envelope `[min_x, max_x, min_y, max_y]` of a GeoPackage blob: from its header, or for
/// a blob without one, from a WKB point. `None` for an empty geometry or a blob too short.
pub fn envelope_of(blob: &[u8]) -> Option<[f64; 4]> {
    if blob.len() < 8 || &blob[..2] != b"GP" || blob[3] & (1 << 4) != 0 {
        return None;
    }
    let f = |at: usize| -> Option<f64> {
        let b = blob.get(at..at + 8)?;
        let bytes: [u8; 8] = b.try_into().ok()?;
        Some(match blob[3] & 1 {
            1 => f64::from_le_bytes(bytes),
            _ => f64::from_be_bytes(bytes),
        })
    };
    match (blob[3] >> 1) & 0b111 {
        0 => {
            // No envelope: a point, whose WKB is byte order, type, x, y.
            let wkb = &blob[8..];
            let le = *wkb.first()? == 1;
            let g = |at: usize| -> Option<f64> {
                let bytes: [u8; 8] = wkb.get(at..at + 8)?.try_into().ok()?;
                Some(match le {
                    true => f64::from_le_bytes(bytes),
                    false => f64::from_be_bytes(bytes),
                })
            };
            let (x, y) = (g(5)?, g(13)?);
            Some([x, x, y, y])
        }
        _ => Some([f(8)?, f(16)?, f(24)?, f(32)?]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo_types::{point, polygon};

    #[test]
    fn a_polygon_has_its_header_envelope_and_wkb() {
        let p: Geometry<f64> =
            polygon![(x: 1.0, y: 2.0), (x: 4.0, y: 2.0), (x: 4.0, y: 6.0)].into();
        let mut out = Vec::new();
        let e = encode(&p, 6674, &mut out).unwrap();
        assert_eq!(e, [1.0, 4.0, 2.0, 6.0]);
        assert_eq!(&out[..4], b"GP\x00\x03");
        assert_eq!(i32::from_le_bytes(out[4..8].try_into().unwrap()), 6674);
        let f = |i: usize| f64::from_le_bytes(out[8 + 8 * i..16 + 8 * i].try_into().unwrap());
        assert_eq!([f(0), f(1), f(2), f(3)], e);
        // WKB: little-endian polygon (type 3), one ring of four points (closed).
        assert_eq!(&out[40..45], &[1, 3, 0, 0, 0]);
        assert_eq!(u32::from_le_bytes(out[45..49].try_into().unwrap()), 1);
        assert_eq!(u32::from_le_bytes(out[49..53].try_into().unwrap()), 4);
        assert_eq!(out.len(), 53 + 4 * 16);
        assert_eq!(envelope_of(&out), Some(e));
    }

    #[test]
    fn a_point_has_no_envelope_in_its_header() {
        let mut out = Vec::new();
        let e = encode(&point!(x: 3.0, y: -1.5).into(), 100000, &mut out).unwrap();
        assert_eq!(e, [3.0, 3.0, -1.5, -1.5]);
        assert_eq!(&out[..4], b"GP\x00\x01");
        assert_eq!(out.len(), 8 + 21);
        assert_eq!(f64::from_le_bytes(out[13..21].try_into().unwrap()), 3.0);
        assert_eq!(envelope_of(&out), Some(e));
        assert_eq!(envelope_of(b"GP"), None);
    }
}
