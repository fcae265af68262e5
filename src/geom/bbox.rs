//! Bounding boxes of point sets, as `[xmin, ymin, xmax, ymax]`.

use geo_types::Coord;

/// The box around `points`, or `None` when there are none. Non-finite coordinates are the
/// caller's to leave out.
///
/// ```
/// use edo_city::geom::bbox::bbox;
/// use geo_types::Coord;
/// let b = bbox([Coord { x: 1.0, y: 5.0 }, Coord { x: -2.0, y: 3.0 }]);
/// assert_eq!(b, Some([-2.0, 3.0, 1.0, 5.0]));
/// assert_eq!(bbox(std::iter::empty()), None);
/// ```
pub fn bbox(points: impl IntoIterator<Item = Coord<f64>>) -> Option<[f64; 4]> {
    let mut it = points.into_iter();
    let first = it.next()?;
    Some(it.fold([first.x, first.y, first.x, first.y], |b, c| {
        [b[0].min(c.x), b[1].min(c.y), b[2].max(c.x), b[3].max(c.y)]
    }))
}

/// The box holding both boxes.
///
/// ```
/// use edo_city::geom::bbox::union;
/// assert_eq!(union([0.0, 0.0, 1.0, 1.0], [2.0, -1.0, 3.0, 0.5]), [0.0, -1.0, 3.0, 1.0]);
/// ```
pub fn union(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}
