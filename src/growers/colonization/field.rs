//! The vector fields that bend growth (seed 001, section 3.6), and the quaternion rotation
//! the seed applies to them about each attraction point's normal.
//!
//! The seed's eq. 13 is garbled: it writes the quaternion's vector part as
//! `(N . x) sin(theta/2) + (N . y) sin(theta/2) + (N . z) sin(theta/2)`, three scalars added.
//! The rotation about the unit axis N by theta is q = cos(theta/2) + (N_x i + N_y j + N_z k)
//! sin(theta/2), and X_rot = q X q* (eq. 14); [`rotate_about`] computes that product.

use crate::growers::v3::{self, V3};

/// A vector field over the growers' space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Field {
    /// No field.
    None,
    /// The same vector everywhere: wind, gravity.
    Constant(V3),
    /// Turning about the z axis (counter-clockwise seen from above for a positive
    /// `strength`), with `rise` upward: twisted trunks.
    Vortex {
        /// Tangential strength.
        strength: f64,
        /// Upward part.
        rise: f64,
    },
    /// Toward a point: light through a gap in the canopy.
    Toward(V3),
}

impl Field {
    /// The field's vector at `p` (not normalised).
    pub fn at(&self, p: V3) -> V3 {
        match *self {
            Field::None => [0.0; 3],
            Field::Constant(v) => v,
            Field::Vortex { strength, rise } => {
                let t = v3::unit([-p[1], p[0], 0.0]).unwrap_or([0.0; 3]);
                [t[0] * strength, t[1] * strength, rise]
            }
            Field::Toward(q) => v3::unit(v3::sub(q, p)).unwrap_or([0.0; 3]),
        }
    }
}

/// `x` rotated by `theta` radians about the unit axis `n` as the quaternion product
/// q x q*, q = cos(theta/2) + n sin(theta/2).
///
/// ```
/// use edo_city::growers::colonization::field::rotate_about;
/// let v = rotate_about([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
/// assert!(v[0].abs() < 1e-12 && (v[1] - 1.0).abs() < 1e-12);
/// ```
pub fn rotate_about(x: V3, n: V3, theta: f64) -> V3 {
    let (s, w) = (theta / 2.0).sin_cos();
    let q = [w, n[0] * s, n[1] * s, n[2] * s];
    let qc = [q[0], -q[1], -q[2], -q[3]];
    let p = mul(mul(q, [0.0, x[0], x[1], x[2]]), qc);
    [p[1], p[2], p[3]]
}

/// The Hamilton product.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quaternion_rotation_agrees_with_rodrigues() {
        let n = v3::unit([1.0, 2.0, 3.0]).unwrap();
        for theta in [0.0, 0.3, 1.0, 2.5, -1.2] {
            let x = [0.4, -1.0, 0.7];
            let a = rotate_about(x, n, theta);
            let b = v3::rotate(x, n, theta);
            assert!(v3::dist(a, b) < 1e-12, "{theta}");
        }
    }
}
