//! A parent's content as GLB: a node per kind of object (`machiya`, `trees`, `ground`, ...:
//! the metadata's `kind`, in `extras.kind` as the leaves have it, so a viewer's kind toggles
//! work at every level), each placed at the content's centre (in the root's frame, y up as
//! glTF has it) and holding one mesh: a primitive of the kind's opaque surfaces coloured per
//! vertex (`COLOR_0`, no texture), and one per cut-out material with its texture. No normals:
//! clients shade a primitive without them flat, as glTF asks, and massing is all flat faces.
//! The metadata table is the leaves' rows, so a feature id still names its lot.

use std::collections::{BTreeMap, HashMap};

use serde_json::{json, Value};

use super::{Content, Part};
use crate::output::glb::buffer::Buffer;
use crate::output::glb::container;
use crate::output::glb::metadata;

/// The GLB of `content` named `name`, compressed with meshopt when `meshopt`.
pub fn content_glb(name: &str, content: &Content, level: u32, meshopt: bool) -> container::Glb {
    let mut solid = content.solid.clone();
    let flat = level > 1;
    let hidden = super::hidden::hidden_walls(&content.masses, flat);
    for (m, hidden) in content.masses.iter().zip(hidden) {
        let tris = if flat {
            m.flat_triangles()
        } else {
            m.gable_triangles()
        };
        let mut shared: HashMap<([u64; 3], bool), u32, foldhash::fast::FixedState> =
            HashMap::default();
        for (i, t) in tris.iter().enumerate() {
            // Wall k is triangles 2k and 2k + 1; one against a neighbour's is not drawn.
            if i < 8 && hidden[i / 2] {
                continue;
            }
            // The 8 walls and the gables in the wall colour; the roof planes (or the flat
            // top) in the roof's. Corners are shared within a colour.
            let roof = i >= 8 && (flat || i < 12);
            let colour = if roof { m.roof } else { m.wall };
            for p in t {
                let v = *shared
                    .entry((p.map(f64::to_bits), roof))
                    .or_insert_with(|| {
                        solid.positions.push(*p);
                        solid.colours.push(colour);
                        solid.ids.push(m.id);
                        (solid.positions.len() - 1) as u32
                    });
                solid.indices.push(v);
            }
        }
    }
    let (centre, step) = frame(content, &solid);
    let mut buf = Buffer::new(meshopt);
    let mut materials = vec![json!({
        "name": "massing",
        "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.9},
    })];
    let (mut images, mut textures) = (Vec::new(), Vec::new());
    // Each kind's primitives, in kind order: its solid surfaces, then its cut-outs.
    let mut kinds: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for (kind, part) in by_kind(&solid, &content.features) {
        let mut p = primitive(&mut buf, &part, centre, step, 0, false);
        p["attributes"]["COLOR_0"] = json!(buf.colours(&part.colours));
        kinds.entry(kind).or_default().push(p);
    }
    for (name, cut) in &content.cutouts {
        if cut.part.indices.is_empty() {
            continue;
        }
        images.push(json!({"uri": format!("../{}", cut.uri), "mimeType": "image/png"}));
        textures.push(json!({"sampler": 0, "source": images.len() - 1}));
        materials.push(json!({
            "name": name,
            "pbrMetallicRoughness": {
                "metallicFactor": 0.0,
                "roughnessFactor": 0.9,
                "baseColorTexture": {"index": textures.len() - 1},
            },
            "alphaMode": "MASK",
            "alphaCutoff": 0.5,
            "doubleSided": true,
        }));
        for (kind, part) in by_kind(&cut.part, &content.features) {
            let p = primitive(&mut buf, &part, centre, step, materials.len() - 1, true);
            kinds.entry(kind).or_default().push(p);
        }
    }
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": format!("edo-city {}", env!("CARGO_PKG_VERSION")),
            "extras": {"tile": name, "level": level},
        },
        "scene": 0,
        "scenes": [{"name": name}],
    });
    if !kinds.is_empty() {
        let metadata = metadata::structural_metadata(&content.features, &mut buf);
        crate::output::glb::declare_extensions(&mut doc, &buf);
        doc["extensions"] = json!({"EXT_structural_metadata": metadata});
        doc["scenes"][0]["nodes"] = json!((0..kinds.len()).collect::<Vec<_>>());
        let (mut nodes, mut meshes) = (Vec::new(), Vec::new());
        for (i, (kind, primitives)) in kinds.into_iter().enumerate() {
            let name = format!("lod_{kind}");
            nodes.push(json!({
                "name": name,
                "mesh": i,
                "translation": [centre[0], centre[2], -centre[1]],
                "scale": [step, step, step],
                "extras": {"kind": kind},
            }));
            meshes.push(json!({"name": name, "primitives": primitives}));
        }
        doc["nodes"] = json!(nodes);
        doc["meshes"] = json!(meshes);
        doc["materials"] = json!(materials);
        doc["buffers"] = buf.buffers_json();
        doc["bufferViews"] = json!(buf.views);
        doc["accessors"] = json!(buf.accessors);
        crate::output::glb::add_images(&mut doc, images, textures);
    }
    container::glb(&doc, buf.bin)
}

/// The triangles of `part` by the kind of their feature (the metadata row of their first
/// vertex; a row out of range is `other`), each with only the vertices it uses, in kind order.
fn by_kind(part: &Part, features: &[crate::output::features::Feature]) -> Vec<(String, Part)> {
    let kind_of = |v: u32| {
        features
            .get(part.ids[v as usize] as usize)
            .map_or("other", |f| f.kind.as_str())
    };
    let mut triangles: BTreeMap<&str, Vec<&[u32]>> = BTreeMap::new();
    for t in part.indices.chunks_exact(3) {
        triangles.entry(kind_of(t[0])).or_default().push(t);
    }
    // One map of vertices for every kind, cleared between them.
    let mut seen = vec![u32::MAX; part.positions.len()];
    triangles
        .into_iter()
        .map(|(kind, tris)| {
            seen.fill(u32::MAX);
            let mut into = Part::default();
            for &v in tris.iter().flat_map(|t| t.iter()) {
                into.keep(part, v, &mut seen);
            }
            (kind.to_string(), into)
        })
        .collect()
}

/// The point the content's positions are taken around (the middle of its box, whole
/// centimetres; root frame, z up) and the step of its quantized positions: the box's half
/// side over 32,767, rounded up to a power of two metres (a root of 3 km: 6 cm, far under
/// its error of tens of metres).
fn frame(content: &Content, solid: &Part) -> ([f64; 3], f64) {
    let all = solid.positions.iter().chain(
        content
            .cutouts
            .values()
            .flat_map(|c| c.part.positions.iter()),
    );
    let (lo, hi) = super::read::bounds(all);
    if lo[0] > hi[0] {
        return ([0.0; 3], 1.0);
    }
    let centre = [0, 1, 2].map(|k| ((lo[k] + hi[k]) / 2.0 * 100.0).round() / 100.0);
    let half = (0..3)
        .map(|k| (hi[k] - centre[k]).max(centre[k] - lo[k]))
        .fold(0.0, f64::max);
    let step = (half / 32_000.0).max(1e-4).log2().ceil().exp2();
    (centre, step)
}

/// One primitive of `part` (positions taken around `centre`, turned y up, in `step`s) with material
/// `material`; texture coordinates when `textured`.
fn primitive(
    buf: &mut Buffer,
    part: &Part,
    centre: [f64; 3],
    step: f64,
    material: usize,
    textured: bool,
) -> Value {
    let part = &reordered(part);
    let q = |v: f64| (v / step).round().clamp(-32767.0, 32767.0) as i16;
    let positions: Vec<[i16; 3]> = part
        .positions
        .iter()
        .map(|p| {
            [
                q(p[0] - centre[0]),
                q(p[2] - centre[2]),
                q(centre[1] - p[1]),
            ]
        })
        .collect();
    let ids: Vec<f32> = part.ids.iter().map(|&i| i as f32).collect();
    let features = {
        let mut seen: Vec<u32> = part.ids.clone();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    };
    let pos = buf.short_positions(&positions);
    let fid = buf.floats(&ids, 1, false);
    let mut attributes = json!({"POSITION": pos, "_FEATURE_ID_0": fid});
    if textured {
        let uvs: Vec<f32> = part.uvs.iter().flat_map(|u| *u).collect();
        attributes["TEXCOORD_0"] = json!(buf.floats(&uvs, 2, false));
    }
    let ind = buf.indices(&part.indices, part.positions.len());
    json!({
        "attributes": attributes,
        "indices": ind,
        "material": material,
        "mode": 4,
        "extensions": {"EXT_mesh_features": {"featureIds": [{
            "featureCount": features,
            "attribute": 0,
            "propertyTable": 0,
        }]}},
    })
}

/// `part` with its triangles ordered for the vertex cache and its vertices by first use
/// (meshoptimizer's two passes, as the leaves have them): the codecs find smaller deltas.
fn reordered(part: &Part) -> Part {
    let n = part.positions.len();
    let mut indices = part.indices.clone();
    if n == 0 {
        return part.clone();
    }
    meshopt::optimize::optimize_vertex_cache_fifo_in_place(&mut indices, n, 16);
    let remap = meshopt::optimize::optimize_vertex_fetch_remap(&indices, n);
    let used = remap.iter().filter(|&&r| r != u32::MAX).count();
    fn permute<T: Copy + Default>(data: &[T], remap: &[u32], used: usize) -> Vec<T> {
        if data.is_empty() {
            return Vec::new();
        }
        let mut out = vec![T::default(); used];
        for (old, &new) in remap.iter().enumerate() {
            if new != u32::MAX {
                out[new as usize] = data[old];
            }
        }
        out
    }
    Part {
        positions: permute(&part.positions, &remap, used),
        colours: permute(&part.colours, &remap, used),
        uvs: permute(&part.uvs, &remap, used),
        ids: permute(&part.ids, &remap, used),
        indices: indices.iter().map(|&i| remap[i as usize]).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::features::Feature;

    #[test]
    fn triangles_are_grouped_by_their_features_kind_with_their_own_vertices() {
        let feature = |kind: &str| Feature {
            kind: kind.into(),
            ..Feature::default()
        };
        let features = [feature("trees"), feature("machiya")];
        // Two triangles of a tree sharing an edge, one house, one of a row out of range.
        let part = Part {
            positions: (0..8).map(|i| [i as f64, 0.0, 0.0]).collect(),
            colours: Vec::new(),
            uvs: (0..8).map(|i| [i as f32 / 8.0, 0.5]).collect(),
            ids: vec![0, 0, 0, 0, 1, 1, 1, 9],
            indices: vec![4, 5, 6, 0, 1, 2, 2, 1, 3, 7, 7, 7],
        };
        let groups = by_kind(&part, &features);
        let kinds: Vec<&str> = groups.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(kinds, ["machiya", "other", "trees"]);
        let trees = &groups[2].1;
        assert_eq!(trees.indices, [0, 1, 2, 2, 1, 3]);
        assert_eq!(trees.positions.len(), 4);
        assert_eq!(trees.uvs, part.uvs[..4]);
        assert!(trees.colours.is_empty());
        assert_eq!(groups[0].1.positions[0], [4.0, 0.0, 0.0]);
        assert_eq!(groups[0].1.ids, [1, 1, 1]);
        let total: usize = groups.iter().map(|(_, p)| p.indices.len()).sum();
        assert_eq!(total, part.indices.len());
    }
}
