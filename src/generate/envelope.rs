//! Roofs as the lower envelope of planes: a roof surface is `min` of sloped planes over the
//! outline, each plane rising from its own eave line. Hip (yosemune 寄棟), pyramidal (hogyo
//! 宝形) and the hip skirt of a hip-and-gable (irimoya 入母屋) roof are all such envelopes;
//! a constant plane cuts a roof flat (the base of the gable set on an irimoya, the top of
//! one tier of a pagoda).
//!
//! The outline is cut into the regions where each plane is the lowest, so every top face is
//! flat and two regions meet along the line where their planes cross (a hip or a ridge).
//! Regions are then welded: a vertex of one region lying on another region's edge is
//! inserted there, so the shell has no T-junctions and stays watertight.

use geo::BooleanOps;
use geo_types::{Coord, LineString, Polygon};

use super::clip::{area, dedup, is_convex, local_polys, LocalPoly, LocalRing};

/// A plane over the site's (u, v): `h = a + b u + c v`.
pub type Plane = [f64; 3];

/// Height of `plane` at `p`.
pub fn height(plane: &Plane, p: [f64; 2]) -> f64 {
    plane[0] + plane[1] * p[0] + plane[2] * p[1]
}

/// The lowest of `planes` at `p`.
pub fn lowest(planes: &[Plane], p: [f64; 2]) -> f64 {
    planes
        .iter()
        .map(|pl| height(pl, p))
        .fold(f64::INFINITY, f64::min)
}

/// The plane rising at `pitch` (metres per metre) from the eave line through `a` -> `b` at
/// height `eave`, towards the left of that line (the inside of a counter-clockwise outline).
pub fn from_eave(a: [f64; 2], b: [f64; 2], eave: f64, pitch: f64) -> Option<Plane> {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len = dx.hypot(dy);
    if len < 1e-9 {
        return None;
    }
    // Inward unit normal (left of a -> b): distance inside = n . (p - a).
    let n = [-dy / len, dx / len];
    Some([
        eave - pitch * (n[0] * a[0] + n[1] * a[1]),
        pitch * n[0],
        pitch * n[1],
    ])
}

/// The convex hull of `points`, counter-clockwise, without collinear points (Andrew's
/// monotone chain).
pub fn hull(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut h: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = h.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 1e-12 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

/// The pieces of `pieces` where each plane is the lowest, as (region, plane index), welded
/// so that regions meeting along an edge share every vertex on it. Identical planes count
/// once (the first); a plane that is nowhere the lowest has no region.
pub fn regions(pieces: &[LocalPoly], planes: &[Plane]) -> Vec<(LocalPoly, usize)> {
    let distinct: Vec<usize> = (0..planes.len())
        .filter(|&i| !(0..i).any(|j| same(&planes[i], &planes[j])))
        .collect();
    let mut out = Vec::new();
    for piece in pieces {
        for &i in &distinct {
            let mut parts = vec![piece.clone()];
            for &j in &distinct {
                if j == i {
                    continue;
                }
                // Keep P_i - P_j <= 0: (b_i - b_j) u + (c_i - c_j) v <= a_j - a_i.
                let n = [planes[i][1] - planes[j][1], planes[i][2] - planes[j][2]];
                let c = planes[j][0] - planes[i][0];
                parts = parts
                    .iter()
                    .flat_map(|p| clip_half_plane(p, n, c))
                    .collect();
                if parts.is_empty() {
                    break;
                }
            }
            out.extend(parts.into_iter().map(|p| (p, i)));
        }
    }
    weld(&mut out);
    out
}

fn same(a: &Plane, b: &Plane) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12)
}

/// The part of `poly` with `n . p <= c`. A convex polygon without holes is clipped by
/// Sutherland-Hodgman, others by geo's boolean intersection with a large half-plane box.
pub fn clip_half_plane(poly: &LocalPoly, n: [f64; 2], c: f64) -> Vec<LocalPoly> {
    let len = n[0].hypot(n[1]);
    if len < 1e-12 {
        // Parallel planes: one lies wholly under the other.
        return if c >= -1e-12 {
            vec![poly.clone()]
        } else {
            Vec::new()
        };
    }
    let g = |p: [f64; 2]| n[0] * p[0] + n[1] * p[1] - c;
    let all_in = poly.rings().flatten().all(|&p| g(p) <= 1e-9 * len);
    if all_in {
        return vec![poly.clone()];
    }
    if poly.rings().flatten().all(|&p| g(p) >= -1e-9 * len) {
        return Vec::new();
    }
    if poly.holes.is_empty() && is_convex(&poly.exterior) {
        let r = poly.exterior.as_slice();
        let m = r.len();
        let mut out: LocalRing = Vec::with_capacity(m + 2);
        for k in 0..m {
            let (p, q) = (r[k], r[(k + 1) % m]);
            let (gp, gq) = (g(p), g(q));
            if gp <= 0.0 {
                out.push(p);
            }
            if (gp <= 0.0) != (gq <= 0.0) {
                let t = gp / (gp - gq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
        let out = dedup(out);
        return if out.len() >= 3 && area(&out) > 1e-9 {
            vec![LocalPoly::simple(out)]
        } else {
            Vec::new()
        };
    }
    clip_boolean(poly, n, c)
}

/// [`clip_half_plane`] for polygons with holes or reflex corners.
fn clip_boolean(poly: &LocalPoly, n: [f64; 2], c: f64) -> Vec<LocalPoly> {
    let len = n[0].hypot(n[1]);
    let (nx, ny) = (n[0] / len, n[1] / len);
    let c = c / len;
    // A square far larger than the polygon on the kept side of the line.
    let reach = poly
        .rings()
        .flatten()
        .map(|p| p[0].abs().max(p[1].abs()))
        .fold(1.0, f64::max)
        * 4.0;
    let (tx, ty) = (-ny, nx);
    let o = [nx * c, ny * c];
    let corner = |s: f64, d: f64| Coord {
        x: o[0] + tx * s - nx * d,
        y: o[1] + ty * s - ny * d,
    };
    let half = Polygon::new(
        LineString(vec![
            corner(-reach, 0.0),
            corner(-reach, 2.0 * reach),
            corner(reach, 2.0 * reach),
            corner(reach, 0.0),
            corner(-reach, 0.0),
        ]),
        vec![],
    );
    let to_ls = |r: &LocalRing| {
        let mut v: Vec<Coord<f64>> = r.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
        v.push(v[0]);
        LineString(v)
    };
    let gp = Polygon::new(
        to_ls(&poly.exterior),
        poly.holes.iter().map(to_ls).collect(),
    );
    local_polys(gp.intersection(&half))
}

/// Inserts into every ring edge the vertices of the other regions that lie on it (within
/// 0.1 mm), so two regions sharing a boundary share its vertices.
fn weld(regions: &mut [(LocalPoly, usize)]) {
    let all: Vec<[f64; 2]> = regions
        .iter()
        .flat_map(|(p, _)| p.rings().flatten().copied().collect::<Vec<_>>())
        .collect();
    for (poly, _) in regions.iter_mut() {
        poly.exterior = weld_ring(&poly.exterior, &all);
        poly.holes = poly.holes.iter().map(|h| weld_ring(h, &all)).collect();
    }
}

/// `r` with every point of `all` that lies inside one of its edges inserted there.
fn weld_ring(r: &LocalRing, all: &[[f64; 2]]) -> LocalRing {
    let m = r.len();
    let mut out = Vec::with_capacity(m);
    for k in 0..m {
        let (p, q) = (r[k], r[(k + 1) % m]);
        out.push(p);
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let l2 = dx * dx + dy * dy;
        if l2 < 1e-12 {
            continue;
        }
        let mut on: Vec<(f64, [f64; 2])> = all
            .iter()
            .filter_map(|&s| {
                let t = ((s[0] - p[0]) * dx + (s[1] - p[1]) * dy) / l2;
                let cross = ((s[0] - p[0]) * dy - (s[1] - p[1]) * dx).abs() / l2.sqrt();
                let l = l2.sqrt();
                (t * l > 1e-4 && (1.0 - t) * l > 1e-4 && cross < 1e-4).then_some((t, s))
            })
            .collect();
        on.sort_by(|a, b| a.0.total_cmp(&b.0));
        on.dedup_by(|a, b| (a.0 - b.0).abs() * l2.sqrt() < 1e-4);
        out.extend(on.into_iter().map(|(_, s)| s));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(w: f64, d: f64) -> LocalPoly {
        LocalPoly::simple(vec![[0.0, 0.0], [w, 0.0], [w, d], [0.0, d]])
    }

    fn hip(w: f64, d: f64, eave: f64, pitch: f64) -> Vec<Plane> {
        let r = rect(w, d).exterior;
        (0..4)
            .filter_map(|k| from_eave(r[k], r[(k + 1) % 4], eave, pitch))
            .collect()
    }

    #[test]
    fn a_plane_from_its_eave_rises_inward() {
        let p = from_eave([0.0, 0.0], [10.0, 0.0], 3.0, 0.5).unwrap();
        assert!((height(&p, [4.0, 0.0]) - 3.0).abs() < 1e-12);
        assert!((height(&p, [4.0, 2.0]) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn a_hip_roof_has_four_faces_two_trapezoids_and_two_triangles() {
        let (w, d) = (12.0, 8.0);
        let rs = regions(&[rect(w, d)], &hip(w, d, 4.0, 0.5));
        assert_eq!(rs.len(), 4);
        let total: f64 = rs.iter().map(|(p, _)| area(&p.exterior)).sum();
        assert!(
            (total - w * d).abs() < 1e-9,
            "regions tile the outline: {total}"
        );
        let mut areas: Vec<f64> = rs.iter().map(|(p, _)| area(&p.exterior)).collect();
        areas.sort_by(f64::total_cmp);
        // Hip ends: triangles of base d and height d/2; sides: trapezoids.
        assert!((areas[0] - d * d / 4.0).abs() < 1e-9);
        assert!((areas[3] - (w + (w - d)) / 2.0 * d / 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_square_gives_a_pyramid_with_its_apex_at_the_centre() {
        let rs = regions(&[rect(6.0, 6.0)], &hip(6.0, 6.0, 3.0, 1.0));
        assert_eq!(rs.len(), 4);
        for (p, _) in &rs {
            assert_eq!(p.exterior.len(), 3, "{p:?}");
        }
        assert!((lowest(&hip(6.0, 6.0, 3.0, 1.0), [3.0, 3.0]) - 6.0).abs() < 1e-12);
    }

    #[test]
    fn a_flat_plane_cuts_the_top_off() {
        let mut planes = hip(10.0, 10.0, 0.0, 1.0);
        planes.push([2.0, 0.0, 0.0]);
        let rs = regions(&[rect(10.0, 10.0)], &planes);
        let flat: f64 = rs
            .iter()
            .filter(|(_, i)| *i == 4)
            .map(|(p, _)| area(&p.exterior))
            .sum();
        assert!((flat - 36.0).abs() < 1e-9, "a 6 x 6 flat top: {flat}");
    }

    #[test]
    fn an_l_shaped_outline_is_cut_by_booleans_and_still_tiles() {
        let l = LocalPoly::simple(vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 4.0],
            [4.0, 4.0],
            [4.0, 10.0],
            [0.0, 10.0],
        ]);
        let planes = [[0.0, 0.3, 0.0], [3.0, -0.3, 0.0], [0.0, 0.0, 0.4]];
        let rs = regions(std::slice::from_ref(&l), &planes);
        let total: f64 = rs.iter().map(|(p, _)| area(&p.exterior)).sum();
        assert!((total - area(&l.exterior)).abs() < 1e-6, "{total}");
    }

    #[test]
    fn the_hull_of_an_l_is_its_box_less_nothing_and_counter_clockwise() {
        let l = [
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 4.0],
            [4.0, 4.0],
            [4.0, 10.0],
            [0.0, 10.0],
            [5.0, 0.0],
        ];
        let h = hull(&l);
        assert_eq!(h.len(), 5, "{h:?}");
        assert!(area(&h) > 0.0);
        assert!((area(&h) - (100.0 - 18.0)).abs() < 1e-9);
    }

    #[test]
    fn welding_puts_a_neighbours_vertex_into_a_long_edge() {
        // Two regions: a flat top splits one side; the slope beside it must share the vertex.
        let planes = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.5]];
        let rs = regions(&[rect(4.0, 4.0)], &planes);
        assert_eq!(rs.len(), 2);
        for (p, _) in &rs {
            assert!(p.exterior.iter().any(|q| (q[1] - 2.0).abs() < 1e-9));
        }
    }
}
