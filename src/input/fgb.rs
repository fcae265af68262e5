//! Reads a FlatGeobuf layer (`.fgb`, issue 77) with the `flatgeobuf` crate into the same
//! [`Collector`] as GeoPackages and GeoJSON.
//!
//! The crate sizes each feature's buffer by the length the file declares before it reads
//! it (up to 4 GiB a feature), so a file from elsewhere is walked first, feature by
//! feature, by its length prefixes alone: every length must fit in what is left of the file
//! and be at most [`MAX_FEATURE`], and the count must be the header's. Only then is it read.

use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use flatgeobuf::packed_r_tree::PackedRTree;
use flatgeobuf::FgbReader;

use super::features::Collector;
use super::shp::Layer;
use super::InputError;

/// The largest FlatGeobuf file read.
pub const MAX_BYTES: u64 = 16 << 30;
/// The largest feature (its geometry and properties) read.
const MAX_FEATURE: u64 = 256 << 20;
/// The largest header (the format's own bound).
const MAX_HEADER: u64 = 1 << 20;

/// Reads the FlatGeobuf file at `path`.
pub fn read_layer(path: &Path) -> Result<Layer, InputError> {
    let err = |message: String| InputError::Layer {
        file: path.display().to_string(),
        message,
    };
    let (file, len) = super::features::open_layer(path, MAX_BYTES, "FlatGeobuf", "")?;
    let mut r = BufReader::with_capacity(1 << 20, file);
    let fgb = FgbReader::open(&mut r)
        .map_err(|e| err(format!("not a FlatGeobuf file edo-city can read: {e}")))?;
    let header = fgb.header();
    let declared = header.features_count();
    let node = header.index_node_size();
    let prj = crs_of(&header);
    let fields: Vec<String> = header
        .columns()
        .map(|c| c.iter().map(|c| c.name().to_string()).collect())
        .unwrap_or_default();
    let (file, _) = crate::bounded::open(path).map_err(|e| err(format!("cannot open it: {e}")))?;
    let found = walk(file, len, declared, node).map_err(err)?;
    let mut c = Collector::default();
    let mut iter = fgb
        .select_all_seq()
        .map_err(|e| err(format!("cannot read its features: {e}")))?;
    iter.process_features(&mut c)
        .map_err(|e| err(format!("cannot read its features: {e}")))?;
    let file = path.display().to_string();
    Ok(Layer {
        path: path.to_path_buf(),
        records: found,
        deleted: Vec::new(),
        features: std::mem::take(&mut c.features),
        encoding: "UTF-8 (FlatGeobuf)".into(),
        text_encoding: Some(encoding_rs::UTF_8),
        fields,
        prj,
        warnings: c.unsupported_warning(&file).into_iter().collect(),
    })
}

/// Walks the features of a FlatGeobuf file of `len` bytes by their length prefixes (see the
/// module's doc); their number.
fn walk(file: std::fs::File, len: u64, declared: u64, node: u16) -> Result<usize, String> {
    let mut r = BufReader::new(file);
    let mut word = [0u8; 4];
    r.seek(SeekFrom::Start(8))
        .and_then(|_| r.read_exact(&mut word))
        .map_err(|e| format!("cannot read its header: {e}"))?;
    let header = u64::from(u32::from_le_bytes(word));
    // Each feature takes at least its 4-byte length: more declared than that is a lie.
    if header > MAX_HEADER || declared > len / 4 {
        return Err(format!(
            "its header says {declared} features in {len} bytes: the file is damaged"
        ));
    }
    let index = match (node, declared) {
        (0, _) | (_, 0) => 0,
        _ => PackedRTree::index_size(declared as usize, node) as u64,
    };
    let mut at = 12 + header + index;
    let mut count = 0u64;
    while at < len {
        r.seek(SeekFrom::Start(at))
            .and_then(|_| r.read_exact(&mut word))
            .map_err(|e| format!("feature {count}: cannot read its length: {e}"))?;
        let size = u64::from(u32::from_le_bytes(word));
        if size > MAX_FEATURE || at + 4 + size > len {
            return Err(format!(
                "feature {count} says it is {size} bytes, more than the file holds or \
                 {MAX_FEATURE} bytes: the file is damaged or cut short"
            ));
        }
        at += 4 + size;
        count += 1;
    }
    if declared > 0 && count != declared {
        return Err(format!(
            "its header says {declared} features, it holds {count}: the file is damaged or \
             cut short"
        ));
    }
    Ok(count as usize)
}

/// The WKT of the header's CRS: its EPSG code's definition (as a `.prj` would give it),
/// else its own WKT.
fn crs_of(header: &flatgeobuf::Header) -> Option<String> {
    let crs = header.crs()?;
    let epsg = crs.org().is_none_or(|o| o.eq_ignore_ascii_case("epsg"));
    match u16::try_from(crs.code()).ok().filter(|_| epsg) {
        Some(code) if code > 0 => crs_definitions::from_code(code).map(|d| d.wkt.to_string()),
        _ => crs.wkt().map(str::to_string),
    }
}
