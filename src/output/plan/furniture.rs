//! What frames the plan: the tile grid with its ids, the scale bar and the legend of what
//! the plan shows.

use std::collections::BTreeMap;

use geo_types::Coord;
use tiny_skia::{PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::paint::{line_path, paint};
use super::{View, FENCE, FOOTPRINT, FRONTAGE, GATE, HALL, KURA, KURA_REFUSED, LANDMARK};
use super::{LANDMARK_LOT, OTHER_USE, PERSON, SKIPPED, TREE};
use crate::model::tile::parse_tile_id;
use crate::model::Plan;
use crate::output::text::{draw_text, text_width};

pub(super) fn draw_tile_grid(
    pm: &mut Pixmap,
    view: &View,
    plan: &Plan,
    (size, origin): (f64, [f64; 2]),
) {
    let tile_px = size * view.scale;
    let dash = Stroke {
        width: 1.0,
        dash: tiny_skia::StrokeDash::new(vec![6.0, 4.0], 0.0),
        ..Stroke::default()
    };
    for id in &plan.tiles {
        let Some((c, r)) = parse_tile_id(id) else {
            continue;
        };
        let (x0, y0) = (origin[0] + c as f64 * size, origin[1] + r as f64 * size);
        let corners = [
            Coord { x: x0, y: y0 },
            Coord {
                x: x0 + size,
                y: y0,
            },
            Coord {
                x: x0 + size,
                y: y0 + size,
            },
            Coord {
                x: x0,
                y: y0 + size,
            },
            Coord { x: x0, y: y0 },
        ];
        if let Some(path) = line_path(view, &corners) {
            pm.stroke_path(
                &path,
                &paint([90, 90, 160], 200),
                &dash,
                Transform::identity(),
                None,
            );
        }
        let scale = if tile_px > 400.0 { 2 } else { 1 };
        if tile_px > f64::from(text_width(id, scale) + 8) {
            // The tile's top-left corner, kept inside the image when the tile is cut off.
            let (x, y) = view.pixel(&corners[3]);
            let (x, y) = (x.max(0.0) + 4.0, y.max(0.0) + 4.0);
            draw_text(pm, x, y, id, scale, [70, 70, 150]);
        }
    }
}

pub(super) fn draw_scale_bar(pm: &mut Pixmap, view: &View) {
    let target = (pm.width() as f64 / 5.0) / view.scale;
    let steps = [
        1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0,
    ];
    // The longest round length that fits a fifth of the width.
    let metres = steps
        .iter()
        .rev()
        .copied()
        .find(|s| *s <= target)
        .unwrap_or(1.0);
    let len = (metres * view.scale) as f32;
    let (x, y) = (20.0, pm.height() as f32 - 30.0);
    for (i, colour) in [[30, 30, 30], [250, 250, 250], [30, 30, 30], [250, 250, 250]]
        .iter()
        .enumerate()
    {
        if let Some(r) = Rect::from_xywh(x + i as f32 * len / 4.0, y, len / 4.0, 8.0) {
            pm.fill_rect(r, &paint(*colour, 255), Transform::identity(), None);
        }
    }
    if let Some(r) = Rect::from_xywh(x, y, len, 8.0) {
        let path = PathBuilder::from_rect(r);
        pm.stroke_path(
            &path,
            &paint([30, 30, 30], 255),
            &Stroke::default(),
            Transform::identity(),
            None,
        );
    }
    draw_text(pm, x, y - 20.0, &format!("{metres} m"), 2, [30, 30, 30]);
}

/// Which rows the legend has (only what the plan shows).
pub(super) struct Shown {
    pub(super) footprints: bool,
    /// 0 (kura off), 1 (kura) or 2 (kura and refused kura).
    pub(super) kura_rows: usize,
    pub(super) fences: bool,
    pub(super) halls: bool,
    pub(super) landmarks: bool,
    pub(super) billboards: bool,
}

pub(super) fn draw_legend(pm: &mut Pixmap, colours: &BTreeMap<String, [u8; 3]>, shown: &Shown) {
    let mut rows: Vec<(String, [u8; 3])> = colours.iter().map(|(t, c)| (t.clone(), *c)).collect();
    if shown.footprints {
        rows.push(("footprint".into(), FOOTPRINT));
    }
    for (name, colour) in [
        ("kura", KURA),
        ("kura refused (plots collide)", KURA_REFUSED),
    ]
    .into_iter()
    .take(shown.kura_rows)
    {
        rows.push((name.into(), colour));
    }
    if shown.fences {
        rows.push(("wall".into(), FENCE));
        rows.push(("gate".into(), GATE));
    }
    if shown.halls {
        rows.push(("hall".into(), HALL));
    }
    if shown.landmarks {
        rows.push(("landmark".into(), LANDMARK));
        rows.push(("lot of a landmark".into(), LANDMARK_LOT));
    }
    if shown.billboards {
        rows.push(("tree".into(), TREE));
        rows.push(("person".into(), PERSON));
    }
    rows.push(("other use".into(), OTHER_USE));
    rows.push(("skipped".into(), SKIPPED));
    rows.push(("frontage".into(), FRONTAGE));
    let width = rows.iter().map(|r| text_width(&r.0, 2)).max().unwrap_or(0) as f32 + 60.0;
    let height = rows.len() as f32 * 24.0 + 16.0;
    // Top right: tile ids sit at the top left of their tiles.
    let x0 = (pm.width() as f32 - width - 10.0).max(0.0);
    if let Some(r) = Rect::from_xywh(x0, 10.0, width, height) {
        pm.fill_rect(r, &paint([255, 255, 255], 230), Transform::identity(), None);
    }
    for (i, (name, colour)) in rows.iter().enumerate() {
        let y = 18.0 + i as f32 * 24.0;
        if let Some(r) = Rect::from_xywh(x0 + 8.0, y, 28.0, 16.0) {
            pm.fill_rect(r, &paint(*colour, 255), Transform::identity(), None);
        }
        draw_text(pm, x0 + 44.0, y, name, 2, [30, 30, 30]);
    }
}
