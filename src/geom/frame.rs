//! A frame on the map: origin `a`, unit axes `u` and `v`. A machiya's frontage frame has `u`
//! along the street and `v` into the lot (paper Fig.5); templates, kura and billboards are
//! laid out in such a frame and mapped back.

use geo_types::Coord;

/// A right-handed frame: map point = `a + x u + y v`.
///
/// ```
/// use edo_city::geom::frame::Frame;
/// use geo_types::Coord;
/// let f = Frame {
///     a: Coord { x: 10.0, y: 5.0 },
///     u: Coord { x: 0.0, y: 1.0 },
///     v: Coord { x: -1.0, y: 0.0 },
/// };
/// let p = Coord { x: 8.0, y: 8.0 };
/// assert_eq!(f.local(p), [3.0, 2.0]);
/// assert_eq!(f.map(f.local(p)), p);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// The frame's origin, map metres.
    pub a: Coord<f64>,
    /// The unit x axis (along the street for a frontage).
    pub u: Coord<f64>,
    /// The unit y axis, `u` turned a quarter to the left (into the lot).
    pub v: Coord<f64>,
}

impl Frame {
    /// The frame at `a` along the unit vector `u`, its `v` axis `u` turned a quarter to the
    /// left: a frontage's frame when `a` is its start and `u` runs along it.
    ///
    /// ```
    /// use edo_city::geom::frame::Frame;
    /// use geo_types::Coord;
    /// let f = Frame::along(Coord { x: 1.0, y: 2.0 }, Coord { x: 0.0, y: 1.0 });
    /// assert_eq!(f.v, Coord { x: -1.0, y: 0.0 });
    /// ```
    pub fn along(a: Coord<f64>, u: Coord<f64>) -> Frame {
        Frame {
            a,
            u,
            v: Coord { x: -u.y, y: u.x },
        }
    }

    /// Map coordinates of the local point `p = [x, y]`.
    pub fn map(&self, p: [f64; 2]) -> Coord<f64> {
        Coord {
            x: self.a.x + p[0] * self.u.x + p[1] * self.v.x,
            y: self.a.y + p[0] * self.u.y + p[1] * self.v.y,
        }
    }

    /// Local coordinates `[x, y]` of the map point `c`.
    pub fn local(&self, c: Coord<f64>) -> [f64; 2] {
        let (dx, dy) = (c.x - self.a.x, c.y - self.a.y);
        [dx * self.u.x + dy * self.u.y, dx * self.v.x + dy * self.v.y]
    }

    /// The local rectangle `[x0, y0, x1, y1]` as a map quad, corners in the order
    /// (x0, y0), (x1, y0), (x1, y1), (x0, y1).
    pub fn quad(&self, r: [f64; 4]) -> [Coord<f64>; 4] {
        [
            self.map([r[0], r[1]]),
            self.map([r[2], r[1]]),
            self.map([r[2], r[3]]),
            self.map([r[0], r[3]]),
        ]
    }
}
