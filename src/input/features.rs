//! Features of the layers that are not shapefiles (GeoPackage, GeoJSON, FlatGeobuf: issue
//! 77), taken as `shp::Feature`s: each geometry as the shape a shapefile would hold (Z kept,
//! M dropped as the shapefile reader drops it), each attribute as text as the DBF reader
//! writes it, so that every step after reading is the shapefiles' own.
//!
//! The three readers feed one [`Collector`], a geozero `FeatureProcessor`: geozero decodes
//! GeoPackage WKB and GeoJSON, flatgeobuf its own format, and each calls the same callbacks.
//! A count a file declares (a ring's points) is never trusted for an allocation: a blob that
//! says 2^31 points reserves at most what its bytes can hold.

use geozero::error::{GeozeroError, Result};
use geozero::{ColumnValue, CoordDimensions, FeatureProcessor, GeomProcessor, PropertyProcessor};
use shapefile::{Point, PointZ, PolygonRing, Shape};

use super::shp::Feature;
use super::InputError;
use crate::model::Attrs;
use std::path::Path;

/// The most points reserved ahead for one part, whatever its header says.
const RESERVE: usize = 4096;
/// The most coordinates one feature may have (a lot has dozens; a county outline a few
/// hundred thousand).
pub const MAX_POINTS: usize = 10_000_000;

/// What a geometry is, as far as a shapefile can hold it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
enum Kind {
    #[default]
    Empty,
    Points,
    Lines,
    Polygons,
    /// A geometry a shapefile cannot hold (a collection, a curve, a TIN): read as empty, and
    /// counted for the layer's warning.
    Other(&'static str),
}

/// One geometry being read: its parts (points, lines or rings) with their z.
#[derive(Debug, Default)]
struct Building {
    kind: Kind,
    parts: Vec<Vec<[f64; 3]>>,
    /// Where each polygon's rings begin in `parts` (its first ring is its outer).
    polygons: Vec<usize>,
    /// The part being read.
    part: Option<Vec<[f64; 3]>>,
    has_z: bool,
    points: usize,
}

/// The features of a layer as read: `shp::Feature`s in order, and the fields' names in the
/// order they were first met.
#[derive(Default)]
pub struct Collector {
    pub features: Vec<Feature>,
    /// Geometries a shapefile cannot hold, by kind, read as empty.
    pub unsupported: std::collections::BTreeMap<&'static str, usize>,
    geometry: Building,
    attrs: Vec<(std::sync::Arc<str>, String)>,
    /// Each field's name in the order first met, shared by every feature's attributes.
    names: Vec<std::sync::Arc<str>>,
}

impl Collector {
    /// Starts a feature (for a reader that is not driven by geozero's feature callbacks).
    pub fn begin(&mut self) {
        self.geometry = Building::default();
        self.attrs.clear();
    }

    /// Ends the feature begun last, as record `record`.
    pub fn end(&mut self, record: usize) {
        let g = std::mem::take(&mut self.geometry);
        if let Kind::Other(what) = g.kind {
            *self.unsupported.entry(what).or_default() += 1;
        }
        let mut attrs = Attrs::default();
        for (k, v) in self.attrs.drain(..) {
            attrs.insert(k, v);
        }
        self.features.push(Feature {
            record,
            shape: shape_of(g),
            attrs,
        });
    }

    /// Forgets what was read of the geometry of the feature begun last (it could not be
    /// decoded: the feature is read as empty).
    pub fn begin_geometry_again(&mut self) {
        self.geometry = Building::default();
    }

    /// The warning for the geometries a shapefile cannot hold, read as empty, if any.
    pub fn unsupported_warning(&self, file: &str) -> Option<crate::model::Warning> {
        (!self.unsupported.is_empty()).then(|| {
            let what: Vec<String> = (self.unsupported.iter())
                .map(|(k, n)| format!("{n} {k}"))
                .collect();
            crate::model::Warning::new(
                crate::model::WarningClass::Layer,
                format!(
                    "{file}: {} read as empty and skipped: a layer holds points, lines or \
                     polygons (in QGIS: Vector > Geometry Tools > Multipart to Singleparts, or \
                     Segmentize for curves)",
                    what.join(", ")
                ),
            )
            .in_file(file)
        })
    }

    /// The fields' names in the order they were first met.
    pub fn fields(&self) -> Vec<String> {
        self.names.iter().map(|n| n.to_string()).collect()
    }

    /// One attribute of the feature begun last, as text.
    pub fn attribute(&mut self, name: &str, value: String) {
        let shared = match self.names.iter().find(|n| &***n == name) {
            Some(n) => n.clone(),
            None => {
                self.names.push(name.into());
                self.names[self.names.len() - 1].clone()
            }
        };
        self.attrs.push((shared, value));
    }

    fn kind(&mut self, kind: Kind) {
        match (self.geometry.kind, kind) {
            // The first of a collection's members decides what it is not.
            (Kind::Other(_), _) => {}
            (Kind::Empty, k) => self.geometry.kind = k,
            (a, b) if a == b => {}
            _ => self.geometry.kind = Kind::Other("geometry collection"),
        }
    }

    fn point(&mut self, x: f64, y: f64, z: Option<f64>) -> Result<()> {
        let g = &mut self.geometry;
        g.points += 1;
        if g.points > MAX_POINTS {
            return Err(GeozeroError::Geometry(format!(
                "more than {MAX_POINTS} points in one feature"
            )));
        }
        g.has_z |= z.is_some();
        let p = [x, y, z.unwrap_or(0.0)];
        match &mut g.part {
            Some(part) => part.push(p),
            None => g.parts.push(vec![p]),
        }
        Ok(())
    }

    fn part_begin(&mut self, size: usize) {
        self.geometry.part = Some(Vec::with_capacity(size.min(RESERVE)));
    }

    fn part_end(&mut self) {
        if let Some(p) = self.geometry.part.take() {
            self.geometry.parts.push(p);
        }
    }
}

/// Opens the regular file `path` of a layer of at most `cap` bytes (`format` names its
/// kind, `hint` says what to do with a larger one): the file and its length.
pub fn open_layer(
    path: &Path,
    cap: u64,
    format: &str,
    hint: &str,
) -> std::result::Result<(std::fs::File, u64), InputError> {
    let err = |message: String| InputError::Layer {
        file: path.display().to_string(),
        message,
    };
    let (file, meta) =
        crate::bounded::open(path).map_err(|e| err(format!("cannot open it: {e}")))?;
    match meta.len() > cap {
        true => Err(err(format!(
            "{} bytes, more than the {cap} a {format} layer may have{hint}",
            meta.len()
        ))),
        false => Ok((file, meta.len())),
    }
}

/// A value as the DBF reader writes it: whole numbers without a fraction.
pub fn text_of(v: &ColumnValue) -> String {
    match v {
        ColumnValue::Float(f) => super::shp::fmt_number(f64::from(*f)),
        ColumnValue::Double(f) => super::shp::fmt_number(*f),
        ColumnValue::String(s) | ColumnValue::Json(s) | ColumnValue::DateTime(s) => s.to_string(),
        ColumnValue::Binary(_) => String::new(),
        other => other.to_string(),
    }
}

/// The shape a shapefile would hold for `g`.
fn shape_of(g: Building) -> Shape {
    let xy = |p: &[f64; 3]| Point::new(p[0], p[1]);
    let xyz = |p: &[f64; 3]| PointZ::new(p[0], p[1], p[2], shapefile::NO_DATA);
    let parts: Vec<&Vec<[f64; 3]>> = g.parts.iter().collect();
    match g.kind {
        Kind::Empty | Kind::Other(_) => Shape::NullShape,
        Kind::Points => {
            let all: Vec<&[f64; 3]> = parts.iter().flat_map(|p| p.iter()).collect();
            match (all.len(), g.has_z) {
                (0, _) => Shape::NullShape,
                (1, false) => Shape::Point(xy(all[0])),
                (1, true) => Shape::PointZ(xyz(all[0])),
                (_, false) => Shape::Multipoint(shapefile::Multipoint::new(
                    all.into_iter().map(xy).collect(),
                )),
                (_, true) => Shape::MultipointZ(shapefile::MultipointZ::new(
                    all.into_iter().map(xyz).collect(),
                )),
            }
        }
        Kind::Lines => {
            let lines: Vec<&&Vec<[f64; 3]>> = parts.iter().filter(|p| p.len() >= 2).collect();
            match (lines.is_empty(), g.has_z) {
                (true, _) => Shape::NullShape,
                (false, false) => Shape::Polyline(shapefile::Polyline::with_parts(
                    lines.iter().map(|p| p.iter().map(xy).collect()).collect(),
                )),
                (false, true) => Shape::PolylineZ(shapefile::PolylineZ::with_parts(
                    lines.iter().map(|p| p.iter().map(xyz).collect()).collect(),
                )),
            }
        }
        Kind::Polygons => {
            if parts.iter().all(|p| p.is_empty()) {
                return Shape::NullShape;
            }
            match g.has_z {
                false => Shape::Polygon(shapefile::Polygon::with_rings(rings(&g, xy))),
                true => Shape::PolygonZ(shapefile::PolygonZ::with_rings(rings(&g, xyz))),
            }
        }
    }
}

/// A polygon geometry's rings, each polygon's first its outer, as points of one kind.
fn rings<P>(g: &Building, to: impl Fn(&[f64; 3]) -> P) -> Vec<PolygonRing<P>> {
    (0..g.parts.len())
        .filter(|&i| !g.parts[i].is_empty())
        .map(|i| {
            let pts = g.parts[i].iter().map(&to).collect();
            match g.polygons.contains(&i) {
                true => PolygonRing::Outer(pts),
                false => PolygonRing::Inner(pts),
            }
        })
        .collect()
}

impl GeomProcessor for Collector {
    fn dimensions(&self) -> CoordDimensions {
        CoordDimensions::xyz()
    }

    fn xy(&mut self, x: f64, y: f64, _idx: usize) -> Result<()> {
        self.point(x, y, None)
    }

    fn coordinate(
        &mut self,
        x: f64,
        y: f64,
        z: Option<f64>,
        _m: Option<f64>,
        _t: Option<f64>,
        _tm: Option<u64>,
        _idx: usize,
    ) -> Result<()> {
        self.point(x, y, z)
    }

    fn point_begin(&mut self, _idx: usize) -> Result<()> {
        self.kind(Kind::Points);
        Ok(())
    }

    fn empty_point(&mut self, _idx: usize) -> Result<()> {
        self.kind(Kind::Points);
        Ok(())
    }

    fn multipoint_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Points);
        Ok(())
    }

    fn linestring_begin(&mut self, tagged: bool, size: usize, _idx: usize) -> Result<()> {
        // Untagged: a ring of the polygon being read, or a part of a multilinestring.
        if tagged {
            self.kind(Kind::Lines);
        }
        self.part_begin(size);
        Ok(())
    }

    fn linestring_end(&mut self, _tagged: bool, _idx: usize) -> Result<()> {
        self.part_end();
        Ok(())
    }

    fn multilinestring_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Lines);
        Ok(())
    }

    fn polygon_begin(&mut self, _tagged: bool, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Polygons);
        let at = self.geometry.parts.len();
        self.geometry.polygons.push(at);
        Ok(())
    }

    fn multipolygon_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Polygons);
        Ok(())
    }

    fn geometrycollection_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("geometry collection"));
        Ok(())
    }

    fn circularstring_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("curve"));
        self.part_begin(0);
        Ok(())
    }

    fn circularstring_end(&mut self, _idx: usize) -> Result<()> {
        self.part_end();
        Ok(())
    }

    fn compoundcurve_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("curve"));
        Ok(())
    }

    fn curvepolygon_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("curve"));
        Ok(())
    }

    fn multicurve_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("curve"));
        Ok(())
    }

    fn multisurface_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("curve"));
        Ok(())
    }

    fn triangle_begin(&mut self, _tagged: bool, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("triangle or TIN"));
        Ok(())
    }

    fn polyhedralsurface_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("polyhedral surface"));
        Ok(())
    }

    fn tin_begin(&mut self, _size: usize, _idx: usize) -> Result<()> {
        self.kind(Kind::Other("triangle or TIN"));
        Ok(())
    }
}

impl PropertyProcessor for Collector {
    fn property(&mut self, _idx: usize, name: &str, value: &ColumnValue) -> Result<bool> {
        self.attribute(name, text_of(value));
        Ok(false)
    }
}

impl FeatureProcessor for Collector {
    fn feature_begin(&mut self, _idx: u64) -> Result<()> {
        self.begin();
        Ok(())
    }

    fn feature_end(&mut self, idx: u64) -> Result<()> {
        self.end(idx as usize);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geozero::GeozeroGeometry;

    fn read(wkb: &[u8]) -> Shape {
        let mut c = Collector::default();
        c.begin();
        geozero::wkb::Wkb(wkb).process_geom(&mut c).unwrap();
        c.end(0);
        c.features.remove(0).shape
    }

    /// WKB of a polygon with one ring of `pts` (little-endian; with z when 3 numbers each).
    fn polygon_wkb(pts: &[[f64; 3]], z: bool) -> Vec<u8> {
        let mut b = vec![1u8];
        b.extend(if z { 1003u32 } else { 3u32 }.to_le_bytes());
        b.extend(1u32.to_le_bytes());
        b.extend((pts.len() as u32).to_le_bytes());
        for p in pts {
            b.extend(p[0].to_le_bytes());
            b.extend(p[1].to_le_bytes());
            if z {
                b.extend(p[2].to_le_bytes());
            }
        }
        b
    }

    #[test]
    fn a_polygon_is_the_shapefiles_with_its_z_kept() {
        let square = [
            [0.0, 0.0, 5.0],
            [0.0, 1.0, 6.0],
            [1.0, 1.0, 7.0],
            [1.0, 0.0, 8.0],
            [0.0, 0.0, 5.0],
        ];
        match read(&polygon_wkb(&square, false)) {
            Shape::Polygon(p) => assert_eq!(p.rings()[0].points().len(), 5),
            s => panic!("{s}"),
        }
        match read(&polygon_wkb(&square, true)) {
            Shape::PolygonZ(p) => assert_eq!(p.rings()[0].points()[2].z, 7.0),
            s => panic!("{s}"),
        }
    }

    #[test]
    fn a_ring_that_claims_two_billion_points_reserves_nothing_for_them() {
        let mut b = polygon_wkb(&[[0.0, 0.0, 0.0]; 4], false);
        b[9..13].copy_from_slice(&(1u32 << 31).to_le_bytes());
        let mut c = Collector::default();
        c.begin();
        assert!(geozero::wkb::Wkb(&b[..]).process_geom(&mut c).is_err());
    }

    #[test]
    fn values_read_as_the_dbf_reader_writes_them() {
        assert_eq!(text_of(&ColumnValue::Double(12.0)), "12");
        assert_eq!(text_of(&ColumnValue::Double(7.5)), "7.5");
        assert_eq!(text_of(&ColumnValue::Long(-3)), "-3");
        assert_eq!(text_of(&ColumnValue::String("中京")), "中京");
    }
}
