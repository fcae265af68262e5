//! Straight segments: their distance to a point, and as R-tree entries.

use rstar::{PointDistance, RTreeObject, AABB};

/// A straight segment carrying a value, in an R-tree: a street edge with its half-width (0 for
/// block boundaries, which are the edge itself), a line carrying a street width, a piece of
/// street centreline.
#[derive(Debug, Clone, Copy)]
pub struct Segment {
    /// One end, map metres.
    pub a: [f64; 2],
    /// The other end.
    pub b: [f64; 2],
    /// What the segment carries (a half-width, a street width).
    pub value: f64,
}

impl RTreeObject for Segment {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        AABB::from_corners(self.a, self.b)
    }
}

impl PointDistance for Segment {
    fn distance_2(&self, p: &[f64; 2]) -> f64 {
        segment_distance_2(*p, self.a, self.b)
    }
}

/// Squared distance from `p` to the segment `a`-`b`.
///
/// ```
/// use edo_city::geom::segment::segment_distance_2;
/// assert_eq!(segment_distance_2([1.0, 2.0], [0.0, 0.0], [4.0, 0.0]), 4.0);
/// assert_eq!(segment_distance_2([-3.0, 4.0], [0.0, 0.0], [4.0, 0.0]), 25.0);
/// assert_eq!(segment_distance_2([1.0, 1.0], [2.0, 2.0], [2.0, 2.0]), 2.0);
/// ```
pub fn segment_distance_2(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (qx, qy) = (a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
    qx * qx + qy * qy
}
