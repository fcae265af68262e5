//! The medial-axis rule (Van Tonder, Lyons & Ejima, Nature 419, 2002): the skeleton of the
//! open space between the stones, and whether its main branch points at the viewpoint.
//!
//! The open space is sampled on a grid of `cell` units; each sample's distance to the
//! nearest stone's edge (stones as discs of their size) is the distance transform, and the
//! skeleton is its ridge: the samples that are local maxima along x or along y. The main
//! branch is the ridge's principal axis (weighted by the distance, so the broad channels
//! count most); the degree of violation is the angle between that axis and the line from
//! the ridge's centre to the viewpoint, 0 to pi/2 radians.

use super::{Layout, Settings};

/// The ridge samples (x, y, distance) of a layout's open space.
pub fn ridge(l: &Layout, s: &Settings) -> Vec<[f64; 3]> {
    let nx = ((s.width / s.cell).ceil() as usize).clamp(4, 400);
    let ny = ((s.depth / s.cell).ceil() as usize).clamp(4, 400);
    let (dx, dy) = (s.width / nx as f64, s.depth / ny as f64);
    // Stone by stone over whole rows (the min of the same values in the same order as cell by
    // cell, so the same bits), which the compiler vectorises; the sqrt of the sum, not hypot:
    // hypot guards against overflow that metres never reach, and it was an eighth of a build.
    let xs: Vec<f64> = (0..nx).map(|i| (i as f64 + 0.5) * dx).collect();
    let mut dist = vec![f64::INFINITY; nx * ny];
    for st in &l.stones {
        let half = st.size / 2.0;
        for (j, row) in dist.chunks_exact_mut(nx).enumerate() {
            let ddy = (j as f64 + 0.5) * dy - st.y;
            let ddy2 = ddy * ddy;
            for (d, &x) in row.iter_mut().zip(&xs) {
                let ddx = x - st.x;
                *d = d.min(((ddx * ddx + ddy2).sqrt() - half).max(0.0));
            }
        }
    }
    let at = |i: usize, j: usize| dist[j * nx + i];
    let mut out = Vec::new();
    for j in 1..ny - 1 {
        for i in 1..nx - 1 {
            let d = at(i, j);
            if d <= 0.0 {
                continue;
            }
            let along_x =
                d >= at(i - 1, j) && d >= at(i + 1, j) && (d > at(i - 1, j) || d > at(i + 1, j));
            let along_y =
                d >= at(i, j - 1) && d >= at(i, j + 1) && (d > at(i, j - 1) || d > at(i, j + 1));
            if along_x || along_y {
                out.push([(i as f64 + 0.5) * dx, (j as f64 + 0.5) * dy, d]);
            }
        }
    }
    out
}

/// The main branch: the weighted centre of the ridge and its principal direction.
pub fn main_axis(ridge: &[[f64; 3]]) -> Option<([f64; 2], [f64; 2])> {
    let w: f64 = ridge.iter().map(|p| p[2]).sum();
    if w <= 0.0 {
        return None;
    }
    let cx = ridge.iter().map(|p| p[0] * p[2]).sum::<f64>() / w;
    let cy = ridge.iter().map(|p| p[1] * p[2]).sum::<f64>() / w;
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in ridge {
        let (x, y) = (p[0] - cx, p[1] - cy);
        sxx += p[2] * x * x;
        syy += p[2] * y * y;
        sxy += p[2] * x * y;
    }
    let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    Some(([cx, cy], [theta.cos(), theta.sin()]))
}

/// The rule's degree: the angle between the main branch and the way to the viewpoint.
pub fn axis_violation(l: &Layout, s: &Settings) -> f64 {
    let Some((c, d)) = main_axis(&ridge(l, s)) else {
        return std::f64::consts::FRAC_PI_2;
    };
    let to = [s.viewpoint[0] - c[0], s.viewpoint[1] - c[1]];
    let n = to[0].hypot(to[1]);
    if n < 1e-12 {
        return 0.0;
    }
    // A line has no sign: the angle to the nearer of its two directions.
    ((d[0] * to[0] + d[1] * to[1]).abs() / n)
        .clamp(0.0, 1.0)
        .acos()
}
