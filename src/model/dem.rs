//! Terrain as the stages see it: an elevation grid in the output CRS, sampled bilinearly.
//!
//! The readers of its files (ESRI ASCII grid, GeoTIFF) are in `input::dem`; analysis grounds
//! houses and fences on it and generation meshes it, without knowing where it came from.
//! Cells that are no-data are left out of the interpolation; a point outside the grid gets
//! the elevation of the nearest edge cell and is counted, so the report can say how many
//! features stood off the DEM.

use geo_types::Coord;

/// An elevation grid: `z[row * ncols + col]`, row 0 at the top (north).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Dem {
    /// The DEM's file, for messages.
    pub file: String,
    /// Columns of the grid.
    pub ncols: usize,
    /// Rows of the grid.
    pub nrows: usize,
    /// Lower-left corner of the lower-left cell.
    pub xll: f64,
    /// The lower edge, as `xll` is the left one.
    pub yll: f64,
    /// The cells' side, metres.
    pub cell: f64,
    z: Vec<f64>,
    /// Cells whose value no ground has (outside [`super::ELEVATION_RANGE`]), read as
    /// no-data: an undeclared no-data value, or damage.
    pub implausible: usize,
}

/// An elevation, and whether the point lay outside the grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The elevation, metres.
    pub z: f64,
    /// Whether the point lay outside the grid (it got the nearest edge's elevation).
    pub outside: bool,
}

impl Dem {
    /// A DEM from its grid (`z[row * ncols + col]`, row 0 north, NaN for no-data); checks
    /// the grid is usable and reads values no ground has as no-data. `Err` says what is
    /// wrong, for the reader to put its file name to.
    pub fn from_grid(
        file: String,
        ncols: usize,
        nrows: usize,
        xll: f64,
        yll: f64,
        cell: f64,
        z: Vec<f64>,
    ) -> Result<Dem, String> {
        let bad = |message: String| message;
        if !(cell.is_finite() && cell > 0.0) || ncols == 0 || nrows == 0 {
            return Err(bad(format!(
                "a grid of {ncols} x {nrows} cells of {cell} m is empty"
            )));
        }
        if !(xll.is_finite() && yll.is_finite() && xll.abs() < super::FAR && yll.abs() < super::FAR)
        {
            return Err(bad(format!(
                "the grid's corner ({xll}, {yll}) is not a place within 1e8 m of the CRS's \
                 origin: the header or the georeferencing is damaged"
            )));
        }
        // Numbers no ground has (an undeclared no-data value such as -3.4e38) are no-data.
        let mut implausible = 0usize;
        let z: Vec<f64> = z
            .into_iter()
            .map(|v| {
                if v.is_nan() || super::ELEVATION_RANGE.contains(&v) {
                    v
                } else {
                    implausible += 1;
                    f64::NAN
                }
            })
            .collect();
        if z.iter().all(|v| v.is_nan()) {
            return Err(bad(format!(
                "every cell is NODATA (or outside {}..{} m)",
                super::ELEVATION_RANGE.start(),
                super::ELEVATION_RANGE.end()
            )));
        }
        Ok(Dem {
            implausible,
            file,
            ncols,
            nrows,
            xll,
            yll,
            cell,
            z,
        })
    }

    fn at(&self, col: usize, row: usize) -> f64 {
        self.z[row * self.ncols + col]
    }

    /// The elevation at `p`: bilinear between the four nearest cell centres (NODATA cells
    /// left out), the nearest edge cell's outside the grid, the nearest valid cell's when all
    /// four are NODATA.
    pub fn sample(&self, p: Coord<f64>) -> Sample {
        let top = self.yll + self.nrows as f64 * self.cell;
        let fx = (p.x - self.xll) / self.cell - 0.5;
        let fy = (top - p.y) / self.cell - 0.5;
        let outside = p.x < self.xll
            || p.x > self.xll + self.ncols as f64 * self.cell
            || p.y < self.yll
            || p.y > top;
        let fx = fx.clamp(0.0, (self.ncols - 1) as f64);
        let fy = fy.clamp(0.0, (self.nrows - 1) as f64);
        let (c0, r0) = (fx.floor() as usize, fy.floor() as usize);
        let (c1, r1) = ((c0 + 1).min(self.ncols - 1), (r0 + 1).min(self.nrows - 1));
        let (tx, ty) = (fx - c0 as f64, fy - r0 as f64);
        let mut sum = 0.0;
        let mut weight = 0.0;
        for (c, r, w) in [
            (c0, r0, (1.0 - tx) * (1.0 - ty)),
            (c1, r0, tx * (1.0 - ty)),
            (c0, r1, (1.0 - tx) * ty),
            (c1, r1, tx * ty),
        ] {
            let v = self.at(c, r);
            if !v.is_nan() && w > 0.0 {
                sum += v * w;
                weight += w;
            }
        }
        let z = if weight > 0.0 {
            sum / weight
        } else {
            self.nearest_valid(c0, r0)
        };
        Sample { z, outside }
    }

    /// The valid cell nearest (col, row), searching rings outward.
    fn nearest_valid(&self, col: usize, row: usize) -> f64 {
        let reach = self.ncols.max(self.nrows);
        for d in 1..=reach {
            let mut best: Option<(usize, f64)> = None;
            let (c0, c1) = (col.saturating_sub(d), (col + d).min(self.ncols - 1));
            let (r0, r1) = (row.saturating_sub(d), (row + d).min(self.nrows - 1));
            for r in r0..=r1 {
                for c in c0..=c1 {
                    let v = self.at(c, r);
                    let dist = c.abs_diff(col).pow(2) + r.abs_diff(row).pow(2);
                    if !v.is_nan() && best.is_none_or(|(bd, _)| dist < bd) {
                        best = Some((dist, v));
                    }
                }
            }
            if let Some((_, v)) = best {
                return v;
            }
        }
        0.0
    }
}
