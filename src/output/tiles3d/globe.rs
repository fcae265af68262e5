//! Where the city stands on the globe: WGS84 earth-centred earth-fixed (ECEF) coordinates,
//! and the local frame of a map point, the matrix that takes metres of the output CRS's grid
//! (east, north) and metres up to ECEF.
//!
//! The frame at a point is the Jacobian of the inverse projection there (central
//! differences over 10 m), not a plain east-north-up frame: a projected grid is turned
//! against true north by the meridian convergence (a fraction of a degree in a Japanese plane
//! zone) and scaled by the projection's scale factor, and both change across a city. Each
//! tile gets the frame at its own centre, so the error stays that of a flat 250 m square
//! (well under a millimetre) however large the city.

use crate::geom::crs::{reproject, Crs};

/// WGS84 semi-major axis, metres.
const A: f64 = 6_378_137.0;
/// WGS84 flattening.
const F: f64 = 1.0 / 298.257_223_563;

/// ECEF metres of a longitude, latitude (degrees) and ellipsoidal height (metres).
pub fn ecef(lon: f64, lat: f64, h: f64) -> [f64; 3] {
    let e2 = F * (2.0 - F);
    let (lon, lat) = (lon.to_radians(), lat.to_radians());
    let n = A / (1.0 - e2 * lat.sin().powi(2)).sqrt();
    [
        (n + h) * lat.cos() * lon.cos(),
        (n + h) * lat.cos() * lon.sin(),
        (n * (1.0 - e2) + h) * lat.sin(),
    ]
}

/// Longitude, latitude (degrees) and height of an ECEF point (Bowring's iteration, to well
/// under a millimetre on the earth's surface).
pub fn geodetic(p: [f64; 3]) -> [f64; 3] {
    let e2 = F * (2.0 - F);
    let lon = p[1].atan2(p[0]);
    let r = p[0].hypot(p[1]);
    let mut lat = p[2].atan2(r * (1.0 - e2));
    let mut h = 0.0;
    for _ in 0..6 {
        let n = A / (1.0 - e2 * lat.sin().powi(2)).sqrt();
        h = r / lat.cos() - n;
        lat = p[2].atan2(r * (1.0 - e2 * n / (n + h)));
    }
    [lon.to_degrees(), lat.to_degrees(), h]
}

/// The unit normal of the ellipsoid (up) at a longitude and latitude, degrees.
fn up(lon: f64, lat: f64) -> [f64; 3] {
    let (lon, lat) = (lon.to_radians(), lat.to_radians());
    [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()]
}

/// A 4x4 affine matrix as 3 columns and a translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    /// The images of x, y, z.
    pub cols: [[f64; 3]; 3],
    /// The image of the origin.
    pub t: [f64; 3],
}

impl Affine {
    /// The identity.
    pub const IDENTITY: Affine = Affine {
        cols: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        t: [0.0; 3],
    };

    /// A translation.
    pub fn translation(t: [f64; 3]) -> Affine {
        Affine {
            t,
            ..Affine::IDENTITY
        }
    }

    /// Applies the matrix to a point.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let c = &self.cols;
        [0, 1, 2].map(|i| c[0][i] * p[0] + c[1][i] * p[1] + c[2][i] * p[2] + self.t[i])
    }

    /// `self` after `other` (`self * other`).
    pub fn then(&self, other: &Affine) -> Affine {
        let lin = |v: [f64; 3]| {
            let c = &self.cols;
            [0, 1, 2].map(|i| c[0][i] * v[0] + c[1][i] * v[1] + c[2][i] * v[2])
        };
        Affine {
            cols: other.cols.map(lin),
            t: self.apply(other.t),
        }
    }

    /// The inverse (the columns are independent for every frame made here).
    pub fn inverse(&self) -> Affine {
        let [a, b, c] = self.cols;
        let cross = |u: [f64; 3], v: [f64; 3]| {
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        };
        let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let det = dot(a, cross(b, c));
        // Rows of the inverse are the cross products over the determinant.
        let rows = [cross(b, c), cross(c, a), cross(a, b)].map(|r| r.map(|v| v / det));
        let cols = [0, 1, 2].map(|j| [rows[0][j], rows[1][j], rows[2][j]]);
        let lin = Affine { cols, t: [0.0; 3] };
        let t = lin.apply(self.t).map(|v| -v);
        Affine { cols, t }
    }

    /// Column-major 4x4, as 3D Tiles' `transform` has it.
    pub fn column_major(&self) -> [f64; 16] {
        let c = &self.cols;
        [
            c[0][0], c[0][1], c[0][2], 0.0, c[1][0], c[1][1], c[1][2], 0.0, c[2][0], c[2][1],
            c[2][2], 0.0, self.t[0], self.t[1], self.t[2], 1.0,
        ]
    }
}

/// How map metres become the globe's.
pub enum Globe {
    /// A projected CRS: the inverse projection, and the height the city's zero stands at.
    Projected {
        /// The output CRS.
        crs: Box<Crs>,
        /// WGS84 longitude/latitude.
        lonlat: Box<Crs>,
        /// Height of the output's zero, metres.
        h: f64,
    },
    /// A local CRS placed by `origin_lonlat`: grid metres are east-north-up at that point.
    Placed([f64; 3]),
}

impl Globe {
    /// The longitude and latitude of map point (x, y) in the output CRS.
    pub fn lonlat(&self, x: f64, y: f64) -> Result<(f64, f64), String> {
        match self {
            Globe::Projected { crs, lonlat, .. } => {
                let mut c = [geo_types::Coord { x, y }];
                reproject(&mut c, crs, lonlat).map_err(|e| e.to_string())?;
                Ok((c[0].x, c[0].y))
            }
            Globe::Placed(_) => Err("a placed city has no projection".into()),
        }
    }

    /// The frame at map point `at` (output CRS metres): grid metres east, north and metres
    /// up from `at` to ECEF.
    pub fn frame(&self, at: [f64; 2]) -> Result<Affine, String> {
        match self {
            Globe::Placed([lon, lat, h]) => Ok(enu(*lon, *lat, *h)),
            Globe::Projected { h, .. } => {
                let d = 10.0;
                let p = |dx: f64, dy: f64| -> Result<[f64; 3], String> {
                    let (lon, lat) = self.lonlat(at[0] + dx, at[1] + dy)?;
                    Ok(ecef(lon, lat, *h))
                };
                let (e1, e0, n1, n0) = (p(d, 0.0)?, p(-d, 0.0)?, p(0.0, d)?, p(0.0, -d)?);
                let diff = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|i| (a[i] - b[i]) / (2.0 * d));
                let (lon, lat) = self.lonlat(at[0], at[1])?;
                let (e, n) = (diff(e1, e0), diff(n1, n0));
                // A conformal projection scales east and north alike; up takes the same
                // scale (1 + a few 1e-4: a millimetre in 10 m of height), so the frame is a
                // rotation and one scale, which viewers' screen-space error needs.
                let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let s = (len(e) + len(n)) / 2.0;
                Ok(Affine {
                    cols: [e, n, up(lon, lat).map(|v| v * s)],
                    t: ecef(lon, lat, *h),
                })
            }
        }
    }
}

/// The east-north-up frame at a longitude, latitude (degrees) and height.
pub fn enu(lon: f64, lat: f64, h: f64) -> Affine {
    let (l, p) = (lon.to_radians(), lat.to_radians());
    Affine {
        cols: [
            [-l.sin(), l.cos(), 0.0],
            [-p.sin() * l.cos(), -p.sin() * l.sin(), p.cos()],
            up(lon, lat),
        ],
        t: ecef(lon, lat, h),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ecef_round_trips_and_matches_known_points() {
        // The equator at Greenwich is (a, 0, 0); the pole is b above the centre.
        let p = ecef(0.0, 0.0, 0.0);
        assert!((p[0] - A).abs() < 1e-6 && p[1].abs() < 1e-6 && p[2].abs() < 1e-6);
        let b = A * (1.0 - F);
        assert!((ecef(0.0, 90.0, 0.0)[2] - b).abs() < 1e-6);
        for (lon, lat, h) in [(135.7681, 35.0116, 45.0), (-70.0, -33.4, 520.0)] {
            let g = geodetic(ecef(lon, lat, h));
            assert!((g[0] - lon).abs() < 1e-10 && (g[1] - lat).abs() < 1e-10);
            assert!((g[2] - h).abs() < 1e-4);
        }
    }

    #[test]
    fn frames_invert_and_compose() {
        let f = enu(135.77, 35.0, 40.0);
        let g = f.inverse().then(&f);
        for (k, col) in g.cols.iter().enumerate() {
            for (i, v) in col.iter().enumerate() {
                let want = if i == k { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-9);
            }
        }
        let p = [120.0, -35.0, 7.0];
        let back = f.inverse().apply(f.apply(p));
        assert!((0..3).all(|i| (back[i] - p[i]).abs() < 1e-6));
        // The ENU frame's up is the ellipsoid normal: 1 m up adds 1 m of height.
        let g = geodetic(f.apply([0.0, 0.0, 1.0]));
        assert!((g[2] - 41.0).abs() < 1e-6);
    }
}
