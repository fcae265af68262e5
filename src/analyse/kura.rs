//! Kura (蔵) storehouses, section 4.2 of the paper: which machiya get one, where it stands,
//! and the collision avoidance of Fig.7.
//!
//! A machiya is a candidate when its frontage is at least `kura.min_frontage` (3 ken: a tax
//! on frontage made a wide one a sign of wealth) and its lot at least `kura.depth_ratio`
//! times as deep. Its kura stands at the back of the lot, a courtyard (`kura.gap`) behind
//! the house, shrunk to fit a narrow or short lot. Every machiya then gets a provisional plot
//! (kari-shikichi 仮敷地): the rectangle, square to its frontage, covering its house and its
//! kura. All plots go into an R-tree; a kura whose plot overlaps any other plot by more than
//! `kura.overlap_tolerance` collides. The decision reads every plot of the city, so it does
//! not depend on the order of lots or on tiles.

use geo::Contains;
use geo_types::{LineString, Polygon};
use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use super::house::{house_end, local_ring};
use crate::geom::clip::{overlap_area, Quad};
use crate::geom::frame::Frame;
use crate::model::{KuraDecision, PlannedHouse};
use crate::params::Params;
use crate::templates::Catalog;

/// The ring's u-range over the band `v0 <= v <= v1`: the smallest range holding every part
/// of the lot in the band (`outer`), and the largest range every line of the band crosses
/// whole (`inner`, exact for convex lots; the kura is checked against the lot afterwards).
fn u_ranges(ring: &[[f64; 2]], v0: f64, v1: f64) -> Option<((f64, f64), (f64, f64))> {
    let n = ring.len();
    let (mut olo, mut ohi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..n {
        let (p, q) = (ring[i], ring[(i + 1) % n]);
        // The part of edge p-q inside the band.
        let (a, b) = if p[1] <= q[1] { (p, q) } else { (q, p) };
        if b[1] < v0 || a[1] > v1 {
            continue;
        }
        let at = |v: f64| {
            if b[1] - a[1] < 1e-12 {
                a[0]
            } else {
                a[0] + (v - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
            }
        };
        for u in [at(a[1].max(v0)), at(b[1].min(v1))] {
            olo = olo.min(u);
            ohi = ohi.max(u);
        }
    }
    if olo > ohi {
        return None;
    }
    // Inner: the crossing range at v0, v1 and at every vertex between them.
    let extent = |v: f64| -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..n {
            let (p, q) = (ring[i], ring[(i + 1) % n]);
            let (a, b) = if p[1] <= q[1] { (p, q) } else { (q, p) };
            if v < a[1] || v > b[1] || b[1] - a[1] < 1e-12 {
                continue;
            }
            let u = a[0] + (v - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            lo = lo.min(u);
            hi = hi.max(u);
        }
        (lo, hi)
    };
    let (mut ilo, mut ihi) = (f64::NEG_INFINITY, f64::INFINITY);
    let levels = ring
        .iter()
        .map(|p| p[1])
        .filter(|v| *v > v0 && *v < v1)
        .chain([v0, v1]);
    for v in levels {
        let (lo, hi) = extent(v);
        ilo = ilo.max(lo);
        ihi = ihi.min(hi);
    }
    Some(((olo, ohi), (ilo, ihi)))
}

/// Where a candidate's kura stands, in its frame: `[u0, v0, u1, v1]`, or why none does.
fn place(
    m: &PlannedHouse,
    ring: &[[f64; 2]],
    f: Frame,
    end: f64,
    depth: f64,
    params: &Params,
) -> KuraDecision {
    let k = &params.kura;
    let width = m.frontage.width();
    if m.is_footprint() || width < k.min_frontage || depth < k.depth_ratio * width {
        return KuraDecision::NotCandidate;
    }
    let v1 = depth - k.back_margin;
    let v0 = (v1 - k.depth).max(end + k.gap);
    if v1 - v0 < k.min_depth {
        return KuraDecision::NoRoom;
    }
    let Some((_, (lo, hi))) = u_ranges(ring, v0, v1) else {
        return KuraDecision::NoRoom;
    };
    let kw = k.width.min(hi - lo - 2.0 * k.side_margin);
    if kw.is_nan() || kw < k.min_width {
        return KuraDecision::NoRoom;
    }
    let mid = (lo + hi) / 2.0;
    let rect = [mid - kw / 2.0, v0, mid + kw / 2.0, v1];
    // The safety net for lots that are not convex: the kura must lie inside the lot, clear of
    // its courtyards.
    let q = f.quad(rect);
    if !lot_holds(&m.outline, &q) {
        return KuraDecision::NoRoom;
    }
    KuraDecision::Clear(rect)
}

/// Whether `lot` holds the quad `q`. A convex lot without courtyards holds it when it holds
/// its four corners strictly inside, a point-in-polygon test each; any other lot (or a corner
/// on the boundary) takes geo's full DE-9IM `contains`, which gives the same answer at many
/// times the cost (perf: 5 % of a single-tile run when every kura took it).
fn lot_holds(lot: &Polygon<f64>, q: &Quad) -> bool {
    use geo::IsConvex;
    if lot.interiors().is_empty() && lot.exterior().is_convex() && q.iter().all(|c| lot.contains(c))
    {
        return true;
    }
    let poly = Polygon::new(LineString(vec![q[0], q[1], q[2], q[3], q[0]]), vec![]);
    lot.contains(&poly)
}

/// The lower-left and upper-right corners of a quad's bounding box, as rstar takes them.
fn corners(q: &Quad) -> ([f64; 2], [f64; 2]) {
    let b = crate::geom::bbox::bbox(q.iter().copied()).expect("a quad has corners");
    ([b[0], b[1]], [b[2], b[3]])
}

/// Decides every machiya's kura: candidates, placement, provisional plots and collisions.
pub fn decide(planned: &mut [&mut PlannedHouse], catalog: &Catalog, params: &Params) {
    if !params.kura.enabled {
        return;
    }
    // Placement and plots, per machiya.
    let plots: Vec<Quad> = planned
        .par_iter_mut()
        .map(|m| {
            let f = super::house::frame_of(m);
            let ring = local_ring(m, f);
            let depth = ring.iter().map(|p| p[1]).fold(0.0, f64::max);
            let end = house_end(m, depth, catalog, params);
            m.kura = place(m, &ring, f, end, depth, params);
            let (hlo, hhi) = u_ranges(&ring, 0.0, end)
                .map(|(outer, _)| outer)
                .unwrap_or((0.0, m.frontage.width()));
            let plot = match m.kura.rect() {
                Some(r) => [hlo.min(r[0]), 0.0, hhi.max(r[2]), r[3].max(end)],
                None => [hlo, 0.0, hhi, end],
            };
            f.quad(plot)
        })
        .collect();
    // Fig.7: a kura whose plot overlaps any other plot is not built (with avoidance).
    let tree = RTree::bulk_load(
        plots
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let (lo, hi) = corners(q);
                GeomWithData::new(Rectangle::from_corners(lo, hi), i)
            })
            .collect(),
    );
    let tol = params.kura.overlap_tolerance;
    let collides: Vec<bool> = planned
        .par_iter()
        .enumerate()
        .map(|(i, m)| {
            if m.kura.rect().is_none() {
                return false;
            }
            let q = &plots[i];
            let (lo, hi) = corners(q);
            tree.locate_in_envelope_intersecting(&AABB::from_corners(lo, hi))
                .any(|other| other.data != i && overlap_area(q, &plots[other.data]) > tol)
        })
        .collect();
    for (m, c) in planned.iter_mut().zip(collides) {
        if let (true, Some(r)) = (c, m.kura.rect()) {
            m.kura = KuraDecision::Collides(r);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo_types::Coord;

    fn quad(x0: f64, y0: f64, x1: f64, y1: f64) -> Quad {
        [
            Coord { x: x0, y: y0 },
            Coord { x: x1, y: y0 },
            Coord { x: x1, y: y1 },
            Coord { x: x0, y: y1 },
        ]
    }

    #[test]
    fn touching_plots_do_not_overlap_and_crossing_ones_do() {
        let a = quad(0.0, 0.0, 5.0, 30.0);
        assert_eq!(overlap_area(&a, &quad(5.0, 0.0, 10.0, 30.0)), 0.0);
        assert!((overlap_area(&a, &quad(4.0, 10.0, 10.0, 20.0)) - 10.0).abs() < 1e-9);
        assert!((overlap_area(&a, &a) - 150.0).abs() < 1e-9);
        assert_eq!(overlap_area(&a, &quad(20.0, 0.0, 30.0, 5.0)), 0.0);
    }

    #[test]
    fn inner_and_outer_ranges_of_a_slanted_lot() {
        let ring = [[0.0, 0.0], [6.0, 0.0], [7.0, 30.0], [1.0, 30.0]];
        let ((olo, ohi), (ilo, ihi)) = u_ranges(&ring, 10.0, 20.0).unwrap();
        assert!((olo - 1.0 / 3.0).abs() < 1e-9 && (ohi - (6.0 + 2.0 / 3.0)).abs() < 1e-9);
        assert!((ilo - 2.0 / 3.0).abs() < 1e-9 && (ihi - (6.0 + 1.0 / 3.0)).abs() < 1e-9);
    }
}
