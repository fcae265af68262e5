//! A user's closed mesh as a crown envelope: checked to enclose a volume when read, and
//! indexed so that sampling tests each point against the few triangles its ray can cross.
//!
//! Points are drawn by rejection from the mesh's box and kept when a ray from them crosses
//! the mesh an odd number of times. Tested against every triangle, a hull of 10,001
//! triangles that enclosed nothing ran for minutes (200 tries a point, 50,000 points, every
//! try a pass over every triangle): a flat or empty hull is now refused when read, the rays
//! look only at the triangles of their cell of a grid over (y, z), and a sample that would
//! still test more than [`MAX_RAY_TESTS`] triangles stops with an error.

use super::v3::{self, V3};

/// The most triangles a hull may have.
pub const MAX_HULL_TRIANGLES: usize = 100_000;
/// Ray-triangle tests one sample may make (about a second on this machine).
pub const MAX_RAY_TESTS: u64 = 200_000_000;
/// The share of its box below which a hull encloses "no volume".
const MIN_VOLUME_SHARE: f64 = 1e-6;
/// The parity ray: along +x, nudged off axis-aligned edges and faces.
const RAY: V3 = [1.0, 1e-7, 2e-7];
/// A triangle covering more cells than this is tested for every point instead.
const MAX_CELLS_PER_TRIANGLE: usize = 64;

/// Refuses a mesh that encloses no volume: a box flat along an axis, or a signed volume (sum
/// of the tetrahedra from the origin) under a millionth of its box.
pub fn check_volume(triangles: &[[V3; 3]]) -> Result<(), String> {
    let (lo, hi) = bounds(triangles);
    let size = v3::sub(hi, lo);
    let boxed = size[0] * size[1] * size[2];
    if !(boxed.is_finite() && boxed > 0.0) {
        return Err(format!(
            "its box is {:.3} x {:.3} x {:.3} m: it encloses no volume",
            size[0], size[1], size[2]
        ));
    }
    let volume = triangles
        .iter()
        .map(|t| {
            v3::dot(
                v3::sub(t[0], lo),
                v3::cross(v3::sub(t[1], lo), v3::sub(t[2], lo)),
            )
        })
        .sum::<f64>()
        .abs()
        / 6.0;
    if volume.is_nan() || volume < MIN_VOLUME_SHARE * boxed {
        return Err(format!(
            "it encloses {volume:.3e} m³ in a box of {boxed:.3e} m³: no volume (a closed \
             mesh, faces wound one way, is needed)"
        ));
    }
    Ok(())
}

/// The box the triangles lie in.
pub fn bounds(triangles: &[[V3; 3]]) -> (V3, V3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in triangles.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Whether `p` is inside, by the parity of crossings with every triangle.
pub fn contains(triangles: &[[V3; 3]], p: V3) -> bool {
    triangles.iter().filter(|t| ray_hits(p, RAY, t)).count() % 2 == 1
}

/// The triangles a ray from a point of each (y, z) cell of the box can cross.
pub struct Index<'a> {
    triangles: &'a [[V3; 3]],
    lo: V3,
    cell: [f64; 2],
    n: usize,
    cells: Vec<Vec<u32>>,
    everywhere: Vec<u32>,
    /// Ray-triangle tests made so far.
    pub tests: u64,
}

impl<'a> Index<'a> {
    /// Bins each triangle by its (y, z) box, widened by how far the nudged ray drifts while
    /// it crosses the box along x.
    pub fn new(triangles: &'a [[V3; 3]]) -> Self {
        let (lo, hi) = bounds(triangles);
        let n = ((triangles.len() as f64).sqrt().ceil() as usize).clamp(1, 128);
        let width = hi[0] - lo[0];
        let span = [hi[1] - lo[1], hi[2] - lo[2]];
        let cell = [span[0].max(1e-9) / n as f64, span[1].max(1e-9) / n as f64];
        let slack = 1e-9 * (width + span[0] + span[1]);
        let margin = [RAY[1] * width + slack, RAY[2] * width + slack];
        let mut index = Index {
            triangles,
            lo,
            cell,
            n,
            cells: vec![Vec::new(); n * n],
            everywhere: Vec::new(),
            tests: 0,
        };
        for (i, t) in triangles.iter().enumerate() {
            let (tlo, thi) = bounds(std::slice::from_ref(t));
            let (y0, z0) = index.at(tlo[1] - margin[0], tlo[2] - margin[1]);
            let (y1, z1) = index.at(thi[1] + margin[0], thi[2] + margin[1]);
            if (y1 - y0 + 1) * (z1 - z0 + 1) > MAX_CELLS_PER_TRIANGLE {
                index.everywhere.push(i as u32);
                continue;
            }
            for y in y0..=y1 {
                for z in z0..=z1 {
                    index.cells[y * n + z].push(i as u32);
                }
            }
        }
        index
    }

    /// The cell of (y, z), clamped to the grid.
    fn at(&self, y: f64, z: f64) -> (usize, usize) {
        let k = |v: f64, lo: f64, size: f64| {
            (((v - lo) / size).floor().max(0.0) as usize).min(self.n - 1)
        };
        (
            k(y, self.lo[1], self.cell[0]),
            k(z, self.lo[2], self.cell[1]),
        )
    }

    /// Whether `p` (inside the box) is inside the mesh; the same answer as [`contains`].
    pub fn contains(&mut self, p: V3) -> bool {
        let (y, z) = self.at(p[1], p[2]);
        let own = &self.cells[y * self.n + z];
        self.tests += (own.len() + self.everywhere.len()) as u64;
        let hits = own
            .iter()
            .chain(&self.everywhere)
            .filter(|&&i| ray_hits(p, RAY, &self.triangles[i as usize]))
            .count();
        hits % 2 == 1
    }
}

/// Möller-Trumbore: whether the ray from `o` along `d` crosses triangle `t` (t > 0).
fn ray_hits(o: V3, d: V3, t: &[V3; 3]) -> bool {
    let e1 = v3::sub(t[1], t[0]);
    let e2 = v3::sub(t[2], t[0]);
    let h = v3::cross(d, e2);
    let a = v3::dot(e1, h);
    if a.abs() < 1e-12 {
        return false;
    }
    let f = 1.0 / a;
    let s = v3::sub(o, t[0]);
    let u = f * v3::dot(s, h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = v3::cross(s, e1);
    let v = f * v3::dot(d, q);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    f * v3::dot(e2, q) > 1e-12
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64;

    /// A sphere of `rings` x `rings` x 2 triangles, radius `r` about `c`.
    fn sphere(c: V3, r: f64, rings: usize) -> Vec<[V3; 3]> {
        let at = |i: usize, j: usize| {
            let th = std::f64::consts::PI * i as f64 / rings as f64;
            let ph = std::f64::consts::TAU * j as f64 / rings as f64;
            v3::add(
                c,
                [
                    r * th.sin() * ph.cos(),
                    r * th.sin() * ph.sin(),
                    r * th.cos(),
                ],
            )
        };
        let mut out = Vec::new();
        for i in 0..rings {
            for j in 0..rings {
                let (a, b, cc, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                out.push([a, b, cc]);
                out.push([a, cc, d]);
            }
        }
        out
    }

    #[test]
    fn the_index_answers_as_every_triangle_does() {
        let mesh = sphere([1.0, -2.0, 6.0], 3.0, 40);
        let mut index = Index::new(&mesh);
        let mut rng = Pcg64::seed_from_u64(9);
        let (lo, hi) = bounds(&mesh);
        let mut inside = 0;
        for _ in 0..5_000 {
            let p: V3 = std::array::from_fn(|k| lo[k] + rng.random::<f64>() * (hi[k] - lo[k]));
            let all = contains(&mesh, p);
            assert_eq!(index.contains(p), all, "{p:?}");
            inside += all as usize;
        }
        // A sphere fills pi/6 of its box; and the index tests far fewer triangles.
        assert!((2_300..2_950).contains(&inside), "{inside}");
        assert!(
            index.tests < 5_000 * mesh.len() as u64 / 20,
            "{}",
            index.tests
        );
    }

    #[test]
    fn a_flat_or_empty_hull_encloses_no_volume() {
        let sphere = sphere([0.0; 3], 2.0, 12);
        assert!(check_volume(&sphere).is_ok());
        // Every triangle in the plane z = 1: a flat box.
        let flat: Vec<[V3; 3]> = sphere
            .iter()
            .map(|t| t.map(|p| [p[0], p[1], 1.0]))
            .collect();
        assert!(check_volume(&flat).unwrap_err().contains("no volume"));
        // Each face twice, wound both ways: a box with volume, a mesh enclosing none.
        let twice: Vec<[V3; 3]> = sphere
            .iter()
            .flat_map(|t| [*t, [t[0], t[2], t[1]]])
            .collect();
        assert!(check_volume(&twice).unwrap_err().contains("no volume"));
    }
}
