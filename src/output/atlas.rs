//! The cut-out atlas (`tiles/textures/cutouts.png`): every cut-out texture of the library
//! (billboard trees, people, leaves) in one image, so a GLB tile draws all the cut-outs of a
//! kind with one material and one draw call instead of one per texture (issue 40: a tile's
//! 10 billboard textures and 8 people's were 18 draw calls).
//!
//! Only the cut-outs: their cards map their texture once (texture coordinates 0-1), so a
//! card's corners move into its cell and nothing else changes. The opaque textures repeat
//! across walls, roofs and streets (coordinates up to 120), which an atlas cannot wrap
//! without cutting every face at each repeat; they keep a material each.
//!
//! The layout depends on the textures' sizes alone (a replaced texture of another size moves
//! the cells), found by `etagere`'s shelf packer, the allocator of Firefox's WebRender. Each
//! cell is surrounded by a gutter of its own edge texels, so bilinear filtering and the first
//! mip levels sample the texture as clamped at its edge, not the next cell; the space left
//! over is transparent in the cells' mean colour. The OBJ tiles keep the separate textures
//! (Blender users find each material by name there).

use std::borrow::Cow;

use serde_json::{json, Value};

use super::Texture;
use crate::materials::MATERIALS;

/// The atlas's file in the texture directory.
pub const FILE: &str = "cutouts.png";

/// The atlas's material name in the GLB tiles.
pub const NAME: &str = "cutouts";

/// The key of the atlas's material among a tile's material ids: past every library and
/// landmark material (a build has at most a few thousand).
pub const MATERIAL: u16 = u16::MAX;

/// Texels of a cell's own edge around it: filtering at the cell's border and mip levels up
/// to the third stay inside the texture's colours.
const GUTTER: i32 = 4;

/// The largest side tried: every WebGL 2 device draws 4096-texel textures (the minimum it
/// must support is 2048; phones and SwiftShader do 4096 and more).
const MAX_SIDE: i32 = 4096;

/// Where one texture is in the atlas.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// The library file.
    pub texture: &'static str,
    /// Its texels' left, top, width and height in the atlas (inside the gutter).
    pub rect: [u32; 4],
}

/// The layout: the atlas's size and each cut-out texture's cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Atlas {
    /// Width and height in texels.
    pub size: [u32; 2],
    /// In the library's order.
    pub cells: Vec<Cell>,
    /// Per library material id: its cell, when the material is a cut-out of the atlas.
    by_material: Vec<Option<usize>>,
}

/// Why a library's cut-outs have no atlas.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AtlasError {
    /// A cut-out texture that could not be read (or the atlas not encoded).
    #[error("texture {0}: not a readable PNG")]
    Unreadable(&'static str),
    /// More texels than the largest atlas holds (a texture set of large replacements).
    #[error(
        "the cut-out textures do not fit one {MAX_SIDE} x {MAX_SIDE} atlas \
         ({0} texels in all): each is drawn with its own material"
    )]
    TooLarge(u64),
}

impl Atlas {
    /// The layout of `library`'s cut-out textures; `Ok(None)` when it has none.
    pub fn layout(library: &[Texture]) -> Result<Option<Atlas>, AtlasError> {
        let mut sizes: Vec<(&'static str, [u32; 2])> = Vec::new();
        for (name, bytes) in library {
            if !crate::materials::is_cut_out_texture(name) {
                continue;
            }
            let dims = image::ImageReader::with_format(
                std::io::Cursor::new(&bytes[..]),
                image::ImageFormat::Png,
            )
            .into_dimensions()
            .map_err(|_| AtlasError::Unreadable(name))?;
            sizes.push((name, [dims.0, dims.1]));
        }
        if sizes.is_empty() {
            return Ok(None);
        }
        // Tallest first (then widest, then by name), the order a shelf packer fills best.
        let mut order: Vec<usize> = (0..sizes.len()).collect();
        order.sort_by_key(|&i| {
            (
                std::cmp::Reverse(sizes[i].1[1]),
                std::cmp::Reverse(sizes[i].1[0]),
                sizes[i].0,
            )
        });
        let padded = |i: usize| {
            let [w, h] = sizes[i].1;
            etagere::size2(w as i32 + 2 * GUTTER, h as i32 + 2 * GUTTER)
        };
        for [w, h] in candidate_sizes() {
            let mut packer = etagere::AtlasAllocator::with_options(
                etagere::size2(w, h),
                &etagere::AllocatorOptions {
                    alignment: etagere::size2(GUTTER, GUTTER),
                    ..Default::default()
                },
            );
            let mut rects = vec![[0u32; 4]; sizes.len()];
            let fits = order.iter().all(|&i| match packer.allocate(padded(i)) {
                Some(a) => {
                    let [tw, th] = sizes[i].1;
                    let (x, y) = (a.rectangle.min.x + GUTTER, a.rectangle.min.y + GUTTER);
                    rects[i] = [x as u32, y as u32, tw, th];
                    true
                }
                None => false,
            });
            if fits {
                let cells: Vec<Cell> = sizes
                    .iter()
                    .zip(rects)
                    .map(|(&(texture, _), rect)| Cell { texture, rect })
                    .collect();
                let by_material = MATERIALS
                    .iter()
                    .map(|m| match (m.alpha, m.texture) {
                        (true, Some(t)) => cells.iter().position(|c| c.texture == t),
                        _ => None,
                    })
                    .collect();
                return Ok(Some(Atlas {
                    size: [w as u32, h as u32],
                    cells,
                    by_material,
                }));
            }
        }
        let texels = sizes
            .iter()
            .map(|(_, [w, h])| u64::from(*w) * u64::from(*h));
        Err(AtlasError::TooLarge(texels.sum()))
    }

    /// The cell of material `id`, when it is one of the atlas's cut-outs.
    pub fn cell(&self, id: u16) -> Option<&Cell> {
        let i = (*self.by_material.get(usize::from(id))?)?;
        self.cells.get(i)
    }

    /// Where `uv` of a card's texture (glTF's frame: 0,0 the image's top left; clamped to
    /// the texture, which a card maps once) lies in the atlas.
    pub fn uv(&self, cell: &Cell, uv: [f64; 2]) -> [f64; 2] {
        let [x, y, w, h] = cell.rect.map(f64::from);
        let [u, v] = uv.map(|c| c.clamp(0.0, 1.0));
        [
            (x + u * w) / f64::from(self.size[0]),
            (y + v * h) / f64::from(self.size[1]),
        ]
    }

    /// The atlas image: each texture in its cell, its edge texels repeated into the gutter,
    /// the rest transparent in the cells' mean colour.
    pub fn image(&self, library: &[Texture]) -> Result<image::RgbaImage, AtlasError> {
        let mut canvas = image::RgbaImage::new(self.size[0], self.size[1]);
        let (mut sum, mut n) = ([0u64; 3], 0u64);
        let mut drawn = Vec::with_capacity(self.cells.len());
        for cell in &self.cells {
            let bytes = library
                .iter()
                .find(|(name, _)| *name == cell.texture)
                .map(|(_, b)| &b[..])
                .ok_or(AtlasError::Unreadable(cell.texture))?;
            let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
                .map_err(|_| AtlasError::Unreadable(cell.texture))?
                .to_rgba8();
            for p in img.pixels().filter(|p| p[3] > 0) {
                for k in 0..3 {
                    sum[k] += u64::from(p[k]);
                }
                n += 1;
            }
            drawn.push(img);
        }
        let mean = sum.map(|s| (s / n.max(1)) as u8);
        for p in canvas.pixels_mut() {
            p.0 = [mean[0], mean[1], mean[2], 0];
        }
        for (cell, img) in self.cells.iter().zip(&drawn) {
            let [x0, y0, w, h] = cell.rect.map(|v| v as i64);
            let g = i64::from(GUTTER);
            for y in (y0 - g)..(y0 + h + g) {
                for x in (x0 - g)..(x0 + w + g) {
                    let sx = (x - x0).clamp(0, w - 1) as u32;
                    let sy = (y - y0).clamp(0, h - 1) as u32;
                    canvas.put_pixel(x as u32, y as u32, *img.get_pixel(sx, sy));
                }
            }
        }
        Ok(canvas)
    }

    /// [`Atlas::image`] as PNG bytes.
    pub fn png(&self, library: &[Texture]) -> Result<Vec<u8>, AtlasError> {
        let img = self.image(library)?;
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png)
            .map_err(|_| AtlasError::Unreadable(FILE))?;
        Ok(out.into_inner())
    }

    /// The layout as the atlas material's `extras` (so a script or a Blender user can find a
    /// texture's cell): the size and each cell by its texture's file.
    pub fn extras(&self) -> Value {
        let cells: Vec<Value> = self
            .cells
            .iter()
            .map(|c| json!({"texture": c.texture, "rect": c.rect}))
            .collect();
        json!({"atlas": {"size": self.size, "cells": cells}})
    }
}

/// Atlas sizes from the smallest: powers of two, width first.
fn candidate_sizes() -> impl Iterator<Item = [i32; 2]> {
    (8..=12)
        .flat_map(|k| {
            let s = 1 << k;
            [[s, s / 2], [s, s]]
        })
        .filter(|&[w, _]| w <= MAX_SIDE)
}

/// A texture library with its atlas: the textures (the atlas's PNG among them), the layout,
/// and why there is none when the cut-outs did not fit.
pub type WithAtlas = (Vec<Texture>, Option<Atlas>, Option<String>);

/// The library with the atlas added when `glb` tiles are written and it has cut-outs, and
/// the atlas's layout; a library whose cut-outs do not fit gets none and the reason.
pub fn with_atlas(mut library: Vec<Texture>, glb: bool) -> Result<WithAtlas, AtlasError> {
    if !glb {
        return Ok((library, None, None));
    }
    let atlas = match Atlas::layout(&library) {
        Ok(Some(a)) => a,
        Ok(None) => return Ok((library, None, None)),
        Err(e @ AtlasError::TooLarge(_)) => return Ok((library, None, Some(e.to_string()))),
        Err(e) => return Err(e),
    };
    let png = atlas.png(&library)?;
    library.push((FILE, Cow::Owned(png)));
    Ok((library, Some(atlas), None))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped() -> Vec<Texture> {
        crate::materials::TEXTURES
            .iter()
            .map(|(n, b)| (*n, Cow::Borrowed(*b)))
            .collect()
    }

    fn overlap(a: [u32; 4], b: [u32; 4]) -> bool {
        let g = GUTTER as u32;
        a[0] < b[0] + b[2] + 2 * g
            && b[0] < a[0] + a[2] + 2 * g
            && a[1] < b[1] + b[3] + 2 * g
            && b[1] < a[1] + a[3] + 2 * g
    }

    #[test]
    fn every_cut_out_has_a_cell_of_its_size_and_no_two_cells_meet() {
        let lib = shipped();
        let atlas = Atlas::layout(&lib).unwrap().unwrap();
        let cut_outs: Vec<&str> = MATERIALS
            .iter()
            .filter(|m| m.alpha)
            .filter_map(|m| m.texture)
            .collect();
        assert_eq!(atlas.cells.len(), cut_outs.len());
        for (id, m) in MATERIALS.iter().enumerate() {
            let cell = atlas.cell(id as u16);
            assert_eq!(cell.is_some(), m.alpha, "{}", m.name);
            if let Some(c) = cell {
                assert_eq!(Some(c.texture), m.texture);
                let (_, bytes) = lib.iter().find(|(n, _)| *n == c.texture).unwrap();
                let img = image::load_from_memory(bytes).unwrap();
                assert_eq!([c.rect[2], c.rect[3]], [img.width(), img.height()]);
                // The gutter inside the atlas.
                let g = GUTTER as u32;
                assert!(c.rect[0] >= g && c.rect[1] >= g);
                assert!(c.rect[0] + c.rect[2] + g <= atlas.size[0]);
                assert!(c.rect[1] + c.rect[3] + g <= atlas.size[1]);
            }
        }
        for (i, a) in atlas.cells.iter().enumerate() {
            for b in &atlas.cells[i + 1..] {
                assert!(!overlap(a.rect, b.rect), "{} and {}", a.texture, b.texture);
            }
        }
        // The shipped set (10 trees, 8 people, 7 leaves: 1.03 million texels) in 2048 x 1024.
        assert_eq!(atlas.size, [2048, 1024]);
        assert_eq!(
            Atlas::layout(&lib).unwrap().unwrap(),
            atlas,
            "deterministic"
        );
    }

    #[test]
    fn a_card_maps_its_texture_once_into_its_cell() {
        let atlas = Atlas::layout(&shipped()).unwrap().unwrap();
        let c = atlas.cells[0].clone();
        let [x, y, w, h] = c.rect.map(f64::from);
        let [aw, ah] = atlas.size.map(f64::from);
        assert_eq!(atlas.uv(&c, [0.0, 0.0]), [x / aw, y / ah]);
        assert_eq!(atlas.uv(&c, [1.0, 1.0]), [(x + w) / aw, (y + h) / ah]);
        assert_eq!(
            atlas.uv(&c, [0.5, 0.25]),
            [(x + w / 2.0) / aw, (y + h / 4.0) / ah]
        );
        // Outside the texture: clamped to its edge, never into the next cell.
        assert_eq!(atlas.uv(&c, [-0.5, 1.5]), atlas.uv(&c, [0.0, 1.0]));
    }

    #[test]
    fn the_image_holds_each_texture_in_its_cell_with_its_edges_around_it() {
        let lib = shipped();
        let atlas = Atlas::layout(&lib).unwrap().unwrap();
        let img = atlas.image(&lib).unwrap();
        for c in &atlas.cells {
            let (_, bytes) = lib.iter().find(|(n, _)| *n == c.texture).unwrap();
            let tex = image::load_from_memory(bytes).unwrap().to_rgba8();
            let [x0, y0, w, h] = c.rect;
            for y in 0..h {
                for x in 0..w {
                    assert_eq!(img.get_pixel(x0 + x, y0 + y), tex.get_pixel(x, y));
                }
            }
            let g = GUTTER as u32;
            // The gutter repeats the edge: the corner's texel, the middle of each side's.
            assert_eq!(img.get_pixel(x0 - g, y0 - g), tex.get_pixel(0, 0));
            assert_eq!(
                img.get_pixel(x0 + w + g - 1, y0 + h / 2),
                tex.get_pixel(w - 1, h / 2)
            );
        }
        // The space between cells is transparent.
        let outside = |x: u32, y: u32| {
            atlas.cells.iter().all(|c| {
                let g = GUTTER as u32;
                let [x0, y0, w, h] = c.rect;
                x + g < x0 || x >= x0 + w + g || y + g < y0 || y >= y0 + h + g
            })
        };
        let free = img
            .enumerate_pixels()
            .filter(|(x, y, _)| outside(*x, *y))
            .collect::<Vec<_>>();
        assert!(!free.is_empty());
        assert!(free.iter().all(|(_, _, p)| p[3] == 0));
    }

    #[test]
    fn cut_outs_too_large_for_one_atlas_get_none_and_the_reason() {
        let mut lib = shipped();
        let big = image::RgbaImage::new(4000, 4000);
        let mut png = std::io::Cursor::new(Vec::new());
        big.write_to(&mut png, image::ImageFormat::Png).unwrap();
        let png = png.into_inner();
        for name in ["tree_01.png", "tree_02.png"] {
            lib.iter_mut().find(|(n, _)| *n == name).unwrap().1 = Cow::Owned(png.clone());
        }
        assert!(matches!(Atlas::layout(&lib), Err(AtlasError::TooLarge(_))));
        let (lib2, atlas, why) = with_atlas(lib.clone(), true).unwrap();
        assert!(atlas.is_none() && lib2.len() == lib.len());
        assert!(why.unwrap().contains("4096 x 4096"));
        // No GLB, no atlas.
        let (lib3, atlas, why) = with_atlas(shipped(), false).unwrap();
        assert!(atlas.is_none() && why.is_none() && lib3.len() == shipped().len());
        let (lib4, atlas, _) = with_atlas(shipped(), true).unwrap();
        assert!(atlas.is_some());
        assert_eq!(lib4.last().unwrap().0, FILE);
    }
}
