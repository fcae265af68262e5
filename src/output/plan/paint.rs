//! The plan's drawing primitives: paints and strokes, map lines and rings as paths, and a
//! batch that fills and outlines many shapes of one look in one path (tiny-skia draws a path
//! of thousands of lots as fast as one).

use geo_types::{Coord, Polygon};
use tiny_skia::{FillRule, Paint, PathBuilder, PixmapMut, Stroke, Transform};

use super::strips::Target;
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
    pub(super) fn path(&self, pm: &mut PixmapMut, path: &tiny_skia::Path) {
        let at = Transform::identity();
        match self {
            Draw::Fill(paint) => pm.fill_path(path, paint, FillRule::Winding, at, None),
            Draw::Stroke(paint, stroke) => pm.stroke_path(path, paint, stroke, at, None),
            Draw::FillOutlined(fill, outline) => {
                pm.fill_path(path, fill, FillRule::Winding, at, None);
                pm.stroke_path(path, outline, &thin(), at, None);
            }
        }
    }

    /// Pixels a shape's ink may reach past its points: half a stroke, its joins' mitres
    /// (at most twice the width with tiny-skia's default limit of 4) and anti-aliasing.
    fn reach(&self) -> f32 {
        match self {
            Draw::Stroke(_, stroke) => 2.0 * stroke.width + 2.0,
            Draw::Fill(_) | Draw::FillOutlined(..) => 2.0,
        }
    }

    /// What the pixels of its shapes depend on besides their points: colours, anti-aliasing,
    /// widths (a strip's key, [`super::strips`]).
    fn look(&self) -> Vec<u8> {
        let mut look = Vec::with_capacity(48);
        let mut paint = |p: &Paint| {
            if let tiny_skia::Shader::SolidColor(c) = &p.shader {
                for v in [c.red(), c.green(), c.blue(), c.alpha()] {
                    look.extend(v.to_le_bytes());
                }
            }
            look.push(p.anti_alias as u8);
        };
        match self {
            Draw::Fill(p) => paint(p),
            Draw::Stroke(p, stroke) => {
                paint(p);
                look.extend(stroke.width.to_le_bytes());
            }
            Draw::FillOutlined(f, o) => {
                paint(f);
                paint(o);
            }
        }
        look
    }
}

/// Shapes of one paint gathered into few paths, each drawn by one call. tiny-skia's cost is
/// per call and per span of pixels, and side by side lots of one colour share their spans:
/// a path per lot made the plan a third of a 30,052-lot build's CPU. A path holds at most
/// [`Batch::SHAPES`] shapes and is drawn as soon as it is full, because tiny-skia builds
/// every edge of a path before it draws, and a million lots' paths held at once would be
/// hundreds of megabytes.
///
/// Each shape is offered to the [`Target`] first, which takes the ones that cross its
/// strip of the image (or only hashes them, for the strips' keys).
pub(super) struct Batch {
    draw: Draw,
    look: Vec<u8>,
    reach: f32,
    open: PathBuilder,
    shapes: usize,
    /// The shape being added, in pixels, and where each of its rings ends.
    points: Vec<(f32, f32)>,
    rings: Vec<usize>,
}

impl Batch {
    /// Shapes per path.
    const SHAPES: usize = 1024;

    pub(super) fn new(draw: Draw) -> Batch {
        Batch {
            look: draw.look(),
            reach: draw.reach(),
            draw,
            open: PathBuilder::new(),
            shapes: 0,
            points: Vec::new(),
            rings: Vec::new(),
        }
    }

    /// A polygon's rings, the exterior counter-clockwise on screen and the holes clockwise,
    /// so the nonzero rule fills the union of overlapping polygons and keeps their holes
    /// (even-odd would punch a hole where two lots of the data overlap).
    pub(super) fn polygon(&mut self, t: &mut Target, view: &View, poly: &Polygon<f64>) {
        let rings = || std::iter::once(poly.exterior()).chain(poly.interiors());
        let rows = self.rows(view, rings().flat_map(|r| r.0.iter()));
        if t.wants(rows) {
            self.push_ring(view, &poly.exterior().0, true);
            for hole in poly.interiors() {
                self.push_ring(view, &hole.0, false);
            }
            self.offer(t, Shape::Rings, rows);
        }
    }

    /// A closed ring (a shape of its own), counter-clockwise on screen.
    pub(super) fn ring(&mut self, t: &mut Target, view: &View, pts: &[Coord<f64>]) {
        let rows = self.rows(view, pts.iter());
        if t.wants(rows) {
            self.push_ring(view, pts, true);
            self.offer(t, Shape::Rings, rows);
        }
    }

    /// The rows of pixels a shape's ink may reach: its points' topmost and bottommost rows,
    /// found from their map coordinates (the pixel row falls as north rises, exactly: the
    /// conversion is monotonic), so a shape away from a strip costs no conversion.
    fn rows<'c>(&self, view: &View, pts: impl Iterator<Item = &'c Coord<f64>>) -> (f32, f32) {
        let (south, north) = pts.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
            (lo.min(c.y), hi.max(c.y))
        });
        let at = |y| view.pixel(&Coord { x: 0.0, y }).1;
        (at(north) - self.reach, at(south) + self.reach)
    }

    /// A closed ring, turned to `outer`'s orientation. The turn is read from the map
    /// coordinates (north up: clockwise there is counter-clockwise on screen), so no copy of
    /// the ring is made.
    fn push_ring(&mut self, view: &View, pts: &[Coord<f64>], outer: bool) {
        let twice_area: f64 = pts
            .iter()
            .zip(pts.iter().cycle().skip(1))
            .map(|(a, b)| a.x * b.y - b.x * a.y)
            .sum();
        if (twice_area < 0.0) == outer {
            self.points.extend(pts.iter().rev().map(|c| view.pixel(c)));
        } else {
            self.points.extend(pts.iter().map(|c| view.pixel(c)));
        }
        self.rings.push(self.points.len());
    }

    /// An open polyline.
    pub(super) fn line(&mut self, t: &mut Target, view: &View, pts: &[Coord<f64>]) {
        let rows = self.rows(view, pts.iter());
        if t.wants(rows) {
            self.points.extend(pts.iter().map(|c| view.pixel(c)));
            self.offer(t, Shape::Line, rows);
        }
    }

    pub(super) fn circle(&mut self, t: &mut Target, x: f32, y: f32, r: f32) {
        let rows = (y - r - self.reach, y + r + self.reach);
        if t.wants(rows) {
            self.points.extend([(x, y), (r, r)]);
            self.offer(t, Shape::Circle, rows);
        }
    }

    /// Hands the shape in `points` to the target, and adds it to the open path, moved to
    /// the target's strip, when the target draws it.
    fn offer(&mut self, t: &mut Target, shape: Shape, rows: (f32, f32)) {
        if let Some(top) = t.take(rows, &self.look, shape as u8, &self.points) {
            self.push(shape, top);
            self.shapes += 1;
            if self.shapes.is_multiple_of(Self::SHAPES) {
                self.draw_open(t);
            }
        }
        self.points.clear();
        self.rings.clear();
    }

    /// The shape in `points` added to the open path, `top` rows up.
    fn push(&mut self, shape: Shape, top: f32) {
        let pb = &mut self.open;
        match shape {
            Shape::Circle => {
                let ((x, y), (r, _)) = (self.points[0], self.points[1]);
                pb.push_circle(x, y - top, r);
            }
            Shape::Line => push_points(pb, &self.points, top, false),
            Shape::Rings => {
                let mut start = 0;
                for &end in &self.rings {
                    push_points(pb, &self.points[start..end], top, true);
                    start = end;
                }
            }
        }
    }

    fn draw_open(&mut self, t: &mut Target) {
        if let Some(path) = std::mem::take(&mut self.open).finish() {
            if let Some(pm) = t.pixmap() {
                self.draw.path(pm, &path);
            }
        }
    }

    /// Draws what is left.
    pub(super) fn finish(mut self, t: &mut Target) {
        self.draw_open(t);
    }
}

/// What the points of a shape in a [`Batch`] make.
#[derive(Clone, Copy)]
enum Shape {
    /// Closed rings, each ending where `Batch::rings` says.
    Rings,
    /// An open polyline.
    Line,
    /// A circle: its centre, then its radius twice.
    Circle,
}

/// A path through `pts`, `top` rows up, closed or not.
fn push_points(pb: &mut PathBuilder, pts: &[(f32, f32)], top: f32, closed: bool) {
    let Some(&(x, y)) = pts.first() else { return };
    pb.move_to(x, y - top);
    for &(x, y) in &pts[1..] {
        pb.line_to(x, y - top);
    }
    if closed {
        pb.close();
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
