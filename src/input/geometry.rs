//! Shapes to geo-types: polygons (with the lowest Z, for ground elevation) and lines, plus
//! the checks a lot must pass before the later stages can work on it.

use std::collections::BTreeSet;

use geo::{orient::Direction, Area, Orient};
use geo_types::{Coord, LineString, Polygon};
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

/// The polygons of one shape, as [`polygons_of`] reads them.
#[derive(Debug, Default)]
pub struct ShapePolygons {
    /// Exterior rings counter-clockwise, holes clockwise (geo's convention).
    pub polygons: Vec<Polygon<f64>>,
    /// The lowest Z of a PolygonZ.
    pub lowest_z: Option<f64>,
    /// Rings wound against the shapefile standard (an outer ring counter-clockwise, a hole
    /// clockwise), read by where they lie all the same: the caller counts them in a warning.
    pub against_winding: usize,
}

/// Polygons of a shape, with the lowest Z of a PolygonZ. Rings are sorted into outers and
/// holes as GDAL and QGIS read shapefiles: rings wound as outers are outers; a ring wound as a
/// hole is the hole of the smallest outer around it, or an outer ring when it lies in none.
/// A feature whose largest ring is counter-clockwise was written with the opposite winding
/// (many non-ESRI tools do), so its windings are read the other way round. The shapefile
/// crate would call such rings orphaned holes and the feature would vanish.
/// `Err` names the shape kind when the shape is not a polygon.
pub fn polygons_of(shape: &Shape) -> Result<ShapePolygons, &'static str> {
    fn rings<P: Copy>(
        r: &[shapefile::PolygonRing<P>],
        xy: impl Fn(P) -> Coord<f64>,
    ) -> Vec<Vec<Coord<f64>>> {
        r.iter()
            .map(|ring| ring.points().iter().map(|p| xy(*p)).collect())
            .collect()
    }
    let (rings, lowest_z) = match shape {
        Shape::Polygon(p) => (rings(p.rings(), |q| Coord { x: q.x, y: q.y }), None),
        Shape::PolygonM(p) => (rings(p.rings(), |q| Coord { x: q.x, y: q.y }), None),
        Shape::PolygonZ(p) => {
            let z = p
                .rings()
                .iter()
                .flat_map(|r| r.points())
                .map(|q| q.z)
                .filter(|z| z.is_finite())
                .fold(f64::INFINITY, f64::min);
            (
                rings(p.rings(), |q| Coord { x: q.x, y: q.y }),
                z.is_finite().then_some(z),
            )
        }
        Shape::NullShape => return Ok(ShapePolygons::default()),
        other => return Err(shape_kind(other)),
    };
    let (polygons, against_winding) = organise_rings(rings);
    Ok(ShapePolygons {
        polygons,
        lowest_z,
        against_winding,
    })
}

/// Sorts rings into polygons (see [`polygons_of`]); returns them with the number of rings
/// wound against the shapefile standard. Outer rings keep the order they were read in, so
/// the parts of a multipart feature keep their numbers.
fn organise_rings(rings: Vec<Vec<Coord<f64>>>) -> (Vec<Polygon<f64>>, usize) {
    use geo::coordinate_position::{CoordPos, CoordinatePosition};
    use geo::BoundingRect;
    let finite = |r: &[Coord<f64>]| r.iter().all(|c| c.x.is_finite() && c.y.is_finite());
    let signed: Vec<f64> = rings.iter().map(|r| shoelace(r)).collect();
    let n = rings.len();
    // The standard winds outers clockwise (a negative shoelace area); a feature whose largest
    // ring winds the other way is read with both windings swapped.
    let largest =
        (0..n).max_by(|&a, &b| signed[a].abs().total_cmp(&signed[b].abs()).then(b.cmp(&a)));
    let reversed = largest.is_some_and(|i| signed[i] > 0.0);
    // A ring with a non-finite coordinate is an outer ring of its own; check_polygon skips
    // it. A ring with no area has no winding: it is a hole where it lies in an outer ring
    // (where it changes nothing) and an outer ring, skipped as having no area, where not.
    let wound_outer: Vec<bool> = (0..n)
        .map(|i| !finite(&rings[i]) || (signed[i] != 0.0 && ((signed[i] < 0.0) != reversed)))
        .collect();
    let mut holder: Vec<Option<usize>> = vec![None; n];
    if wound_outer.iter().any(|o| !o) {
        let boxes: Vec<_> = rings
            .iter()
            .map(|r| {
                finite(r)
                    .then(|| LineString(r.clone()).bounding_rect())
                    .flatten()
            })
            .collect();
        // Each outer ring as a polygon once, for the point-in-ring tests of every hole.
        let shells: Vec<Option<Polygon<f64>>> = (0..n)
            .map(|j| {
                (wound_outer[j] && boxes[j].is_some())
                    .then(|| Polygon::new(LineString(rings[j].clone()), vec![]))
            })
            .collect();
        for i in (0..n).filter(|&i| !wound_outer[i]) {
            let Some(bi) = boxes[i] else { continue };
            holder[i] = (0..n)
                .filter(|&j| j != i)
                .filter(|&j| {
                    let (Some(bj), Some(shell)) = (boxes[j], &shells[j]) else {
                        return false;
                    };
                    let in_box = bj.min().x <= bi.min().x
                        && bj.min().y <= bi.min().y
                        && bj.max().x >= bi.max().x
                        && bj.max().y >= bi.max().y;
                    in_box
                        && rings[i]
                            .iter()
                            .map(|c| shell.coordinate_position(c))
                            .find(|p| *p != CoordPos::OnBoundary)
                            == Some(CoordPos::Inside)
                })
                .min_by(|&a, &b| signed[a].abs().total_cmp(&signed[b].abs()).then(a.cmp(&b)));
        }
    }
    let is_outer = |i: usize| wound_outer[i] || holder[i].is_none();
    let against_winding = match reversed {
        true => n,
        false => (0..n)
            .filter(|&i| !wound_outer[i] && holder[i].is_none() && signed[i] != 0.0)
            .count(),
    };
    let outer: Vec<bool> = (0..n).map(is_outer).collect();
    let mut rings: Vec<Option<Vec<Coord<f64>>>> = rings.into_iter().map(Some).collect();
    let mut slot = vec![usize::MAX; n];
    let mut polygons: Vec<Polygon<f64>> = Vec::new();
    for i in (0..n).filter(|&i| outer[i]) {
        slot[i] = polygons.len();
        let ring = rings[i].take().unwrap_or_default();
        polygons.push(Polygon::new(LineString(ring), vec![]));
    }
    for i in (0..n).filter(|&i| !outer[i]) {
        if let (Some(j), Some(ring)) = (holder[i], rings[i].take()) {
            polygons[slot[j]].interiors_push(LineString(ring));
        }
    }
    // geo's orient compares coordinates with partial_cmp().unwrap(): a NaN would panic, so
    // a polygon with a non-finite coordinate goes through unoriented.
    let polygons = polygons
        .into_iter()
        .map(|p| {
            let ok = finite(&p.exterior().0) && p.interiors().iter().all(|r| finite(&r.0));
            if ok {
                p.orient(Direction::Default)
            } else {
                p
            }
        })
        .collect();
    (polygons, against_winding)
}

/// Twice the signed area of a ring, positive when counter-clockwise (y up).
fn shoelace(ring: &[Coord<f64>]) -> f64 {
    let closing = match (ring.first(), ring.last()) {
        (Some(a), Some(b)) => b.x * a.y - a.x * b.y,
        _ => 0.0,
    };
    ring.windows(2)
        .map(|w| w[0].x * w[1].y - w[1].x * w[0].y)
        .sum::<f64>()
        + closing
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

/// How far outside the box of the city's lots, footprints and streets a point feature (a
/// landmark, a link) may lie, metres. A municipality's layer of public buildings reaches
/// well past the lots surveyed in its centre (Chino's post offices and schools stand up to
/// 9.6 km beyond its parcels, `tests/real_data.rs`); a point tens of kilometres away is a
/// typo or a coordinate in another CRS, and one thousands of kilometres away fails the
/// reprojection after the tiles are written.
pub const CITY_MARGIN: f64 = 20_000.0;

/// Why `at` (output CRS) cannot be a feature of the city whose box is `city`, or `None`.
pub fn beyond_city(at: Coord<f64>, city: Option<geo_types::Rect<f64>>) -> Option<String> {
    if !(at.x.is_finite() && at.y.is_finite()) {
        return Some("its coordinates are not finite numbers: give its x, y".into());
    }
    if !crate::model::sane(at) {
        return Some(format!(
            "it lies {:.0e} m or more from the CRS's origin: check its x, y",
            crate::model::FAR
        ));
    }
    let city = city?;
    let dx = (city.min().x - at.x).max(at.x - city.max().x).max(0.0);
    let dy = (city.min().y - at.y).max(at.y - city.max().y).max(0.0);
    let off = dx.hypot(dy);
    (off > CITY_MARGIN).then(|| {
        format!(
            "it lies {off:.0} m outside the city (the box of its lots, footprints and streets \
             widened by {CITY_MARGIN} m): check its x, y, and that they are in the output CRS"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed square ring, clockwise (the shapefile's outer winding) or not.
    fn square(x: f64, y: f64, size: f64, clockwise: bool) -> Vec<Coord<f64>> {
        let mut r = vec![
            Coord { x, y },
            Coord { x: x + size, y },
            Coord {
                x: x + size,
                y: y + size,
            },
            Coord { x, y: y + size },
        ];
        if clockwise {
            r.reverse();
        }
        r.push(r[0]);
        r
    }

    #[test]
    fn standard_winding_gives_an_outer_with_its_hole() {
        let (p, against) = organise_rings(vec![
            square(0.0, 0.0, 10.0, true),
            square(2.0, 2.0, 2.0, false),
        ]);
        assert_eq!(p.len(), 1);
        assert_eq!(p[0].interiors().len(), 1);
        assert_eq!(against, 0);
    }

    #[test]
    fn a_counter_clockwise_outer_is_read_and_counted() {
        let (p, against) = organise_rings(vec![square(0.0, 0.0, 10.0, false)]);
        assert_eq!(p.len(), 1);
        assert!((p[0].unsigned_area() - 100.0).abs() < 1e-9);
        assert_eq!(against, 1);
    }

    #[test]
    fn a_feature_wound_the_other_way_keeps_its_hole() {
        let (p, against) = organise_rings(vec![
            square(0.0, 0.0, 10.0, false),
            square(2.0, 2.0, 2.0, true),
        ]);
        assert_eq!(
            p.len(),
            1,
            "one polygon with a courtyard, not two overlapping ones"
        );
        assert_eq!(p[0].interiors().len(), 1);
        assert!((p[0].unsigned_area() - 96.0).abs() < 1e-9);
        assert_eq!(against, 2);
    }

    #[test]
    fn a_hole_outside_every_outer_is_an_outer_and_holes_find_their_own_outer() {
        // Two parts; the second part's hole is written first, after the first part.
        let (p, against) = organise_rings(vec![
            square(0.0, 0.0, 10.0, true),
            square(22.0, 2.0, 2.0, false),
            square(20.0, 0.0, 10.0, true),
            square(50.0, 0.0, 1.0, false),
        ]);
        assert_eq!(p.len(), 3);
        assert_eq!(p[0].interiors().len(), 0);
        assert_eq!(
            p[1].interiors().len(),
            1,
            "the hole went to the ring around it"
        );
        assert_eq!(p[2].interiors().len(), 0);
        assert_eq!(against, 1);
    }

    #[test]
    fn exteriors_come_out_counter_clockwise_for_geo() {
        use geo::Winding;
        for clockwise in [true, false] {
            let (p, _) = organise_rings(vec![square(0.0, 0.0, 1.0, clockwise)]);
            assert!(p[0].exterior().is_ccw());
        }
    }

    #[test]
    fn points_far_outside_the_city_are_named_with_the_distance() {
        let city = Some(geo_types::Rect::new(
            Coord { x: 0.0, y: 0.0 },
            Coord { x: 100.0, y: 100.0 },
        ));
        assert_eq!(beyond_city(Coord { x: 50.0, y: 50.0 }, city), None);
        assert_eq!(
            beyond_city(
                Coord {
                    x: -19_999.0,
                    y: 50.0
                },
                city
            ),
            None
        );
        assert!(beyond_city(
            Coord {
                x: -20_001.0,
                y: 50.0
            },
            city
        )
        .is_some());
        let far = beyond_city(Coord { x: 5e7, y: 50.0 }, city).unwrap();
        assert!(far.contains("49999900 m outside"), "{far}");
        assert!(beyond_city(Coord { x: 1e300, y: 0.0 }, city).is_some());
        assert!(beyond_city(
            Coord {
                x: f64::NAN,
                y: 0.0
            },
            None
        )
        .is_some());
        assert_eq!(beyond_city(Coord { x: 9e7, y: 0.0 }, None), None);
        assert!(beyond_city(Coord { x: 2e8, y: 0.0 }, None).is_some());
    }
}
