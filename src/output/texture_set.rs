//! The texture library a build writes: the shipped PNGs, or a texture set replacing some of
//! them (a scan of a painting), checked before anything is built; and the cut-out
//! materials' masks derived from them.

use std::borrow::Cow;
use std::path::Path;

use rayon::prelude::*;

use super::{cutout, Texture, TEXTURES};

/// Why a texture set cannot be used; each names the directory or the file.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// The set's directory cannot be read.
    #[error("texture set {dir}: cannot read the directory: {cause}")]
    Directory {
        /// The directory.
        dir: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
    /// A PNG of the set replaces no texture of the library.
    #[error(
        "texture set {dir}: {name} replaces no texture of the library (its files: {})",
        TEXTURES.iter().map(|t| t.0).collect::<Vec<_>>().join(", ")
    )]
    ReplacesNone {
        /// The directory.
        dir: String,
        /// The PNG's name.
        name: String,
    },
    /// A file of the set refused before it was read (not a regular file, too large).
    #[error("{path} {cause}{hint}")]
    Refused {
        /// The file.
        path: String,
        /// Why.
        cause: crate::bounded::Refusal,
        /// What to do, when there is something to say.
        hint: &'static str,
    },
    /// A file of the set is not a PNG the build can read.
    #[error("{path}: not a readable PNG: {cause}")]
    NotPng {
        /// The file.
        path: String,
        /// What the decoder said.
        cause: image::ImageError,
    },
    /// The cut-out textures' atlas cannot be made.
    #[error(transparent)]
    Atlas(#[from] super::atlas::AtlasError),
    /// A cut-out texture's mask cannot be made.
    #[error("{tex}: {cause}")]
    Mask {
        /// The texture.
        tex: &'static str,
        /// What the decoder said.
        cause: image::ImageError,
    },
}

/// The texture library: the shipped PNGs, each replaced by the file of the same name in the
/// directory `set` when it has one (a scan of a painting, say). "" = the shipped set.
/// Every replacement must be a readable PNG, and every PNG in `set` must replace one.
pub fn texture_library(set: &str) -> Result<Vec<Texture>, TextureError> {
    let mut lib: Vec<Texture> = TEXTURES
        .iter()
        .map(|(n, b)| (*n, Cow::Borrowed(*b)))
        .collect();
    if set.is_empty() {
        return Ok(lib);
    }
    let dir = Path::new(set);
    let entries = std::fs::read_dir(dir).map_err(|cause| TextureError::Directory {
        dir: dir.display().to_string(),
        cause,
    })?;
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.to_lowercase().ends_with(".png"))
        .collect();
    names.sort();
    for name in names {
        let path = dir.join(&name);
        let Some(slot) = lib.iter_mut().find(|(n, _)| *n == name) else {
            return Err(TextureError::ReplacesNone {
                dir: dir.display().to_string(),
                name,
            });
        };
        let bytes = read_texture(&path)?;
        let not_png = |cause| TextureError::NotPng {
            path: path.display().to_string(),
            cause,
        };
        image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).map_err(not_png)?;
        // A cut-out's transparent texels get the colour of their drawn neighbours, as the
        // shipped ones have (`cutout::bleed`).
        let bytes = match crate::materials::is_cut_out_texture(slot.0) {
            true => cutout::bleed_png(&bytes).map_err(not_png)?,
            false => bytes,
        };
        slot.1 = Cow::Owned(bytes);
    }
    Ok(lib)
}

/// Bytes of one texture of a texture set.
pub const MAX_TEXTURE_BYTES: u64 = 32 << 20;

/// A texture set's file, refused before it is opened when it is not a regular file (a FIFO
/// named `x.png` blocked the build) or larger than [`MAX_TEXTURE_BYTES`].
fn read_texture(path: &Path) -> Result<Vec<u8>, TextureError> {
    crate::bounded::read(path, MAX_TEXTURE_BYTES).map_err(|cause| {
        let hint = match cause {
            crate::bounded::Refusal::NotRegular => ": remove it from the set",
            _ => "",
        };
        TextureError::Refused {
            path: path.display().to_string(),
            cause,
            hint,
        }
    })
}

/// The library with the cut-out materials' masks added (see
/// [`crate::materials::Material::mask`]), each derived from the texture as it is now (a
/// replaced tree texture gets its own mask).
pub fn with_masks(mut lib: Vec<Texture>) -> Result<Vec<Texture>, TextureError> {
    let mut wanted: Vec<(&'static str, &'static str, &[u8])> = Vec::new();
    for m in crate::materials::MATERIALS {
        let (Some(mask), Some(tex)) = (m.mask, m.texture) else {
            continue;
        };
        let have_mask = lib.iter().any(|(n, _)| *n == mask) || wanted.iter().any(|w| w.0 == mask);
        if let (false, Some((_, bytes))) = (have_mask, lib.iter().find(|(n, _)| *n == tex)) {
            wanted.push((mask, tex, bytes));
        }
    }
    // Each mask decodes and encodes a PNG: in parallel, and pushed in the materials' order.
    let masks: Vec<Result<Texture, TextureError>> = wanted
        .par_iter()
        .map(|&(mask, tex, bytes)| {
            let png = cutout::mask_png(bytes).map_err(|cause| TextureError::Mask { tex, cause })?;
            Ok((mask, Cow::Owned(png)))
        })
        .collect();
    for m in masks {
        lib.push(m?);
    }
    Ok(lib)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_texture_set_holding_a_pipe_or_a_huge_file_is_refused_without_reading_it() {
        let tmp = tempfile::tempdir().unwrap();
        let name = TEXTURES[0].0;
        let path = tmp.path().join(name);
        let made = std::process::Command::new("mkfifo")
            .arg(&path)
            .status()
            .unwrap();
        assert!(made.success());
        let set = tmp.path().to_str().unwrap();
        let e = texture_library(set).unwrap_err();
        let e = e.to_string();
        assert!(e.contains("not a regular file"), "{e}");
        std::fs::remove_file(&path).unwrap();
        std::fs::File::create(&path)
            .unwrap()
            .set_len(MAX_TEXTURE_BYTES + 1)
            .unwrap();
        let e = texture_library(set).unwrap_err();
        let e = e.to_string();
        assert!(e.contains("more than the"), "{e}");
    }
}
