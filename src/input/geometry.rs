//! Shapes to geo-types: polygons (with the lowest Z, for ground elevation) and lines, plus
//! the checks a lot must pass before the later stages can work on it.

use std::collections::BTreeSet;

use geo::{orient::Direction, Area, Orient};
use geo_types::{Coord, LineString, MultiPolygon, Polygon};
use shapefile::Shape;

/// The kind of a shape, for messages ("record 3 is a point; ...").
pub fn shape_kind(shape: &Shape) -> &'static str {
    match shape {
        Shape::NullShape => "null shape",
        Shape::Point(_) | Shape::PointM(_) | Shape::PointZ(_) => "point",
        Shape::Multipoint(_) | Shape::MultipointM(_) | Shape::MultipointZ(_) => "multipoint",
        Shape::Polyline(_) | Shape::PolylineM(_) | Shape::PolylineZ(_) => "polyline",
        Shape::Polygon(_) | Shape::PolygonM(_) | Shape::PolygonZ(_) => "polygon",
        Shape::Multipatch(_) => "multipatch",
    }
}

/// Polygons of a shape, exterior rings counter-clockwise, with the lowest Z of a PolygonZ.
/// `Err` names the shape kind when the shape is not a polygon.
pub fn polygons_of(shape: &Shape) -> Result<(Vec<Polygon<f64>>, Option<f64>), &'static str> {
    let (mp, z): (Result<MultiPolygon<f64>, _>, Option<f64>) = match shape {
        Shape::Polygon(p) => (MultiPolygon::try_from(p.clone()), None),
        Shape::PolygonM(p) => (MultiPolygon::try_from(p.clone()), None),
        Shape::PolygonZ(p) => {
            let z = p
                .rings()
                .iter()
                .flat_map(|r| r.points())
                .map(|q| q.z)
                .filter(|z| z.is_finite())
                .fold(f64::INFINITY, f64::min);
            (
                MultiPolygon::try_from(p.clone()),
                z.is_finite().then_some(z),
            )
        }
        Shape::NullShape => return Ok((Vec::new(), None)),
        other => return Err(shape_kind(other)),
    };
    // geo's orient compares coordinates with partial_cmp().unwrap(): a NaN would panic. Rings
    // with a non-finite coordinate go through unoriented; check_polygon skips them.
    let finite = |p: &Polygon<f64>| {
        p.exterior()
            .0
            .iter()
            .chain(p.interiors().iter().flat_map(|r| r.0.iter()))
            .all(|c| c.x.is_finite() && c.y.is_finite())
    };
    let polys = mp
        .map(|m| {
            m.0.into_iter()
                .map(|p| {
                    if finite(&p) {
                        p.orient(Direction::Default)
                    } else {
                        p
                    }
                })
                .collect()
        })
        .unwrap_or_default();
    Ok((polys, z))
}

/// Lines of a shape (each part one line).
pub fn lines_of(shape: &Shape) -> Result<Vec<LineString<f64>>, &'static str> {
    fn parts<P: Copy>(parts: &[Vec<P>], xy: impl Fn(P) -> Coord<f64>) -> Vec<LineString<f64>> {
        parts
            .iter()
            .map(|r| LineString(r.iter().map(|p| xy(*p)).collect()))
            .collect()
    }
    Ok(match shape {
        Shape::Polyline(p) => parts(p.parts(), |q| Coord { x: q.x, y: q.y }),
        Shape::PolylineM(p) => parts(p.parts(), |q| Coord { x: q.x, y: q.y }),
        Shape::PolylineZ(p) => parts(p.parts(), |q| Coord { x: q.x, y: q.y }),
        Shape::NullShape => Vec::new(),
        other => return Err(shape_kind(other)),
    })
}

/// Points of a shape (a multipoint gives each of its points).
pub fn points_of(shape: &Shape) -> Result<Vec<Coord<f64>>, &'static str> {
    let xy = |x: f64, y: f64| Coord { x, y };
    Ok(match shape {
        Shape::Point(p) => vec![xy(p.x, p.y)],
        Shape::PointM(p) => vec![xy(p.x, p.y)],
        Shape::PointZ(p) => vec![xy(p.x, p.y)],
        Shape::Multipoint(m) => m.points().iter().map(|p| xy(p.x, p.y)).collect(),
        Shape::MultipointM(m) => m.points().iter().map(|p| xy(p.x, p.y)).collect(),
        Shape::MultipointZ(m) => m.points().iter().map(|p| xy(p.x, p.y)).collect(),
        Shape::NullShape => Vec::new(),
        other => return Err(shape_kind(other)),
    })
}

/// A polygon the later stages can work on: finite, at least a triangle, with an area.
pub fn check_polygon(poly: &Polygon<f64>) -> Result<(), String> {
    let ext = poly.exterior();
    let all = || {
        ext.0
            .iter()
            .chain(poly.interiors().iter().flat_map(|r| r.0.iter()))
    };
    if all().any(|c| !c.x.is_finite() || !c.y.is_finite()) {
        return Err(
            "a coordinate is not a finite number (NaN or infinite): the geometry is damaged; \
             redraw the feature or export the layer again"
                .into(),
        );
    }
    if all().any(|c| !crate::model::sane(*c)) {
        return Err(format!(
            "a coordinate lies {:.0e} m or more from the CRS's origin (the Earth is 4e7 m \
             round): the geometry is damaged; redraw the feature or export the layer again",
            crate::model::FAR
        ));
    }
    let distinct: BTreeSet<(u64, u64)> = ext
        .0
        .iter()
        .map(|c| (c.x.to_bits(), c.y.to_bits()))
        .collect();
    if distinct.len() < 3 {
        return Err(format!(
            "the outline has {} distinct vertices; a polygon needs at least 3: redraw it or \
             delete it",
            distinct.len()
        ));
    }
    if poly.unsigned_area() < 1e-6 {
        // A bow tie's two loops cancel; a flat outline has no loop at all.
        let pts: Vec<&Coord<f64>> = ext.0.iter().collect();
        let flat = pts.windows(3).all(|w| {
            let (a, b, c) = (w[0], w[1], w[2]);
            ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)).abs() < 1e-6
        });
        return Err(match flat {
            true => "the outline has no area (under 1 mm2: its vertices lie on one line, or \
                     its numbers are not metres); redraw it or delete it"
                .into(),
            false => "the outline crosses itself and its loops enclose no net area (a bow \
                      tie); redraw it as a simple polygon"
                .into(),
        });
    }
    Ok(())
}

/// A change applied to a run of coordinates in place (a reprojection).
pub type CoordsFn<'a> = dyn FnMut(&mut [Coord<f64>]) -> Result<(), String> + 'a;

/// Applies `f` to every coordinate of a polygon.
pub fn map_polygon(poly: &mut Polygon<f64>, f: &mut CoordsFn) -> Result<(), String> {
    let mut result = Ok(());
    poly.exterior_mut(|ls| result = f(&mut ls.0));
    result?;
    let mut result = Ok(());
    poly.interiors_mut(|rings| {
        for ls in rings {
            if result.is_ok() {
                result = f(&mut ls.0);
            }
        }
    });
    result
}
