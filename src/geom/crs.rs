//! Coordinate reference systems: read from `.prj`, chosen for the output, and reprojection
//! (input reads the layers with it; the tileset writer places the city on the globe).
//!
//! The pipeline works in projected metres. Each layer's `.prj` (ESRI WKT) is turned into a
//! proj string with `proj4wkt` and coordinates are moved with `proj4rs`, both pure Rust.
//! The output CRS is the parameter file's `crs`, else the lots layer's own CRS when it is
//! projected, else the UTM zone of the lots' centre.

use geo_types::Coord;
use proj4rs::Proj;

/// Why a CRS cannot be read or coordinates not moved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CrsError {
    /// The WKT is not one `proj4wkt` reads.
    #[error("cannot read the projection WKT ({0})")]
    Wkt(String),
    /// `EPSG:` and no number.
    #[error("`{0}` is not an EPSG code")]
    NotEpsg(String),
    /// A code the built-in list does not hold.
    #[error("EPSG:{0} is not in the built-in list of codes")]
    UnknownEpsg(u16),
    /// Neither `EPSG:<code>`, a proj string nor WKT.
    #[error("`{0}` is not a CRS: give `EPSG:<code>`, a proj string (+proj=...) or WKT")]
    NotACrs(String),
    /// A proj string `proj4rs` cannot use.
    #[error("cannot use the projection `{definition}`: {cause}")]
    Proj {
        /// The proj string.
        definition: String,
        /// What proj4rs said.
        cause: String,
    },
    /// A point that cannot be moved.
    #[error("cannot reproject ({x:.6}, {y:.6}): {cause}")]
    Reproject {
        /// Its x (or longitude).
        x: f64,
        /// Its y (or latitude).
        y: f64,
        /// What proj4rs said.
        cause: String,
    },
}

/// A coordinate reference system we can transform to and from.
pub struct Crs {
    /// The proj string, as written into the manifest.
    pub definition: String,
    proj: Proj,
}

impl std::fmt::Debug for Crs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.definition)
    }
}

impl Crs {
    /// From the text of a `.prj` file (ESRI or OGC WKT).
    pub fn from_wkt(wkt: &str) -> Result<Crs, CrsError> {
        let def =
            proj4wkt::wkt_to_projstring(wkt.trim()).map_err(|e| CrsError::Wkt(format!("{e:?}")))?;
        Crs::from_proj_string(&def)
    }

    /// From the parameter file: `EPSG:6674`, a proj string (`+proj=...`) or WKT.
    pub fn from_user(s: &str) -> Result<Crs, CrsError> {
        let t = s.trim();
        if t.starts_with("PROJCS") || t.starts_with("GEOGCS") || t.starts_with("PROJCRS") {
            return Crs::from_wkt(t);
        }
        if let Some(code) = t.strip_prefix("EPSG:").or_else(|| t.strip_prefix("epsg:")) {
            let n: u16 = code
                .trim()
                .parse()
                .map_err(|_| CrsError::NotEpsg(t.to_string()))?;
            let def = crs_definitions::from_code(n).ok_or(CrsError::UnknownEpsg(n))?;
            return Crs::from_proj_string(def.proj4);
        }
        if t.starts_with('+') {
            return Crs::from_proj_string(t);
        }
        Err(CrsError::NotACrs(t.to_string()))
    }

    fn from_proj_string(def: &str) -> Result<Crs, CrsError> {
        let proj = Proj::from_proj_string(def).map_err(|e| CrsError::Proj {
            definition: def.to_string(),
            cause: format!("{e:?}"),
        })?;
        Ok(Crs {
            definition: def.to_string(),
            proj,
        })
    }

    /// The EPSG code whose definition bears the name `name` (a WKT's `PROJCS["<name>"`, as
    /// a `.prj` without AUTHORITY gives it), from the built-in list of codes.
    ///
    /// ```
    /// let code = edo_city::geom::crs::Crs::epsg_named("JGD2011 / Japan Plane Rectangular CS VI");
    /// assert_eq!(code, Some(6674));
    /// assert_eq!(edo_city::geom::crs::Crs::epsg_named("My own grid"), None);
    /// ```
    pub fn epsg_named(name: &str) -> Option<u16> {
        let head = format!("PROJCS[\"{name}\",");
        (1024..=u16::MAX).find(|&code| {
            crs_definitions::from_code(code).is_some_and(|d| d.wkt.starts_with(&head))
        })
    }

    /// The UTM zone (WGS84) holding a longitude/latitude in degrees.
    pub fn utm_for(lon: f64, lat: f64) -> Crs {
        let zone = (((lon + 180.0) / 6.0).floor() as i32).clamp(0, 59) + 1;
        let south = if lat < 0.0 { " +south" } else { "" };
        let def = format!("+proj=utm +zone={zone}{south} +datum=WGS84 +units=m +no_defs");
        Crs::from_proj_string(&def).expect("UTM definitions are valid")
    }

    /// Whether the CRS is longitude/latitude in degrees (not projected metres).
    pub fn is_geographic(&self) -> bool {
        self.proj.is_latlong()
    }

    /// True when both describe the same system (same proj parameters, in any order).
    pub fn same_as(&self, other: &Crs) -> bool {
        normalise(&self.definition) == normalise(&other.definition)
    }
}

fn normalise(def: &str) -> Vec<String> {
    let mut parts: Vec<String> = def
        .split_whitespace()
        .filter(|p| *p != "+no_defs" && *p != "+type=crs")
        .map(|p| {
            // "+x_0=0.0" and "+x_0=0" are the same parameter.
            match p.split_once('=') {
                Some((k, v)) => match v.parse::<f64>() {
                    Ok(n) => format!("{k}={n}"),
                    Err(_) => p.to_string(),
                },
                None => p.to_string(),
            }
        })
        .collect();
    parts.sort();
    parts
}

/// Moves coordinates from `src` to `dst` in place. Geographic coordinates are in degrees.
pub fn reproject(coords: &mut [Coord<f64>], src: &Crs, dst: &Crs) -> Result<(), CrsError> {
    if src.same_as(dst) {
        return Ok(());
    }
    for c in coords.iter_mut() {
        let mut p = if src.is_geographic() {
            (c.x.to_radians(), c.y.to_radians(), 0.0)
        } else {
            (c.x, c.y, 0.0)
        };
        proj4rs::transform::transform(&src.proj, &dst.proj, &mut p).map_err(|e| {
            CrsError::Reproject {
                x: c.x,
                y: c.y,
                cause: format!("{e:?}"),
            }
        })?;
        *c = if dst.is_geographic() {
            Coord {
                x: p.0.to_degrees(),
                y: p.1.to_degrees(),
            }
        } else {
            Coord { x: p.0, y: p.1 }
        };
    }
    Ok(())
}

/// True when every coordinate could be a longitude/latitude in degrees: used to catch layers
/// without a `.prj` whose numbers are degrees where metres are expected. A town in degrees
/// spans well under a degree, so a layer wider than [`DEGREES_SPAN`] is metres near its
/// CRS's origin (a local survey grid), not degrees.
pub fn looks_like_degrees(coords: impl IntoIterator<Item = Coord<f64>>) -> bool {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for c in coords {
        if !(c.x.abs() <= 180.0 && c.y.abs() <= 90.0) {
            return false;
        }
        lo = [lo[0].min(c.x), lo[1].min(c.y)];
        hi = [hi[0].max(c.x), hi[1].max(c.y)];
    }
    lo[0] <= hi[0] && hi[0] - lo[0] <= DEGREES_SPAN && hi[1] - lo[1] <= DEGREES_SPAN
}

/// The widest layer taken for degrees: 2 degrees is about 200 km, more than any city; 2 m is
/// less than any lot.
pub const DEGREES_SPAN: f64 = 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zone_vi_round_trips_through_lon_lat() {
        let zone6 = Crs::from_user("EPSG:6674").unwrap();
        let geo = Crs::from_user("EPSG:6668").unwrap();
        assert!(geo.is_geographic() && !zone6.is_geographic());
        // Kyoto station, roughly.
        let mut c = [Coord {
            x: 135.7588,
            y: 34.9858,
        }];
        reproject(&mut c, &geo, &zone6).unwrap();
        assert!((c[0].x - -22_000.0).abs() < 2_000.0, "{:?}", c[0]);
        assert!((c[0].y - -112_000.0).abs() < 2_000.0, "{:?}", c[0]);
        reproject(&mut c, &zone6, &geo).unwrap();
        assert!((c[0].x - 135.7588).abs() < 1e-9 && (c[0].y - 34.9858).abs() < 1e-9);
    }

    #[test]
    fn esri_wkt_and_epsg_name_the_same_zone() {
        let wkt = r#"PROJCS["JGD_2011_Japan_Zone_6",GEOGCS["GCS_JGD_2011",DATUM["D_JGD_2011",SPHEROID["GRS_1980",6378137.0,298.257222101]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["False_Easting",0.0],PARAMETER["False_Northing",0.0],PARAMETER["Central_Meridian",136.0],PARAMETER["Scale_Factor",0.9999],PARAMETER["Latitude_Of_Origin",36.0],UNIT["Meter",1.0]]"#;
        let a = Crs::from_wkt(wkt).unwrap();
        let b = Crs::from_user("EPSG:6674").unwrap();
        let mut p = [Coord {
            x: -20_000.0,
            y: -110_000.0,
        }];
        reproject(&mut p, &a, &b).unwrap();
        assert!(
            (p[0].x + 20_000.0).abs() < 0.01 && (p[0].y + 110_000.0).abs() < 0.01,
            "{:?}",
            p[0]
        );
    }

    #[test]
    fn utm_zone_of_swellendam_is_34_south() {
        let c = Crs::utm_for(20.44, -34.02);
        assert!(c.definition.contains("+zone=34") && c.definition.contains("+south"));
    }

    #[test]
    fn degrees_are_recognised() {
        assert!(looks_like_degrees([Coord { x: 135.7, y: 35.0 }]));
        assert!(!looks_like_degrees([Coord {
            x: -22_000.0,
            y: -110_000.0
        }]));
        // A local grid in metres near its origin: 80 m wide is not 80 degrees.
        assert!(!looks_like_degrees([
            Coord { x: 0.0, y: 0.0 },
            Coord { x: 80.0, y: 45.0 }
        ]));
        assert!(looks_like_degrees([
            Coord {
                x: 135.75,
                y: 34.98
            },
            Coord {
                x: 135.78,
                y: 35.01
            }
        ]));
        assert!(!looks_like_degrees(Vec::<Coord<f64>>::new()));
    }

    #[test]
    fn nonsense_is_an_error_that_says_what_to_give() {
        let e = Crs::from_user("kyoto").unwrap_err();
        assert_eq!(e, CrsError::NotACrs("kyoto".into()));
        assert!(e.to_string().contains("EPSG"), "{e}");
    }
}
