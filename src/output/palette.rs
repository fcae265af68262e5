//! The materials a tile's faces name: the library's ([`crate::materials::MATERIALS`], ids
//! from 0) and after them the build's landmark materials (prefixed `lm_<model>_`). The one
//! place the OBJ, MTL and GLB writers look a material id up.

use crate::materials::MATERIALS;
use crate::model::landmark::PaletteEntry;

/// The library plus a build's model materials.
#[derive(Debug, Clone, Copy)]
pub struct Palette<'a> {
    extra: &'a [PaletteEntry],
}

/// What the writers need of one material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry<'a> {
    /// Its name in MTL files and glTF.
    pub name: &'a str,
    /// Diffuse colour.
    pub kd: [f32; 3],
    /// Its texture's file in `tiles/textures/`.
    pub texture: Option<&'a str>,
    /// Cut out by its texture's alpha (the library's billboards).
    pub alpha: bool,
    /// The mask texture of a cut-out.
    pub mask: Option<&'a str>,
}

impl<'a> Palette<'a> {
    /// The library alone (templates and trees written on their own).
    pub const LIBRARY: Palette<'static> = Palette { extra: &[] };

    /// The library and `extra` after it.
    pub fn new(extra: &'a [PaletteEntry]) -> Palette<'a> {
        Palette { extra }
    }

    /// Whether `id` is a model's material (not the library's).
    pub fn is_extra(id: u16) -> bool {
        usize::from(id) >= MATERIALS.len()
    }

    /// The material of `id`. An id past both (a defect) reads as the library's first, so a
    /// writer never fails on it.
    pub fn get(&self, id: u16) -> Entry<'a> {
        let i = usize::from(id);
        match MATERIALS.get(i) {
            Some(m) => Entry {
                name: m.name,
                kd: m.kd,
                texture: m.texture,
                alpha: m.alpha,
                mask: m.mask,
            },
            None => match self.extra.get(i - MATERIALS.len()) {
                Some(e) => Entry {
                    name: &e.name,
                    kd: e.kd,
                    texture: e.texture.as_deref(),
                    alpha: false,
                    mask: None,
                },
                None => Palette::LIBRARY.get(0),
            },
        }
    }
}

/// The MIME type of a texture file by its name (the library's are PNGs; models bring PNG or
/// JPEG, renamed to match their bytes when read).
pub fn mime_type(file: &str) -> &'static str {
    match file.rsplit('.').next() {
        Some("jpg") | Some("jpeg") => "image/jpeg",
        _ => "image/png",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_materials_follow_the_library() {
        let extra = [PaletteEntry {
            name: "lm_keep_roof".into(),
            kd: [0.2, 0.3, 0.4],
            texture: Some("lm_keep_roof.jpg".into()),
        }];
        let p = Palette::new(&extra);
        let first = MATERIALS.len() as u16;
        assert_eq!(p.get(0).name, MATERIALS[0].name);
        assert_eq!(p.get(first).name, "lm_keep_roof");
        assert!(Palette::is_extra(first) && !Palette::is_extra(first - 1));
        assert_eq!(mime_type(p.get(first).texture.unwrap()), "image/jpeg");
        assert_eq!(p.get(first + 1).name, MATERIALS[0].name);
    }
}
