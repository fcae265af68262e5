//! Landmark models: an OBJ (tobj) or a glTF/GLB (the gltf crate) read into plain triangles
//! with their materials and texture bytes. A model that cannot be used is an error string
//! naming the file and what to do; the records using it are skipped with it.

use std::path::Path;
use std::sync::Arc;

use crate::model::landmark::{Model, ModelMaterial, ModelTriangle};

/// The most triangles a model may have: a landmark is one building, and a scan of a city
/// block given as a landmark would fill its tile many times over.
pub const MAX_TRIANGLES: usize = 2_000_000;

/// Reads the model at `path` (named `name` in messages). Unusable textures are left out
/// with a note in `notes` (the material keeps its colour).
pub fn load_model(path: &Path, name: &str, notes: &mut Vec<String>) -> Result<Model, String> {
    if !path.is_file() {
        return Err(format!(
            "model file {} does not exist (give a path relative to landmarks.models_dir, or \
             map the kind to a file in [landmarks.models])",
            path.display()
        ));
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let mut model = match ext.as_str() {
        "obj" => load_obj(path, notes)?,
        "gltf" | "glb" => load_gltf(path, notes)?,
        _ => {
            return Err(format!(
                "model file {}: unsupported format `.{ext}`: give an OBJ (.obj) or a glTF \
                 (.gltf, .glb); export it so from Blender or your modeller",
                path.display()
            ))
        }
    };
    if model.triangles.is_empty() {
        return Err(format!(
            "model file {} has no faces (points or lines only, or empty): export it with \
             its surfaces",
            path.display()
        ));
    }
    if model.triangles.len() > MAX_TRIANGLES {
        return Err(format!(
            "model file {} has {} triangles, more than {MAX_TRIANGLES}: decimate it first",
            path.display(),
            model.triangles.len()
        ));
    }
    if model
        .positions
        .iter()
        .flatten()
        .any(|v| !v.is_finite() || v.abs() > crate::model::FAR)
    {
        return Err(format!(
            "model file {} holds a coordinate that is not a number or is absurdly far: it is \
             damaged",
            path.display()
        ));
    }
    model.file = name.to_string();
    model.stem = stem_of(name);
    Ok(model)
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

/// A texture's bytes, if it is a PNG or a JPEG (what every client of ours reads).
fn texture(path: &Path, notes: &mut Vec<String>) -> Option<(String, Arc<Vec<u8>>)> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) => {
            notes.push(format!(
                "texture {} cannot be read ({e}): its material keeps its colour",
                path.display()
            ));
            return None;
        }
    };
    let file = path.file_name()?.to_string_lossy().into_owned();
    image_kind(&bytes)
        .map(|ext| (file_with_ext(&file, ext), Arc::new(bytes)))
        .or_else(|| {
            notes.push(format!(
                "texture {} is neither a PNG nor a JPEG: its material keeps its colour",
                path.display()
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

/// An OBJ with its MTL, faces triangulated (tobj), positions in f64.
fn load_obj(path: &Path, notes: &mut Vec<String>) -> Result<Model, String> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (objects, mtl) = tobj::load_obj(path, &opts)
        .map_err(|e| format!("model file {} is not a readable OBJ: {e}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut model = Model::default();
    let mtl = match mtl {
        Ok(m) => m,
        Err(e) => {
            if !objects.is_empty() {
                notes.push(format!(
                    "{}: its materials cannot be read ({e}): it is drawn grey",
                    path.display()
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
            texture: m
                .diffuse_texture
                .as_deref()
                .and_then(|t| texture(&dir.join(t.replace('\\', "/")), notes)),
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
                    "model file {}: object `{}` has a face naming a vertex it lacks: it is \
                     damaged",
                    path.display(),
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

/// A glTF or GLB: the default scene's meshes (else the first scene's) with their nodes'
/// transforms, triangle primitives only.
fn load_gltf(path: &Path, notes: &mut Vec<String>) -> Result<Model, String> {
    let bad = |e: &dyn std::fmt::Display| {
        // The crate lists every invalid field; the first few say enough.
        let mut e = e.to_string();
        if e.len() > 400 {
            let cut = (0..=400)
                .rev()
                .find(|&i| e.is_char_boundary(i))
                .unwrap_or(0);
            e.truncate(cut);
            e.push_str(" ...");
        }
        format!("model file {} is not a readable glTF: {e}", path.display())
    };
    let g = gltf::Gltf::open(path).map_err(|e| bad(&e))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let buffers =
        gltf::import_buffers(&g.document, Some(dir), g.blob.clone()).map_err(|e| bad(&e))?;
    let mut model = Model::default();
    for m in g.document.materials() {
        let c = m.pbr_metallic_roughness().base_color_factor();
        let tex = m
            .pbr_metallic_roughness()
            .base_color_texture()
            .and_then(|info| gltf_image(info.texture().source(), &buffers, dir, notes));
        model.materials.push(ModelMaterial {
            name: m
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0))),
            kd: [c[0], c[1], c[2]],
            texture: tex,
        });
    }
    let grey = model.materials.len() as u32;
    let mut needs_grey = false;
    let scene = g
        .document
        .default_scene()
        .or_else(|| g.document.scenes().next());
    let mut stack: Vec<(gltf::Node, [[f64; 4]; 4])> = scene
        .into_iter()
        .flat_map(|s| s.nodes())
        .map(|n| (n, IDENTITY))
        .collect();
    let mut visited = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1_000_000 {
            return Err(bad(&"its node tree does not end (a cycle)"));
        }
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let world = mul(&parent, &local);
        for child in node.children() {
            stack.push((child, world));
        }
        let Some(mesh) = node.mesh() else { continue };
        for prim in mesh.primitives() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let Some(pos) = reader.read_positions() else {
                continue;
            };
            let base = model.positions.len() as u32;
            model
                .positions
                .extend(pos.map(|p| apply(&world, p.map(f64::from))));
            let n = model.positions.len() as u32 - base;
            let uv_base = model.uvs.len() as u32;
            if let Some(t) = reader.read_tex_coords(0) {
                // glTF's v runs down the image, OBJ's (and ours) up.
                model.uvs.extend(
                    t.into_f32()
                        .map(|[u, v]| [f64::from(u), 1.0 - f64::from(v)]),
                );
            }
            let nt = model.uvs.len() as u32 - uv_base;
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..n).collect(),
            };
            let material = match prim.material().index() {
                Some(k) => k as u32,
                None => {
                    needs_grey = true;
                    grey
                }
            };
            // A mirrored transform turns the faces inside out: wind them back.
            let flip = det3(&world) < 0.0;
            for tri in indices.chunks_exact(3) {
                if tri.iter().any(|&i| i >= n) {
                    return Err(bad(&"a primitive's index names a vertex it lacks"));
                }
                let t = if flip {
                    [tri[0], tri[2], tri[1]]
                } else {
                    [tri[0], tri[1], tri[2]]
                };
                model.triangles.push(ModelTriangle {
                    positions: t.map(|i| base + i),
                    uvs: (nt == n).then(|| t.map(|i| uv_base + i)),
                    material,
                });
            }
        }
    }
    if needs_grey {
        model.materials.push(grey_material());
    }
    Ok(model)
}

/// A glTF image's bytes: from a buffer view, or a file beside the model (data URIs and web
/// addresses are left out with a note).
fn gltf_image(
    image: gltf::Image,
    buffers: &[gltf::buffer::Data],
    dir: &Path,
    notes: &mut Vec<String>,
) -> Option<(String, Arc<Vec<u8>>)> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let data = buffers.get(view.buffer().index())?;
            let bytes = data.0.get(view.offset()..view.offset() + view.length())?;
            let ext = image_kind(bytes).or_else(|| {
                notes.push("an embedded texture is neither a PNG nor a JPEG".into());
                None
            })?;
            let name = image
                .name()
                .map(stem_of)
                .unwrap_or_else(|| format!("image{}", image.index()));
            Some((format!("{name}.{ext}"), Arc::new(bytes.to_vec())))
        }
        gltf::image::Source::Uri { uri, .. } => {
            if uri.starts_with("data:") || uri.contains("://") {
                notes.push(format!(
                    "texture `{}` is a data URI or web address: save it as a file beside the \
                     model",
                    uri.chars().take(40).collect::<String>()
                ));
                return None;
            }
            let decoded = uri.replace("%20", " ");
            texture(&dir.join(decoded), notes)
        }
    }
}

const IDENTITY: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// `a * b`, column-major as glTF stores them (`m[column][row]`).
fn mul(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    for (c, col) in out.iter_mut().enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    out
}

/// A point through a column-major transform.
fn apply(m: &[[f64; 4]; 4], p: [f64; 3]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (r, v) in out.iter_mut().enumerate() {
        *v = m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
    }
    out
}

/// The determinant of the upper 3x3.
fn det3(m: &[[f64; 4]; 4]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_compose_translation_after_scale() {
        // Column-major: a translation by (1, 2, 3) and a scale by 2.
        let t = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [1.0, 2.0, 3.0, 1.0],
        ];
        let s = [
            [2.0, 0.0, 0.0, 0.0],
            [0.0, 2.0, 0.0, 0.0],
            [0.0, 0.0, 2.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        assert_eq!(apply(&mul(&t, &s), [1.0, 1.0, 1.0]), [3.0, 4.0, 5.0]);
        assert_eq!(det3(&s), 8.0);
    }

    #[test]
    fn stems_are_safe_names() {
        assert_eq!(stem_of("keep/Nijo keep.v2.obj"), "Nijo_keep_v2");
        assert_eq!(stem_of("天守.glb"), "__");
        assert_eq!(image_kind(b"\x89PNG\r\n\x1a\nrest"), Some("png"));
        assert_eq!(image_kind(b"GIF89a"), None);
    }
}
