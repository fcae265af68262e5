//! Three-dimensional vectors as `[f64; 3]`, just the operations the growers need. The growers'
//! space is x east, y north, z up, metres; a tree stands at the origin.

/// A point or direction in the growers' space.
pub type V3 = [f64; 3];

/// a + b.
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a - b.
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s a.
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// The dot product.
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product a x b.
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The length.
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// The distance between two points.
pub fn dist(a: V3, b: V3) -> f64 {
    norm(sub(a, b))
}

/// `a` scaled to length 1, or `None` when it is (nearly) zero.
pub fn unit(a: V3) -> Option<V3> {
    let n = norm(a);
    (n > 1e-12 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

/// `v` rotated by `angle` radians about the unit axis `k`, right-handed (Rodrigues): a
/// positive angle turns counter-clockwise seen from the tip of `k`.
///
/// ```
/// use edo_city::growers::v3::rotate;
/// let v = rotate([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
/// assert!((v[0]).abs() < 1e-12 && (v[1] - 1.0).abs() < 1e-12);
/// ```
pub fn rotate(v: V3, k: V3, angle: f64) -> V3 {
    let (s, c) = angle.sin_cos();
    let kv = cross(k, v);
    let kd = dot(k, v) * (1.0 - c);
    [
        v[0] * c + kv[0] * s + k[0] * kd,
        v[1] * c + kv[1] * s + k[1] * kd,
        v[2] * c + kv[2] * s + k[2] * kd,
    ]
}

/// Any unit vector perpendicular to the unit vector `d`, chosen the same way every time.
pub fn perpendicular(d: V3) -> V3 {
    let helper = if d[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    unit(cross(d, helper)).unwrap_or([0.0, 1.0, 0.0])
}
