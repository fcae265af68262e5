//! A glTF or GLB landmark model. The gltf crate parses and validates the document; the
//! files it names (buffers, images) are read here, through [`Confined`], because the crate's
//! own importer follows `../` and `file:///` anywhere, reads devices until memory runs out
//! and panics on a URI whose percent-encoding is not UTF-8. Every count the document
//! declares is checked before the crate is asked to read that many elements.

use std::path::Path;
use std::sync::Arc;

use super::{excerpt, grey_material, image_kind, stem_of, texture, too_many};
use super::{MAX_MODEL_BYTES, MAX_TRIANGLES};
use crate::bounded::Confined;
use crate::model::landmark::{Model, ModelMaterial, ModelTriangle};

/// The most nodes a scene may place (a node reached twice through a DAG counts twice): a
/// 6 KB file of nodes that each name the next twice would otherwise place a mesh 2^n times.
const MAX_INSTANCES: usize = 100_000;
/// The most vertices an accessor may declare.
const MAX_ELEMENTS: usize = 3 * MAX_TRIANGLES;

/// A glTF or GLB (its bytes; `dir` is where its relative URIs point): the default scene's
/// meshes (else the first scene's) with their nodes' transforms, triangle primitives only.
pub(super) fn load_gltf(
    bytes: Vec<u8>,
    dir: &Path,
    shown: &str,
    confined: &Confined,
    notes: &mut Vec<String>,
) -> Result<Model, String> {
    let bad = |e: &dyn std::fmt::Display| {
        // The crate lists every invalid field; the first few say enough.
        let e = e.to_string();
        let e = match e.char_indices().nth(400) {
            Some((i, _)) => format!("{} ...", &e[..i]),
            None => e,
        };
        format!("{shown} is not a readable glTF: {e}")
    };
    let g = gltf::Gltf::from_slice_without_validation(&bytes).map_err(|e| bad(&e))?;
    validate(&g.document).map_err(|e| bad(&e))?;
    drop(bytes);
    readable_positions(&g.document, shown)?;
    let mut buffers = buffers(&g, dir, shown, confined)?;
    crate::geom::meshopt::decode(&g.document, &mut buffers, shown)?;
    let mut model = Model::default();
    for m in g.document.materials() {
        let c = m.pbr_metallic_roughness().base_color_factor();
        let tex = m
            .pbr_metallic_roughness()
            .base_color_texture()
            .and_then(|info| gltf_image(info.texture().source(), &buffers, dir, confined, notes));
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
    let mut placed = 0usize;
    while let Some((node, parent)) = stack.pop() {
        placed += 1;
        // Every node waiting on the stack will be placed: counting them too bounds the stack
        // itself (a node listing thousands of children, each listing them again).
        if placed + stack.len() + node.children().len() > MAX_INSTANCES {
            return Err(format!(
                "{shown} places more than {MAX_INSTANCES} nodes (its node tree repeats itself, \
                 or has a cycle): export it with its instances applied"
            ));
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
            let material = match prim.material().index() {
                Some(k) => k as u32,
                None => {
                    needs_grey = true;
                    grey
                }
            };
            add_primitive(&mut model, &prim, &buffers, &world, material, shown)?;
        }
    }
    if needs_grey {
        model.materials.push(grey_material());
    }
    Ok(model)
}

/// One triangle primitive placed by `world`, its size checked against the model's budget
/// before it is read.
fn add_primitive(
    model: &mut Model,
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    world: &[[f64; 4]; 4],
    material: u32,
    shown: &str,
) -> Result<(), String> {
    let bad = |why: &str| format!("{shown} is not a readable glTF: {why}");
    let Some(pos_accessor) = prim.get(&gltf::Semantic::Positions) else {
        return Ok(());
    };
    let corners = prim.indices().map_or(pos_accessor.count(), |i| i.count());
    let triangles = model.triangles.len() + corners / 3;
    if triangles > MAX_TRIANGLES || model.positions.len() + pos_accessor.count() > MAX_ELEMENTS {
        return Err(too_many(shown, triangles));
    }
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(|d| &d.0[..]);
    let reader = prim.reader(get);
    // Quantized ones too (`KHR_mesh_quantization`: our own tiles' shorts, gltfpack's):
    // the node's transform, in `world`, turns them into metres.
    let Some(pos) = crate::geom::accessor::positions(prim, get) else {
        return Ok(());
    };
    let base = model.positions.len() as u32;
    model
        .positions
        .extend(pos.into_iter().map(|p| apply(world, p.map(f64::from))));
    let n = model.positions.len() as u32 - base;
    let uv_base = model.uvs.len() as u32;
    if let Some(t) = reader.read_tex_coords(0) {
        // glTF's v runs down the image, OBJ's (and ours) up.
        model.uvs.extend(
            t.into_f32()
                .take(n as usize)
                .map(|[u, v]| [f64::from(u), 1.0 - f64::from(v)]),
        );
    }
    let nt = model.uvs.len() as u32 - uv_base;
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..n).collect(),
    };
    // A mirrored transform turns the faces inside out: wind them back.
    let flip = det3(world) < 0.0;
    for tri in indices.chunks_exact(3) {
        if tri.iter().any(|&i| i >= n) {
            return Err(bad("a primitive's index names a vertex it lacks"));
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
    Ok(())
}

/// The document's buffers: the GLB's binary chunk, data URIs, and files beside the model
/// read through `confined`, each at least as long as it declares, together under
/// [`MAX_MODEL_BYTES`] (`geom::buffers` checks every declared size and count).
fn buffers(
    g: &gltf::Gltf,
    dir: &Path,
    shown: &str,
    confined: &Confined,
) -> Result<Vec<gltf::buffer::Data>, String> {
    let budget = crate::geom::buffers::Budget {
        bytes: MAX_MODEL_BYTES,
        elements: MAX_ELEMENTS,
    };
    crate::geom::buffers::gather(g, &budget, shown, |uri, left| {
        if uri.starts_with("data:") {
            let source = gltf::buffer::Source::Uri(uri);
            return gltf::buffer::Data::from_source(source, None)
                .map(|d| d.0)
                .map_err(|e| format!("{shown}: a buffer's data URI: {e}"));
        }
        let path = local_uri(uri, dir, shown)?;
        confined.read(&path, &format!("{shown}: buffer {}", excerpt(uri)), left)
    })
}

/// The file a relative URI names, percent-decoded; a URI with a scheme (`file:`, `http:`)
/// or whose decoding is not UTF-8 is refused.
fn local_uri(uri: &str, dir: &Path, shown: &str) -> Result<std::path::PathBuf, String> {
    if uri.contains(':') {
        return Err(format!(
            "{shown}: the URI `{}` names a scheme or drive: a model names its files by paths \
             relative to itself (or embeds them)",
            excerpt(uri)
        ));
    }
    let decoded = urlencoding::decode(uri).map_err(|_| {
        format!(
            "{shown}: the URI `{}` is not valid percent-encoded UTF-8",
            excerpt(uri)
        )
    })?;
    Ok(dir.join(&*decoded))
}

/// The crate's validation, with two extensions more than it knows: `KHR_mesh_quantization`,
/// which our own GLB tiles require (byte normals), and `EXT_meshopt_compression`, which
/// they require by default and [`super::meshopt`] decodes. What this reader takes from a model reads
/// the same under it: positions (floats or `KHR_mesh_quantization`'s integers, checked by
/// [`readable_positions`] and read each as itself by [`crate::geom::accessor`]), texture
/// coordinates (normalized integers turned to floats by the crate) and indices; normals are
/// not read.
fn validate(doc: &gltf::Document) -> Result<(), gltf::Error> {
    use gltf::json::validation::{Error, Validate};
    let root = doc.as_json();
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        errors.push((path(), error))
    });
    errors.retain(|(path, error)| {
        let quantization = path.as_str().starts_with("extensionsRequired[")
            && (path.as_str().ends_with("= \"KHR_mesh_quantization\"")
                || path.as_str().ends_with("= \"EXT_meshopt_compression\""));
        !(quantization && matches!(error, Error::Unsupported))
    });
    match errors.is_empty() {
        true => Ok(()),
        false => Err(gltf::Error::Validation(errors)),
    }
}

/// Refuses positions that are not three floats, shorts or bytes (what `KHR_mesh_quantization`
/// allows): no reader would know what else means.
fn readable_positions(doc: &gltf::Document, shown: &str) -> Result<(), String> {
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let Some(a) = prim.get(&gltf::Semantic::Positions) else {
                continue;
            };
            if a.data_type() == gltf::accessor::DataType::U32
                || a.dimensions() != gltf::accessor::Dimensions::Vec3
            {
                return Err(format!(
                    "{shown}: mesh {} has positions of {:?}, which glTF does not allow: \
                     export the model with float positions",
                    mesh.index(),
                    a.data_type()
                ));
            }
        }
    }
    Ok(())
}

/// A glTF image's bytes: from a buffer view, or a file beside the model (data URIs and web
/// addresses are left out with a note).
fn gltf_image(
    image: gltf::Image,
    buffers: &[gltf::buffer::Data],
    dir: &Path,
    confined: &Confined,
    notes: &mut Vec<String>,
) -> Option<(String, Arc<Vec<u8>>)> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let data = buffers.get(view.buffer().index())?;
            let end = view.offset().checked_add(view.length())?;
            let bytes = data.0.get(view.offset()..end)?;
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
            if uri.starts_with("data:") {
                notes.push(format!(
                    "texture `{}` is a data URI: save it as a file beside the model",
                    excerpt(uri)
                ));
                return None;
            }
            match local_uri(uri, dir, "texture") {
                Ok(path) => texture(&path, uri, confined, notes),
                Err(e) => {
                    notes.push(format!("{e}: its material keeps its colour"));
                    None
                }
            }
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
}
