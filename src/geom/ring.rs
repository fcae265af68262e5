//! Rings as the stages walk them: without the closing point that geo and shapefiles repeat.

use geo_types::{Coord, LineString};

/// The vertices of a closed ring without its closing repeat.
///
/// ```
/// use edo_city::geom::ring::open;
/// use geo_types::LineString;
/// let ring = LineString::from(vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.0)]);
/// assert_eq!(open(&ring).len(), 3);
/// assert!(open(&LineString::new(vec![])).is_empty());
/// ```
pub fn open(ring: &LineString<f64>) -> &[Coord<f64>] {
    let r = &ring.0;
    &r[..r.len().saturating_sub(1)]
}
