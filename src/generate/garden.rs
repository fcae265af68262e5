//! The meshes of a dry rock garden (seed 000): a bed of raked gravel, rake lines ringing each
//! group, a moss island under each group, every stone an irregular flat-bottomed block (a
//! seeded perturbed convex hull, sunk a little), and a low earthen wall on the three far
//! sides when asked for.
//!
//! Garden coordinates (x along the viewing side, y away from it) are placed on the map by a
//! [`GardenSite`]: the corner of the viewing side's left end, the viewing side's direction.

use geo_types::Coord;

use smallvec::smallvec;

use super::mesh::{Corners, Frame, Mesh};
use crate::growers::garden::{Layout, Settings};
use crate::materials;
use crate::model::object::{ObjectKind, Owner};

/// Where a garden lies on the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GardenSite {
    /// The map point of garden (0, 0): the left end of the viewing side.
    pub corner: Coord<f64>,
    /// The direction of the garden's x axis (unit), radians counter-clockwise from east.
    pub angle: f64,
    /// Ground elevation.
    pub ground: f64,
}

impl GardenSite {
    fn map(&self, x: f64, y: f64) -> Coord<f64> {
        let (s, c) = self.angle.sin_cos();
        // y runs to the left of x: away from a viewer who looks along +y.
        Coord {
            x: self.corner.x + x * c - y * s,
            y: self.corner.y + x * s + y * c,
        }
    }
}

/// How high above the ground the gravel lies, metres.
const GRAVEL: f64 = 0.03;

/// Every object of a garden: the bed (gravel, rings, moss, wall) named `garden_<id>`, then
/// one `stone_<id>_<group>_<role>_<k>` per stone. `stone_rng(k)` gives the k-th stone's RNG.
pub fn build(
    owner: &Owner,
    layout: &Layout,
    s: &Settings,
    site: GardenSite,
    wall: bool,
    frame: Frame,
    stone_rng: &mut dyn FnMut(usize) -> rand_pcg::Pcg64,
) -> Vec<Mesh> {
    let id = &owner.id;
    let mut bed = Mesh::object(format!("garden_{id}"), ObjectKind::Garden, owner.clone());
    let z = site.ground + GRAVEL;
    let v = |m: &mut Mesh, x: f64, y: f64, h: f64| m.vertex(frame, site.map(x, y), h);
    // The gravel: one quad, its rake lines running along the viewing side.
    let corners = [
        (0.0, 0.0),
        (s.width, 0.0),
        (s.width, s.depth),
        (0.0, s.depth),
    ];
    let q: Corners = corners
        .iter()
        .map(|&(x, y)| {
            let p = v(&mut bed, x, y, z);
            (p, bed.uv(x / 2.0, y / 2.0))
        })
        .collect();
    bed.face(materials::id("gravel_raked"), q);
    for g in layout.groups() {
        let (cx, cy, r) = group_circle(layout, &g);
        // A moss island under each stone of the group.
        for &i in &g {
            let st = &layout.stones[i];
            let moss = materials::id("moss");
            disc(
                &mut bed,
                &site,
                frame,
                (st.x, st.y),
                st.size * 0.8,
                z + 0.01,
                moss,
                0.12,
            );
        }
        // Rake lines ringing the group.
        for k in 1..=3 {
            let rr = r + 0.2 + 0.35 * k as f64;
            ring(&mut bed, &site, frame, (cx, cy), rr, 0.06, z + 0.005, s);
        }
    }
    if wall {
        walls(&mut bed, &site, frame, s);
    }
    let mut out = vec![bed.finish()];
    for (k, st) in layout.stones.iter().enumerate() {
        let mut rng = stone_rng(k);
        let name = format!("stone_{id}_{}_{}_{k}", st.group + 1, st.role.name());
        let mut m = Mesh::object(name, ObjectKind::Stone, owner.clone());
        stone(&mut m, &site, frame, st.x, st.y, st.size, &mut rng);
        out.push(m.finish());
    }
    out
}

/// The centre and radius of the circle around a group's stones.
fn group_circle(l: &Layout, g: &[usize]) -> (f64, f64, f64) {
    let n = g.len() as f64;
    let cx = g.iter().map(|&i| l.stones[i].x).sum::<f64>() / n;
    let cy = g.iter().map(|&i| l.stones[i].y).sum::<f64>() / n;
    let r = g
        .iter()
        .map(|&i| (l.stones[i].x - cx).hypot(l.stones[i].y - cy) + l.stones[i].size / 2.0)
        .fold(0.0, f64::max);
    (cx, cy, r)
}

/// A flat irregular disc (a fan about its centre), radius varied by `wobble`.
#[allow(clippy::too_many_arguments)]
fn disc(
    m: &mut Mesh,
    site: &GardenSite,
    frame: Frame,
    c: (f64, f64),
    r: f64,
    h: f64,
    mat: u16,
    wobble: f64,
) {
    let n = 20;
    let centre = m.vertex(frame, site.map(c.0, c.1), h);
    let cuv = m.uv(c.0 / 2.0, c.1 / 2.0);
    let pts: Vec<(u32, u32)> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            let rr = r * (1.0 + wobble * (3.0 * a).sin() * (5.0 * a + 1.0).cos());
            let (x, y) = (c.0 + rr * a.cos(), c.1 + rr * a.sin());
            (m.vertex(frame, site.map(x, y), h), m.uv(x / 2.0, y / 2.0))
        })
        .collect();
    for k in 0..n {
        m.face(mat, smallvec![(centre, cuv), pts[k], pts[(k + 1) % n]]);
    }
}

/// A rake line: an annulus `w` wide at radius `r`, clipped to the garden.
#[allow(clippy::too_many_arguments)]
fn ring(
    m: &mut Mesh,
    site: &GardenSite,
    frame: Frame,
    c: (f64, f64),
    r: f64,
    w: f64,
    h: f64,
    s: &Settings,
) {
    let n = 40;
    let mat = materials::id("rake_line");
    let uv = m.uv(0.0, 0.0);
    for k in 0..n {
        let (a0, a1) = (
            std::f64::consts::TAU * k as f64 / n as f64,
            std::f64::consts::TAU * (k + 1) as f64 / n as f64,
        );
        let p = |a: f64, rr: f64| (c.0 + rr * a.cos(), c.1 + rr * a.sin());
        let quad = [p(a0, r), p(a1, r), p(a1, r + w), p(a0, r + w)];
        if quad
            .iter()
            .any(|&(x, y)| x < 0.0 || y < 0.0 || x > s.width || y > s.depth)
        {
            continue;
        }
        let f = quad
            .iter()
            .map(|&(x, y)| (m.vertex(frame, site.map(x, y), h), uv))
            .collect();
        m.face(mat, f);
    }
}

/// One stone: a perturbed convex hull of eight points for its base, two narrower rings above
/// it and a peak, sunk a tenth of its height; closed.
fn stone(
    m: &mut Mesh,
    site: &GardenSite,
    frame: Frame,
    x: f64,
    y: f64,
    size: f64,
    rng: &mut rand_pcg::Pcg64,
) {
    use rand::RngExt;
    let turn = rng.random::<f64>() * std::f64::consts::TAU;
    let (a, b) = (size / 2.0, size / 2.0 * (0.6 + 0.3 * rng.random::<f64>()));
    let height = size * (0.45 + 0.45 * rng.random::<f64>());
    let mut pts: Vec<[f64; 2]> = (0..8)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / 8.0 + rng.random::<f64>() * 0.5;
            let j = 0.85 + 0.3 * rng.random::<f64>();
            let (px, py) = (a * j * t.cos(), b * j * t.sin());
            let (s, c) = turn.sin_cos();
            [px * c - py * s, px * s + py * c]
        })
        .collect();
    pts = hull(pts);
    let base = site.ground - 0.1 * height;
    let lean = [
        (rng.random::<f64>() - 0.5) * 0.2 * size,
        (rng.random::<f64>() - 0.5) * 0.2 * size,
    ];
    let levels = [
        (base, 1.0, 0.0),
        (base + 0.6 * height, 0.85, 0.5),
        (base + 0.9 * height, 0.5, 1.0),
    ];
    let mat = materials::id("stone");
    let rings: Vec<Vec<u32>> = levels
        .iter()
        .map(|&(h, k, shift)| {
            pts.iter()
                .map(|p| {
                    let q = site.map(
                        x + p[0] * k + lean[0] * shift,
                        y + p[1] * k + lean[1] * shift,
                    );
                    m.vertex(frame, q, h)
                })
                .collect()
        })
        .collect();
    let apex = m.vertex(frame, site.map(x + lean[0], y + lean[1]), base + height);
    let n = pts.len();
    let per = |k: usize, level: usize| m_uv(k, n, level);
    for l in 0..2 {
        for k in 0..n {
            let k1 = (k + 1) % n;
            let f = smallvec![
                (rings[l][k], m.uv(per(k, l).0, per(k, l).1)),
                (rings[l][k1], m.uv(per(k + 1, l).0, per(k + 1, l).1)),
                (
                    rings[l + 1][k1],
                    m.uv(per(k + 1, l + 1).0, per(k + 1, l + 1).1),
                ),
                (rings[l + 1][k], m.uv(per(k, l + 1).0, per(k, l + 1).1)),
            ];
            m.face(mat, f);
        }
    }
    let top = m.uv(0.5, 1.0);
    for k in 0..n {
        let f = smallvec![
            (rings[2][k], top),
            (rings[2][(k + 1) % n], top),
            (apex, top),
        ];
        m.face(mat, f);
    }
    let bottom: Corners = rings[0].iter().rev().map(|&i| (i, top)).collect();
    m.face(mat, bottom);
}

fn m_uv(k: usize, n: usize, level: usize) -> (f64, f64) {
    (k as f64 / n as f64, level as f64 * 0.4)
}

/// The convex hull of points (monotone chain), counter-clockwise.
fn hull(mut p: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut lower: Vec<[f64; 2]> = Vec::new();
    for &q in &p {
        while lower.len() >= 2 && cross(lower[lower.len() - 2], lower[lower.len() - 1], q) <= 0.0 {
            lower.pop();
        }
        lower.push(q);
    }
    let mut upper: Vec<[f64; 2]> = Vec::new();
    for &q in p.iter().rev() {
        while upper.len() >= 2 && cross(upper[upper.len() - 2], upper[upper.len() - 1], q) <= 0.0 {
            upper.pop();
        }
        upper.push(q);
    }
    lower.pop();
    upper.pop();
    lower.extend(upper);
    lower
}

/// A low earthen wall (tsuiji 築地 of clay) with a tiled cap on the three far sides.
fn walls(m: &mut Mesh, site: &GardenSite, frame: Frame, s: &Settings) {
    let (t, h) = (0.4, 1.8);
    let sides = [
        ((0.0, s.depth), (s.width, s.depth)),
        ((0.0, 0.0), (0.0, s.depth)),
        ((s.width, 0.0), (s.width, s.depth)),
    ];
    let wall = materials::id("tsuchikabe_wall");
    let roof = materials::id("kawara_roof");
    for ((x0, y0), (x1, y1)) in sides {
        let len = (x1 - x0).hypot(y1 - y0);
        let (ux, uy) = ((x1 - x0) / len, (y1 - y0) / len);
        // Outward: away from the garden's inside.
        let (nx, ny) = if y0 == y1 {
            (0.0, 1.0)
        } else if x0 == 0.0 {
            (-1.0, 0.0)
        } else {
            (1.0, 0.0)
        };
        let c = |a: f64, o: f64| (x0 + ux * a + nx * o, y0 + uy * a + ny * o);
        let foot = [c(0.0, 0.0), c(len, 0.0), c(len, t), c(0.0, t)];
        // Counter-clockwise seen from above.
        let ccw = {
            let a = (foot[1].0 - foot[0].0) * (foot[2].1 - foot[0].1)
                - (foot[1].1 - foot[0].1) * (foot[2].0 - foot[0].0);
            a > 0.0
        };
        let foot: Vec<(f64, f64)> = if ccw {
            foot.to_vec()
        } else {
            foot.iter().rev().copied().collect()
        };
        let lo: Vec<u32> = foot
            .iter()
            .map(|&(x, y)| m.vertex(frame, site.map(x, y), site.ground))
            .collect();
        let hi: Vec<u32> = foot
            .iter()
            .map(|&(x, y)| m.vertex(frame, site.map(x, y), site.ground + h))
            .collect();
        for k in 0..4 {
            let k1 = (k + 1) % 4;
            let along = if k % 2 == 0 { len } else { t };
            let f = smallvec![
                (lo[k], m.uv(0.0, 0.0)),
                (lo[k1], m.uv(along / 2.0, 0.0)),
                (hi[k1], m.uv(along / 2.0, h / 2.0)),
                (hi[k], m.uv(0.0, h / 2.0)),
            ];
            m.face(wall, f);
        }
        let top: Corners = (0..4).map(|k| (hi[k], m.uv(k as f64 * 0.5, 0.0))).collect();
        m.face(roof, top);
        let bottom: Corners = (0..4).rev().map(|k| (lo[k], m.uv(0.0, 0.0))).collect();
        m.face(wall, bottom);
    }
}

/// The meshes of a garden the city planned (its lot is walled already: no wall of its own).
pub fn planned(g: &crate::model::PlannedGarden, seed: u64, frame: Frame) -> Vec<Mesh> {
    let layout = Layout::from_rows(&g.stones);
    let settings = Settings::sized(g.size[0], g.size[1]);
    let site = GardenSite {
        corner: g.corner,
        angle: g.angle,
        ground: g.ground,
    };
    build(
        &g.owner(),
        &layout,
        &settings,
        site,
        false,
        frame,
        &mut |k| crate::rng::feature_rng(seed, "garden/stone", &format!("{}/{k}", g.lot)),
    )
}
