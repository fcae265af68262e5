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
    /// Writes the canvas; the transparent texels of a cut-out take the colour of the drawn
    /// ones next to them (`edo_city::output::cutout::bleed`): black there made dark fringes
    /// and black cards where a converter drops the alpha.
    fn save(&self, name: &str) {
        let path = format!("textures/{name}");
        let mut img = self.img.clone();
        edo_city::output::cutout::bleed(&mut img);
        img.save(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        println!("wrote {path}");
    }
}

/// A transparent canvas for billboards: everything not drawn stays alpha 0.
fn clear(w: u32, h: u32) -> Canvas {
    let mut c = Canvas::new(w, h);
    for p in c.img.pixels_mut() {
        *p = Rgba([0, 0, 0, 0]);
    }
    c
}

/// Paints every pixel of `c` for which `inside(x, y)` (y up from the bottom, in pixels) holds.
fn paint(c: &mut Canvas, inside: impl Fn(f32, f32) -> bool, colour: impl Fn(u32, u32) -> Rgba<u8>) {
    let h = c.h();
    for y in 0..h {
        for x in 0..c.w() {
            if inside(x as f32 + 0.5, (h - 1 - y) as f32 + 0.5) {
                c.img.put_pixel(x, y, colour(x, y));
            }
        }
    }
}

/// A leaf card: `count` leaves (ellipses `len` x `wid` pixels) scattered over a transparent
/// 64 x 64 canvas by the golden angle, each turned its own way, in `colour` with some
/// shading; `hang` makes them point down (willow), `flowers` draws five-petalled blossoms.
fn leaf(name: &str, colour: Px, count: u32, len: f32, wid: f32, hang: bool, flowers: bool) {
    let mut c = clear(64, 64);
    let golden = 2.399_963_f32;
    let leaves: Vec<(f32, f32, f32, f32)> = (0..count)
        .map(|i| {
            let r = 26.0 * ((i as f32 + 0.5) / count as f32).sqrt();
            let a = i as f32 * golden;
            let turn = if hang {
                std::f32::consts::FRAC_PI_2 + noise(i, 1, 90) * 0.3
            } else {
                a + noise(i, 2, 91) * 0.8
            };
            (
                32.0 + r * a.cos(),
                32.0 + r * a.sin(),
                turn,
                noise(i, 3, 92) * 0.2,
            )
        })
        .collect();
    paint(
        &mut c,
        |x, y| {
            leaves.iter().any(|&(lx, ly, t, _)| {
                let (dx, dy) = (x - lx, y - ly);
                if flowers {
                    // Five round petals around the centre.
                    let r = (dx * dx + dy * dy).sqrt();
                    let petal = (5.0 * (dy.atan2(dx) + t)).cos().abs();
                    r < len * (0.55 + 0.45 * petal)
                } else {
                    let (u, v) = (dx * t.cos() + dy * t.sin(), -dx * t.sin() + dy * t.cos());
                    (u / len).powi(2) + (v / wid).powi(2) < 1.0
                }
            })
        },
        |x, y| {
            shade(
                colour,
                noise(x / 2, y / 2, 93) * 0.18 + (y as f32 / 64.0 - 0.5) * 0.2,
            )
        },
    );
    c.save(name);
}

/// Bark: vertical furrows; tileable (period 64 across, 128 along).
fn bark() {
    let mut c = Canvas::new(64, 128);
    c.band(0.0, 1.0, |x, y| {
        let furrow = ((x as f32 / 64.0 * std::f32::consts::TAU * 5.0).sin()
            + noise(x / 4, y / 16, 94) * 0.6)
            * 0.16;
        shade([92, 72, 54], furrow + noise(x, y, 95) * 0.08)
    });
    c.save("bark.png");
}

/// A bamboo culm: green, faint streaks, a node ring every 32 pixels (0.375 m of a 1.5 m
/// repeat).
fn bamboo_culm() {
    let mut c = Canvas::new(64, 128);
    c.band(0.0, 1.0, |x, y| {
        if y % 32 < 3 {
            shade([96, 118, 60], -0.25)
        } else {
            shade(
                [110, 142, 70],
                noise(x / 2, 0, 96) * 0.1 + noise(x, y, 97) * 0.04,
            )
        }
    });
    c.save("bamboo_culm.png");
}

/// The tree billboards, rendered from the species that name them (`billboard = "tree_NN"`
/// in templates/trees/): LOD0 of a tree grown with seed 1 at the middle of its height range,
/// in summer, seen from the south, framed as LOD2's crossed quads are (the farthest branch
/// from the trunk to each side, ground to top). Binary alpha: no fringe of background colour.
fn species_billboards() {
    use edo_city::generate::tree;
    let catalog = edo_city::templates::Catalog::load(None).expect("the shipped species load");
    let from_disk = |name: &str| {
        image::open(format!("textures/{name}"))
            .ok()
            .map(|i| i.to_rgba8())
    };
    for s in catalog.species.values() {
        let (mesh, (r, top)) = tree::sample_lod0(s, "summer").expect("a shipped species grows");
        let r = r.max(top * 0.1);
        let height = 256u32;
        let width = ((f64::from(height) * 2.0 * r / top).round() as u32).clamp(96, 512);
        let mut img = edo_city::output::render::render(
            &[mesh],
            edo_city::output::render::View::South,
            [-r, r, 0.0, top],
            (width, height),
            &from_disk,
        );
        let name = edo_city::materials::MATERIALS[s.billboard as usize]
            .texture
            .expect("a billboard material has a texture");
        let path = format!("textures/{name}");
        edo_city::output::cutout::bleed(&mut img);
        img.save(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        println!("wrote {path} (species {})", s.name);
    }
}

/// One person billboard: head, hair, kimono with an obi, legs; `hat` adds a straw kasa,
/// `load` a bundle carried on the back.
fn person(name: &str, variant: u32, kimono: Px, hat: bool, load: bool) {
    let (w, h) = (64u32, 160u32);
    let mut c = clear(w, h);
    let cx = w as f32 / 2.0 + noise(variant, 2, 40) * 2.0;
    let skin = [224, 188, 150];
    // Legs and sandals.
    paint(
        &mut c,
        |x, y| y < 22.0 && ((x - cx + 5.0).abs() < 3.0 || (x - cx - 5.0).abs() < 3.0),
        |_, _| shade(skin, -0.1),
    );
    // Kimono: a trapezoid from the ankles to the shoulders.
    paint(
        &mut c,
        |x, y| (14.0..120.0).contains(&y) && (x - cx).abs() < 14.0 - (y - 14.0) / 40.0 + 2.0,
        |x, y| shade(kimono, noise(x / 2, y / 2, 41 + variant) * 0.1),
    );
    // Obi sash.
    paint(
        &mut c,
        |x, y| (72.0..82.0).contains(&y) && (x - cx).abs() < 13.0,
        |_, _| shade([60, 48, 40], 0.0),
    );
    // Sleeves.
    paint(
        &mut c,
        |x, y| (70.0..112.0).contains(&y) && ((x - cx).abs() - 15.0).abs() < 4.0,
        |x, y| shade(kimono, -0.15 + noise(x, y, 42) * 0.05),
    );
    // Head and hair.
    paint(
        &mut c,
        |x, y| (x - cx).powi(2) + (y - 132.0).powi(2) < 81.0,
        |_, _| shade(skin, 0.0),
    );
    paint(
        &mut c,
        |x, y| (x - cx).powi(2) + (y - 137.0).powi(2) < 64.0 && y > 134.0,
        |_, _| shade([26, 22, 20], 0.0),
    );
    if hat {
        paint(
            &mut c,
            |x, y| y > 136.0 && y < 150.0 && (x - cx).abs() < 26.0 - (y - 136.0) * 1.8,
            |x, y| shade([186, 160, 96], noise(x, y, 43) * 0.1),
        );
    }
    if load {
        paint(
            &mut c,
            |x, y| (84.0..118.0).contains(&y) && x > cx + 6.0 && x < cx + 22.0,
            |x, y| shade([150, 130, 100], noise(x, y, 44) * 0.1),
        );
    }
    c.save(name);
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

    // Bare ground of streets and yards: packed earth with pebbles, 4 m per repeat.
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let pebble = if noise(x / 3, y / 3, 48) > 0.82 {
            -0.2
        } else {
            0.0
        };
        shade(
            [150, 128, 98],
            noise(x, y, 49) * 0.06 + noise(x / 8, y / 8, 50) * 0.05 + pebble,
        )
    });
    c.save("ground.png");

    // Koshi (格子) lattice on its own, tileable: 8 slats per repeat.
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, lattice(16, 7));
    c.save("koshi.png");

    // Gate leaves: vertical planks, two horizontal battens, iron studs.
    let mut c = Canvas::new(128, 256);
    c.band(0.0, 1.0, |x, y| {
        let seam = if x % 32 < 2 || x == 63 || x == 64 {
            -0.35
        } else {
            0.0
        };
        let batten = if (60..76).contains(&y) || (180..196).contains(&y) {
            0.15
        } else {
            0.0
        };
        let stud = if y % 120 == 68 && x % 16 == 8 {
            -0.6
        } else {
            0.0
        };
        shade(
            [96, 64, 38],
            seam + batten + stud + noise(x, y / 4, 45) * 0.06,
        )
    });
    c.save("gate.png");

    // Namako-kabe (海鼠壁): square tiles set diagonally with raised white plaster joints, the
    // skirt of a kura. Tileable: the diagonal grid has period 32 in both directions.
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let (a, b) = ((x + y) % 32, (x + 128 - y % 128) % 32);
        if a < 4 || b < 4 {
            shade(PLASTER, noise(x, y, 46) * 0.04)
        } else {
            shade([58, 60, 66], noise(x, y, 47) * 0.06)
        }
    });
    c.save("namako.png");

    // Leaf cards and bark of the grown trees, then the billboards rendered from them.
    leaf("leaf_broad.png", [70, 110, 54], 22, 7.0, 3.6, false, false);
    leaf("leaf_needle.png", [44, 84, 50], 60, 9.0, 0.9, false, false);
    leaf(
        "leaf_blossom.png",
        [240, 196, 210],
        16,
        6.0,
        0.0,
        false,
        true,
    );
    leaf("leaf_red.png", [186, 58, 36], 22, 7.0, 3.6, false, false);
    leaf(
        "leaf_yellow.png",
        [204, 160, 52],
        22,
        7.0,
        3.6,
        false,
        false,
    );
    leaf(
        "leaf_willow.png",
        [120, 152, 72],
        30,
        10.0,
        1.6,
        true,
        false,
    );
    leaf(
        "leaf_bamboo.png",
        [92, 136, 60],
        14,
        12.0,
        2.2,
        false,
        false,
    );
    bark();
    bamboo_culm();
    // The rock garden's raked gravel (rake lines along the texture's width, 2 m a repeat,
    // eight furrows), its moss and its stones.
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let furrow = ((y as f32 / 128.0 * std::f32::consts::TAU * 8.0).sin()) * 0.09;
        shade([214, 208, 196], furrow + noise(x, y, 98) * 0.07)
    });
    c.save("gravel_raked.png");
    // The ground of the tiles: a street's packed earth with cart ruts along it (4 m a
    // repeat), the white gravel (shirasu 白州) of temple and court grounds, and water.
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let rut = if (x % 64).abs_diff(20) < 3 {
            -0.08
        } else {
            0.0
        };
        shade(
            [122, 108, 90],
            noise(x, y, 120) * 0.07 + noise(x / 5, y / 5, 121) * 0.06 + rut,
        )
    });
    c.save("street.png");
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        shade(
            [178, 172, 160],
            noise(x, y, 122) * 0.12 + noise(x / 2, y / 2, 123) * 0.05,
        )
    });
    c.save("gravel.png");
    let mut c = Canvas::new(128, 128);
    c.band(0.0, 1.0, |x, y| {
        let ripple = ((y as f32 / 128.0 * std::f32::consts::TAU * 6.0
            + (x as f32 / 128.0 * std::f32::consts::TAU * 2.0).sin() * 0.8)
            .sin())
            * 0.06;
        shade([66, 102, 122], ripple + noise(x / 4, y / 4, 124) * 0.05)
    });
    c.save("water.png");
    let mut c = Canvas::new(64, 64);
    c.band(0.0, 1.0, |x, y| {
        shade(
            [72, 104, 50],
            noise(x / 2, y / 2, 99) * 0.25 + noise(x, y, 100) * 0.1,
        )
    });
    c.save("moss.png");
    let mut c = Canvas::new(64, 64);
    c.band(0.0, 1.0, |x, y| {
        shade(
            [118, 114, 108],
            noise(x / 4, y / 3, 101) * 0.2 + noise(x, y, 102) * 0.08,
        )
    });
    c.save("stone.png");
    species_billboards();

    // Eight people in kimono of the period's common dyes (indigo, brown, grey, persimmon).
    let people: [(Px, bool, bool); 8] = [
        ([40, 56, 96], false, false),
        ([40, 56, 96], true, true),
        ([110, 80, 50], false, true),
        ([120, 120, 116], true, false),
        ([170, 96, 56], false, false),
        ([60, 90, 80], false, false),
        ([90, 50, 60], true, false),
        ([30, 36, 50], false, true),
    ];
    for (i, (kimono, hat, load)) in people.iter().enumerate() {
        person(
            &format!("person_{:02}.png", i + 1),
            i as u32,
            *kimono,
            *hat,
            *load,
        );
    }
}
