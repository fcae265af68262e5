//! `plan.png`: the city seen from above, to check the input and the analysis at a glance.
//!
//! Streets (grey bands, blue centrelines) and block outlines; lots filled by what was built
//! on them (machiya by type, footprints blue-grey, skipped lots red, other uses green); the
//! frontage the paper's Fig.4 chose for each house as a thick red edge (a red line away from
//! the street is a wrong frontage); the tile grid with ids; a legend and a scale bar.

mod furniture;
mod paint;
mod strips;

use std::collections::{BTreeMap, HashSet};

use geo_types::Coord;
use tiny_skia::Pixmap;

use crate::model::{Dataset, Plan};
use furniture::{draw_legend, draw_scale_bar, draw_tile_grid, Shown};
use paint::{crisp, paint, thin, wide, Batch, Draw, OUTLINE};
use strips::Target;
pub use strips::{Kept, STRIP_ROWS};

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

/// Draws the plan; `None` when there is nothing to draw. `tile_grid` = (size, origin).
/// `kura`: `None` when kura are off, else whether collisions are avoided (then the refused
/// kura are outlined in red). `kept`: the workbench's image of the rebuild before, whose
/// strips are kept where nothing in them changed ([`strips`]).
pub fn draw_plan(
    data: &Dataset,
    plan: &Plan,
    view: &View,
    tile_grid: (f64, [f64; 2]),
    kura: Option<bool>,
    kept: Option<&Kept>,
) -> Option<Vec<u8>> {
    let (w, h) = view.size();
    let colours = type_colours(plan);
    let fills = Fills::of(data, plan, &colours);
    // Bottom to top: street bands and blocks, lots and houses, kura, walls, people and trees,
    // then the lines a reader checks (centrelines, frontages); over them the grid and the
    // legend.
    let layers = |t: &mut Target| {
        draw_streets(t, view, data);
        draw_lots_and_houses(t, view, data, plan, &fills);
        if let Some(avoid) = kura {
            draw_kura(t, view, plan, avoid);
        }
        draw_fences(t, view, plan);
        draw_halls(t, view, plan);
        draw_landmarks(t, view, plan);
        draw_billboards(t, view, plan);
        draw_lines_on_top(t, view, data, plan);
    };
    let mut pm = strips::draw(w, h, &layers, kept)?;
    draw_tile_grid(&mut pm, view, plan, tile_grid);
    draw_scale_bar(&mut pm, view);
    draw_legend(&mut pm, &colours, &Shown::of(data, plan, kura));
    encode_png(&pm)
}

impl Shown {
    /// The legend's rows for what the plan holds.
    fn of(data: &Dataset, plan: &Plan, kura: Option<bool>) -> Shown {
        let refused = |avoid| {
            (plan.houses.values().flatten())
                .any(|m| m.kura.rect().is_some() && m.kura.to_build(avoid).is_none())
        };
        let kura_rows = match kura {
            Some(avoid) => 1 + usize::from(refused(avoid)),
            None => 0,
        };
        Shown {
            footprints: !data.footprints.is_empty(),
            kura_rows,
            fences: plan.fences.values().any(|f| !f.is_empty()),
            halls: plan.halls.values().any(|h| !h.is_empty()),
            landmarks: plan.landmarks.values().any(|l| !l.is_empty()),
            billboards: plan.billboards.values().any(|b| !b.is_empty()),
        }
    }
}

/// Street bands as wide as the streets, and block outlines.
fn draw_streets(t: &mut Target, view: &View, data: &Dataset) {
    t.layer("streets");
    // One batch per band width (its f32 bits: a key that sorts and compares exactly).
    let mut bands: BTreeMap<u32, Batch> = BTreeMap::new();
    for street in &data.streets {
        let width = ((street.width * view.scale) as f32).max(1.0);
        bands
            .entry(width.to_bits())
            .or_insert_with(|| Batch::new(Draw::Stroke(paint([215, 212, 205], 255), wide(width))))
            .line(t, view, &street.line.0);
    }
    for batch in bands.into_values() {
        batch.finish(t);
    }
    let mut blocks = Batch::new(Draw::Stroke(paint([160, 160, 160], 255), thin()));
    for block in &data.blocks {
        blocks.polygon(t, view, block);
    }
    blocks.finish(t);
}

/// The colour of each lot drawn without a house (`None`: a house stands on it), in the
/// data's order, and of each house, in the plan's: decided once, not once a strip.
struct Fills {
    lots: Vec<Option<[u8; 3]>>,
    houses: Vec<[u8; 3]>,
}

impl Fills {
    fn of(data: &Dataset, plan: &Plan, colours: &BTreeMap<String, [u8; 3]>) -> Fills {
        let skipped: HashSet<&str> = plan.skipped.iter().map(|s| s.id.as_str()).collect();
        let displaced: HashSet<&str> = (plan.landmark_report.displaced.iter())
            .filter(|d| d.kind == "machiya")
            .map(|d| d.id.as_str())
            .collect();
        let planned: HashSet<&str> = (plan.houses.values().flatten())
            .filter(|m| !m.is_footprint())
            .map(|m| m.id.as_str())
            .collect();
        let lots = (data.lots.iter())
            .map(|lot| {
                let id = lot.id.as_str();
                (!planned.contains(id)).then(|| {
                    if displaced.contains(id) {
                        LANDMARK_LOT
                    } else if skipped.contains(id) {
                        SKIPPED
                    } else {
                        OTHER_USE
                    }
                })
            })
            .collect();
        let houses = (plan.houses.values().flatten())
            .map(|m| match m.footprint_height() {
                Some(_) => FOOTPRINT,
                None => colours.get(&m.mtype).copied().unwrap_or(TYPE_COLOURS[0]),
            })
            .collect();
        Fills { lots, houses }
    }
}

/// Lots without a house (other uses, given to a landmark, skipped ones), then every house by its type's colour.
fn draw_lots_and_houses(t: &mut Target, view: &View, data: &Dataset, plan: &Plan, fills: &Fills) {
    t.layer("lots_and_houses");
    let outlined = |colour: [u8; 3]| {
        Batch::new(Draw::FillOutlined(
            crisp(paint(colour, 255)),
            paint(OUTLINE, 255),
        ))
    };
    let mut lots: BTreeMap<[u8; 3], Batch> = BTreeMap::new();
    for (lot, fill) in data.lots.iter().zip(&fills.lots) {
        if let Some(fill) = *fill {
            lots.entry(fill)
                .or_insert_with(|| outlined(fill))
                .polygon(t, view, &lot.outline);
        }
    }
    for batch in lots.into_values() {
        batch.finish(t);
    }
    t.layer("houses");
    let mut houses: BTreeMap<[u8; 3], Batch> = BTreeMap::new();
    for (m, &colour) in plan.houses.values().flatten().zip(&fills.houses) {
        houses
            .entry(colour)
            .or_insert_with(|| outlined(colour))
            .polygon(t, view, &m.outline);
    }
    for batch in houses.into_values() {
        batch.finish(t);
    }
}

/// Kura filled where built, outlined where the avoidance (`avoid`) refused them.
fn draw_kura(t: &mut Target, view: &View, plan: &Plan, avoid: bool) {
    t.layer("kura");
    let mut built = Batch::new(Draw::Fill(crisp(paint(KURA, 255))));
    let mut refused = Batch::new(Draw::Stroke(paint(KURA_REFUSED, 255), wide(1.5)));
    for m in plan.houses.values().flatten() {
        let Some(r) = m.kura.rect() else { continue };
        let q = crate::geom::frame::Frame::along(m.frontage.a, m.frontage.u_axis()).quad(r);
        match m.kura.to_build(avoid) {
            Some(_) => built.ring(t, view, &q),
            None => refused.ring(t, view, &q),
        }
    }
    built.finish(t);
    refused.finish(t);
}

/// The halls' plots, filled.
fn draw_halls(t: &mut Target, view: &View, plan: &Plan) {
    t.layer("halls");
    let mut halls = Batch::new(Draw::Fill(crisp(paint(HALL, 255))));
    for h in plan.halls.values().flatten() {
        halls.ring(t, view, &h.outline());
    }
    halls.finish(t);
}

/// The landmarks' footprints, filled and outlined.
fn draw_landmarks(t: &mut Target, view: &View, plan: &Plan) {
    t.layer("landmarks");
    let draw = Draw::FillOutlined(crisp(paint(LANDMARK, 255)), paint([40, 20, 60], 255));
    let mut landmarks = Batch::new(draw);
    for l in plan.landmarks.values().flatten() {
        landmarks.polygon(t, view, &l.footprint);
    }
    landmarks.finish(t);
}

/// Walls and gates (section 4.3): a dark line along each wall segment, a red bar per gate
/// (gates over walls).
fn draw_fences(t: &mut Target, view: &View, plan: &Plan) {
    t.layer("fences");
    let mut walls = Batch::new(Draw::Stroke(paint(FENCE, 255), wide(2.0)));
    let mut gates = Batch::new(Draw::Stroke(paint(GATE, 255), wide(4.0)));
    for f in plan.fences.values().flatten() {
        match f.kind {
            crate::model::FenceKind::Wall => walls.line(t, view, &[f.a, f.b]),
            crate::model::FenceKind::Gate => gates.line(t, view, &[f.a, f.b]),
        }
    }
    walls.finish(t);
    gates.finish(t);
}

/// People and trees (section 4.4): a dot each, a tree's as wide as its crown (people over
/// trees).
fn draw_billboards(t: &mut Target, view: &View, plan: &Plan) {
    t.layer("billboards");
    // Dots stay anti-aliased: crisp, a small circle is a cross.
    let mut trees = Batch::new(Draw::Fill(paint(TREE, 220)));
    let mut people = Batch::new(Draw::Fill(paint(PERSON, 220)));
    for b in plan.billboards.values().flatten() {
        let (x, y) = view.pixel(&b.at);
        match b.kind {
            crate::model::BillboardKind::Tree => {
                let r = (b.height * 0.25 * view.scale) as f32;
                trees.circle(t, x, y, r.max(1.5));
            }
            crate::model::BillboardKind::Person => people.circle(t, x, y, 2.5),
        }
    }
    trees.finish(t);
    people.finish(t);
}

/// Street centrelines and each house's frontage, on top: in cadastral data the roads are
/// parcels too and would hide them.
fn draw_lines_on_top(t: &mut Target, view: &View, data: &Dataset, plan: &Plan) {
    t.layer("lines_on_top");
    let mut centrelines = Batch::new(Draw::Stroke(paint([60, 90, 140], 160), thin()));
    for street in &data.streets {
        centrelines.line(t, view, &street.line.0);
    }
    centrelines.finish(t);
    let mut frontages = Batch::new(Draw::Stroke(paint(FRONTAGE, 255), wide(2.5)));
    for m in plan.houses.values().flatten() {
        frontages.line(t, view, &[m.frontage.a, m.frontage.b]);
    }
    frontages.finish(t);
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

#[cfg(test)]
mod tests {
    use super::*;
    use geo_types::{coord, LineString, Polygon};

    fn square(x: f64, y: f64, side: f64, clockwise: bool) -> LineString<f64> {
        let mut pts = vec![
            coord! { x: x, y: y },
            coord! { x: x + side, y: y },
            coord! { x: x + side, y: y + side },
            coord! { x: x, y: y + side },
            coord! { x: x, y: y },
        ];
        if clockwise {
            pts.reverse();
        }
        LineString(pts)
    }

    fn red_at(pm: &Pixmap, x: u32, y: u32) -> bool {
        let p = pm.pixel(x, y).unwrap();
        (p.red(), p.green(), p.blue()) == (255, 0, 0)
    }

    /// One path for many polygons must draw what a path each drew: the union of polygons
    /// that overlap (whatever way the data winds them), and their holes left open.
    #[test]
    fn a_batch_fills_overlaps_and_keeps_holes() {
        let view = View {
            bounds: [0.0, 0.0, 100.0, 100.0],
            scale: 1.0,
        };
        let mut pm = Pixmap::new(100, 100).unwrap();
        let mut t = Target::Draw {
            pm: pm.as_mut(),
            top: 0,
        };
        let mut batch = Batch::new(Draw::Fill(paint([255, 0, 0], 255)));
        // Two squares overlapping in 40..60, wound opposite ways.
        batch.polygon(
            &mut t,
            &view,
            &Polygon::new(square(0.0, 0.0, 60.0, false), vec![]),
        );
        batch.polygon(
            &mut t,
            &view,
            &Polygon::new(square(40.0, 0.0, 60.0, true), vec![]),
        );
        // A square with a hole, the hole wound like its exterior (as careless data has it).
        let holed = Polygon::new(
            square(10.0, 70.0, 25.0, false),
            vec![square(17.0, 77.0, 10.0, false)],
        );
        batch.polygon(&mut t, &view, &holed);
        batch.finish(&mut t);
        // Map y up, pixel y down: map (x, y) is pixel (x, 100 - y).
        assert!(red_at(&pm, 50, 70), "the overlap is filled");
        assert!(
            red_at(&pm, 20, 70) && red_at(&pm, 80, 70),
            "both squares are filled"
        );
        assert!(!red_at(&pm, 22, 18), "the hole stays open");
        assert!(red_at(&pm, 12, 18), "around the hole is filled");
        assert!(!red_at(&pm, 50, 10), "outside every polygon is not");
    }

    /// Squares of side 10 m (pixels, at this view) at each of `at`, in one batch, and a
    /// circle over the first.
    fn layers(at: &[(f64, f64)]) -> impl Fn(&mut Target) + Sync + '_ {
        let view = View {
            bounds: [0.0, 0.0, 300.0, 600.0],
            scale: 1.0,
        };
        move |t: &mut Target| {
            t.layer("squares");
            let mut squares = Batch::new(Draw::Fill(paint([200, 40, 40], 255)));
            for &(x, y) in at {
                let ring = LineString(vec![
                    coord! { x: x, y: y },
                    coord! { x: x + 10.0, y: y },
                    coord! { x: x + 10.0, y: y + 10.0 },
                    coord! { x: x, y: y + 10.0 },
                    coord! { x: x, y: y },
                ]);
                squares.polygon(t, &view, &Polygon::new(ring, vec![]));
            }
            squares.finish(t);
            t.layer("dots");
            let mut dots = Batch::new(Draw::Fill(paint([20, 20, 120], 200)));
            let (x, y) = view.pixel(&coord! { x: at[0].0, y: at[0].1 });
            dots.circle(t, x, y, 7.0);
            dots.finish(t);
        }
    }

    /// A kept image with one shape moved is the image drawn afresh, byte for byte, and
    /// only the strips the shape left and entered have new keys.
    #[test]
    fn a_kept_image_redrawn_where_a_shape_moved_is_the_image_drawn_afresh() {
        let before = [(20.0, 580.0), (150.0, 300.0), (250.0, 20.0)];
        // The second square moves from rows ~290-300 (strip 2) to ~440-450 (strip 3).
        let after = [(20.0, 580.0), (150.0, 150.0), (250.0, 20.0)];
        let kept = Kept::default();
        strips::draw(300, 600, &layers(&before), Some(&kept)).unwrap();
        let again = strips::draw(300, 600, &layers(&after), Some(&kept)).unwrap();
        let afresh = strips::draw(300, 600, &layers(&after), None).unwrap();
        assert_eq!(again.data(), afresh.data());
        assert_eq!(
            kept.strips_kept(),
            600usize.div_ceil(STRIP_ROWS as usize) - 2
        );
        assert_ne!(
            again.data(),
            strips::draw(300, 600, &layers(&before), None)
                .unwrap()
                .data()
        );
        let n = 600u32.div_ceil(STRIP_ROWS);
        let (a, b) = (
            strips::strip_keys(n, &layers(&before)),
            strips::strip_keys(n, &layers(&after)),
        );
        let changed: Vec<usize> = (0..a.len()).filter(|&s| a[s] != b[s]).collect();
        assert_eq!(changed, vec![2, 3]);
    }

    #[test]
    fn an_image_of_another_size_is_drawn_whole() {
        let at = [(20.0, 580.0), (150.0, 300.0)];
        let kept = Kept::default();
        strips::draw(300, 600, &layers(&at), Some(&kept)).unwrap();
        let smaller = strips::draw(300, 590, &layers(&at), Some(&kept)).unwrap();
        assert_eq!(
            smaller.data(),
            strips::draw(300, 590, &layers(&at), None).unwrap().data()
        );
    }
}
