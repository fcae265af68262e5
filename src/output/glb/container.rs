//! The GLB container (glTF 2.0's binary file): a 12-byte header, the JSON chunk padded with
//! spaces and the BIN chunk padded with zeros, each to 4 bytes.

use serde_json::Value;

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
