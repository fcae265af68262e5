//! Reads a GeoJSON layer (issue 77): a FeatureCollection, streamed one feature at a time by
//! geozero (through the `geojson` crate's feature reader), never held whole as text, in a
//! file of at most [`MAX_BYTES`].
//!
//! RFC 7946 fixes the CRS: longitude and latitude on WGS 84, reprojected as lon/lat
//! shapefiles are. A file that names another CRS the way GDAL writes one for a projected
//! layer (the 2008 format's `"crs": {"type": "name", "properties": {"name":
//! "urn:ogc:def:crs:EPSG::6674"}}`, before the features) is read in that CRS.

use std::io::Read;
use std::path::Path;

use super::features::Collector;
use super::shp::Layer;
use super::InputError;

/// The largest GeoJSON file read: past it, a GeoPackage or FlatGeobuf is the better file.
pub const MAX_BYTES: u64 = 2 << 30;
/// How much of the file's beginning is looked at for a `crs` member.
const HEAD: u64 = 64 << 10;
/// WGS 84's EPSG code, RFC 7946's only CRS.
const WGS84: u16 = 4326;

/// Reads the GeoJSON FeatureCollection at `path`.
pub fn read_layer(path: &Path) -> Result<Layer, InputError> {
    let err = |message: String| InputError::Layer {
        file: path.display().to_string(),
        message,
    };
    let hint = format!(
        ": save it as a GeoPackage (ogr2ogr -f GPKG town.gpkg {})",
        path.display()
    );
    let (file, _) = super::features::open_layer(path, MAX_BYTES, "GeoJSON", &hint)?;
    let mut head = Vec::new();
    (&file)
        .take(HEAD)
        .read_to_end(&mut head)
        .map_err(|e| err(format!("cannot read it: {e}")))?;
    let code = named_crs(&String::from_utf8_lossy(&head)).unwrap_or(WGS84);
    let prj = crs_definitions::from_code(code)
        .map(|d| d.wkt.to_string())
        .ok_or_else(|| {
            err(format!(
                "its `crs` names EPSG:{code}, which edo-city does not know"
            ))
        })?;
    // The beginning already read, then the rest of the same file: it is opened and read once.
    let rest = file.take(MAX_BYTES - head.len() as u64);
    let reader = std::io::BufReader::with_capacity(1 << 20, head.as_slice().chain(rest));
    let mut c = Collector::default();
    geozero::geojson::read_geojson_fc(reader, &mut c).map_err(|e| {
        err(format!(
            "not a GeoJSON FeatureCollection edo-city can read: {e} (a layer is one \
             FeatureCollection of Features)"
        ))
    })?;
    let file = path.display().to_string();
    let warnings = c.unsupported_warning(&file).into_iter().collect();
    let records = c.features.last().map_or(0, |f| f.record + 1);
    let present: std::collections::BTreeSet<usize> = c.features.iter().map(|f| f.record).collect();
    Ok(Layer {
        path: path.to_path_buf(),
        records,
        // A Feature with neither geometry nor properties gives no feature: it is listed as
        // skipped, as a deleted record is.
        deleted: (0..records).filter(|r| !present.contains(r)).collect(),
        features: std::mem::take(&mut c.features),
        encoding: "UTF-8 (GeoJSON)".into(),
        text_encoding: Some(encoding_rs::UTF_8),
        fields: c.fields(),
        prj: Some(prj),
        warnings,
    })
}

/// Whether the file at `path` begins as a GeoJSON FeatureCollection does (a `.json` file
/// is not always a layer): its first 4 KiB name one. A FIFO or device is no layer.
pub fn looks_like_geojson(path: &Path) -> bool {
    let mut head = Vec::new();
    crate::bounded::file(path)
        .and_then(|f| f.take(4096).read_to_end(&mut head))
        .is_ok()
        && String::from_utf8_lossy(&head).contains("\"FeatureCollection\"")
}

/// The EPSG code of a 2008-style named `crs` member in the file's beginning, if any
/// (`urn:ogc:def:crs:EPSG::6674`, `EPSG:6674`; CRS84 is WGS 84).
fn named_crs(head: &str) -> Option<u16> {
    // A member of the collection, before its features begin (a feature's own `crs`
    // property is none).
    let head = &head[..head.find("\"features\"").unwrap_or(head.len())];
    let rest = &head[head.find("\"crs\"")?..];
    if rest.contains("CRS84") {
        return Some(WGS84);
    }
    let i = rest.find("EPSG:")? + "EPSG:".len();
    let digits: String = rest[i..]
        .trim_start_matches(':')
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_named_crs_is_read_from_the_files_beginning() {
        let gdal = r#"{"type": "FeatureCollection", "name": "lots", "crs": { "type": "name", "properties": { "name": "urn:ogc:def:crs:EPSG::6674" } }, "features": []}"#;
        assert_eq!(named_crs(gdal), Some(6674));
        let crs84 = r#"{"crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:OGC:1.3:CRS84"}}, "features": []}"#;
        assert_eq!(named_crs(crs84), Some(WGS84));
        assert_eq!(
            named_crs(r#"{"type": "FeatureCollection", "features": []}"#),
            None
        );
        // A property named crs in a feature is no CRS of the file.
        let late = r#"{"features": [{"properties": {"crs": "EPSG:1"}}]}"#;
        assert_eq!(named_crs(late), None);
    }
}

#[cfg(test)]
mod precision {
    use crate::input::features::Collector;

    #[test]
    fn coordinates_are_read_to_the_last_bit() {
        let text = r#"{"type":"FeatureCollection","features":[{"type":"Feature","properties":{"id":1},"geometry":{"type":"Point","coordinates":[-22972.53877852516,-109875.978158782527316]}}]}"#;
        let mut c = Collector::default();
        geozero::geojson::read_geojson_fc(text.as_bytes(), &mut c).unwrap();
        match &c.features[0].shape {
            shapefile::Shape::Point(p) => {
                assert_eq!(p.x, -22972.53877852516_f64);
                assert_eq!(p.y, "-109875.978158782527316".parse::<f64>().unwrap());
            }
            s => panic!("{s}"),
        }
    }
}
