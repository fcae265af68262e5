//! Where attraction points are sampled: the crown's envelope (an ellipsoid, a cone, a
//! cylinder), the half-ellipsoid below ground the roots grow into, or a closed mesh a user
//! gives (a hull). Each shape also gives the point's normal (the axis the vector field's
//! rotation turns about, seed 001 eq. 13).

use rand::RngExt;
use rand_pcg::Pcg64;

use super::hull;
use crate::growers::v3::{self, V3};

/// A volume to sample attraction points in.
#[derive(Debug, Clone, PartialEq)]
pub enum Envelope {
    /// An ellipsoid around `center` with semi-axes `radii`.
    Ellipsoid {
        /// Its centre.
        center: V3,
        /// Its semi-axes along x, y, z.
        radii: V3,
    },
    /// The lower half (z <= 0) of an ellipsoid centred on the ground at the origin: roots.
    BelowGround {
        /// Semi-axes along x, y and the depth.
        radii: V3,
    },
    /// A cone standing on z = `base` with radius `radius`, apex at z = `top`.
    Cone {
        /// Height of its base.
        base: f64,
        /// Height of its apex.
        top: f64,
        /// Radius at the base.
        radius: f64,
    },
    /// A vertical cylinder about the z axis.
    Cylinder {
        /// Bottom height.
        base: f64,
        /// Top height.
        top: f64,
        /// Radius.
        radius: f64,
    },
    /// The inside of a closed triangle mesh (a user's OBJ), tested by ray parity.
    Hull {
        /// Its triangles.
        triangles: Vec<[V3; 3]>,
    },
}

impl Envelope {
    /// The box the shape lies in.
    pub fn bounds(&self) -> (V3, V3) {
        match self {
            Envelope::Ellipsoid {
                center: c,
                radii: r,
            } => (v3::sub(*c, *r), v3::add(*c, *r)),
            Envelope::BelowGround { radii: r } => ([-r[0], -r[1], -r[2]], [r[0], r[1], 0.0]),
            Envelope::Cone { base, top, radius } | Envelope::Cylinder { base, top, radius } => {
                ([-radius, -radius, *base], [*radius, *radius, *top])
            }
            Envelope::Hull { triangles } => hull::bounds(triangles),
        }
    }

    /// Whether `p` is inside.
    pub fn contains(&self, p: V3) -> bool {
        match self {
            Envelope::Ellipsoid {
                center: c,
                radii: r,
            } => {
                let d = v3::sub(p, *c);
                (d[0] / r[0]).powi(2) + (d[1] / r[1]).powi(2) + (d[2] / r[2]).powi(2) <= 1.0
            }
            Envelope::BelowGround { radii: r } => {
                p[2] <= 0.0
                    && (p[0] / r[0]).powi(2) + (p[1] / r[1]).powi(2) + (p[2] / r[2]).powi(2) <= 1.0
            }
            Envelope::Cone { base, top, radius } => {
                let t = (p[2] - base) / (top - base);
                (0.0..=1.0).contains(&t) && p[0].hypot(p[1]) <= radius * (1.0 - t)
            }
            Envelope::Cylinder { base, top, radius } => {
                p[2] >= *base && p[2] <= *top && p[0].hypot(p[1]) <= *radius
            }
            // Parity of crossings of a ray along +x (nudged off axis-aligned edges).
            Envelope::Hull { triangles } => hull::contains(triangles, p),
        }
    }

    /// The outward normal at (or toward) `p`: the gradient of the shape's implicit function.
    pub fn normal(&self, p: V3) -> V3 {
        let n = match self {
            Envelope::Ellipsoid {
                center: c,
                radii: r,
            } => {
                let d = v3::sub(p, *c);
                [
                    d[0] / (r[0] * r[0]),
                    d[1] / (r[1] * r[1]),
                    d[2] / (r[2] * r[2]),
                ]
            }
            Envelope::BelowGround { radii: r } => [
                p[0] / (r[0] * r[0]),
                p[1] / (r[1] * r[1]),
                p[2] / (r[2] * r[2]),
            ],
            Envelope::Cone { .. } | Envelope::Cylinder { .. } => [p[0], p[1], 0.0],
            Envelope::Hull { .. } => {
                let (lo, hi) = self.bounds();
                v3::sub(p, v3::scale(v3::add(lo, hi), 0.5))
            }
        };
        v3::unit(n).unwrap_or([0.0, 0.0, 1.0])
    }

    /// `count` points drawn uniformly inside by rejection from the bounding box; an error
    /// when the shape is (nearly) empty (fewer than `count` hits in 200 x `count` tries) or
    /// a hull would take more than [`hull::MAX_RAY_TESTS`] ray tests.
    pub fn sample(&self, count: usize, rng: &mut Pcg64) -> Result<Vec<V3>, String> {
        let empty = || "its envelope is empty (no points could be placed in it)".to_string();
        let (lo, hi) = self.bounds();
        if !(0..3).all(|k| lo[k].is_finite() && hi[k].is_finite() && hi[k] >= lo[k]) {
            return Err(empty());
        }
        let mut index = match self {
            Envelope::Hull { triangles } => Some(hull::Index::new(triangles)),
            _ => None,
        };
        let mut out = Vec::with_capacity(count);
        let mut tries = 0usize;
        while out.len() < count {
            tries += 1;
            if tries > 200 * count.max(1) {
                return Err(empty());
            }
            let p = [
                lo[0] + rng.random::<f64>() * (hi[0] - lo[0]),
                lo[1] + rng.random::<f64>() * (hi[1] - lo[1]),
                lo[2] + rng.random::<f64>() * (hi[2] - lo[2]),
            ];
            let inside = match &mut index {
                Some(index) if index.tests > hull::MAX_RAY_TESTS => {
                    return Err(format!(
                        "its hull took {} ray tests for {} of {count} points: make it \
                         smaller, with fewer or smaller triangles, or ask fewer points",
                        index.tests,
                        out.len()
                    ));
                }
                Some(index) => index.contains(p),
                None => self.contains(p),
            };
            if inside {
                out.push(p);
            }
        }
        Ok(out)
    }

    /// A hull of a user's triangles, refused when it encloses no volume.
    pub fn hull(triangles: Vec<[V3; 3]>) -> Result<Envelope, String> {
        hull::check_volume(&triangles)?;
        Ok(Envelope::Hull { triangles })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn samples_lie_inside_and_a_cube_hull_holds_its_centre() {
        let mut rng = Pcg64::seed_from_u64(3);
        let shapes = [
            Envelope::Ellipsoid {
                center: [0.0, 0.0, 5.0],
                radii: [3.0, 2.0, 1.0],
            },
            Envelope::BelowGround {
                radii: [2.0, 2.0, 1.0],
            },
            Envelope::Cone {
                base: 1.0,
                top: 4.0,
                radius: 1.0,
            },
        ];
        for s in &shapes {
            for p in s.sample(500, &mut rng).unwrap() {
                assert!(s.contains(p), "{s:?} {p:?}");
            }
        }
        // A unit cube as twelve triangles.
        let c = |x: f64, y: f64, z: f64| [x, y, z];
        let quads = [
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 1., 0.), c(0., 1., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(1., 1., 0.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(0., 1., 0.), c(0., 1., 1.), c(0., 0., 1.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let hull = Envelope::Hull { triangles };
        assert!(hull.contains([0.5, 0.5, 0.5]));
        assert!(!hull.contains([1.5, 0.5, 0.5]));
        assert!(!hull.contains([-0.5, 0.5, 0.5]));
    }
}
