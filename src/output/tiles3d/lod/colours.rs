//! The textures' mean colours, which the parents draw a textured face in (a parent has
//! vertex colours, no textures): each file of the output's texture directory read once per
//! tileset, and in the workbench carried from rebuild to rebuild by its bytes' sha256.

use std::collections::BTreeMap;
use std::path::Path;

use sha2::{Digest, Sha256};

use super::{TextureColours, MAX_FILE_BYTES};

/// Texture colours measured before: by file name, the sha256 of the bytes measured and
/// their colour (none for a file that is no image). The workbench rebuilds every few
/// seconds with the same textures, and decoding each again was 5 % of a lot's edit.
pub type KnownColours = BTreeMap<String, ([u8; 32], Option<[f32; 4]>)>;

/// The mean colour of each texture of the library (linear, alpha-weighted), read once.
/// Each file is read through `bounded` (a regular file, within [`MAX_FILE_BYTES`]): the
/// directory may hold what an earlier run or a person left there, and a FIFO named `x.png`
/// would have held the build forever; such a file has no colour. With `known`, a file whose
/// bytes are those measured before keeps its colour, and `known` is left holding this
/// directory's.
pub fn texture_colours(out: &Path, mut known: Option<&mut KnownColours>) -> TextureColours {
    let mut means = BTreeMap::new();
    let dir = out.join(crate::output::TEXTURE_DIR);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return TextureColours(means);
    };
    let mut names: Vec<_> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    // Each 8-bit value's linear value, looked up: the same numbers as computing it per
    // texel (a `powf` each, which was 3 % of a one-lot rebuild in the workbench).
    let linear: [f64; 256] =
        std::array::from_fn(|v| crate::output::glb::linear(v as f32 / 255.0) as f64);
    let mut now = KnownColours::new();
    for name in names {
        let Ok(bytes) = crate::bounded::read(&dir.join(&name), MAX_FILE_BYTES) else {
            continue;
        };
        let colour = match known.as_deref() {
            Some(before) => {
                let digest: [u8; 32] = Sha256::digest(&bytes).into();
                let colour = match before.get(&name) {
                    Some((d, c)) if *d == digest => *c,
                    _ => mean_colour(&bytes, &linear),
                };
                now.insert(name.clone(), (digest, colour));
                colour
            }
            None => mean_colour(&bytes, &linear),
        };
        if let Some(c) = colour {
            means.insert(format!("textures/{name}"), c);
        }
    }
    if let Some(known) = known.as_mut() {
        **known = now;
    }
    TextureColours(means)
}

/// The mean colour of an image file's bytes (linear, alpha-weighted; `linear` each 8-bit
/// value's linear value); none when they are no image or wholly transparent.
fn mean_colour(bytes: &[u8], linear: &[f64; 256]) -> Option<[f32; 4]> {
    let img = image::load_from_memory(bytes).ok()?.to_rgba8();
    let (mut sum, mut weight) = ([0.0f64; 3], 0.0f64);
    for p in img.pixels() {
        let a = p[3] as f64 / 255.0;
        for k in 0..3 {
            sum[k] += a * linear[p[k] as usize];
        }
        weight += a;
    }
    (weight > 0.0).then(|| {
        let m = sum.map(|s| (s / weight) as f32);
        [m[0], m[1], m[2], 1.0]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A FIFO among the textures is passed over, not opened (it blocked the levels of
    /// detail forever); the PNG beside it still gives its colour.
    #[test]
    fn a_pipe_among_the_textures_has_no_colour_and_holds_nothing_up() {
        let out = tempfile::tempdir().unwrap();
        let dir = out.path().join(crate::output::TEXTURE_DIR);
        std::fs::create_dir_all(&dir).unwrap();
        let made = std::process::Command::new("mkfifo")
            .arg(dir.join("a.png"))
            .status()
            .unwrap();
        assert!(made.success());
        let red = image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 0, 0, 255]));
        red.save(dir.join("b.png")).unwrap();
        let TextureColours(means) = texture_colours(out.path(), None);
        assert_eq!(means.keys().collect::<Vec<_>>(), ["textures/b.png"]);
        assert_eq!(means["textures/b.png"], [1.0, 0.0, 0.0, 1.0]);
    }

    /// A texture whose bytes were measured before keeps the colour remembered for them; one
    /// whose bytes changed, or that was not known, is measured; the colours are the ones
    /// measured without a memory.
    #[test]
    fn a_texture_measured_before_is_not_measured_again() {
        let out = tempfile::tempdir().unwrap();
        let dir = out.path().join(crate::output::TEXTURE_DIR);
        std::fs::create_dir_all(&dir).unwrap();
        let fill = |name: &str, c: [u8; 4]| {
            image::RgbaImage::from_pixel(2, 2, image::Rgba(c))
                .save(dir.join(name))
                .unwrap()
        };
        fill("a.png", [255, 0, 0, 255]);
        fill("b.png", [0, 0, 255, 255]);
        std::fs::write(dir.join("c.png"), b"no image").unwrap();
        let mut known = KnownColours::new();
        let first = texture_colours(out.path(), Some(&mut known)).0;
        assert_eq!(first, texture_colours(out.path(), None).0);
        assert_eq!(
            known.len(),
            3,
            "every file read is remembered, an image or not"
        );
        assert_eq!(known["c.png"].1, None);
        // A colour remembered for a.png's bytes is taken as it is (a made-up one shows it).
        known.get_mut("a.png").unwrap().1 = Some([0.5; 4]);
        fill("b.png", [0, 255, 0, 255]);
        let second = texture_colours(out.path(), Some(&mut known)).0;
        assert_eq!(second["textures/a.png"], [0.5; 4]);
        assert_eq!(second["textures/b.png"], [0.0, 1.0, 0.0, 1.0]);
        assert_eq!(known["b.png"].1, Some([0.0, 1.0, 0.0, 1.0]));
        // A file gone is forgotten.
        std::fs::remove_file(dir.join("c.png")).unwrap();
        texture_colours(out.path(), Some(&mut known));
        assert!(!known.contains_key("c.png"));
    }
}
