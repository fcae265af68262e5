//! Landmark models: an OBJ (tobj) or a glTF/GLB (the gltf crate) read into plain triangles
//! with their materials and texture bytes. A model that cannot be used is an error string
//! naming the file and what to do; the records using it are skipped with it.
//!
//! Every file a model names (its MTL, textures, buffers, images) is read through
//! [`Confined`]: inside the input directory or `landmarks.models_dir`, a regular file, under a
//! size cap; and every count a file declares is checked against [`MAX_TRIANGLES`] before
//! anything of that size is allocated.

mod gltf;

use std::cell::RefCell;
use std::path::Path;
use std::sync::Arc;

use crate::bounded::Confined;
use crate::model::landmark::{Model, ModelMaterial, ModelTriangle};

/// The most triangles a model may have: a landmark is one building, and a scan of a city
/// block given as a landmark would fill its tile many times over. (Tiles and the build have
/// budgets of their own: `analyse::landmarks`.)
pub const MAX_TRIANGLES: usize = 1_000_000;
/// The largest model file (and the most its buffers may take together): a million
/// triangles in OBJ text are about 100 MB.
pub const MAX_MODEL_BYTES: u64 = 256 << 20;
/// The largest texture or MTL file read.
pub const MAX_TEXTURE_BYTES: u64 = 32 << 20;

/// Reads the model at `path` (named `name` in messages), and only files inside `confined`.
/// Unusable textures are left out with a note in `notes` (the material keeps its colour).
pub fn load_model(
    path: &Path,
    name: &str,
    confined: &Confined,
    notes: &mut Vec<String>,
) -> Result<Model, String> {
    let shown = format!("model file {}", excerpt(name));
    let real = confined.resolve(path, &shown).map_err(|e| {
        format!(
            "{e}; give a path relative to landmarks.models_dir, or map the kind to a file in \
             [landmarks.models]"
        )
    })?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if !matches!(ext.as_str(), "obj" | "gltf" | "glb") {
        return Err(format!(
            "{shown}: unsupported format `.{}`: give an OBJ (.obj) or a glTF (.gltf, .glb); \
             export it so from Blender or your modeller",
            excerpt(&ext)
        ));
    }
    let bytes = confined.read(&real, &shown, MAX_MODEL_BYTES)?;
    let dir = real.parent().unwrap_or(Path::new("."));
    let mut model = match ext.as_str() {
        "obj" => load_obj(&bytes, dir, &shown, confined, notes)?,
        _ => gltf::load_gltf(bytes, dir, &shown, confined, notes)?,
    };
    if model.triangles.is_empty() {
        return Err(format!(
            "{shown} has no faces (points or lines only, or empty): export it with its surfaces"
        ));
    }
    if model
        .positions
        .iter()
        .flatten()
        .any(|v| !v.is_finite() || v.abs() > crate::model::FAR)
    {
        return Err(format!(
            "{shown} holds a coordinate that is not a number or is absurdly far: it is damaged"
        ));
    }
    model.file = name.to_string();
    model.stem = stem_of(name);
    Ok(model)
}

/// At most 80 characters of a name a file gives (messages stay short whatever it holds).
pub fn excerpt(s: &str) -> String {
    match s.char_indices().nth(80) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

/// The error of a model over [`MAX_TRIANGLES`].
fn too_many(shown: &str, at_least: usize) -> String {
    format!(
        "{shown} has {at_least} triangles or more, more than {MAX_TRIANGLES}: decimate it \
         first (Blender: the Decimate modifier)"
    )
}

/// Letters, digits, `-` and `_` of the file's stem (others become `_`): the prefix of the
/// model's materials and textures in the output.
pub fn stem_of(name: &str) -> String {
    let stem = Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let s: String = stem
        .chars()
        .map(
            |c| match c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                true => c,
                false => '_',
            },
        )
        .collect();
    if s.is_empty() {
        "model".into()
    } else {
        s
    }
}

/// A texture's bytes (`written` is its path as the model writes it), if it is a PNG or a
/// JPEG (what every client of ours reads) inside the allowed directories.
fn texture(
    path: &Path,
    written: &str,
    confined: &Confined,
    notes: &mut Vec<String>,
) -> Option<(String, Arc<Vec<u8>>)> {
    let shown = format!("texture {}", excerpt(written));
    let bytes = match confined.read(path, &shown, MAX_TEXTURE_BYTES) {
        Ok(b) => b,
        Err(e) => {
            notes.push(format!("{e}: its material keeps its colour"));
            return None;
        }
    };
    let file = path.file_name()?.to_string_lossy().into_owned();
    image_kind(&bytes)
        .map(|ext| (file_with_ext(&file, ext), Arc::new(bytes)))
        .or_else(|| {
            notes.push(format!(
                "{shown} is neither a PNG nor a JPEG: its material keeps its colour"
            ));
            None
        })
}

/// `png` or `jpg` by the bytes' signature.
pub fn image_kind(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("png")
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        Some("jpg")
    } else {
        None
    }
}

/// `file` with the extension its bytes call for (a JPEG named `.png` is renamed).
fn file_with_ext(file: &str, ext: &str) -> String {
    let stem = Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "texture".into());
    format!("{stem}.{ext}")
}

/// Triangles an OBJ's faces make, counted from the text before tobj reads it (a file of ten
/// million faces is refused without holding them).
fn obj_triangles(bytes: &[u8]) -> usize {
    bytes
        .split(|&b| b == b'\n')
        .filter(|l| l.starts_with(b"f ") || l.starts_with(b"f\t"))
        .map(|l| {
            l.split(u8::is_ascii_whitespace)
                .filter(|w| !w.is_empty())
                .count()
                .saturating_sub(3)
        })
        .sum()
}

/// An OBJ with its MTL, faces triangulated (tobj), positions in f64.
fn load_obj(
    bytes: &[u8],
    dir: &Path,
    shown: &str,
    confined: &Confined,
    notes: &mut Vec<String>,
) -> Result<Model, String> {
    let n = obj_triangles(bytes);
    if n > MAX_TRIANGLES {
        return Err(too_many(shown, n));
    }
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj's loader is a `Fn`: why an MTL was refused is kept aside and told after.
    let refused = RefCell::new(Vec::new());
    let (objects, mtl) = tobj::load_obj_buf(&mut &bytes[..], &opts, |mtl_path| {
        let shown = format!("MTL file {}", excerpt(&mtl_path.display().to_string()));
        match confined.read(&dir.join(mtl_path), &shown, MAX_TEXTURE_BYTES) {
            Ok(b) => tobj::load_mtl_buf(&mut &b[..]),
            Err(e) => {
                refused.borrow_mut().push(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    })
    .map_err(|e| format!("{shown} is not a readable OBJ: {e}"))?;
    let mut model = Model::default();
    let mtl = match mtl {
        Ok(m) => m,
        Err(e) => {
            if !objects.is_empty() {
                let why = refused.take().join("; ");
                let why = if why.is_empty() { e.to_string() } else { why };
                notes.push(format!(
                    "{shown}: its materials cannot be read ({why}): it is drawn grey"
                ));
            }
            Vec::new()
        }
    };
    for m in &mtl {
        let kd = m.diffuse.unwrap_or([0.7, 0.7, 0.7]);
        model.materials.push(ModelMaterial {
            name: m.name.clone(),
            kd: [kd[0] as f32, kd[1] as f32, kd[2] as f32],
            texture: m.diffuse_texture.as_deref().and_then(|t| {
                let t = t.replace('\\', "/");
                texture(&dir.join(&t), &t, confined, notes)
            }),
        });
    }
    let grey = model.materials.len() as u32;
    let mut needs_grey = false;
    for o in &objects {
        let m = &o.mesh;
        let base = model.positions.len() as u32;
        let uv_base = model.uvs.len() as u32;
        model
            .positions
            .extend(m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        model
            .uvs
            .extend(m.texcoords.chunks_exact(2).map(|t| [t[0], t[1]]));
        let n = (m.positions.len() / 3) as u32;
        let nt = (m.texcoords.len() / 2) as u32;
        let material = match m.material_id {
            Some(k) if k < mtl.len() => k as u32,
            _ => {
                needs_grey = true;
                grey
            }
        };
        let with_uv = m.texcoord_indices.len() == m.indices.len() && nt > 0;
        for (k, tri) in m.indices.chunks_exact(3).enumerate() {
            if tri.iter().any(|&i| i >= n) {
                return Err(format!(
                    "{shown}: object `{}` has a face naming a vertex it lacks: it is damaged",
                    o.name
                ));
            }
            let uvs = with_uv
                .then(|| {
                    let t = &m.texcoord_indices[3 * k..3 * k + 3];
                    t.iter()
                        .all(|&i| i < nt)
                        .then(|| [uv_base + t[0], uv_base + t[1], uv_base + t[2]])
                })
                .flatten();
            model.triangles.push(ModelTriangle {
                positions: [base + tri[0], base + tri[1], base + tri[2]],
                uvs,
                material,
            });
        }
    }
    if needs_grey {
        model.materials.push(grey_material());
    }
    Ok(model)
}

/// The material of faces that name none.
fn grey_material() -> ModelMaterial {
    ModelMaterial {
        name: "default".into(),
        kd: [0.7, 0.7, 0.7],
        texture: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_faces_are_counted_as_triangles_before_reading() {
        let obj = b"v 0 0 0\nf 1 2 3\nf 1 2 3 4\n# f 1 2 3\nf\t1 2 3 4 5\n";
        assert_eq!(obj_triangles(obj), 1 + 2 + 3);
        assert_eq!(excerpt(&"x".repeat(100)).len(), 83);
    }

    #[test]
    fn stems_are_safe_names() {
        assert_eq!(stem_of("keep/Nijo keep.v2.obj"), "Nijo_keep_v2");
        assert_eq!(stem_of("天守.glb"), "__");
        assert_eq!(image_kind(b"\x89PNG\r\n\x1a\nrest"), Some("png"));
        assert_eq!(image_kind(b"GIF89a"), None);
    }
}
