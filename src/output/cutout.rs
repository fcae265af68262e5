//! The cut-out textures of billboards and leaves (materials with `alpha`): the colour of their
//! transparent texels, and the grey masks derived from their alpha.
//!
//! A texel of alpha 0 is never seen where the alpha test cuts it out, but its colour is: a
//! mipmap or a bilinear sample mixes it into the visible edge (a dark fringe round every
//! leaf), and a converter that drops the alpha (assimp's OBJ -> glTF export) draws the whole
//! card in it. Drawn on a cleared canvas those texels were RGB 0,0,0, so every tree and person
//! became a black rectangle. [`bleed`] gives each transparent texel the colour of the nearest
//! drawn ones (the average of its already-coloured neighbours, ring by ring outwards, the
//! "edge padding" of texture bakers), leaving alpha and every drawn texel as they are.

/// RGBA pixels with every alpha-0 texel coloured from its nearest drawn neighbours (8-way,
/// in rings: each ring from the ring inside it only, so the result does not depend on the
/// order of the scan). Alpha is untouched. A texture with no drawn texel is left as it is.
pub fn bleed(img: &mut image::RgbaImage) {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let mut done: Vec<bool> = img.pixels().map(|p| p[3] > 0).collect();
    if !done.iter().any(|&d| d) {
        return;
    }
    let neighbours = |i: usize| {
        let (x, y) = ((i % w) as isize, (i / w) as isize);
        (-1..=1)
            .flat_map(move |dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(nx, ny)| {
                (nx, ny) != (x, y) && nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h
            })
            .map(move |(nx, ny)| ny as usize * w + nx as usize)
    };
    // The first ring: transparent texels touching a drawn one.
    let mut ring: Vec<usize> = (0..w * h)
        .filter(|&i| !done[i] && neighbours(i).any(|n| done[n]))
        .collect();
    while !ring.is_empty() {
        let colours: Vec<[u8; 3]> = ring
            .iter()
            .map(|&i| {
                let (mut sum, mut n) = ([0u32; 3], 0u32);
                for j in neighbours(i).filter(|&j| done[j]) {
                    let p = img.as_raw();
                    for c in 0..3 {
                        sum[c] += u32::from(p[4 * j + c]);
                    }
                    n += 1;
                }
                // Rounded to the nearest: a ring of one colour keeps it exactly.
                sum.map(|s| ((s + n / 2) / n.max(1)) as u8)
            })
            .collect();
        for (&i, c) in ring.iter().zip(&colours) {
            let p = img.get_pixel_mut((i % w) as u32, (i / w) as u32);
            p.0 = [c[0], c[1], c[2], p[3]];
            done[i] = true;
        }
        let mut next: Vec<usize> = ring
            .iter()
            .flat_map(|&i| neighbours(i))
            .filter(|&j| !done[j])
            .collect();
        next.sort_unstable();
        next.dedup();
        ring = next;
    }
}

/// A PNG with [`bleed`] applied, re-encoded; the same bytes when there is nothing to colour.
pub fn bleed_png(png: &[u8]) -> Result<Vec<u8>, image::ImageError> {
    let mut img = image::load_from_memory_with_format(png, image::ImageFormat::Png)?.to_rgba8();
    let before = img.clone();
    bleed(&mut img);
    if img == before {
        return Ok(png.to_vec());
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)?;
    Ok(out.into_inner())
}

/// RGBA = (a, a, a, a) of a PNG: the mask of a cut-out material (three.js reads an alpha map
/// from its green channel, Blender from its alpha).
pub fn mask_png(png: &[u8]) -> Result<Vec<u8>, image::ImageError> {
    let mut img = image::load_from_memory_with_format(png, image::ImageFormat::Png)?.to_rgba8();
    for p in img.pixels_mut() {
        let a = p[3];
        p.0 = [a, a, a, a];
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{Rgba, RgbaImage};

    #[test]
    fn transparent_texels_take_the_nearest_drawn_colour_and_drawn_ones_stay() {
        let mut img = RgbaImage::new(7, 3);
        img.put_pixel(1, 1, Rgba([200, 100, 50, 255]));
        img.put_pixel(5, 1, Rgba([0, 60, 0, 128]));
        let before = img.clone();
        bleed(&mut img);
        assert_eq!(img.get_pixel(1, 1), before.get_pixel(1, 1));
        assert_eq!(img.get_pixel(5, 1), before.get_pixel(5, 1));
        // Next to one drawn texel: its colour, alpha still 0.
        assert_eq!(img.get_pixel(0, 0).0, [200, 100, 50, 0]);
        assert_eq!(img.get_pixel(6, 2).0, [0, 60, 0, 0]);
        // Halfway: the first ring's average of both sides' neighbours.
        assert_eq!(img.get_pixel(3, 1)[3], 0);
        assert!(
            img.pixels().all(|p| p[0] > 0 || p[1] > 0),
            "no black texel left"
        );
        let mut empty = RgbaImage::new(3, 3);
        bleed(&mut empty);
        assert!(empty.pixels().all(|p| p.0 == [0, 0, 0, 0]));
    }

    #[test]
    fn the_shipped_cut_outs_are_bled_already() {
        // `make textures` bleeds them when it draws them: the build then copies them as they
        // are, and a texture set's replacement is bled when it is read.
        for m in crate::materials::MATERIALS.iter().filter(|m| m.alpha) {
            let name = m.texture.unwrap();
            let (_, bytes) = crate::materials::TEXTURES
                .iter()
                .find(|(n, _)| *n == name)
                .unwrap();
            let img = image::load_from_memory(bytes).unwrap().to_rgba8();
            let mut again = img.clone();
            bleed(&mut again);
            assert!(again == img, "{name} has transparent texels without colour");
            assert!(
                img.pixels().any(|p| p[3] == 0),
                "{name} is a cut-out with holes"
            );
        }
    }
}
