//! A small software renderer: meshes drawn orthographically from the south (x east to the
//! right, up up) or from above, textured, alpha-tested at 0.5, with a depth buffer and
//! Lambert shading. It renders the tree billboard textures from the species themselves (so
//! a billboard is a picture of the same tree) and the pictures of `edo-city tree --png`;
//! deterministic to the byte, with no GPU or display.

use image::{Rgba, RgbaImage};

use crate::generate::mesh::Mesh;
use crate::materials::MATERIALS;

/// Where the camera looks from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// From the south, level: x to the right, height up.
    South,
    /// From above: x to the right, north up.
    Top,
}

/// The window of the view in metres: (left, right, bottom, top) in the view's axes.
pub type Window = [f64; 4];

/// Renders `meshes` into a `width` x `height` RGBA image (transparent where nothing is
/// drawn). `texture` gives a material's texture image by file name; materials without one
/// are drawn in their colour.
pub fn render(
    meshes: &[Mesh],
    view: View,
    window: Window,
    (width, height): (u32, u32),
    texture: &dyn Fn(&str) -> Option<RgbaImage>,
) -> RgbaImage {
    let mut img = RgbaImage::from_pixel(width, height, Rgba([0, 0, 0, 0]));
    let mut depth = vec![f64::NEG_INFINITY; (width * height) as usize];
    let mut cache: Vec<Option<Option<RgbaImage>>> = vec![None; MATERIALS.len()];
    let [l, r, b, t] = window;
    let (sx, sy) = (f64::from(width) / (r - l), f64::from(height) / (t - b));
    // Output frame, millimetres: x east, y up, z south.
    let project = |p: [i64; 3]| -> [f64; 3] {
        let (x, y, z) = (
            p[0] as f64 / 1000.0,
            p[1] as f64 / 1000.0,
            p[2] as f64 / 1000.0,
        );
        match view {
            View::South => [(x - l) * sx, (t - y) * sy, z],
            View::Top => [(x - l) * sx, (t + z) * sy, y],
        }
    };
    let light = unit([0.4, 0.8, 0.45]);
    for mesh in meshes {
        for f in &mesh.faces {
            let m = f.material as usize;
            let tex = cache[m]
                .get_or_insert_with(|| MATERIALS[m].texture.and_then(texture))
                .as_ref();
            let corners: Vec<([f64; 3], [f64; 2], [f64; 3])> = f
                .corners
                .iter()
                .map(|&(v, uv)| {
                    let p = mesh.positions[v as usize];
                    let w = [p[0] as f64, p[1] as f64, p[2] as f64];
                    let t = mesh.uvs[uv as usize];
                    (
                        project(p),
                        [f64::from(t[0]) / 1e4, f64::from(t[1]) / 1e4],
                        w,
                    )
                })
                .collect();
            let normal = unit(cross(
                sub(corners[1].2, corners[0].2),
                sub(corners[2].2, corners[0].2),
            ));
            // Leaves and billboards are seen from both sides: light them on either.
            let shade = 0.55 + 0.45 * dot(normal, light).abs();
            for k in 1..corners.len() - 1 {
                let tri = [corners[0], corners[k], corners[k + 1]];
                fill(&mut img, &mut depth, tri, shade, tex, MATERIALS[m].kd);
            }
        }
    }
    img
}

type Corner = ([f64; 3], [f64; 2], [f64; 3]);

fn fill(
    img: &mut RgbaImage,
    depth: &mut [f64],
    tri: [Corner; 3],
    shade: f64,
    tex: Option<&RgbaImage>,
    kd: [f32; 3],
) {
    let (w, h) = (img.width() as i64, img.height() as i64);
    let [a, b, c] = tri.map(|t| t.0);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area.abs() < 1e-12 {
        return;
    }
    let x0 = a[0].min(b[0]).min(c[0]).floor().max(0.0) as i64;
    let x1 = (a[0].max(b[0]).max(c[0]).ceil() as i64).min(w - 1);
    let y0 = a[1].min(b[1]).min(c[1]).floor().max(0.0) as i64;
    let y1 = (a[1].max(b[1]).max(c[1]).ceil() as i64).min(h - 1);
    for py in y0..=y1 {
        for px in x0..=x1 {
            let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
            let wa = ((b[0] - x) * (c[1] - y) - (b[1] - y) * (c[0] - x)) / area;
            let wb = ((c[0] - x) * (a[1] - y) - (c[1] - y) * (a[0] - x)) / area;
            let wc = 1.0 - wa - wb;
            if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                continue;
            }
            let z = wa * a[2] + wb * b[2] + wc * c[2];
            let i = (py * w + px) as usize;
            if z <= depth[i] {
                continue;
            }
            let rgba = match tex {
                Some(t) => {
                    let u = wa * tri[0].1[0] + wb * tri[1].1[0] + wc * tri[2].1[0];
                    let v = wa * tri[0].1[1] + wb * tri[1].1[1] + wc * tri[2].1[1];
                    let tx = ((u.rem_euclid(1.0) * f64::from(t.width())) as u32).min(t.width() - 1);
                    let ty = (((1.0 - v.rem_euclid(1.0)) * f64::from(t.height())) as u32)
                        .min(t.height() - 1);
                    t.get_pixel(tx, ty).0
                }
                None => [
                    (kd[0] * 255.0) as u8,
                    (kd[1] * 255.0) as u8,
                    (kd[2] * 255.0) as u8,
                    255,
                ],
            };
            if rgba[3] < 128 {
                continue;
            }
            depth[i] = z;
            let s = |v: u8| (f64::from(v) * shade).round().clamp(0.0, 255.0) as u8;
            img.put_pixel(
                px as u32,
                py as u32,
                Rgba([s(rgba[0]), s(rgba[1]), s(rgba[2]), 255]),
            );
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// `img` over a pale sky fading to the ground colour at the bottom, as PNG bytes (for the
/// pictures in docs/).
pub fn on_sky(img: &RgbaImage) -> Vec<u8> {
    let h = img.height().max(1) as f32;
    let mut out = image::RgbImage::new(img.width(), img.height());
    for (x, y, p) in img.enumerate_pixels() {
        let t = y as f32 / h;
        let sky = [
            (200.0 + 30.0 * t) as u8,
            (220.0 + 10.0 * t) as u8,
            (240.0 - 20.0 * t) as u8,
        ];
        let a = f32::from(p.0[3]) / 255.0;
        let mix = |k: usize| (f32::from(p.0[k]) * a + f32::from(sky[k]) * (1.0 - a)).round() as u8;
        out.put_pixel(x, y, image::Rgb([mix(0), mix(1), mix(2)]));
    }
    let mut bytes = Vec::new();
    out.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .expect("encoding a PNG in memory does not fail");
    bytes
}

/// A contact sheet: `cells` (label, picture; all the same size) in rows of `columns` on a pale
/// sky, each labelled below, as PNG bytes.
pub fn sheet(cells: &[(String, RgbaImage)], columns: usize) -> Option<Vec<u8>> {
    let (w, h) = cells.first().map(|c| c.1.dimensions())?;
    let label = 24u32;
    let columns = columns.max(1);
    let rows = cells.len().div_ceil(columns);
    let mut pm = tiny_skia::Pixmap::new(w * columns as u32, (h + label) * rows as u32)?;
    pm.fill(tiny_skia::Color::from_rgba8(236, 240, 244, 255));
    let width = pm.width();
    for (k, (name, img)) in cells.iter().enumerate() {
        let (x0, y0) = ((k % columns) as u32 * w, (k / columns) as u32 * (h + label));
        let data = pm.data_mut();
        for (x, y, p) in img.enumerate_pixels() {
            let t = y as f32 / h as f32;
            let sky = [200.0 + 30.0 * t, 220.0 + 10.0 * t, 240.0 - 20.0 * t];
            let a = f32::from(p.0[3]) / 255.0;
            let i = (((y0 + y) * width + x0 + x) * 4) as usize;
            for c in 0..3 {
                data[i + c] = (f32::from(p.0[c]) * a + sky[c] * (1.0 - a)).round() as u8;
            }
            data[i + 3] = 255;
        }
        let tx = x0 as f32 + (w.saturating_sub(super::text::text_width(name, 2)) / 2) as f32;
        super::text::draw_text(&mut pm, tx, (y0 + h + 4) as f32, name, 2, [40, 40, 40]);
    }
    pm.encode_png().ok()
}

/// The shipped texture of a material file name, decoded.
pub fn shipped_texture(name: &str) -> Option<RgbaImage> {
    let bytes = crate::materials::TEXTURES
        .iter()
        .find(|(n, _)| *n == name)?
        .1;
    image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .ok()
        .map(|i| i.to_rgba8())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::mesh::Frame;
    use geo_types::Coord;

    #[test]
    fn a_square_facing_south_fills_its_window_and_nothing_else() {
        let mut m = Mesh::new("q".into());
        let f = Frame { origin: [0.0, 0.0] };
        // A wall in the x-up plane, seen from the south.
        let q = [
            m.vertex(f, Coord { x: 0.0, y: 0.0 }, 0.0),
            m.vertex(f, Coord { x: 1.0, y: 0.0 }, 0.0),
            m.vertex(f, Coord { x: 1.0, y: 0.0 }, 1.0),
            m.vertex(f, Coord { x: 0.0, y: 0.0 }, 1.0),
        ];
        let uv = m.uv(0.0, 0.0);
        m.face(
            crate::materials::id("floor"),
            q.iter().map(|&v| (v, uv)).collect(),
        );
        let img = render(&[m], View::South, [-1.0, 2.0, -1.0, 2.0], (30, 30), &|_| {
            None
        });
        let drawn = img.pixels().filter(|p| p.0[3] == 255).count();
        assert_eq!(drawn, 100);
        assert_eq!(img.get_pixel(15, 15).0[3], 255);
        assert_eq!(img.get_pixel(5, 5).0[3], 0);
    }
}
