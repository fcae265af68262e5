//! Terrain files: an elevation grid (ESRI ASCII grid `.asc`, or GeoTIFF `.tif` placed by its
//! GeoTIFF tags or a `.tfw` world file) read into a [`Dem`].
//!
//! The grid is in the output CRS (a `.prj` beside it that says otherwise is an error: reproject
//! the DEM first). Cells equal to `NODATA_value` (or GDAL's no-data tag) are no-data.

use std::path::Path;

use super::InputError;

/// The largest world file (`.tfw`, six numbers) read.
const SIDECAR_BYTES: u64 = 1 << 20;
/// The largest ESRI ASCII grid read (4e8 cells, the GeoTIFF bound, at about ten characters
/// a cell).
const ASCII_GRID_BYTES: u64 = 4 << 30;
pub use crate::model::dem::{Dem, Sample};

/// [`Dem::from_grid`], its complaint put to the file.
fn grid(
    file: String,
    ncols: usize,
    nrows: usize,
    xll: f64,
    yll: f64,
    cell: f64,
    z: Vec<f64>,
) -> Result<Dem, InputError> {
    Dem::from_grid(file.clone(), ncols, nrows, xll, yll, cell, z)
        .map_err(|message| InputError::Layer { file, message })
}

/// Reads a DEM: a GeoTIFF by its extension (`.tif`, `.tiff`), else an ESRI ASCII grid.
pub fn read(path: &Path) -> Result<Dem, InputError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("tif" | "tiff") => read_geotiff(path),
        _ => read_ascii(path),
    }
}

/// Reads a single-band GeoTIFF: placed by ModelPixelScale + ModelTiepoint, else by a
/// world file beside it; GDAL's NODATA tag is honoured.
pub fn read_geotiff(path: &Path) -> Result<Dem, InputError> {
    use tiff::decoder::{Decoder, DecodingResult};
    use tiff::tags::Tag;
    let file = path.display().to_string();
    let bad = |message: String| InputError::Layer {
        file: file.clone(),
        message,
    };
    let reader = crate::bounded::file(path).map_err(|e| bad(format!("cannot read: {e}")))?;
    let mut dec = Decoder::new(std::io::BufReader::new(reader))
        .map_err(|e| bad(format!("not a readable TIFF: {e}")))?;
    let (w, h) = dec
        .dimensions()
        .map_err(|e| bad(format!("not a readable TIFF: {e}")))?;
    let (ncols, nrows) = (w as usize, h as usize);
    if ncols.saturating_mul(nrows) > 400_000_000 {
        return Err(bad(format!(
            "{ncols} x {nrows} cells is more than this tool reads (4e8); crop or resample the DEM"
        )));
    }
    let tag = |dec: &mut Decoder<_>, t: Tag| -> Option<Vec<f64>> {
        dec.find_tag(t)
            .ok()
            .flatten()
            .and_then(|v| v.into_f64_vec().ok())
    };
    let scale = tag(&mut dec, Tag::ModelPixelScaleTag);
    let tie = tag(&mut dec, Tag::ModelTiepointTag);
    let nodata = dec
        .find_tag(Tag::Unknown(42113))
        .ok()
        .flatten()
        .and_then(|v| v.into_string().ok())
        .and_then(|s| s.trim().trim_end_matches('\0').parse::<f64>().ok());
    // Upper-left corner and cell size.
    let (x0, ytop, cell) = match (scale, tie) {
        (Some(s), Some(t)) if s.len() >= 2 && t.len() >= 6 => {
            if (s[0] - s[1]).abs() > 1e-9 * s[0].abs() {
                return Err(bad(format!(
                    "cells of {} x {} are not square; resample the DEM",
                    s[0], s[1]
                )));
            }
            (t[3] - t[0] * s[0], t[4] + t[1] * s[1], s[0])
        }
        _ => {
            let tfw = path.with_extension("tfw");
            let text = crate::bounded::read_text(&tfw, SIDECAR_BYTES).map_err(|_| {
                bad(format!(
                    "no GeoTIFF placement tags and no world file {}: the DEM cannot be placed",
                    tfw.display()
                ))
            })?;
            let v: Vec<f64> = text
                .split_ascii_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            let [a, d, b, e, c, f] = v[..] else {
                return Err(bad(format!(
                    "{}: a world file has 6 numbers",
                    tfw.display()
                )));
            };
            if d != 0.0 || b != 0.0 || (a + e).abs() > 1e-9 * a.abs() {
                return Err(bad(format!(
                    "{}: a rotated or non-square grid; resample the DEM",
                    tfw.display()
                )));
            }
            // C, F are the centre of the upper-left cell.
            (c - a / 2.0, f + a / 2.0, a)
        }
    };
    let data = dec
        .read_image()
        .map_err(|e| bad(format!("cannot decode the raster: {e}")))?;
    let z: Vec<f64> = match data {
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
        _ => {
            return Err(bad(
                "an unsupported sample type (use 8-32 bit integers or floats)".into(),
            ))
        }
    };
    if z.len() != ncols * nrows {
        return Err(bad(format!(
            "{} samples for {ncols} x {nrows} cells: one band only",
            z.len()
        )));
    }
    let z = z
        .into_iter()
        .map(|v| {
            if Some(v) == nodata || !v.is_finite() {
                f64::NAN
            } else {
                v
            }
        })
        .collect();
    grid(file, ncols, nrows, x0, ytop - nrows as f64 * cell, cell, z)
}

/// Reads an ESRI ASCII grid.
pub fn read_ascii(path: &Path) -> Result<Dem, InputError> {
    let file = path.display().to_string();
    let bad = |message: String| InputError::Layer {
        file: file.clone(),
        message,
    };
    let text = crate::bounded::read_text(path, ASCII_GRID_BYTES)
        .map_err(|e| bad(format!("cannot be read: it {e}")))?;
    let mut words = text.split_ascii_whitespace().peekable();
    let (mut ncols, mut nrows, mut cell, mut nodata) = (None, None, None, None);
    let (mut x, mut y, mut centre) = (None, None, false);
    while let Some(w) = words.peek() {
        let key = w.to_ascii_lowercase();
        if key.parse::<f64>().is_ok() {
            break;
        }
        words.next();
        let v = words
            .next()
            .ok_or_else(|| bad(format!("header `{key}` has no value")))?;
        let num = |v: &str| -> Result<f64, InputError> {
            v.parse::<f64>()
                .map_err(|_| bad(format!("header `{key}` = `{v}` is not a number")))
        };
        match key.as_str() {
            "ncols" => ncols = Some(num(v)? as usize),
            "nrows" => nrows = Some(num(v)? as usize),
            "xllcorner" => x = Some(num(v)?),
            "yllcorner" => y = Some(num(v)?),
            "xllcenter" => {
                x = Some(num(v)?);
                centre = true;
            }
            "yllcenter" => {
                y = Some(num(v)?);
                centre = true;
            }
            "cellsize" => cell = Some(num(v)?),
            "nodata_value" => nodata = Some(num(v)?),
            other => return Err(bad(format!("unknown header `{other}` (an ESRI ASCII grid has ncols, nrows, xllcorner, yllcorner, cellsize, NODATA_value)"))),
        }
    }
    let missing = |k: &str| bad(format!("the header lacks `{k}`"));
    let (ncols, nrows) = (
        ncols.ok_or_else(|| missing("ncols"))?,
        nrows.ok_or_else(|| missing("nrows"))?,
    );
    let cell = cell.ok_or_else(|| missing("cellsize"))?;
    let (mut xll, mut yll) = (
        x.ok_or_else(|| missing("xllcorner"))?,
        y.ok_or_else(|| missing("yllcorner"))?,
    );
    if !(cell.is_finite() && cell > 0.0) || ncols == 0 || nrows == 0 {
        return Err(bad(format!(
            "a grid of {ncols} x {nrows} cells of {cell} m is empty"
        )));
    }
    if ncols.saturating_mul(nrows) > 400_000_000 {
        return Err(bad(format!(
            "{ncols} x {nrows} cells is more than this tool reads (4e8); crop or resample the DEM"
        )));
    }
    if centre {
        xll -= cell / 2.0;
        yll -= cell / 2.0;
    }
    let mut z = Vec::with_capacity(ncols * nrows);
    for w in words {
        let v: f64 = w
            .parse()
            .map_err(|_| bad(format!("value {} (`{w}`) is not a number", z.len() + 1)))?;
        z.push(if Some(v) == nodata || !v.is_finite() {
            f64::NAN
        } else {
            v
        });
    }
    if z.len() != ncols * nrows {
        return Err(bad(format!(
            "{} values for {ncols} x {nrows} = {} cells (is the file cut short?)",
            z.len(),
            ncols * nrows
        )));
    }
    grid(file, ncols, nrows, xll, yll, cell, z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo_types::Coord;

    fn grid(text: &str) -> Result<Dem, InputError> {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("dem.asc");
        std::fs::write(&p, text).unwrap();
        read_ascii(&p)
    }

    const SLOPE: &str =
        "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n\
                         0 10 20\n0 10 20\n";

    #[test]
    fn bilinear_inside_and_nearest_edge_outside() {
        let d = grid(SLOPE).unwrap();
        // Cell centres at x = 5, 15, 25: z rises 1 m per metre east.
        let s = d.sample(Coord { x: 10.0, y: 10.0 });
        assert!((s.z - 5.0).abs() < 1e-9 && !s.outside, "{s:?}");
        let s = d.sample(Coord { x: 22.5, y: 3.0 });
        assert!((s.z - 17.5).abs() < 1e-9);
        let s = d.sample(Coord { x: 100.0, y: 5.0 });
        assert!(s.outside && (s.z - 20.0).abs() < 1e-9);
    }

    #[test]
    fn nodata_cells_are_left_out() {
        let d = grid("ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n7 -9999\n").unwrap();
        assert!((d.sample(Coord { x: 12.0, y: 5.0 }).z - 7.0).abs() < 1e-12);
        assert!((d.sample(Coord { x: 19.0, y: 5.0 }).z - 7.0).abs() < 1e-12);
    }

    /// A GeoTIFF of the SLOPE grid (f32), placed by its tags or by a world file.
    fn geotiff(dir: &Path, tags: bool) -> std::path::PathBuf {
        use tiff::encoder::{colortype, TiffEncoder};
        use tiff::tags::Tag;
        let p = dir.join("dem.tif");
        let mut enc = TiffEncoder::new(std::fs::File::create(&p).unwrap()).unwrap();
        let mut img = enc.new_image::<colortype::Gray32Float>(3, 2).unwrap();
        if tags {
            img.encoder()
                .write_tag(Tag::ModelPixelScaleTag, &[10.0f64, 10.0, 0.0][..])
                .unwrap();
            img.encoder()
                .write_tag(
                    Tag::ModelTiepointTag,
                    &[0.0f64, 0.0, 0.0, 0.0, 20.0, 0.0][..],
                )
                .unwrap();
        } else {
            std::fs::write(dir.join("dem.tfw"), "10\n0\n0\n-10\n5\n15\n").unwrap();
        }
        img.write_data(&[0.0f32, 10.0, 20.0, 0.0, 10.0, 20.0])
            .unwrap();
        p
    }

    #[test]
    fn geotiffs_read_like_the_ascii_grid() {
        let dir = tempfile::tempdir().unwrap();
        let ascii = grid(SLOPE).unwrap();
        for tags in [true, false] {
            let d = read(&geotiff(dir.path(), tags)).unwrap();
            assert_eq!(
                (d.ncols, d.nrows, d.xll, d.yll, d.cell),
                (3, 2, 0.0, 0.0, 10.0)
            );
            for p in [(10.0, 10.0), (22.5, 3.0), (100.0, 5.0)] {
                let c = Coord { x: p.0, y: p.1 };
                assert_eq!(d.sample(c), ascii.sample(c), "tags {tags}: {p:?}");
            }
            let _ = std::fs::remove_file(dir.path().join("dem.tfw"));
        }
        // Neither tags nor a world file: the DEM cannot be placed.
        let p = geotiff(dir.path(), false);
        std::fs::remove_file(dir.path().join("dem.tfw")).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("cannot be placed"), "{e}");
    }

    #[test]
    fn broken_grids_say_what_is_wrong() {
        let e = grid("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\n1 2 3\n4 5\n")
            .unwrap_err();
        assert!(e.to_string().contains("5 values for 3 x 2"), "{e}");
        let e = grid("ncols 3\nnrows 2\nxllcorner 0\ncellsize 10\n1 2 3 4 5 6\n").unwrap_err();
        assert!(e.to_string().contains("lacks `yllcorner`"), "{e}");
        let e =
            grid("ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value 1\n1\n")
                .unwrap_err();
        assert!(e.to_string().contains("every cell is NODATA"), "{e}");
    }
}
