//! `plan.png`: the city seen from above, to check the input and the analysis at a glance.
//!
//! Streets (grey bands, blue centrelines) and block outlines, lots filled by what was built on them (machiya by
//! type, footprints blue-grey, skipped lots red), and the frontage the paper's Fig.4 chose
//! for each house as a thick red edge: a wrong frontage shows up as a red line away from the
//! street.

use std::collections::{BTreeMap, HashSet};

use geo_types::{Coord, Polygon};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

use crate::model::{Dataset, Plan};

/// Longest side of the image in pixels.
const MAX_SIDE: f64 = 2400.0;

/// Fill colours of the machiya types, cycling for types beyond the list.
const TYPE_COLOURS: &[[u8; 3]] = &[
    [214, 180, 120],
    [190, 140, 90],
    [160, 110, 70],
    [230, 205, 150],
    [150, 160, 110],
    [200, 160, 160],
    [170, 150, 190],
    [120, 150, 170],
];

/// Draws the plan; `None` when there is nothing to draw.
pub fn draw_plan(data: &Dataset, plan: &Plan) -> Option<Vec<u8>> {
    let outlines = data
        .lots
        .iter()
        .map(|l| &l.outline)
        .chain(data.footprints.iter().map(|f| &f.outline));
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for c in outlines.flat_map(|p| p.exterior().0.iter()) {
        x0 = x0.min(c.x);
        y0 = y0.min(c.y);
        x1 = x1.max(c.x);
        y1 = y1.max(c.y);
    }
    if x0 >= x1 || y0 >= y1 {
        return None;
    }
    let margin = 0.03 * (x1 - x0).max(y1 - y0);
    let (x0, y0, x1, y1) = (x0 - margin, y0 - margin, x1 + margin, y1 + margin);
    let scale = MAX_SIDE / (x1 - x0).max(y1 - y0);
    let (w, h) = (
        ((x1 - x0) * scale).ceil() as u32,
        ((y1 - y0) * scale).ceil() as u32,
    );
    let mut pm = Pixmap::new(w.max(1), h.max(1))?;
    pm.fill(Color::from_rgba8(250, 248, 242, 255));
    // Map metres to pixels, north up.
    let px = |c: &Coord<f64>| (((c.x - x0) * scale) as f32, ((y1 - c.y) * scale) as f32);

    let paint = |rgb: [u8; 3], a: u8| {
        let mut p = Paint::default();
        p.set_color_rgba8(rgb[0], rgb[1], rgb[2], a);
        p
    };
    let polygon_path = |poly: &Polygon<f64>| {
        let mut pb = PathBuilder::new();
        for ring in std::iter::once(poly.exterior()).chain(poly.interiors()) {
            for (i, c) in ring.0.iter().enumerate() {
                let (x, y) = px(c);
                if i == 0 {
                    pb.move_to(x, y)
                } else {
                    pb.line_to(x, y)
                }
            }
            pb.close();
        }
        pb.finish()
    };
    let thin = Stroke {
        width: 1.0,
        ..Stroke::default()
    };

    for street in &data.streets {
        let mut pb = PathBuilder::new();
        for (i, c) in street.line.0.iter().enumerate() {
            let (x, y) = px(c);
            if i == 0 {
                pb.move_to(x, y)
            } else {
                pb.line_to(x, y)
            }
        }
        if let Some(path) = pb.finish() {
            let stroke = Stroke {
                width: ((street.width * scale) as f32).max(1.0),
                ..Stroke::default()
            };
            pm.stroke_path(
                &path,
                &paint([215, 212, 205], 255),
                &stroke,
                Transform::identity(),
                None,
            );
        }
    }
    for block in &data.blocks {
        if let Some(path) = polygon_path(block) {
            pm.stroke_path(
                &path,
                &paint([160, 160, 160], 255),
                &thin,
                Transform::identity(),
                None,
            );
        }
    }

    let types: BTreeMap<&str, usize> = plan
        .tiles
        .values()
        .flatten()
        .map(|m| m.mtype.as_str())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .enumerate()
        .map(|(i, t)| (t, i))
        .collect();
    let skipped: HashSet<&str> = plan.skipped.iter().map(|s| s.id.as_str()).collect();
    let planned: HashSet<&str> = plan
        .tiles
        .values()
        .flatten()
        .map(|m| m.id.as_str())
        .collect();
    for lot in &data.lots {
        if let Some(path) = polygon_path(&lot.outline) {
            let fill = if skipped.contains(lot.id.as_str()) {
                paint([220, 90, 80], 200)
            } else if planned.contains(lot.id.as_str()) {
                paint([235, 225, 200], 255)
            } else {
                // Not a town lot (buke, kuge, jisha, other): built by later stages.
                paint([200, 215, 190], 255)
            };
            pm.fill_path(&path, &fill, FillRule::EvenOdd, Transform::identity(), None);
            pm.stroke_path(
                &path,
                &paint([90, 80, 70], 255),
                &thin,
                Transform::identity(),
                None,
            );
        }
    }
    // Centrelines on top: in cadastral data the roads are parcels too and hide the bands.
    for street in &data.streets {
        let mut pb = PathBuilder::new();
        for (i, c) in street.line.0.iter().enumerate() {
            let (x, y) = px(c);
            if i == 0 {
                pb.move_to(x, y)
            } else {
                pb.line_to(x, y)
            }
        }
        if let Some(path) = pb.finish() {
            pm.stroke_path(
                &path,
                &paint([60, 90, 140], 160),
                &thin,
                Transform::identity(),
                None,
            );
        }
    }
    let frontage = Stroke {
        width: 2.5,
        ..Stroke::default()
    };
    for m in plan.tiles.values().flatten() {
        let colour = match m.height {
            Some(_) => [140, 155, 175],
            None => TYPE_COLOURS[types[m.mtype.as_str()] % TYPE_COLOURS.len()],
        };
        if m.height.is_some() {
            if let Some(path) = polygon_path(&m.outline) {
                pm.fill_path(
                    &path,
                    &paint(colour, 255),
                    FillRule::EvenOdd,
                    Transform::identity(),
                    None,
                );
                pm.stroke_path(
                    &path,
                    &paint([70, 80, 95], 255),
                    &thin,
                    Transform::identity(),
                    None,
                );
            }
        } else if let Some(path) = polygon_path(&m.outline) {
            pm.fill_path(
                &path,
                &paint(colour, 150),
                FillRule::EvenOdd,
                Transform::identity(),
                None,
            );
        }
        let mut pb = PathBuilder::new();
        let (ax, ay) = px(&m.frontage.a);
        let (bx, by) = px(&m.frontage.b);
        pb.move_to(ax, ay);
        pb.line_to(bx, by);
        if let Some(path) = pb.finish() {
            pm.stroke_path(
                &path,
                &paint([200, 30, 30], 255),
                &frontage,
                Transform::identity(),
                None,
            );
        }
    }
    pm.encode_png().ok()
}
