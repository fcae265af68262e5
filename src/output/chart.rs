//! Line charts of time series (the crowd's order parameters over the steps, as the seed's
//! fig. 8 draws them), and the snapshot of a crowd as SVG.

use tiny_skia::{Color, Paint, PathBuilder, Pixmap, Stroke, Transform};

use super::text::draw_text;
use crate::growers::boids::Boid;

/// One line of a chart.
pub struct Series<'a> {
    /// Its name in the legend.
    pub label: &'a str,
    /// Its colour.
    pub rgb: [u8; 3],
    /// Dashed (the random system's lines, as in the seed's figure).
    pub dashed: bool,
    /// A value per step.
    pub values: &'a [f64],
}

/// A chart of `series` against the step, values from `lo` to `hi`, as PNG bytes.
pub fn line_chart(title: &str, series: &[Series], lo: f64, hi: f64) -> Option<Vec<u8>> {
    let (w, h) = (960u32, 480u32);
    let (left, right, top, bottom) = (60.0f32, 150.0f32, 40.0f32, 40.0f32);
    let mut pm = Pixmap::new(w, h)?;
    pm.fill(Color::from_rgba8(250, 248, 242, 255));
    let (pw, ph) = (w as f32 - left - right, h as f32 - top - bottom);
    let steps = series
        .iter()
        .map(|s| s.values.len())
        .max()
        .unwrap_or(0)
        .max(2);
    let x = |i: usize| left + pw * i as f32 / (steps - 1) as f32;
    let y = |v: f64| top + ph * (1.0 - ((v - lo) / (hi - lo)).clamp(0.0, 1.0) as f32);
    let id = Transform::identity();
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    // Axes and grid lines at every 0.25.
    let mut v = lo;
    while v <= hi + 1e-9 {
        let mut pb = PathBuilder::new();
        pb.move_to(left, y(v));
        pb.line_to(left + pw, y(v));
        if let Some(path) = pb.finish() {
            paint.set_color_rgba8(210, 205, 195, 255);
            pm.stroke_path(&path, &paint, &Stroke::default(), id, None);
        }
        draw_text(
            &mut pm,
            8.0,
            y(v) - 4.0,
            &format!("{v:.2}"),
            1,
            [60, 60, 60],
        );
        v += 0.25;
    }
    draw_text(&mut pm, left, 12.0, title, 2, [30, 30, 30]);
    draw_text(
        &mut pm,
        left + pw - 40.0,
        h as f32 - 24.0,
        &format!("{} steps", steps - 1),
        1,
        [60, 60, 60],
    );
    for (k, s) in series.iter().enumerate() {
        let mut pb = PathBuilder::new();
        for (i, v) in s.values.iter().enumerate() {
            if i == 0 {
                pb.move_to(x(i), y(*v));
            } else {
                pb.line_to(x(i), y(*v));
            }
        }
        let stroke = Stroke {
            width: 1.5,
            dash: s
                .dashed
                .then(|| tiny_skia::StrokeDash::new(vec![6.0, 4.0], 0.0))
                .flatten(),
            ..Stroke::default()
        };
        paint.set_color_rgba8(s.rgb[0], s.rgb[1], s.rgb[2], 255);
        if let Some(path) = pb.finish() {
            pm.stroke_path(&path, &paint, &stroke, id, None);
        }
        let ly = top + 16.0 * k as f32;
        let mut pb = PathBuilder::new();
        pb.move_to(left + pw + 12.0, ly + 4.0);
        pb.line_to(left + pw + 36.0, ly + 4.0);
        if let Some(path) = pb.finish() {
            pm.stroke_path(&path, &paint, &stroke, id, None);
        }
        draw_text(&mut pm, left + pw + 42.0, ly, s.label, 1, [30, 30, 30]);
    }
    super::plan::encode_png(&pm)
}

/// The crowd at one moment as SVG: the space, each agent a dot with its heading, and the
/// separation and alignment zones (r0, r1) around the first agent.
pub fn flock_svg(boids: &[Boid], width: f64, height: f64, r0: f64, r1: f64) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {width} {height}\" \
         width=\"{width}\" height=\"{height}\">"
    );
    let _ = writeln!(
        s,
        "<rect width=\"{width}\" height=\"{height}\" fill=\"#faf8f2\" stroke=\"#999\"/>"
    );
    if let Some(b) = boids.first() {
        for (r, colour) in [(r1, "#c8d8f0"), (r0, "#f0c8c8")] {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"{r}\" fill=\"none\" stroke=\"{colour}\"/>",
                b.pos[0],
                height - b.pos[1]
            );
        }
    }
    for b in boids {
        // y up in the model, down in SVG.
        let (x, y) = (b.pos[0], height - b.pos[1]);
        let (hx, hy) = (x + 8.0 * b.heading[0], y - 8.0 * b.heading[1]);
        let _ = writeln!(
            s,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"3\" fill=\"#1e2878\"/>\
             <line x1=\"{x:.2}\" y1=\"{y:.2}\" x2=\"{hx:.2}\" y2=\"{hy:.2}\" stroke=\"#1e2878\"/>"
        );
    }
    s.push_str("</svg>\n");
    s
}
