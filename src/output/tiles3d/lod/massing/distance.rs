//! How far a massing lies from its building: the two-way largest distance between their
//! surfaces, searched with boxes, early breaks and starts carried between candidates, since
//! it is measured for every candidate height of every building at every level.

/// Where the searches of [`hausdorff`] start, both ways, carried from one candidate height to
/// the next (the candidates differ in a few heights, so the nearest face and the farthest
/// point rarely move).
#[derive(Debug, Clone, Default)]
pub struct Starts {
    there: Search,
    back: Search,
}

/// Where one way of [`hausdorff`] starts: each point's first triangle, and the point measured
/// first.
#[derive(Debug, Clone, Default)]
pub struct Search {
    /// Point `i`'s search starts at triangle `starts[i]` (`usize::MAX`, past the end or
    /// missing: where the point before it ended); left where it ended.
    starts: Vec<usize>,
    /// The point measured first: the one that set the largest distance last time. Measured
    /// first, it makes every other point's search stop at its first triangle within that
    /// distance.
    hot: usize,
}

/// The distance between a building (its vertices `points`, its triangles `original`) and its
/// massing `tris`, both ways: from each vertex of the building to the massing, and from each
/// corner and centre of the massing's faces to the building (a flat top at the ridge touches
/// every vertex of a gable roof, yet stands metres above its eaves). Once it reaches
/// `cutoff` (the best massing's so far) it stops with some figure no smaller: this massing
/// has lost, by how much does not matter.
pub fn hausdorff(
    points: &[[f64; 3]],
    original: &Faces,
    (tris, corners): (&[[[f64; 3]; 3]], &[[f64; 3]]),
    cutoff: f64,
    starts: &mut Starts,
) -> f64 {
    starts.there.starts.resize(points.len(), usize::MAX);
    let there = error(points, &Faces::new(tris), 0.0, cutoff, &mut starts.there);
    if there >= cutoff {
        return there;
    }
    let samples = samples(tris, corners);
    starts.back.starts.resize(samples.len(), usize::MAX);
    // The way back only matters where it is larger than the way there.
    error(&samples, original, there, cutoff, &mut starts.back)
}

/// Where the massing is measured against the building: its `corners`, each once (the
/// corners of its faces `tris`: a gable massing's 14 faces share 10, a flat box's 10 share
/// 8), and each face's centre. A point measured again cannot change a largest distance;
/// each corner was measured four times over, most of the way back's searches.
pub(super) fn samples(tris: &[[[f64; 3]; 3]], corners: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let centres = tris
        .iter()
        .map(|t| [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0));
    corners.iter().copied().chain(centres).collect()
}

/// The largest of `floor` and the distances from each point to the nearest of the triangles;
/// once that reaches `cutoff`, some figure no smaller. `search` says where the searches start
/// and is left where they ended ([`Search`]); the figure does not depend on it.
///
/// Exact, with the early break of Taha and Hanbury (2015): a point's search stops as soon as
/// some triangle is no farther than the largest distance found so far, since that point can
/// no longer raise it; and each search starts at a triangle likely near the point
/// (neighbouring points are near the same faces). Measuring every point against every
/// triangle was three quarters of a build's time (a massing's corners against a house's
/// thousands of triangles, twice a level). The floor and the cutoff carry the same idea
/// across calls: a distance within the other direction's cannot raise the pair's largest,
/// and a candidate already worse than the best need not be measured to the end (1,000,000
/// lots: the massing's error was still 52 % of the build without them).
pub fn error(
    points: &[[f64; 3]],
    faces: &Faces,
    floor: f64,
    cutoff: f64,
    search: &mut Search,
) -> f64 {
    let Faces { tris, boxes } = faces;
    let n = tris.len();
    if n == 0 {
        return if points.is_empty() {
            floor
        } else {
            f64::INFINITY
        };
    }
    let (mut worst, mut before) = (floor, 0);
    let hot = search.hot.min(points.len().saturating_sub(1));
    let order = (hot..hot + 1).chain((0..points.len()).filter(|&i| i != hot));
    for i in order.take(points.len()) {
        let p = points[i];
        let start = match search.starts.get(i) {
            Some(&s) if s < n => s,
            _ => before,
        };
        let (mut nearest, mut nearest2, mut at) = (f64::INFINITY, f64::INFINITY, start);
        for k in 0..n {
            let j = (start + k) % n;
            // A triangle whose box is no nearer than the nearest so far cannot be nearer.
            if box_distance2(p, &boxes[j]) >= nearest2 {
                continue;
            }
            let d2 = distance2(p, &tris[j]);
            if d2 < nearest2 {
                (nearest, nearest2, at) = (d2.sqrt(), d2, j);
                if nearest <= worst {
                    break;
                }
            }
        }
        if nearest > worst {
            (worst, search.hot) = (nearest, i);
        }
        if let Some(s) = search.starts.get_mut(i) {
            *s = at;
        }
        before = at;
        if worst >= cutoff {
            break;
        }
    }
    worst
}

/// Triangles with their bounding boxes, made once for every search against them: a box
/// farther than the nearest triangle found so far rules its triangle out for three clamps.
#[derive(Debug, Clone)]
pub struct Faces<'a> {
    tris: &'a [[[f64; 3]; 3]],
    boxes: Vec<[[f64; 3]; 2]>,
}

impl<'a> Faces<'a> {
    /// The triangles `tris` and their boxes.
    pub fn new(tris: &'a [[[f64; 3]; 3]]) -> Self {
        Faces {
            tris,
            boxes: tris.iter().map(bounds).collect(),
        }
    }
}

/// A triangle's bounding box, grown by a micrometre so that a closest point computed with
/// rounding still lies inside it: the box's distance stays a lower bound of the triangle's.
fn bounds(t: &[[f64; 3]; 3]) -> [[f64; 3]; 2] {
    const SLACK: f64 = 1e-6;
    let lo = [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k]) - SLACK);
    let hi = [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k]) + SLACK);
    [lo, hi]
}

/// The squared distance from `p` to the box `b`.
fn box_distance2(p: [f64; 3], b: &[[f64; 3]; 2]) -> f64 {
    let gap = |k: usize| (b[0][k] - p[k]).max(p[k] - b[1][k]).max(0.0);
    let (x, y, z) = (gap(0), gap(1), gap(2));
    x * x + y * y + z * z
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The distance from `p` to triangle `t`: to its closest point, found by the triangle's
/// Voronoi regions (Ericson, Real-Time Collision Detection, 5.1.5). The build measures
/// squared distances ([`distance2`]); the tests compare with this one's closed forms.
#[cfg(test)]
fn distance(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    distance2(p, t).sqrt()
}

/// The squared distance from `p` to triangle `t` (the root is taken only for a new nearest).
fn distance2(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let at = |q: [f64; 3]| dot(sub(p, q), sub(p, q));
    let lerp =
        |u: [f64; 3], d: [f64; 3], s: f64| [u[0] + d[0] * s, u[1] + d[1] * s, u[2] + d[2] * s];
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return at(a);
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return at(lerp(a, ab, d1 / (d1 - d3)));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return at(lerp(a, ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return at(lerp(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = va + vb + vc;
    if denom.abs() < 1e-18 {
        // A degenerate triangle: its corners.
        return at(a).min(at(b)).min(at(c));
    }
    let (v, w) = (vb / denom, vc / denom);
    at([
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distances in closed form: above the face, beside an edge, beyond a corner.
    #[test]
    fn point_to_triangle_distances_are_the_closed_form_ones() {
        let t = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        assert!((distance([1.0, 1.0, 3.0], &t) - 3.0).abs() < 1e-12);
        assert!((distance([2.0, -2.0, 0.0], &t) - 2.0).abs() < 1e-12);
        assert!((distance([-3.0, -4.0, 0.0], &t) - 5.0).abs() < 1e-12);
        // Beyond the hypotenuse: (3, 3) is |3 + 3 - 4| / sqrt(2) from the line x + y = 4.
        assert!((distance([3.0, 3.0, 0.0], &t) - 2.0f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_early_break_finds_what_every_point_against_every_triangle_finds() {
        // A fixed scatter (an LCG): 300 points against 200 triangles, in a 20 m box.
        let mut x: u64 = 12345;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 20.0
        };
        let points: Vec<[f64; 3]> = (0..300).map(|_| [next(), next(), next()]).collect();
        let tris: Vec<[[f64; 3]; 3]> = (0..200)
            .map(|_| {
                [
                    [next(), next(), next()],
                    [next(), next(), next()],
                    [next(), next(), next()],
                ]
            })
            .collect();
        let brute = points
            .iter()
            .map(|&p| {
                tris.iter()
                    .map(|t| distance(p, t))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        let inf = f64::INFINITY;
        assert_eq!(
            error(
                &points,
                &Faces::new(&tris),
                0.0,
                inf,
                &mut Search::default()
            )
            .to_bits(),
            brute.to_bits()
        );
        assert_eq!(
            error(&[], &Faces::new(&tris), 0.0, inf, &mut Search::default()),
            0.0
        );
        assert_eq!(
            error(&points, &Faces::new(&[]), 0.0, inf, &mut Search::default()),
            inf
        );
        // Any starts, and the starts a search left, find the same.
        let mut search = Search {
            starts: vec![usize::MAX; 300],
            hot: 123,
        };
        search.starts[..150].fill(7);
        for _ in 0..2 {
            let e = error(&points, &Faces::new(&tris), 0.0, inf, &mut search);
            assert_eq!(e.to_bits(), brute.to_bits());
        }
        assert!(search.starts.iter().all(|&s| s < 200));
        // The point measured first is the farthest one.
        let farthest = |p: [f64; 3]| {
            tris.iter()
                .map(|t| distance(p, t))
                .fold(f64::INFINITY, f64::min)
        };
        assert_eq!(farthest(points[search.hot]).to_bits(), brute.to_bits());
        // A floor below the largest distance does not change it; one above it is the answer.
        assert_eq!(
            error(
                &points,
                &Faces::new(&tris),
                brute / 2.0,
                inf,
                &mut Search::default()
            )
            .to_bits(),
            brute.to_bits()
        );
        assert_eq!(
            error(
                &points,
                &Faces::new(&tris),
                brute * 2.0,
                inf,
                &mut Search::default()
            ),
            brute * 2.0
        );
        // A cutoff below it stops early with a figure no smaller than the cutoff; one above
        // it changes nothing.
        let cut = error(
            &points,
            &Faces::new(&tris),
            0.0,
            brute / 2.0,
            &mut Search::default(),
        );
        assert!(cut >= brute / 2.0 && cut <= brute, "{cut} of {brute}");
        assert_eq!(
            error(
                &points,
                &Faces::new(&tris),
                0.0,
                brute * 1.01,
                &mut Search::default()
            )
            .to_bits(),
            brute.to_bits()
        );
    }
}
