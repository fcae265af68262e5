//! Clipping a lot outline to a band of depth behind its frontage, in the frontage frame.
//!
//! In the frame (u along the street, v into the lot) a house occupies the part of the lot with
//! `lo <= v <= hi`. For convex lots (nearly all town lots) two half-plane clips do it exactly
//! and cheaply; other lots go through geo's boolean operations.

use geo::BooleanOps;
use geo_types::{Coord, LineString, Polygon, Rect};

/// A ring in the frontage frame: (u, v) pairs, not closed.
pub type LocalRing = Vec<[f64; 2]>;

/// A polygon in the frontage frame: exterior counter-clockwise, holes (courtyards) clockwise,
/// so the polygon's inside is on the left of every edge.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalPoly {
    /// The outer ring, counter-clockwise, not closed.
    pub exterior: LocalRing,
    /// The holes, clockwise, not closed.
    pub holes: Vec<LocalRing>,
}

impl LocalPoly {
    /// A polygon without holes.
    pub fn simple(exterior: LocalRing) -> LocalPoly {
        LocalPoly {
            exterior,
            holes: Vec::new(),
        }
    }

    /// Every ring, exterior first.
    pub fn rings(&self) -> impl Iterator<Item = &LocalRing> {
        std::iter::once(&self.exterior).chain(&self.holes)
    }
}

/// The parts of `poly` with `lo <= v <= hi` (infinite bounds allowed).
pub fn clip_band(poly: &LocalPoly, lo: f64, hi: f64) -> Vec<LocalPoly> {
    let ring = &poly.exterior;
    if poly.holes.is_empty() && is_convex(ring) {
        let mut r = ring.to_vec();
        if lo.is_finite() {
            r = clip_half(&r, lo, true);
        }
        if hi.is_finite() {
            r = clip_half(&r, hi, false);
        }
        let r = dedup(r);
        if r.len() >= 3 && area(&r) > 1e-9 {
            vec![LocalPoly::simple(r)]
        } else {
            Vec::new()
        }
    } else {
        clip_boolean(poly, lo, hi)
    }
}

/// The parts of `poly` with `lo <= u <= hi`: the band clip in a frame turned a quarter,
/// so that both clips share one implementation.
pub fn clip_band_u(poly: &LocalPoly, lo: f64, hi: f64) -> Vec<LocalPoly> {
    if !lo.is_finite() && !hi.is_finite() {
        return vec![poly.clone()];
    }
    // (u, v) -> (-v, u) is a rotation, so rings keep their orientation.
    let turn = |r: &LocalRing| r.iter().map(|p| [-p[1], p[0]]).collect::<LocalRing>();
    let back = |r: &LocalRing| r.iter().map(|p| [p[1], -p[0]]).collect::<LocalRing>();
    let turned = LocalPoly {
        exterior: turn(&poly.exterior),
        holes: poly.holes.iter().map(turn).collect(),
    };
    clip_band(&turned, lo, hi)
        .into_iter()
        .map(|p| LocalPoly {
            exterior: back(&p.exterior),
            holes: p.holes.iter().map(back).collect(),
        })
        .collect()
}

/// The lot's extent along u on the line at depth `v`, clamped to 0.1 mm inside the lot's
/// depth range: at its very edge a frontage that is not exactly level in floating point
/// would give a single point instead of the frontage.
pub fn extent_at(ring: &[[f64; 2]], v: f64) -> (f64, f64) {
    let (vmin, vmax) = ring
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[1]), b.max(p[1])));
    let inset = if vmax - vmin > 4e-4 { 1e-4 } else { 0.0 };
    let v = v.clamp(vmin + inset, vmax - inset);
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    let n = ring.len();
    for i in 0..n {
        let (p, q) = (ring[i], ring[(i + 1) % n]);
        let (a, b) = if p[1] <= q[1] { (p, q) } else { (q, p) };
        if v < a[1] || v > b[1] {
            continue;
        }
        let us: &[f64] = if b[1] - a[1] < 1e-12 {
            &[a[0], b[0]]
        } else {
            &[a[0] + (v - a[1]) / (b[1] - a[1]) * (b[0] - a[0])]
        };
        for &u in us {
            lo = lo.min(u);
            hi = hi.max(u);
        }
    }
    if lo > hi {
        (f64::NAN, f64::NAN)
    } else {
        (lo, hi)
    }
}

/// Sutherland-Hodgman against one line `v = c`, keeping `v >= c` (`above`) or `v <= c`.
/// Points made on the line get `v = c` exactly, so two halves split at the same line share
/// their cut points bit for bit.
fn clip_half(ring: &[[f64; 2]], c: f64, above: bool) -> LocalRing {
    let g = |p: [f64; 2]| if above { p[1] - c } else { c - p[1] };
    let n = ring.len();
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let p = ring[i];
        let q = ring[(i + 1) % n];
        let (gp, gq) = (g(p), g(q));
        if gp >= 0.0 {
            out.push(p);
        }
        if (gp >= 0.0) != (gq >= 0.0) && gp != gq {
            let t = gp / (gp - gq);
            out.push([p[0] + t * (q[0] - p[0]), c]);
        }
    }
    out
}

fn clip_boolean(poly: &LocalPoly, lo: f64, hi: f64) -> Vec<LocalPoly> {
    let (mut umin, mut umax, mut vmin, mut vmax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &poly.exterior {
        umin = umin.min(p[0]);
        umax = umax.max(p[0]);
        vmin = vmin.min(p[1]);
        vmax = vmax.max(p[1]);
    }
    let lo = if lo.is_finite() { lo } else { vmin - 1.0 };
    let hi = if hi.is_finite() { hi } else { vmax + 1.0 };
    if hi <= lo {
        return Vec::new();
    }
    let to_ls = |r: &LocalRing| LineString(r.iter().map(|p| Coord { x: p[0], y: p[1] }).collect());
    let geo_poly = Polygon::new(
        to_ls(&poly.exterior),
        poly.holes.iter().map(to_ls).collect(),
    );
    let band = Rect::new(
        Coord {
            x: umin - 1.0,
            y: lo,
        },
        Coord {
            x: umax + 1.0,
            y: hi,
        },
    )
    .to_polygon();
    local_polys(geo_poly.intersection(&band))
}

/// The polygons of a boolean operation's result in the frame's ring convention (exterior
/// counter-clockwise, holes clockwise), without slivers.
pub fn local_polys(mp: geo_types::MultiPolygon<f64>) -> Vec<LocalPoly> {
    let ring_of = |ls: &LineString<f64>, ccw: bool| {
        let mut r: LocalRing = crate::geom::ring::open(ls)
            .iter()
            .map(|c| [c.x, c.y])
            .collect();
        if (area(&r) > 0.0) != ccw {
            r.reverse();
        }
        let r = dedup(r);
        (r.len() >= 3 && area(&r).abs() > 1e-9).then_some(r)
    };
    mp.0.into_iter()
        .filter_map(|p| {
            let exterior = ring_of(p.exterior(), true)?;
            let holes = p
                .interiors()
                .iter()
                .filter_map(|h| ring_of(h, false))
                .collect();
            Some(LocalPoly { exterior, holes })
        })
        .collect()
}

/// Signed area, positive for counter-clockwise.
pub fn area(r: &[[f64; 2]]) -> f64 {
    let n = r.len();
    (0..n)
        .map(|i| {
            let (p, q) = (r[i], r[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        / 2.0
}

/// True when no turn of the ring goes clockwise (collinear points allowed).
pub fn is_convex(r: &[[f64; 2]]) -> bool {
    let n = r.len();
    if n < 3 {
        return false;
    }
    (0..n).all(|i| {
        let (p, q, s) = (r[i], r[(i + 1) % n], r[(i + 2) % n]);
        let cross = (q[0] - p[0]) * (s[1] - q[1]) - (q[1] - p[1]) * (s[0] - q[0]);
        cross >= -1e-9
    })
}

/// Drops consecutive points closer than 0.1 mm, and spikes: points where the ring runs out
/// and straight back (they would give a wall of no thickness, used from both sides).
pub fn dedup(r: LocalRing) -> LocalRing {
    let mut out = dedup_points(r);
    let mut i = 0;
    while out.len() >= 3 && i < out.len() {
        let n = out.len();
        let (p, q, s) = (out[(i + n - 1) % n], out[i], out[(i + 1) % n]);
        let (a, b) = ([q[0] - p[0], q[1] - p[1]], [s[0] - q[0], s[1] - q[1]]);
        let cross = a[0] * b[1] - a[1] * b[0];
        let dot = a[0] * b[0] + a[1] * b[1];
        let scale = (a[0].hypot(a[1]) * b[0].hypot(b[1])).max(1e-12);
        if cross.abs() / scale < 1e-9 && dot < 0.0 {
            out.remove(i);
            out = dedup_points(out);
            i = 0;
        } else {
            i += 1;
        }
    }
    out
}

fn dedup_points(r: LocalRing) -> LocalRing {
    let mut out: LocalRing = Vec::with_capacity(r.len());
    for p in r {
        if out
            .last()
            .is_none_or(|l| (l[0] - p[0]).abs() > 1e-4 || (l[1] - p[1]).abs() > 1e-4)
        {
            out.push(p);
        }
    }
    while out.len() > 1 {
        let (f, l) = (out[0], out[out.len() - 1]);
        if (f[0] - l[0]).abs() <= 1e-4 && (f[1] - l[1]).abs() <= 1e-4 {
            out.pop();
        } else {
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn convex_band_clip_is_exact() {
        let sq = LocalPoly::simple(vec![[0., 0.], [4., 0.], [4., 20.], [0., 20.]]);
        let parts = clip_band(&sq, 2.0, 14.0);
        assert_eq!(parts.len(), 1);
        assert!((area(&parts[0].exterior) - 48.0).abs() < 1e-9);
        assert!(parts[0]
            .exterior
            .iter()
            .all(|p| p[1] >= 2.0 && p[1] <= 14.0));
    }

    #[test]
    fn concave_band_clip_keeps_both_arms() {
        // A U shape open at the top: the band above y = 5 cuts it into two arms.
        let u = vec![
            [0., 0.],
            [6., 0.],
            [6., 10.],
            [4., 10.],
            [4., 5.],
            [2., 5.],
            [2., 10.],
            [0., 10.],
        ];
        assert!(!is_convex(&u));
        let parts = clip_band(&LocalPoly::simple(u), 6.0, f64::INFINITY);
        assert_eq!(parts.len(), 2);
        let total: f64 = parts.iter().map(|p| area(&p.exterior)).sum();
        assert!((total - 16.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn spikes_are_removed() {
        let r = dedup(vec![
            [0., 0.],
            [4., 0.],
            [6., 0.],
            [4., 0.],
            [4., 3.],
            [0., 3.],
        ]);
        assert_eq!(r, vec![[0., 0.], [4., 0.], [4., 3.], [0., 3.]]);
    }

    #[test]
    fn u_band_and_extent_follow_a_slanted_lot() {
        let lot = LocalPoly::simple(vec![[0., 0.], [5., 0.], [6., 20.], [1., 20.]]);
        let parts = clip_band_u(&lot, 2.0, 4.0);
        assert_eq!(parts.len(), 1);
        assert!(area(&parts[0].exterior) > 0.0, "still counter-clockwise");
        assert!(parts[0]
            .exterior
            .iter()
            .all(|p| p[0] >= 2.0 - 1e-9 && p[0] <= 4.0 + 1e-9));
        let (lo, hi) = extent_at(&lot.exterior, 10.0);
        assert!(
            (lo - 0.5).abs() < 1e-9 && (hi - 5.5).abs() < 1e-9,
            "{lo} {hi}"
        );
        let (lo, hi) = extent_at(&lot.exterior, -3.0);
        assert!(
            lo.abs() < 1e-4 && (hi - 5.0).abs() < 1e-4,
            "clamped to the frontage"
        );
    }

    #[test]
    fn a_courtyard_inside_the_band_stays_a_hole() {
        let lot = LocalPoly {
            exterior: vec![[0., 0.], [10., 0.], [10., 30.], [0., 30.]],
            holes: vec![vec![[3., 4.], [3., 8.], [7., 8.], [7., 4.]]],
        };
        let parts = clip_band(&lot, 0.0, 12.0);
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].holes.len(), 1);
        assert!(area(&parts[0].holes[0]) < 0.0, "holes run clockwise");
        let net = area(&parts[0].exterior) + area(&parts[0].holes[0]);
        assert!((net - 104.0).abs() < 1e-6, "{net}");
    }
}
