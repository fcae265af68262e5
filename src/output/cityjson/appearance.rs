//! A feature's appearance: the materials its surfaces name (the library's colours), and with
//! `[output] cityjson_textures` the texture images of the textured ones and the texture
//! coordinates of their corners.
//!
//! CityJSONSeq features are self-contained, so each numbers its own materials, textures and
//! texture vertices from 0. A texture is the library's PNG in `tiles/textures/`, named
//! relative to `city.city.jsonl` (CityJSON resolves an image's path from the file); its
//! coordinates are the meshes' own (u, v from the image's bottom-left, as OBJ has them),
//! tiled (`wrapMode: wrap`) where a facade repeats its texture.

use std::collections::HashMap;

use super::text;
use crate::output::palette::Palette;

/// The materials and textures one feature's geometries number.
pub struct Appearance<'a> {
    palette: Palette<'a>,
    /// The library id of each local material index.
    materials: Vec<u16>,
    /// With textures: their files and the texture coordinates, numbered by first use.
    textures: Option<Textures<'a>>,
}

#[derive(Default)]
struct Textures<'a> {
    files: Vec<&'a str>,
    uvs: Vec<[i32; 2]>,
    uv_index: HashMap<[i32; 2], u32, foldhash::fast::FixedState>,
}

impl<'a> Appearance<'a> {
    /// An empty appearance over `palette`; `textures` when texture references are written.
    pub fn new(palette: Palette<'a>, textures: bool) -> Self {
        Appearance {
            palette,
            materials: Vec::new(),
            textures: textures.then(Textures::default),
        }
    }

    /// The local index of library material `id`.
    pub fn material(&mut self, id: u16) -> usize {
        match self.materials.iter().position(|&m| m == id) {
            Some(k) => k,
            None => {
                self.materials.push(id);
                self.materials.len() - 1
            }
        }
    }

    /// Whether texture references are written.
    pub fn has_textures(&self) -> bool {
        self.textures.is_some()
    }

    /// Writes one surface's texture values, `[[t,uv,...]]` for its one ring, or `[[null]]`
    /// when its material has no texture or its corners no coordinates (`uvs` the mesh's
    /// coordinates, `corners` the ring's indices into them).
    pub fn write_texture_ring(
        &mut self,
        out: &mut String,
        material: u16,
        uvs: &[[i32; 2]],
        corners: &[u32],
    ) {
        let file = self.palette.get(material).texture;
        let Some(textures) = self.textures.as_mut() else {
            out.push_str("[[null]]");
            return;
        };
        let known = corners.iter().all(|&t| (t as usize) < uvs.len());
        let (Some(file), true, false) = (file, known, corners.is_empty()) else {
            out.push_str("[[null]]");
            return;
        };
        let t = match textures.files.iter().position(|&f| f == file) {
            Some(k) => k,
            None => {
                textures.files.push(file);
                textures.files.len() - 1
            }
        };
        out.push_str("[[");
        text::int(out, t);
        for &c in corners {
            let uv = uvs[c as usize];
            let next = textures.uvs.len() as u32;
            let k = *textures.uv_index.entry(uv).or_insert_with(|| {
                textures.uvs.push(uv);
                next
            });
            out.push(',');
            text::int(out, k);
        }
        out.push_str("]]");
    }

    /// Whether nothing is to be written.
    pub fn is_empty(&self) -> bool {
        self.materials.is_empty()
    }

    /// Writes the feature's `appearance` object: its materials (name and colour) and, with
    /// textures, the images and the texture vertices. Keys in serde_json's order.
    pub fn write(&self, out: &mut String) {
        out.push('{');
        text::key(out, "materials");
        text::array(out, &self.materials, |out, &m| {
            let e = self.palette.get(m);
            out.push('{');
            text::key(out, "diffuseColor");
            text::array(out, e.kd, |out, c| {
                out.push_str(&serde_json::to_string(&round_colour(c as f64)).unwrap_or_default())
            });
            out.push(',');
            text::key(out, "name");
            text::string(out, e.name);
            out.push('}');
        });
        if let Some(t) = self.textures.as_ref().filter(|t| !t.files.is_empty()) {
            out.push(',');
            text::key(out, "textures");
            text::array(out, &t.files, |out, f| {
                out.push('{');
                text::key(out, "image");
                text::string(out, &format!("{}/{f}", crate::output::TEXTURE_DIR));
                out.push_str(",\"type\":\"PNG\",\"wrapMode\":\"wrap\"}");
            });
            out.push(',');
            text::key(out, "vertices-texture");
            text::array(out, &t.uvs, |out, uv| text::array(out, *uv, fixed4));
        }
        out.push('}');
    }
}

/// A colour channel to three decimals (the library's colours are given so).
fn round_colour(c: f64) -> f64 {
    (c.clamp(0.0, 1.0) * 1000.0).round() / 1000.0
}

/// Writes a texture coordinate kept in ten-thousandths (the meshes' quantum) as a decimal:
/// `12500` as `1.25`, exact, with no float printing in between.
fn fixed4(out: &mut String, v: i32) {
    if v < 0 {
        out.push('-');
    }
    let a = v.unsigned_abs();
    text::int(out, a / 10_000);
    let frac = a % 10_000;
    if frac != 0 {
        let digits = format!("{frac:04}");
        out.push('.');
        out.push_str(digits.trim_end_matches('0'));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_coordinates_are_the_meshes_ten_thousandths_exactly() {
        for (v, want) in [
            (0, "0"),
            (10_000, "1"),
            (12_500, "1.25"),
            (3, "0.0003"),
            (-7_250, "-0.725"),
        ] {
            let mut s = String::new();
            fixed4(&mut s, v);
            assert_eq!(s, want);
            assert_eq!(s.parse::<f64>().unwrap(), v as f64 / 10_000.0);
        }
    }

    #[test]
    fn a_textured_ring_names_its_image_and_an_untextured_one_null() {
        let lib = crate::materials::MATERIALS;
        let textured = lib.iter().position(|m| m.texture.is_some()).unwrap() as u16;
        let plain = lib.iter().position(|m| m.texture.is_none()).unwrap() as u16;
        let mut a = Appearance::new(Palette::LIBRARY, true);
        a.material(textured);
        let uvs = [[0, 0], [10_000, 0], [10_000, 5_000]];
        let mut s = String::new();
        a.write_texture_ring(&mut s, textured, &uvs, &[0, 1, 2]);
        s.push(',');
        a.write_texture_ring(&mut s, plain, &uvs, &[0, 1, 2]);
        s.push(',');
        // A corner past the mesh's coordinates: no texture rather than a bad index.
        a.write_texture_ring(&mut s, textured, &uvs, &[0, 1, 9]);
        assert_eq!(s, "[[0,0,1,2]],[[null]],[[null]]");
        let mut w = String::new();
        a.write(&mut w);
        let v: serde_json::Value = serde_json::from_str(&w).unwrap();
        let image = v["textures"][0]["image"].as_str().unwrap();
        assert_eq!(
            image,
            format!("tiles/textures/{}", lib[textured as usize].texture.unwrap())
        );
        assert_eq!(v["vertices-texture"][2], serde_json::json!([1, 0.5]));
    }
}
