//! Draws the texture library in `textures/` (run `make textures`; the PNGs are committed).
//!
//! The paper cut its textures from the Rakuchu-rakugai-zu screen and photographs; we have no
//! such images under a free licence, so these are drawn from the elements of a Kyoto machiya
//! facade: the wooden lattice (koshi 格子), the beam under the pent roof, plaster walls
//! (shikkui 漆喰) with insect-cage windows (mushiko-mado 虫籠窓), roof tiles (kawara 瓦).
//! A facade texture spans one repeat along the street (1 ken) and the full facade height,
//! bottom to top; the band heights follow the type files in templates/machiya/.

use image::{Rgba, RgbaImage};

type Px = [u8; 3];

const LATTICE_BG: Px = [44, 30, 20];
const LATTICE_SLAT: Px = [128, 84, 48];
const BEAM: Px = [70, 46, 28];
const PLASTER: Px = [228, 222, 206];
const MUSHIKO_BG: Px = [40, 34, 30];
const STONE: Px = [96, 92, 86];

/// Cheap deterministic noise in [-1, 1].
fn noise(x: u32, y: u32, salt: u32) -> f32 {
    let mut h = x
        .wrapping_mul(374_761_393)
        .wrapping_add(y.wrapping_mul(668_265_263))
        .wrapping_add(salt.wrapping_mul(2_147_483_647));
    h = (h ^ (h >> 13)).wrapping_mul(1_274_126_177);
    h ^= h >> 16;
    (h & 0xffff) as f32 / 32_767.5 - 1.0
}

fn shade(c: Px, amount: f32) -> Rgba<u8> {
    let f = |v: u8| ((v as f32) * (1.0 + amount)).clamp(0.0, 255.0) as u8;
    Rgba([f(c[0]), f(c[1]), f(c[2]), 255])
}

struct Canvas {
    img: RgbaImage,
}

impl Canvas {
    fn new(w: u32, h: u32) -> Canvas {
        Canvas {
            img: RgbaImage::new(w, h),
        }
    }
    fn w(&self) -> u32 {
        self.img.width()
    }
    fn h(&self) -> u32 {
        self.img.height()
    }
    /// Fills the band between heights `v0` and `v1` (0 = bottom, 1 = top) with `f(x, y)`.
    fn band(&mut self, v0: f32, v1: f32, f: impl Fn(u32, u32) -> Rgba<u8>) {
        let h = self.h() as f32;
        let (y0, y1) = (((1.0 - v1) * h) as u32, ((1.0 - v0) * h) as u32);
        for y in y0..y1.min(self.h()) {
            for x in 0..self.w() {
                self.img.put_pixel(x, y, f(x, y));
            }
        }
    }
    fn save(&self, name: &str) {
        let path = format!("textures/{name}");
        self.img
            .save(&path)
            .unwrap_or_else(|e| panic!("{path}: {e}"));
        println!("wrote {path}");
    }
}

/// Vertical lattice slats: `period` pixels per slat, `slat` of them wood.
fn lattice(period: u32, slat: u32) -> impl Fn(u32, u32) -> Rgba<u8> {
    move |x, y| {
        let n = noise(x, y, 1) * 0.08;
        if x % period < slat {
            shade(LATTICE_SLAT, n - if x % period == 0 { 0.2 } else { 0.0 })
        } else {
            shade(LATTICE_BG, n)
        }
    }
}

fn plaster(x: u32, y: u32) -> Rgba<u8> {
    shade(
        PLASTER,
        noise(x, y, 2) * 0.03 + noise(x / 8, y / 8, 3) * 0.02,
    )
}

fn beam(x: u32, y: u32) -> Rgba<u8> {
    shade(BEAM, noise(x, y / 3, 4) * 0.1)
}

/// Plaster with a mushiko-mado window between horizontal fractions `a` and `b` of the width.
fn mushiko(w: u32, a: f32, b: f32) -> impl Fn(u32, u32) -> Rgba<u8> {
    move |x, y| {
        let fx = x as f32 / w as f32;
        if fx > a && fx < b {
            if (x / 5) % 2 == 0 {
                shade(PLASTER, noise(x, y, 5) * 0.04 - 0.05)
            } else {
                shade(MUSHIKO_BG, noise(x, y, 6) * 0.1)
            }
        } else {
            plaster(x, y)
        }
    }
}

/// A whole facade: base stones, lattice, beam, then the upper part.
fn facade(
    name: &str,
    h: u32,
    lattice_top: f32,
    slats: (u32, u32),
    upper: &dyn Fn(&mut Canvas, f32),
) {
    let mut c = Canvas::new(128, h);
    let beam_top = lattice_top + 0.05;
    c.band(0.0, 1.0, plaster);
    c.band(0.0, 0.03, |x, y| shade(STONE, noise(x, y, 7) * 0.1));
    c.band(0.03, lattice_top, lattice(slats.0, slats.1));
    c.band(lattice_top, beam_top, beam);
    upper(&mut c, beam_top);
    c.save(name);
}

fn main() {
    // hiraya: eave 3.4 m, pent roof 2.7 m.
    facade("facade_hiraya.png", 256, 0.76, (8, 4), &|c, top| {
        c.band(top, 1.0, plaster);
        c.band(0.96, 1.0, beam);
    });
    // naka-nikai: low second storey with a mushiko-mado.
    facade("facade_nakanikai.png", 320, 0.57, (8, 4), &|c, top| {
        let w = c.w();
        c.band(top, 1.0, plaster);
        c.band(top + 0.12, 0.9, mushiko(w, 0.12, 0.88));
        c.band(0.96, 1.0, beam);
    });
    // sou-nikai: full second storey with a wooden lattice window.
    facade("facade_sounikai.png", 384, 0.46, (8, 4), &|c, top| {
        c.band(top, 1.0, plaster);
        c.band(top + 0.1, 0.88, lattice(6, 3));
        c.band(0.96, 1.0, beam);
    });
    // sangai: two upper storeys.
    facade("facade_sangai.png", 512, 0.32, (8, 4), &|c, top| {
        c.band(top, 1.0, plaster);
        c.band(top + 0.08, 0.6, lattice(6, 3));
        c.band(0.64, 0.68, beam);
        c.band(0.72, 0.92, lattice(6, 3));
        c.band(0.96, 1.0, beam);
    });
    // shimoutaya: a finer lattice, no shop front.
    facade("facade_shimoutaya.png", 320, 0.56, (5, 2), &|c, top| {
        let w = c.w();
        c.band(top, 1.0, plaster);
        c.band(top + 0.14, 0.86, mushiko(w, 0.25, 0.75));
        c.band(0.96, 1.0, beam);
    });
    // kanban-gatera: shop front below a flat board facade (eave 5.8 + board 1.8 m).
    {
        let mut c = Canvas::new(128, 512);
        let board = [118, 140, 128];
        c.band(0.0, 1.0, |x, y| {
            let line = if y % 24 < 2 { -0.25 } else { 0.0 };
            shade(board, noise(x, y, 8) * 0.05 + line)
        });
        c.band(0.0, 0.03, |x, y| shade(STONE, noise(x, y, 7) * 0.1));
        c.band(0.03, 0.36, lattice(16, 3));
        c.band(0.36, 0.40, beam);
        c.band(0.48, 0.70, |x, y| {
            if x % 32 < 3 || y % 40 < 3 {
                shade(BEAM, 0.0)
            } else {
                shade([150, 170, 180], noise(x, y, 9) * 0.05)
            }
        });
        c.band(0.80, 0.92, |x, y| {
            shade([40, 40, 44], noise(x, y, 10) * 0.05)
        });
        c.save("facade_kanban.png");
    }
    // Plain materials, tiled by world size (2 m walls, 1 m roof).
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, plaster);
    c.save("shikkui.png");

    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        // Pantiles: channels down the slope every 32 px, courses every 32 px.
        let across = ((x % 32) as f32 / 32.0 * std::f32::consts::TAU).sin() * 0.18;
        let course = if y % 32 < 3 {
            -0.3
        } else {
            (y % 32) as f32 / 32.0 * 0.1
        };
        shade([88, 90, 96], across + course + noise(x, y, 11) * 0.04)
    });
    c.save("kawara.png");

    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let grain = ((y as f32 * 0.35 + noise(x / 16, y / 4, 12) * 2.0).sin()) * 0.08;
        shade([110, 74, 44], grain + noise(x, y, 13) * 0.05)
    });
    c.save("wood.png");

    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let course = if y % 32 < 2 { -0.15 } else { 0.0 };
        shade(
            [196, 164, 112],
            noise(x, y, 14) * 0.06 + noise(x / 6, y / 6, 15) * 0.05 + course,
        )
    });
    c.save("tsuchikabe.png");
}
