//! The plan's drawing primitives: paints and strokes, map lines and rings as paths, and a
//! batch that fills and outlines many shapes of one look in one path (tiny-skia draws a path
//! of thousands of lots as fast as one).

use geo_types::{Coord, Polygon};
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

use super::View;

pub(super) fn paint(rgb: [u8; 3], a: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb[0], rgb[1], rgb[2], a);
    p
}

pub(super) fn line_path(view: &View, pts: &[Coord<f64>]) -> Option<tiny_skia::Path> {
    let mut pb = PathBuilder::new();
    push_line(&mut pb, view, pts);
    pb.finish()
}

/// An open polyline.
pub(super) fn push_line(pb: &mut PathBuilder, view: &View, pts: &[Coord<f64>]) {
    for (i, c) in pts.iter().enumerate() {
        let (x, y) = view.pixel(c);
        if i == 0 {
            pb.move_to(x, y)
        } else {
            pb.line_to(x, y)
        }
    }
}

/// A closed ring through `pts`, in their order.
pub(super) fn push_closed<'a>(
    pb: &mut PathBuilder,
    view: &View,
    mut pts: impl Iterator<Item = &'a Coord<f64>>,
) {
    if let Some(first) = pts.next() {
        let (x, y) = view.pixel(first);
        pb.move_to(x, y);
        for c in pts {
            let (x, y) = view.pixel(c);
            pb.line_to(x, y);
        }
        pb.close();
    }
}

/// What a [`Batch`] does with each of its paths.
pub(super) enum Draw {
    /// Fills it (nonzero rule).
    Fill(Paint<'static>),
    /// Strokes it.
    Stroke(Paint<'static>, Stroke),
    /// Fills it, then outlines it with a hairline of the second paint. The fill is meant
    /// [`crisp`]: the outline smooths its edges, and anti-aliasing the fills of 30,000 lots
    /// took as long as everything else in the plan.
    FillOutlined(Paint<'static>, Paint<'static>),
}

impl Draw {
    pub(super) fn path(&self, pm: &mut Pixmap, path: &tiny_skia::Path) {
        let id = Transform::identity();
        match self {
            Draw::Fill(paint) => pm.fill_path(path, paint, FillRule::Winding, id, None),
            Draw::Stroke(paint, stroke) => pm.stroke_path(path, paint, stroke, id, None),
            Draw::FillOutlined(fill, outline) => {
                pm.fill_path(path, fill, FillRule::Winding, id, None);
                pm.stroke_path(path, outline, &thin(), id, None);
            }
        }
    }
}

/// Shapes of one paint gathered into few paths, each drawn by one call. tiny-skia's cost is
/// per call and per span of pixels, and side by side lots of one colour share their spans:
/// a path per lot made the plan a third of a 30,052-lot build's CPU. A path holds at most
/// [`Batch::SHAPES`] shapes and is drawn as soon as it is full, because tiny-skia builds
/// every edge of a path before it draws, and a million lots' paths held at once would be
/// hundreds of megabytes.
pub(super) struct Batch {
    draw: Draw,
    open: PathBuilder,
    shapes: usize,
}

impl Batch {
    /// Shapes per path.
    const SHAPES: usize = 1024;

    pub(super) fn new(draw: Draw) -> Batch {
        Batch {
            draw,
            open: PathBuilder::new(),
            shapes: 0,
        }
    }

    /// A polygon's rings, the exterior counter-clockwise on screen and the holes clockwise,
    /// so the nonzero rule fills the union of overlapping polygons and keeps their holes
    /// (even-odd would punch a hole where two lots of the data overlap).
    pub(super) fn polygon(&mut self, pm: &mut Pixmap, view: &View, poly: &Polygon<f64>) {
        self.push_ring(view, &poly.exterior().0, true);
        for hole in poly.interiors() {
            self.push_ring(view, &hole.0, false);
        }
        self.shape_done(pm);
    }

    /// A closed ring (a shape of its own), counter-clockwise on screen.
    pub(super) fn ring(&mut self, pm: &mut Pixmap, view: &View, pts: &[Coord<f64>]) {
        self.push_ring(view, pts, true);
        self.shape_done(pm);
    }

    /// A closed ring, turned to `outer`'s orientation. The turn is read from the map
    /// coordinates (north up: clockwise there is counter-clockwise on screen), so no copy of
    /// the ring is made.
    pub(super) fn push_ring(&mut self, view: &View, pts: &[Coord<f64>], outer: bool) {
        let twice_area: f64 = pts
            .iter()
            .zip(pts.iter().cycle().skip(1))
            .map(|(a, b)| a.x * b.y - b.x * a.y)
            .sum();
        if (twice_area < 0.0) == outer {
            push_closed(&mut self.open, view, pts.iter().rev());
        } else {
            push_closed(&mut self.open, view, pts.iter());
        }
    }

    /// An open polyline.
    pub(super) fn line(&mut self, pm: &mut Pixmap, view: &View, pts: &[Coord<f64>]) {
        push_line(&mut self.open, view, pts);
        self.shape_done(pm);
    }

    pub(super) fn circle(&mut self, pm: &mut Pixmap, x: f32, y: f32, r: f32) {
        self.open.push_circle(x, y, r);
        self.shape_done(pm);
    }

    pub(super) fn shape_done(&mut self, pm: &mut Pixmap) {
        self.shapes += 1;
        if self.shapes.is_multiple_of(Self::SHAPES) {
            self.draw_open(pm);
        }
    }

    pub(super) fn draw_open(&mut self, pm: &mut Pixmap) {
        if let Some(path) = std::mem::take(&mut self.open).finish() {
            self.draw.path(pm, &path);
        }
    }

    /// Draws what is left; whether anything was added.
    pub(super) fn finish(mut self, pm: &mut Pixmap) -> bool {
        self.draw_open(pm);
        self.shapes > 0
    }
}

/// Outlines of lots, houses and blocks.
pub(super) const OUTLINE: [u8; 3] = [90, 80, 70];

/// A stroke `width` pixels wide.
pub(super) fn wide(width: f32) -> Stroke {
    Stroke {
        width,
        ..Stroke::default()
    }
}

/// The paint without anti-aliasing: for shapes whose edges are outlined anyway, and small
/// squares that stay squares.
pub(super) fn crisp(mut paint: Paint<'static>) -> Paint<'static> {
    paint.anti_alias = false;
    paint
}

/// A hairline: one pixel wide at any scale, drawn by tiny-skia's line rasteriser instead of
/// being stroked into a polygon (a third of the plan's time when every outline was one).
pub(super) fn thin() -> Stroke {
    Stroke {
        width: 0.0,
        ..Stroke::default()
    }
}
