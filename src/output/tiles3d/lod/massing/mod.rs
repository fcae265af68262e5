//! A building as massing (量塊): the walls of its footprint's smallest enclosing rectangle and
//! a gable roof of two planes along its long side, or at the coarser levels a flat-topped
//! box. The heights are chosen among a few by the measured error: the largest distance from
//! a vertex of the building to the massing's surface.

mod distance;

use geo::{Coord, MinimumRotatedRect, MultiPoint, Point};

use distance::{cross, dot, hausdorff, sub, Faces, Starts};

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

/// The heights tried, `k` of [`STEPS`] from the base (the upper half), from the middle of the
/// roof outwards. The error mostly falls and rises again about its least, so the best is met
/// among the first two or three, and the others stop at their first points (the cutoff of
/// [`hausdorff`]); in rising order each better height was measured in full. The choice is
/// the same whatever the order ([`Best`]).
const ORDER: [usize; 5] = [6, 5, 7, 4, 8];

/// The least error measured so far among one kind's candidates, and its step: a height
/// wins on a smaller error or, at an equal one, a lower step, so the choice is the one of
/// trying them in rising order and keeping each strictly better one.
#[derive(Debug, Clone, Copy)]
struct Best {
    error: f64,
    k: usize,
}

impl Best {
    /// None yet: an infinite error never wins (a building no candidate fits keeps its
    /// ridge).
    const NONE: Best = Best {
        error: f64::INFINITY,
        k: 0,
    };

    /// Where candidate `k`'s measure may stop: at the best error for a higher step (a tie
    /// loses), past it for a lower one (a tie wins, so it is measured in full).
    fn cutoff(&self, k: usize) -> f64 {
        match k < self.k {
            true => self.error.next_up(),
            false => self.error,
        }
    }

    /// Whether candidate `k` of error `e` is the new best (and takes its place).
    fn offer(&mut self, k: usize, e: f64) -> bool {
        let wins = e < self.error || (e == self.error && k < self.k);
        if wins {
            *self = Best { error: e, k };
        }
        wins
    }
}

impl Default for Best {
    fn default() -> Best {
        Best::NONE
    }
}

/// One kind of massing's candidates as they are measured in turn.
#[derive(Debug, Default)]
struct Trial {
    best: Best,
    starts: Starts,
}

impl Trial {
    /// Measures the candidate of step `k` (its faces and their corners) against the
    /// building (its vertices `points`, its faces `original`); its error when it is the new
    /// best.
    fn height(
        &mut self,
        k: usize,
        points: &[[f64; 3]],
        original: &Faces,
        faces: (&[[[f64; 3]; 3]], &[[f64; 3]]),
    ) -> Option<f64> {
        let cutoff = self.best.cutoff(k);
        let e = hausdorff(points, original, faces, cutoff, &mut self.starts);
        self.best.offer(k, e).then_some(e)
    }
}

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
    // Each kind of massing's trial: its best height so far, and where each point's search
    // starts (where it ended for the height before: the candidates differ in a few
    // heights, so the nearest face rarely moves).
    let (mut gable, mut flat) = (Trial::default(), Trial::default());
    for k in ORDER {
        let h = base + (ridge - base) * k as f64 / STEPS as f64;
        let g = Mass {
            eave: h,
            ..m.clone()
        };
        let faces = (&g.gable_triangles()[..], &g.gable_corners()[..]);
        if let Some(e) = gable.height(k, &points, &original, faces) {
            (m.eave, m.gable_error) = (h, e);
        }
        let f = Mass {
            flat: h,
            ..m.clone()
        };
        let faces = (&f.flat_triangles()[..], &f.flat_corners()[..]);
        if let Some(e) = flat.height(k, &points, &original, faces) {
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

    /// The corners of [`Mass::gable_triangles`], each once.
    fn gable_corners(&self) -> [[f64; 3]; 10] {
        let (lo, hi) = (self.ring(self.base), self.ring(self.eave));
        let [r1, r2] = self.ridge_points();
        [
            lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3], r1, r2,
        ]
    }

    /// The corners of [`Mass::flat_triangles`], each once.
    fn flat_corners(&self) -> [[f64; 3]; 8] {
        let (lo, hi) = (self.ring(self.base), self.ring(self.flat));
        [lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]]
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

#[cfg(test)]
mod tests {
    use super::distance::{error, samples, Faces, Search};
    use super::*;

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

    /// A gabled house of 12 x 7 m (eaves 3.5 m, ridge 7.5 m) and a low lean-to beside it.
    fn house_and_lean_to() -> (Mass, Mass) {
        let house = gabled(12.0, 7.0, 3.5, 7.5);
        let lean_to = Mass {
            rect: [[12.0, 1.0], [15.0, 1.0], [15.0, 5.0], [12.0, 5.0]],
            eave: 2.0,
            ridge: 2.6,
            ..house.clone()
        };
        (house, lean_to)
    }

    /// The way back measures each corner once: a gable massing's 14 faces give their 14
    /// centres and 10 corners, a flat box's 10 faces 10 centres and 8 corners, and the
    /// figure against an irregular building is the one of every face's corners and centre.
    #[test]
    fn the_way_back_measures_each_corner_once_and_finds_the_same() {
        let (house, lean_to) = house_and_lean_to();
        let building: Vec<_> = [house.clone(), lean_to]
            .iter()
            .flat_map(|m| m.gable_triangles())
            .collect();
        let massing = Mass {
            eave: 4.5,
            flat: 5.0,
            ..house
        };
        for (tris, corners, points) in [
            (
                massing.gable_triangles(),
                massing.gable_corners().to_vec(),
                14 + 10,
            ),
            (
                massing.flat_triangles(),
                massing.flat_corners().to_vec(),
                10 + 8,
            ),
        ] {
            let once = samples(&tris, &corners);
            assert_eq!(once.len(), points);
            let bits = |p: &[f64; 3]| p.map(f64::to_bits);
            let distinct: std::collections::BTreeSet<_> = once.iter().map(bits).collect();
            assert_eq!(distinct.len(), points, "each corner once");
            assert!(every_sample(&tris).iter().all(|p| once.contains(p)));
            let inf = f64::INFINITY;
            let faces = Faces::new(&building);
            let deduped = error(&once, &faces, 0.0, inf, &mut Search::default());
            let all = error(
                &every_sample(&tris),
                &faces,
                0.0,
                inf,
                &mut Search::default(),
            );
            assert_eq!(deduped.to_bits(), all.to_bits());
            assert!(
                all > 0.5,
                "the massing's eaves stand above the house's: {all}"
            );
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

    /// The cutoffs, the floor and the order of the candidates only skip work: the chosen
    /// heights and errors are those of measuring every candidate in full, in rising order,
    /// keeping each strictly better one. On an irregular building (a gabled box with a
    /// lean-to and a chimney), on an L (its error is the empty corner of its rectangle,
    /// farther from the low wing the higher the massing: the lowest height wins though it
    /// is tried fourth), and on a plain gabled house.
    #[test]
    fn the_cutoffs_choose_what_measuring_every_candidate_chooses() {
        let (house, lean_to) = house_and_lean_to();
        let chimney = Mass {
            rect: [[2.0, 2.0], [3.0, 2.0], [3.0, 3.0], [2.0, 3.0]],
            eave: 9.0,
            ridge: 9.0,
            ..house.clone()
        };
        let wing = Mass {
            rect: [[0.0, 7.0], [4.0, 7.0], [4.0, 20.0], [0.0, 20.0]],
            eave: 3.0,
            ridge: 3.2,
            ..house.clone()
        };
        let buildings = [
            vec![house.clone(), lean_to, chimney],
            vec![house.clone(), wing],
            vec![gabled(9.0, 5.0, 3.0, 6.0)],
        ];
        let (mut steps, mut errors) = (Vec::new(), Vec::new());
        for parts in buildings {
            let tris: Vec<_> = (parts.iter())
                .flat_map(|m| m.gable_triangles())
                .map(|t| (t, [200, 200, 200, 255]))
                .collect();
            let m = mass(1, &tris).unwrap();
            let (gable, flat) = in_full(&tris, &m);
            assert_eq!((m.gable_error, m.eave), gable);
            assert_eq!((m.flat_error, m.flat), flat);
            steps.push(((m.eave - m.base) / (m.ridge - m.base) * STEPS as f64).round());
            errors.push(m.gable_error);
        }
        assert!(errors[0] > 0.1, "an irregular building: {}", errors[0]);
        assert_eq!(steps[1], 4.0, "the L: the lowest height");
    }

    /// Each face's corners and centre, as the way back measured them before each corner was
    /// measured once.
    fn every_sample(tris: &[[[f64; 3]; 3]]) -> Vec<[f64; 3]> {
        tris.iter()
            .flat_map(|t| {
                let c = [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
                [t[0], t[1], t[2], c]
            })
            .collect()
    }

    /// Each candidate of `m`'s building (`tris`) measured in full, both ways, in rising
    /// order, each strictly better one kept: (error, height) of the gable and of the flat
    /// box.
    fn in_full(tris: &[([[f64; 3]; 3], [u8; 4])], m: &Mass) -> ((f64, f64), (f64, f64)) {
        let points: Vec<[f64; 3]> = tris.iter().flat_map(|(t, _)| *t).collect();
        let original: Vec<_> = tris.iter().map(|(t, _)| *t).collect();
        let full = |massing: &[[[f64; 3]; 3]]| {
            let inf = f64::INFINITY;
            let faces = Faces::new(massing);
            let there = error(&points, &faces, 0.0, inf, &mut Search::default());
            let back = Faces::new(&original);
            there.max(error(
                &every_sample(massing),
                &back,
                0.0,
                inf,
                &mut Search::default(),
            ))
        };
        let (mut gable, mut flat) = ((f64::INFINITY, m.ridge), (f64::INFINITY, m.ridge));
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
        (gable, flat)
    }

    /// Equal errors go to the lowest height whatever the order they are met in; a lower
    /// height is measured past the best error (a tie would win), a higher one stops at it;
    /// an infinite error never wins.
    #[test]
    fn equal_errors_go_to_the_lowest_height() {
        let mut best = Best::NONE;
        assert!(!best.offer(6, f64::INFINITY));
        for k in ORDER {
            best.offer(k, 2.0);
        }
        assert_eq!((best.error, best.k), (2.0, 4));
        let best = Best { error: 2.0, k: 6 };
        assert!(best.cutoff(5) > 2.0 && best.cutoff(5) == 2.0f64.next_up());
        assert_eq!(best.cutoff(7), 2.0);
        assert_eq!(Best::NONE.cutoff(4), f64::INFINITY);
    }

    /// [`ORDER`] tries every height of the upper half once.
    #[test]
    fn the_order_tries_each_height_once() {
        let mut order = ORDER.to_vec();
        order.sort_unstable();
        assert_eq!(order, (STEPS / 2..=STEPS).collect::<Vec<_>>());
    }
}
