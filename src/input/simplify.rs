//! Vertex generalisation (section 2.2 of the paper): vertices that lie on the line between
//! their neighbours, within `simplify.tolerance` metres, carry no shape and only cost time
//! and bytes (digitised maps and cadastral exports are full of them). They are removed from
//! lot, footprint and block outlines and street lines before analysis, and the report counts
//! the vertices before and after.
//!
//! Not geo's Ramer-Douglas-Peucker: on a closed ring it keeps the ring's first point whether
//! or not it is redundant (measured: a lot with three redundant points kept one).

use geo_types::{Coord, LineString, Polygon};

use crate::model::{Dataset, Skipped};
use crate::params::SimplifyParams;

fn ring_len(ls: &LineString<f64>) -> usize {
    ls.0.len().saturating_sub(1)
}

fn polygon_vertices(p: &Polygon<f64>) -> usize {
    ring_len(p.exterior()) + p.interiors().iter().map(ring_len).sum::<usize>()
}

/// Distance from `p` to the segment `a`-`b`.
fn deviation(a: Coord<f64>, p: Coord<f64>, b: Coord<f64>) -> f64 {
    let (dx, dy) = (b.x - a.x, b.y - a.y);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.x - a.x) * dx + (p.y - a.y) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p.x - a.x - t * dx).hypot(p.y - a.y - t * dy)
}

/// Longest run of vertices one chord may replace: bounds the work on a line of a million
/// collinear points (it keeps one vertex per run).
const MAX_RUN: usize = 256;

/// An open line without the vertices that lie within `tol` of the chord replacing them: a
/// vertex goes when it, and every vertex already dropped since the last kept one, is within
/// `tol` of the segment from the last kept vertex to the next. So a gently curved boundary
/// digitised in short segments keeps its curve. The ends are kept. Linear in the points.
fn reduce_open(pts: &[Coord<f64>], tol: f64) -> Vec<Coord<f64>> {
    kept_indices(pts, tol).into_iter().map(|i| pts[i]).collect()
}

/// The indices of the vertices [`reduce_open`] keeps.
fn kept_indices(pts: &[Coord<f64>], tol: f64) -> Vec<usize> {
    if pts.is_empty() {
        return Vec::new();
    }
    let mut kept = vec![0];
    let mut run: Vec<usize> = Vec::new();
    let mut cand: Option<usize> = None;
    for p in 1..pts.len() {
        if let Some(c) = cand {
            let a = pts[*kept.last().expect("starts with the first point")];
            let droppable = run.len() < MAX_RUN
                && deviation(a, pts[c], pts[p]) <= tol
                && run.iter().all(|&q| deviation(a, pts[q], pts[p]) <= tol);
            if droppable {
                run.push(c);
            } else {
                kept.push(c);
                run.clear();
            }
        }
        cand = Some(p);
    }
    kept.extend(cand);
    kept
}

fn reduce_ring(r: &LineString<f64>, tol: f64) -> LineString<f64> {
    let pts = &r.0[..ring_len(r)];
    let n = pts.len();
    if n <= 3 {
        return r.clone();
    }
    // Start at the sharpest corner, which stays, and close the ring on it.
    let start = (0..n)
        .max_by(|&i, &j| {
            let d = |k: usize| deviation(pts[(k + n - 1) % n], pts[k], pts[(k + 1) % n]);
            d(i).total_cmp(&d(j)).then(j.cmp(&i))
        })
        .unwrap_or(0);
    let rotated: Vec<Coord<f64>> = (0..=n).map(|k| pts[(start + k) % n]).collect();
    let mut kept: Vec<usize> = kept_indices(&rotated, tol)
        .into_iter()
        .map(|k| (start + k) % n)
        .collect();
    kept.pop(); // the start again, closing the ring
    if kept.len() < 3 {
        // Fewer than 3 corners left: the ring was (nearly) a line; keep it as it was.
        return r.clone();
    }
    // Back in the input's order from its first kept vertex, so that the same outline with
    // other floating-point noise (a reprojected copy) keeps the same vertex order.
    kept.sort_unstable();
    // Sized for the closing vertex too: a pushed one would double a million outlines.
    let mut out: Vec<Coord<f64>> = Vec::with_capacity(kept.len() + 1);
    out.extend(kept.iter().map(|&i| pts[i]));
    out.push(out[0]);
    LineString(out)
}

/// The polygon without its redundant vertices.
fn simplify_polygon(p: &Polygon<f64>, tol: f64) -> Polygon<f64> {
    Polygon::new(
        reduce_ring(p.exterior(), tol),
        p.interiors().iter().map(|h| reduce_ring(h, tol)).collect(),
    )
}

/// Removes redundant vertices from every outline and line of `data` and records the
/// vertex counts of each layer in its `LayerInfo` (a tolerance of 0 removes none); then
/// skips every lot, footprint and fence line left with more than `max_vertices`.
pub fn generalise(data: &mut Dataset, params: &SimplifyParams) {
    let tol = params.tolerance;
    if tol > 0.0 {
        reduce_all(data, tol);
    }
    skip_too_detailed(data, params.max_vertices);
}

fn reduce_all(data: &mut Dataset, tol: f64) {
    let mut count = |role: &str, before: usize, after: usize| {
        if let Some(l) = data.layers.iter_mut().find(|l| l.role == role) {
            l.vertices_before += before;
            l.vertices_after += after;
        }
    };
    let (mut b, mut a) = (0, 0);
    for lot in &mut data.lots {
        b += polygon_vertices(&lot.outline);
        lot.outline = simplify_polygon(&lot.outline, tol);
        a += polygon_vertices(&lot.outline);
    }
    count("lots", b, a);
    let (mut b, mut a) = (0, 0);
    for f in &mut data.footprints {
        b += polygon_vertices(&f.outline);
        f.outline = simplify_polygon(&f.outline, tol);
        a += polygon_vertices(&f.outline);
    }
    count("footprints", b, a);
    let (mut b, mut a) = (0, 0);
    for p in &mut data.blocks {
        b += polygon_vertices(p);
        *p = simplify_polygon(p, tol);
        a += polygon_vertices(p);
    }
    count("blocks", b, a);
    let (mut b, mut a) = (0, 0);
    for s in &mut data.streets {
        b += s.line.0.len();
        s.line = LineString(reduce_open(&s.line.0, tol));
        a += s.line.0.len();
    }
    count("streets", b, a);
    let (mut b, mut a) = (0, 0);
    for f in &mut data.fence_lines {
        b += f.line.0.len();
        f.line = LineString(reduce_open(&f.line.0, tol));
        a += f.line.0.len();
    }
    count("fences", b, a);
}

/// A feature with more vertices than any plot of land needs (a traced scan, a curve
/// digitised every millimetre) would build a wall segment, a mesh edge and a tree test per
/// vertex: measured, one temple lot of a million vertices took 3 minutes, 2.3 GB and a
/// 600 MB tile. It is skipped with the way out instead. Blocks and streets are only looked
/// up, never built, so they are kept whatever their size.
fn skip_too_detailed(data: &mut Dataset, max: usize) {
    let file_of = |role: &str| {
        data.layers
            .iter()
            .find(|l| l.role == role)
            .map_or_else(String::new, |l| l.file.clone())
    };
    let files = [file_of("lots"), file_of("footprints"), file_of("fences")];
    let mut skipped = Vec::new();
    let mut over = |layer: &str, file: &str, id: &str, n: usize| {
        let keep = n <= max;
        if !keep {
            skipped.push(Skipped {
                layer: layer.into(),
                file: file.into(),
                id: id.into(),
                record: None,
                reason: format!(
                    "{n} vertices after simplification, more than `simplify.max_vertices` \
                     ({max}); simplify the outline in the GIS (QGIS: Vector > Geometry Tools > \
                     Simplify) or raise the limit"
                ),
            });
        }
        keep
    };
    data.lots
        .retain(|l| over("lots", &files[0], &l.id, polygon_vertices(&l.outline)));
    data.footprints
        .retain(|f| over("footprints", &files[1], &f.id, polygon_vertices(&f.outline)));
    data.fence_lines
        .retain(|f| over("fences", &files[2], &f.id, f.line.0.len()));
    data.skipped.extend(skipped);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collinear_vertices_go_and_corners_stay() {
        let p = Polygon::new(
            LineString::from(vec![
                (0.0, 0.0),
                (2.0, 0.004),
                (5.0, 0.0),
                (5.0, 10.0),
                (2.5, 10.0),
                (0.0, 10.0),
                (0.0, 0.0),
            ]),
            vec![],
        );
        let s = simplify_polygon(&p, 0.01);
        assert_eq!(polygon_vertices(&s), 4);
        // A real bend larger than the tolerance stays.
        let s = simplify_polygon(&p, 0.001);
        assert_eq!(polygon_vertices(&s), 5);
    }

    #[test]
    fn a_curve_in_short_segments_keeps_its_shape() {
        // A quarter circle of radius 20 m in 1 m segments: each vertex is 6 mm off the chord of
        // its neighbours, the arc 5.9 m off the chord of its ends.
        let pts: Vec<Coord<f64>> = (0..=31)
            .map(|k| {
                let a = k as f64 / 31.0 * std::f64::consts::FRAC_PI_2;
                Coord {
                    x: 20.0 * a.cos(),
                    y: 20.0 * a.sin(),
                }
            })
            .collect();
        let out = reduce_open(&pts, 0.01);
        assert!(out.len() > 10, "{} points left", out.len());
        for p in &pts {
            let d = out
                .windows(2)
                .map(|w| deviation(w[0], *p, w[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 0.01 + 1e-9, "{p:?} is {d} m off");
        }
        // 200,000 collinear points: linear time, one vertex per run kept.
        let line: Vec<Coord<f64>> = (0..200_000)
            .map(|k| Coord {
                x: k as f64 * 0.01,
                y: 0.0,
            })
            .collect();
        let out = reduce_open(&line, 0.01);
        assert!(out.len() < 200_000 / MAX_RUN + 10, "{}", out.len());
    }
}
