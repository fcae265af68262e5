//! `plan.png`: the city seen from above, to check the input and the analysis at a glance.
//!
//! Streets (grey bands, blue centrelines) and block outlines; lots filled by what was built
//! on them (machiya by type, footprints blue-grey, skipped lots red, other uses green); the
//! frontage the paper's Fig.4 chose for each house as a thick red edge (a red line away from
//! the street is a wrong frontage); the tile grid with ids; a legend and a scale bar.

use std::collections::{BTreeMap, HashSet};

use geo_types::{Coord, Polygon};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::text::{draw_text, text_width};
use crate::model::tile::parse_tile_id;
use crate::model::{Dataset, Plan};

/// Longest side of the image in pixels.
pub const MAX_SIDE: f64 = 2400.0;

/// Fill colours of the machiya types, in type-name order, cycling beyond the list.
pub const TYPE_COLOURS: &[[u8; 3]] = &[
    [214, 170, 100],
    [176, 120, 70],
    [120, 150, 90],
    [230, 200, 130],
    [150, 110, 160],
    [200, 130, 130],
    [100, 150, 170],
    [190, 190, 90],
];
/// Houses built from a footprint layer.
pub const FOOTPRINT: [u8; 3] = [140, 155, 175];
/// Lots skipped (with a reason in the report).
pub const SKIPPED: [u8; 3] = [220, 90, 80];
/// Lots of other uses, with no house.
pub const OTHER_USE: [u8; 3] = [200, 215, 190];
/// The frontage Fig.4 chose for each house.
pub const FRONTAGE: [u8; 3] = [200, 30, 30];
/// Halls of estates and temples: a temple's lacquer red.
pub const HALL: [u8; 3] = [178, 58, 42];
/// Kura built.
pub const KURA: [u8; 3] = [70, 70, 78];
/// Walls.
pub const FENCE: [u8; 3] = [95, 60, 35];
/// Gates.
pub const GATE: [u8; 3] = [210, 40, 40];
/// Kura the collision avoidance refused (outlined).
pub const KURA_REFUSED: [u8; 3] = [235, 120, 30];
/// Trees, as wide as their crowns.
pub const TREE: [u8; 3] = [40, 130, 50];
/// People.
pub const PERSON: [u8; 3] = [30, 40, 120];
/// A landmark's footprint (placed from its own model).
pub const LANDMARK: [u8; 3] = [110, 50, 160];
/// A lot whose house a landmark displaced.
pub const LANDMARK_LOT: [u8; 3] = [214, 200, 232];

/// What the image shows and how metres map to pixels.
#[derive(Debug, Clone, Copy)]
pub struct View {
    /// [xmin, ymin, xmax, ymax] in projected metres.
    pub bounds: [f64; 4],
    /// Pixels per metre.
    pub scale: f64,
}

impl View {
    /// The whole data set with a small margin, or one tile's square.
    pub fn fit(data: &Dataset, tile: Option<[f64; 4]>) -> Option<View> {
        let bounds = match tile {
            Some(b) => b,
            None => {
                let outlines = data
                    .lots
                    .iter()
                    .map(|l| &l.outline)
                    .chain(data.footprints.iter().map(|f| &f.outline));
                let [x0, y0, x1, y1] =
                    crate::geom::bbox::bbox(outlines.flat_map(|p| p.exterior().0.iter().copied()))?;
                if x0 >= x1 || y0 >= y1 {
                    return None;
                }
                let m = 0.03 * (x1 - x0).max(y1 - y0);
                [x0 - m, y0 - m, x1 + m, y1 + m]
            }
        };
        let scale = MAX_SIDE / (bounds[2] - bounds[0]).max(bounds[3] - bounds[1]);
        Some(View { bounds, scale })
    }

    /// Pixel of a map point (north up).
    pub fn pixel(&self, c: &Coord<f64>) -> (f32, f32) {
        (
            ((c.x - self.bounds[0]) * self.scale) as f32,
            ((self.bounds[3] - c.y) * self.scale) as f32,
        )
    }

    fn size(&self) -> (u32, u32) {
        (
            ((self.bounds[2] - self.bounds[0]) * self.scale)
                .ceil()
                .max(1.0) as u32,
            ((self.bounds[3] - self.bounds[1]) * self.scale)
                .ceil()
                .max(1.0) as u32,
        )
    }
}

/// The colour each machiya type gets: by type-name order among the types in the plan.
pub fn type_colours(plan: &Plan) -> BTreeMap<String, [u8; 3]> {
    plan.houses
        .values()
        .flatten()
        .filter(|m| !m.is_footprint())
        .map(|m| m.mtype.clone())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .enumerate()
        .map(|(i, t)| (t, TYPE_COLOURS[i % TYPE_COLOURS.len()]))
        .collect()
}

fn paint(rgb: [u8; 3], a: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb[0], rgb[1], rgb[2], a);
    p
}

fn line_path(view: &View, pts: &[Coord<f64>]) -> Option<tiny_skia::Path> {
    let mut pb = PathBuilder::new();
    for (i, c) in pts.iter().enumerate() {
        let (x, y) = view.pixel(c);
        if i == 0 {
            pb.move_to(x, y)
        } else {
            pb.line_to(x, y)
        }
    }
    pb.finish()
}

fn polygon_path(view: &View, poly: &Polygon<f64>) -> Option<tiny_skia::Path> {
    let mut pb = PathBuilder::new();
    for ring in std::iter::once(poly.exterior()).chain(poly.interiors()) {
        for (i, c) in ring.0.iter().enumerate() {
            let (x, y) = view.pixel(c);
            if i == 0 {
                pb.move_to(x, y)
            } else {
                pb.line_to(x, y)
            }
        }
        pb.close();
    }
    pb.finish()
}

/// Draws the plan; `None` when there is nothing to draw. `tile_grid` = (size, origin).
/// `kura`: `None` when kura are off, else whether collisions are avoided (then the refused
/// kura are outlined in red).
pub fn draw_plan(
    data: &Dataset,
    plan: &Plan,
    view: &View,
    tile_grid: (f64, [f64; 2]),
    kura: Option<bool>,
) -> Option<Vec<u8>> {
    let (w, h) = view.size();
    let mut pm = Pixmap::new(w, h)?;
    pm.fill(Color::from_rgba8(250, 248, 242, 255));
    // Bottom to top: street bands and blocks, lots and houses, kura, walls, people and trees,
    // then the lines a reader checks (centrelines, frontages), the grid and the legend.
    draw_streets(&mut pm, view, data);
    let colours = type_colours(plan);
    draw_lots_and_houses(&mut pm, view, data, plan, &colours);
    let refused_any = kura.is_some_and(|avoid| draw_kura(&mut pm, view, plan, avoid));
    let any_fence = draw_fences(&mut pm, view, plan);
    let any_hall = draw_halls(&mut pm, view, plan);
    let any_landmark = draw_landmarks(&mut pm, view, plan);
    let any_billboard = draw_billboards(&mut pm, view, plan);
    draw_lines_on_top(&mut pm, view, data, plan);
    draw_tile_grid(&mut pm, view, plan, tile_grid);
    draw_scale_bar(&mut pm, view);
    let kura_rows = match kura {
        Some(_) => 1 + usize::from(refused_any),
        None => 0,
    };
    let shown = Shown {
        footprints: !data.footprints.is_empty(),
        kura_rows,
        fences: any_fence,
        halls: any_hall,
        landmarks: any_landmark,
        billboards: any_billboard,
    };
    draw_legend(&mut pm, &colours, &shown);
    encode_png(&pm)
}

/// A one-pixel stroke.
fn thin() -> Stroke {
    Stroke {
        width: 1.0,
        ..Stroke::default()
    }
}

/// Street bands as wide as the streets, and block outlines.
fn draw_streets(pm: &mut Pixmap, view: &View, data: &Dataset) {
    let id = Transform::identity();
    for street in &data.streets {
        if let Some(path) = line_path(view, &street.line.0) {
            let stroke = Stroke {
                width: ((street.width * view.scale) as f32).max(1.0),
                ..Stroke::default()
            };
            pm.stroke_path(&path, &paint([215, 212, 205], 255), &stroke, id, None);
        }
    }
    for block in &data.blocks {
        if let Some(path) = polygon_path(view, block) {
            pm.stroke_path(&path, &paint([160, 160, 160], 255), &thin(), id, None);
        }
    }
}

/// Lots without a house (other uses, given to a landmark, skipped ones), then every house by its type's colour.
fn draw_lots_and_houses(
    pm: &mut Pixmap,
    view: &View,
    data: &Dataset,
    plan: &Plan,
    colours: &BTreeMap<String, [u8; 3]>,
) {
    let id = Transform::identity();
    let skipped: HashSet<&str> = plan.skipped.iter().map(|s| s.id.as_str()).collect();
    let displaced: HashSet<&str> = (plan.landmark_report.displaced.iter())
        .filter(|d| d.kind == "machiya")
        .map(|d| d.id.as_str())
        .collect();
    let planned: HashSet<&str> = plan
        .houses
        .values()
        .flatten()
        .filter(|m| !m.is_footprint())
        .map(|m| m.id.as_str())
        .collect();
    for lot in &data.lots {
        if planned.contains(lot.id.as_str()) {
            continue;
        }
        if let Some(path) = polygon_path(view, &lot.outline) {
            let fill = if displaced.contains(lot.id.as_str()) {
                LANDMARK_LOT
            } else if skipped.contains(lot.id.as_str()) {
                SKIPPED
            } else {
                OTHER_USE
            };
            pm.fill_path(&path, &paint(fill, 255), FillRule::EvenOdd, id, None);
            pm.stroke_path(&path, &paint([90, 80, 70], 255), &thin(), id, None);
        }
    }
    for m in plan.houses.values().flatten() {
        let colour = match m.footprint_height() {
            Some(_) => FOOTPRINT,
            None => colours.get(&m.mtype).copied().unwrap_or(TYPE_COLOURS[0]),
        };
        if let Some(path) = polygon_path(view, &m.outline) {
            pm.fill_path(&path, &paint(colour, 255), FillRule::EvenOdd, id, None);
            pm.stroke_path(&path, &paint([90, 80, 70], 255), &thin(), id, None);
        }
    }
}

/// Kura filled where built, outlined where the avoidance (`avoid`) refused them; whether any
/// was refused (for the legend).
fn draw_kura(pm: &mut Pixmap, view: &View, plan: &Plan, avoid: bool) -> bool {
    let id = Transform::identity();
    let refused = Stroke {
        width: 1.5,
        ..Stroke::default()
    };
    let mut refused_any = false;
    for m in plan.houses.values().flatten() {
        let Some(r) = m.kura.rect() else { continue };
        let q = crate::geom::frame::Frame {
            a: m.frontage.a,
            u: m.frontage.u_axis(),
            v: m.frontage.v_axis(),
        }
        .quad(r);
        let Some(path) = line_path(view, &[q[0], q[1], q[2], q[3], q[0]]) else {
            continue;
        };
        if m.kura.to_build(avoid).is_some() {
            pm.fill_path(&path, &paint(KURA, 255), FillRule::EvenOdd, id, None);
        } else {
            refused_any = true;
            pm.stroke_path(&path, &paint(KURA_REFUSED, 255), &refused, id, None);
        }
    }
    refused_any
}

/// The halls' plots, filled (whether there was any).
fn draw_halls(pm: &mut Pixmap, view: &View, plan: &Plan) -> bool {
    let mut any = false;
    for h in plan.halls.values().flatten() {
        let ring = h.outline();
        let Some(path) = line_path(view, &[ring[0], ring[1], ring[2], ring[3], ring[0]]) else {
            continue;
        };
        pm.fill_path(
            &path,
            &paint(HALL, 255),
            FillRule::EvenOdd,
            Transform::identity(),
            None,
        );
        any = true;
    }
    any
}

/// The landmarks' footprints, filled and outlined (whether there was any).
fn draw_landmarks(pm: &mut Pixmap, view: &View, plan: &Plan) -> bool {
    let mut any = false;
    for l in plan.landmarks.values().flatten() {
        let Some(path) = polygon_path(view, &l.footprint) else {
            continue;
        };
        let id = Transform::identity();
        pm.fill_path(&path, &paint(LANDMARK, 255), FillRule::EvenOdd, id, None);
        pm.stroke_path(&path, &paint([40, 20, 60], 255), &thin(), id, None);
        any = true;
    }
    any
}

/// Walls and gates (section 4.3): a dark line along each wall segment, a red bar per gate;
/// whether there was any.
fn draw_fences(pm: &mut Pixmap, view: &View, plan: &Plan) -> bool {
    let id = Transform::identity();
    let (wall, gate_bar) = (
        Stroke {
            width: 2.0,
            ..Stroke::default()
        },
        Stroke {
            width: 4.0,
            ..Stroke::default()
        },
    );
    let mut any_fence = false;
    for f in plan.fences.values().flatten() {
        if let Some(path) = line_path(view, &[f.a, f.b]) {
            any_fence = true;
            let (colour, stroke) = match f.kind {
                crate::model::FenceKind::Wall => (FENCE, &wall),
                crate::model::FenceKind::Gate => (GATE, &gate_bar),
            };
            pm.stroke_path(&path, &paint(colour, 255), stroke, id, None);
        }
    }
    any_fence
}

/// People and trees (section 4.4): a dot each, a tree's as wide as its crown; whether there
/// was any.
fn draw_billboards(pm: &mut Pixmap, view: &View, plan: &Plan) -> bool {
    let mut any_billboard = false;
    for b in plan.billboards.values().flatten() {
        let (x, y) = view.pixel(&b.at);
        let (colour, r) = match b.kind {
            crate::model::BillboardKind::Tree => (TREE, (b.height * 0.25 * view.scale) as f32),
            crate::model::BillboardKind::Person => (PERSON, 2.5),
        };
        if let Some(dot) = tiny_skia::PathBuilder::from_circle(x, y, r.max(1.5)) {
            any_billboard = true;
            let id = Transform::identity();
            pm.fill_path(&dot, &paint(colour, 220), FillRule::Winding, id, None);
        }
    }
    any_billboard
}

/// Street centrelines and each house's frontage, on top: in cadastral data the roads are
/// parcels too and would hide them.
fn draw_lines_on_top(pm: &mut Pixmap, view: &View, data: &Dataset, plan: &Plan) {
    let id = Transform::identity();
    for street in &data.streets {
        if let Some(path) = line_path(view, &street.line.0) {
            pm.stroke_path(&path, &paint([60, 90, 140], 160), &thin(), id, None);
        }
    }
    let frontage = Stroke {
        width: 2.5,
        ..Stroke::default()
    };
    for m in plan.houses.values().flatten() {
        if let Some(path) = line_path(view, &[m.frontage.a, m.frontage.b]) {
            pm.stroke_path(&path, &paint(FRONTAGE, 255), &frontage, id, None);
        }
    }
}

/// PNG with fast compression: at 2400 x 2400 the default level took most of the plan's time.
/// The background is opaque, so tiny-skia's premultiplied pixels are plain RGBA.
pub fn encode_png(pm: &Pixmap) -> Option<Vec<u8>> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::ImageEncoder;
    let mut buf = Vec::new();
    PngEncoder::new_with_quality(&mut buf, CompressionType::Fast, FilterType::Adaptive)
        .write_image(
            pm.data(),
            pm.width(),
            pm.height(),
            image::ExtendedColorType::Rgba8,
        )
        .ok()?;
    Some(buf)
}

fn draw_tile_grid(pm: &mut Pixmap, view: &View, plan: &Plan, (size, origin): (f64, [f64; 2])) {
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

fn draw_scale_bar(pm: &mut Pixmap, view: &View) {
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
struct Shown {
    footprints: bool,
    /// 0 (kura off), 1 (kura) or 2 (kura and refused kura).
    kura_rows: usize,
    fences: bool,
    halls: bool,
    landmarks: bool,
    billboards: bool,
}

fn draw_legend(pm: &mut Pixmap, colours: &BTreeMap<String, [u8; 3]>, shown: &Shown) {
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
