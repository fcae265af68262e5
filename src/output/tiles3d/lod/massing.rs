//! A building as massing (量塊): the walls of its footprint's smallest enclosing rectangle and
//! a gable roof of two planes along its long side, or at the coarser levels a flat-topped
//! box. The heights are chosen among a few by the measured error: the largest distance from
//! a vertex of the building to the massing's surface.

use geo::{Coord, MinimumRotatedRect, MultiPoint, Point};

/// One building's massing, in the root's frame (z up, metres).
#[derive(Debug, Clone, PartialEq)]
pub struct Mass {
    /// The building's row in the metadata table (of the content it is in).
    pub id: u32,
    /// The footprint rectangle, counter-clockwise from above, `[0]`-`[1]` a long side.
    pub rect: [[f64; 2]; 4],
    /// Ground (the lowest vertex).
    pub base: f64,
    /// Eaves of the gable roof.
    pub eave: f64,
    /// Ridge of the gable roof (the highest vertex).
    pub ridge: f64,
    /// Top of the flat box.
    pub flat: f64,
    /// Wall colour (linear RGBA).
    pub wall: [u8; 4],
    /// Roof colour (linear RGBA).
    pub roof: [u8; 4],
    /// Measured error of the gable massing, metres.
    pub gable_error: f64,
    /// Measured error of the flat box, metres.
    pub flat_error: f64,
}

/// How many heights are tried between the base and the ridge.
const STEPS: usize = 8;

/// The massing of the building whose triangles are `tris` (corner positions) with their
/// colours; `None` when it has no footprint (fewer than three distinct plan points).
pub fn mass(id: u32, tris: &[([[f64; 3]; 3], [u8; 4])]) -> Option<Mass> {
    let mut points: Vec<[f64; 3]> = tris.iter().flat_map(|(t, _)| *t).collect();
    // Each vertex once (a house's corners are shared by up to six of its triangles): the
    // error is a largest distance, which the same point measured again cannot change.
    points.sort_unstable_by_key(|p| p.map(f64::to_bits));
    points.dedup_by_key(|p| p.map(f64::to_bits));
    let base = points.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    let ridge = points
        .iter()
        .map(|p| p[2])
        .fold(f64::NEG_INFINITY, f64::max);
    let rect = rectangle(&points)?;
    let (wall, roof) = colours(tris);
    let mut m = Mass {
        id,
        rect,
        base,
        eave: ridge,
        ridge,
        flat: ridge,
        wall,
        roof,
        gable_error: f64::INFINITY,
        flat_error: f64::INFINITY,
    };
    let original: Vec<[[f64; 3]; 3]> = tris.iter().map(|(t, _)| *t).collect();
    // Measured against by every candidate: its boxes once.
    let original = Faces::new(&original);
    // Where each point's search starts, per kind of massing: where it ended for the height
    // before (the candidates differ in a few heights, so the nearest face rarely moves).
    let (mut gable_starts, mut flat_starts) = (Starts::default(), Starts::default());
    for k in STEPS / 2..=STEPS {
        let h = base + (ridge - base) * k as f64 / STEPS as f64;
        let gable = Mass {
            eave: h,
            ..m.clone()
        };
        let tris = gable.gable_triangles();
        let e = hausdorff(&points, &original, &tris, m.gable_error, &mut gable_starts);
        if e < m.gable_error {
            (m.eave, m.gable_error) = (h, e);
        }
        let flat = Mass {
            flat: h,
            ..m.clone()
        };
        let tris = flat.flat_triangles();
        let e = hausdorff(&points, &original, &tris, m.flat_error, &mut flat_starts);
        if e < m.flat_error {
            (m.flat, m.flat_error) = (h, e);
        }
    }
    Some(m)
}

impl Mass {
    /// The largest of its long side and its height.
    pub fn size(&self) -> f64 {
        let [a, b, ..] = self.rect;
        (b[0] - a[0]).hypot(b[1] - a[1]).max(self.ridge - self.base)
    }

    /// The corners of the footprint at height `z`.
    fn ring(&self, z: f64) -> [[f64; 3]; 4] {
        self.rect.map(|c| [c[0], c[1], z])
    }

    /// The two points of the ridge: above the middles of the short sides `[3]`-`[0]` and
    /// `[1]`-`[2]`.
    fn ridge_points(&self) -> [[f64; 3]; 2] {
        let r = &self.rect;
        let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, self.ridge];
        [mid(r[3], r[0]), mid(r[1], r[2])]
    }

    /// Walls to the eaves, two roof planes and two gables: 14 triangles, facing out.
    pub fn gable_triangles(&self) -> Vec<[[f64; 3]; 3]> {
        let (lo, hi) = (self.ring(self.base), self.ring(self.eave));
        let [r1, r2] = self.ridge_points();
        let mut t = walls(&lo, &hi);
        t.extend([
            [hi[0], hi[1], r2],
            [hi[0], r2, r1],
            [hi[2], hi[3], r1],
            [hi[2], r1, r2],
            [hi[1], hi[2], r2],
            [hi[3], hi[0], r1],
        ]);
        t
    }

    /// Walls to the flat top and the top: 10 triangles, facing out.
    pub fn flat_triangles(&self) -> Vec<[[f64; 3]; 3]> {
        let (lo, hi) = (self.ring(self.base), self.ring(self.flat));
        let mut t = walls(&lo, &hi);
        t.extend([[hi[0], hi[1], hi[2]], [hi[0], hi[2], hi[3]]]);
        t
    }
}

/// The four walls between rings `lo` and `hi` (counter-clockwise from above), facing out.
fn walls(lo: &[[f64; 3]; 4], hi: &[[f64; 3]; 4]) -> Vec<[[f64; 3]; 3]> {
    (0..4)
        .flat_map(|i| {
            let j = (i + 1) % 4;
            [[lo[i], lo[j], hi[j]], [lo[i], hi[j], hi[i]]]
        })
        .collect()
}

/// The smallest rectangle around the points seen from above, counter-clockwise, starting
/// with a long side.
fn rectangle(points: &[[f64; 3]]) -> Option<[[f64; 2]; 4]> {
    let mp = MultiPoint::new(points.iter().map(|p| Point::new(p[0], p[1])).collect());
    let poly = mp.minimum_rotated_rect()?;
    let ring: Vec<Coord<f64>> = poly.exterior().0.clone();
    if ring.len() < 4 {
        return None;
    }
    let mut c: Vec<[f64; 2]> = ring[..4].iter().map(|p| [p.x, p.y]).collect();
    // Counter-clockwise: positive area.
    let area: f64 = (0..4)
        .map(|i| c[i][0] * c[(i + 1) % 4][1] - c[(i + 1) % 4][0] * c[i][1])
        .sum();
    if area.abs() < 1e-6 {
        return None;
    }
    if area < 0.0 {
        c.reverse();
    }
    let len = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]).hypot(b[1] - a[1]);
    if len(c[0], c[1]) < len(c[1], c[2]) {
        c.rotate_left(1);
    }
    Some([c[0], c[1], c[2], c[3]])
}

/// Area-weighted mean colours of the walls (steep faces) and of the roof (faces looking up);
/// each falls back on the other, and on grey.
fn colours(tris: &[([[f64; 3]; 3], [u8; 4])]) -> ([u8; 4], [u8; 4]) {
    let mut sums = [[0.0f64; 4]; 2];
    for (t, c) in tris {
        let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        let area = dot(n, n).sqrt();
        if area < 1e-12 {
            continue;
        }
        let k = usize::from(n[2] / area > 0.5);
        for i in 0..3 {
            sums[k][i] += area * c[i] as f64;
        }
        sums[k][3] += area;
    }
    // Rounded to steps of 8 (of 255, linear): no eye tells them apart on a distant roof, and
    // houses of the same materials then share colours, which the vertex codec stores in
    // next to nothing.
    let mean = |s: [f64; 4]| {
        (s[3] > 0.0)
            .then(|| [0, 1, 2].map(|i| ((s[i] / s[3] / 8.0).round() * 8.0).min(255.0) as u8))
    };
    let grey = [128, 128, 128];
    let wall = mean(sums[0]).or(mean(sums[1])).unwrap_or(grey);
    let roof = mean(sums[1]).unwrap_or(wall);
    (
        [wall[0], wall[1], wall[2], 255],
        [roof[0], roof[1], roof[2], 255],
    )
}

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
    tris: &[[[f64; 3]; 3]],
    cutoff: f64,
    starts: &mut Starts,
) -> f64 {
    starts.there.starts.resize(points.len(), usize::MAX);
    let there = error(points, &Faces::new(tris), 0.0, cutoff, &mut starts.there);
    if there >= cutoff {
        return there;
    }
    let samples = samples(tris);
    starts.back.starts.resize(samples.len(), usize::MAX);
    // The way back only matters where it is larger than the way there.
    error(&samples, original, there, cutoff, &mut starts.back)
}

/// The corners and centre of each of the massing's faces: where it is measured against the
/// building.
fn samples(tris: &[[[f64; 3]; 3]]) -> Vec<[f64; 3]> {
    tris.iter()
        .flat_map(|t| {
            let c = [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
            [t[0], t[1], t[2], c]
        })
        .collect()
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

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The distance from `p` to triangle `t`: to its closest point, found by the triangle's
/// Voronoi regions (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn distance(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
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

    /// A house of `long` x `wide` m on the ground, eaves and ridge at those heights.
    fn gabled(long: f64, wide: f64, eave: f64, ridge: f64) -> Mass {
        Mass {
            id: 0,
            rect: [[0.0, 0.0], [long, 0.0], [long, wide], [0.0, wide]],
            base: 0.0,
            eave,
            ridge,
            flat: ridge,
            wall: [0; 4],
            roof: [0; 4],
            gable_error: 0.0,
            flat_error: 0.0,
        }
    }

    /// A box of 10 x 6 x 8 m with a gable roof: its own massing is exact (error 0 up to the
    /// height steps), and the flat box's error is the roof's height above its top.
    #[test]
    fn a_gabled_house_is_its_own_massing_and_a_flat_box_errs_by_its_roof() {
        let house = gabled(10.0, 6.0, 4.0, 8.0);
        let tris: Vec<_> = (house.gable_triangles().into_iter())
            .map(|t| (t, [200, 200, 200, 255]))
            .collect();
        let m = mass(7, &tris).unwrap();
        assert_eq!(m.id, 7);
        assert!(m.gable_error < 1e-9, "{}", m.gable_error);
        assert!((m.eave - 4.0).abs() < 1e-9);
        // The best flat top lies between eave and ridge; the error is then at most half the
        // roof's rise, and more than zero.
        assert!(
            m.flat_error > 0.5 && m.flat_error <= 2.0 + 1e-9,
            "{}",
            m.flat_error
        );
        let area = |r: &[[f64; 2]; 4]| {
            (0..4)
                .map(|i| r[i][0] * r[(i + 1) % 4][1] - r[(i + 1) % 4][0] * r[i][1])
                .sum::<f64>()
                / 2.0
        };
        assert!(
            (area(&m.rect) - 60.0).abs() < 1e-6,
            "counter-clockwise, 60 m2"
        );
        assert_eq!(m.gable_triangles().len(), 14);
        assert_eq!(m.flat_triangles().len(), 10);
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

    /// The cutoffs and the floor only skip work: on an irregular building (a gabled box with
    /// a lean-to and a chimney) the chosen heights and errors are those of measuring every
    /// candidate in full.
    #[test]
    fn the_cutoffs_choose_what_measuring_every_candidate_chooses() {
        let house = gabled(12.0, 7.0, 3.5, 7.5);
        let lean_to = Mass {
            rect: [[12.0, 1.0], [15.0, 1.0], [15.0, 5.0], [12.0, 5.0]],
            eave: 2.0,
            ridge: 2.6,
            ..house.clone()
        };
        let chimney = Mass {
            rect: [[2.0, 2.0], [3.0, 2.0], [3.0, 3.0], [2.0, 3.0]],
            eave: 9.0,
            ridge: 9.0,
            ..house.clone()
        };
        let tris: Vec<_> = [house, lean_to, chimney]
            .iter()
            .flat_map(|m| m.gable_triangles())
            .map(|t| (t, [200, 200, 200, 255]))
            .collect();
        let m = mass(1, &tris).unwrap();
        // Every candidate measured in full, both ways, as before the cutoffs.
        let points: Vec<[f64; 3]> = tris.iter().flat_map(|(t, _)| *t).collect();
        let original: Vec<_> = tris.iter().map(|(t, _)| *t).collect();
        let full = |massing: &[[[f64; 3]; 3]]| {
            let inf = f64::INFINITY;
            let there = error(
                &points,
                &Faces::new(massing),
                0.0,
                inf,
                &mut Search::default(),
            );
            there.max(error(
                &samples(massing),
                &Faces::new(&original),
                0.0,
                inf,
                &mut Search::default(),
            ))
        };
        let (mut gable, mut flat) = ((f64::INFINITY, 0.0), (f64::INFINITY, 0.0));
        for k in STEPS / 2..=STEPS {
            let h = m.base + (m.ridge - m.base) * k as f64 / STEPS as f64;
            let e = full(
                &Mass {
                    eave: h,
                    ..m.clone()
                }
                .gable_triangles(),
            );
            if e < gable.0 {
                gable = (e, h);
            }
            let e = full(
                &Mass {
                    flat: h,
                    ..m.clone()
                }
                .flat_triangles(),
            );
            if e < flat.0 {
                flat = (e, h);
            }
        }
        assert_eq!((m.gable_error, m.eave), gable);
        assert_eq!((m.flat_error, m.flat), flat);
        assert!(
            m.gable_error > 0.1,
            "an irregular building: {}",
            m.gable_error
        );
    }
}
