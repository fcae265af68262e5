//! Binary glTF 2.0 tiles (`tiles/<id>.glb`), written by our own writer with serde_json: the
//! glTF JSON we need is small and fixed, and the extensions (`EXT_mesh_features`,
//! `EXT_structural_metadata`) are plain JSON that `gltf-json` would hold as untyped values
//! anyway.
//!
//! Frame: y-up, x = east, z = -north, metres around the tile's centre (positions as shorts
//! on one grid per tile, [`quantize`], the nodes' translation and scale making them metres);
//! `tileset.json` places each tile. One node per object kind
//! (`machiya`, `kura`, `fence`, `people`, ...), so a viewer can hide a kind; one primitive
//! per material within it, merged across objects; each vertex carries its object's row in
//! the metadata table (`_FEATURE_ID_0`). Normals are normalized bytes (`KHR_mesh_quantization`,
//! required). Cut-outs are `MASK` at 0.5, double-sided; no BLEND.
//! Textures are the shared library by relative URI (`textures/<file>`, in `tiles/`): one copy per
//! build, cached by a browser across tiles, loadable from any static server.

mod animation;
mod instances;
pub mod models;
mod primitive;
pub mod quantize;

use serde_json::{json, Value};

use crate::model::object::ObjectKind;
use crate::output::atlas::{self, Atlas};
use crate::output::features::Feature;
use crate::output::glb::buffer::Buffer;
use crate::output::glb::{add_images, declare_extensions, linear, metadata};
use crate::output::palette::{mime_type, Palette};
use primitive::{material_index, primitive_json, Primitive, Slot};

/// What a tile's GLB is assembled into, in the order it is written: the BIN chunk with its
/// views and accessors, the materials in first-use order, and the meshes and the nodes
/// drawing them (a node names its mesh by its index).
pub(super) struct Scene {
    pub(super) buf: Buffer,
    pub(super) used: Vec<u16>,
    pub(super) meshes: Vec<Value>,
    pub(super) nodes: Vec<Value>,
}

/// A tile's primitives: per node kind in order of first appearance, per material by id.
type Kinds<'a> = Vec<(&'a str, std::collections::BTreeMap<u16, Primitive>)>;

/// The GLB bytes of one tile. `shift` (millimetres, output frame) is the tile centre the
/// positions are taken around; `features` has one entry per mesh. Grown trees come
/// instanced when the tile has `instanced` variants (their copies in `trees_grown` are left
/// out), each tree with its row of `instance_features` after the meshes' rows, drawn from
/// `models` (the shared model of each variant with trees, in their order).
pub fn tile_glb(
    tile: &crate::output::sink::TileContent,
    meshopt: bool,
    atlas: Option<&Atlas>,
    models: &[&models::Model],
) -> crate::output::glb::container::Glb {
    // Walkers come animated: their standing copies are left out, their figures carry the
    // copies' row.
    let walking =
        (tile.crowd).and_then(|_| (tile.meshes.iter()).position(|m| m.kind == ObjectKind::Walkers));
    let kinds = primitives(tile, atlas, walking);
    let mut buf = Buffer::new(meshopt);
    // The vertex data's bytes (and each view's padding), reserved once: grown by doubling,
    // the buffer was copied again and again.
    let vertex_bytes: usize = (kinds.iter().flat_map(|(_, p)| p.values()))
        .map(|p| {
            4 * (p.positions.len() + p.normals.len() / 3 + p.uvs.len() + p.ids.len())
                + 4 * p.indices.len()
                + 40
        })
        .sum();
    buf.bin.reserve(vertex_bytes);
    let mut scene = Scene {
        buf,
        used: Vec::new(),
        meshes: Vec::new(),
        nodes: Vec::new(),
    };
    kind_nodes(&kinds, &mut scene);
    let (origin, shift) = (tile.origin, tile.centre);
    let first_tree = tile.features.len();
    instances::add(
        tile.instanced,
        models,
        origin,
        shift,
        first_tree,
        &mut scene,
    );
    let animated = match (tile.crowd, walking) {
        (Some(crowd), Some(row)) => {
            animation::add(crowd, atlas, origin, shift, row as u32, &mut scene)
        }
        _ => None,
    };
    document(tile, scene, animated, atlas)
}

/// The tile's meshes as primitives by kind and material, ordered for the GPU: every mesh
/// but the grown trees' copies when the tile instances them and the walkers' standing
/// copies (the mesh `walking`) when they walk.
fn primitives<'a>(
    tile: &crate::output::sink::TileContent<'a>,
    atlas: Option<&Atlas>,
    walking: Option<usize>,
) -> Kinds<'a> {
    let instanced = !tile.instanced.is_empty();
    let mut kinds: Kinds = Vec::new();
    for (i, (mesh, f)) in tile.meshes.iter().zip(tile.features).enumerate() {
        if (instanced && mesh.kind == ObjectKind::GrownTrees) || walking == Some(i) {
            continue;
        }
        let k = match kinds.iter().position(|(k, _)| *k == f.kind) {
            Some(k) => k,
            None => {
                kinds.push((&f.kind, Default::default()));
                kinds.len() - 1
            }
        };
        for face in &mesh.faces {
            let slot = Slot::of(atlas, face.material);
            kinds[k].1.entry(slot.key).or_default().face(
                i as u32,
                mesh,
                &face.corners,
                tile.centre,
                slot,
            );
        }
    }
    for p in kinds.iter_mut().flat_map(|(_, p)| p.values_mut()) {
        p.reorder();
    }
    kinds
}

/// A node and a mesh per kind with faces, its positions shorts on one grid for the tile.
fn kind_nodes(kinds: &Kinds, scene: &mut Scene) {
    let grid = quantize::Grid::over(
        (kinds.iter().flat_map(|(_, p)| p.values())).flat_map(|p| p.positions.iter().copied()),
    );
    for (kind, prims) in kinds {
        let mut primitives = Vec::new();
        for (&material, p) in prims {
            if p.indices.is_empty() {
                continue;
            }
            primitives.push(primitive_json(
                p,
                material,
                true,
                Some(&grid),
                &mut scene.buf,
                &mut scene.used,
            ));
        }
        if primitives.is_empty() {
            continue;
        }
        // The kind in `extras` too: three.js copies it into the object's userData.
        let mut node = json!({"name": kind, "mesh": scene.meshes.len(), "extras": {"kind": kind}});
        if let (Some(n), Some(t)) = (node.as_object_mut(), grid.node_transform().as_object()) {
            n.extend(t.clone());
        }
        scene.nodes.push(node);
        scene
            .meshes
            .push(json!({"name": kind, "primitives": primitives}));
    }
}

/// The glTF document of `scene` with its metadata table (the meshes' rows, then the
/// instanced trees'), extensions, materials and the walkers' clip, in the GLB container.
fn document(
    tile: &crate::output::sink::TileContent,
    scene: Scene,
    animated: Option<animation::Animated>,
    atlas: Option<&Atlas>,
) -> crate::output::glb::container::Glb {
    let Scene {
        mut buf,
        used,
        meshes,
        nodes,
    } = scene;
    let (materials, images, textures) = materials(&used, tile.palette, atlas);
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": format!("edo-city {}", env!("CARGO_PKG_VERSION")),
            "extras": {"tile": tile.id},
        },
        "scene": 0,
        "scenes": [{"name": tile.id}],
    });
    if !nodes.is_empty() {
        let rows: Vec<Feature> = (tile.features.iter())
            .chain(tile.instance_features)
            .cloned()
            .collect();
        let metadata = metadata::structural_metadata(&rows, &mut buf);
        declare_extensions(&mut doc, &buf);
        if !tile.instanced.is_empty() {
            for (list, name) in [
                ("extensionsUsed", "EXT_mesh_gpu_instancing"),
                ("extensionsUsed", "EXT_instance_features"),
                ("extensionsRequired", "EXT_mesh_gpu_instancing"),
            ] {
                if let Some(a) = doc[list].as_array_mut() {
                    a.push(json!(name));
                }
            }
        }
        doc["extensions"] = json!({"EXT_structural_metadata": metadata});
        // The roots: every node that is no other's child (a crowd's walkers are its joints).
        let children: std::collections::BTreeSet<u64> = (nodes.iter())
            .filter_map(|n| n["children"].as_array())
            .flatten()
            .filter_map(Value::as_u64)
            .collect();
        doc["scenes"][0]["nodes"] = json!((0..nodes.len() as u64)
            .filter(|n| !children.contains(n))
            .collect::<Vec<_>>());
        doc["nodes"] = json!(nodes);
        doc["meshes"] = json!(meshes);
        doc["materials"] = json!(materials);
        doc["buffers"] = buf.buffers_json();
        doc["bufferViews"] = json!(buf.views);
        doc["accessors"] = json!(buf.accessors);
        if let Some(a) = animated {
            doc["animations"] = json!([a.clip]);
            doc["skins"] = json!(a.skins);
        }
    }
    add_images(&mut doc, images, textures);
    crate::output::glb::container::glb(&doc, buf.bin)
}

/// The materials `used` (library ids, in first-use order; [`atlas::MATERIAL`] the cut-out
/// atlas) as glTF materials, with the images and textures the textured ones need.
fn materials(
    used: &[u16],
    palette: Palette,
    atlas: Option<&Atlas>,
) -> (Vec<Value>, Vec<Value>, Vec<Value>) {
    let (mut out, mut images, mut textures) = (Vec::new(), Vec::new(), Vec::new());
    for &id in used {
        let m = match id {
            atlas::MATERIAL => crate::output::palette::Entry {
                name: atlas::NAME,
                kd: [1.0; 3],
                texture: Some(atlas::FILE),
                alpha: true,
                mask: None,
            },
            _ => palette.get(id),
        };
        let mut pbr = json!({"metallicFactor": 0.0, "roughnessFactor": 0.9});
        match m.texture {
            Some(file) => {
                images
                    .push(json!({"uri": format!("textures/{file}"), "mimeType": mime_type(file)}));
                textures.push(json!({"sampler": 0, "source": images.len() - 1}));
                pbr["baseColorTexture"] = json!({"index": textures.len() - 1});
            }
            None => {
                let [r, g, b] = m.kd;
                pbr["baseColorFactor"] = json!([linear(r), linear(g), linear(b), 1.0]);
            }
        }
        let mut mat = json!({"name": m.name, "pbrMetallicRoughness": pbr});
        if let (atlas::MATERIAL, Some(a)) = (id, atlas) {
            mat["extras"] = a.extras();
        }
        if m.alpha {
            mat["alphaMode"] = json!("MASK");
            mat["alphaCutoff"] = json!(0.5);
            mat["doubleSided"] = json!(true);
        }
        out.push(mat);
    }
    (out, images, textures)
}

/// The GLB format: `tiles/<id>.glb`, and `tileset.json` over all of them.
pub struct GlbSink {
    /// `output.glb_compression = "meshopt"`.
    pub meshopt: bool,
    /// The cut-out atlas the build wrote (`tiles/textures/cutouts.png`), if any.
    pub atlas: Option<Atlas>,
    /// The grown trees' variants, written once for every tile that plants them.
    pub shared: models::Shared,
    /// The parents of the build before in this directory ([`crate::output::tiles3d::memory`]).
    pub memory: Option<std::sync::Arc<crate::output::tiles3d::memory::Memory>>,
}

impl crate::output::sink::Sink for GlbSink {
    fn format(&self) -> &'static str {
        "glb"
    }

    fn write_tile(
        &self,
        out: &std::path::Path,
        tile: &crate::output::sink::TileContent,
    ) -> std::io::Result<crate::output::sink::TileFiles> {
        let atlas = self.atlas.as_ref();
        let written = (tile.instanced.iter())
            .filter(|g| !g.trees.is_empty())
            .map(|g| self.shared.get(out, &g.model, atlas, self.meshopt))
            .collect::<std::io::Result<Vec<_>>>()?;
        let models: Vec<&models::Model> = written.iter().map(|w| &w.model).collect();
        let glb = tile_glb(tile, self.meshopt, atlas, &models);
        let path = format!("tiles/{}.glb", tile.id);
        let mut files = vec![crate::output::write_listed(out, path, &glb.parts())?];
        // The shared models it draws: listed with every tile that needs them, so that a
        // tile's files are whole wherever it is copied (merge) or checked.
        files.extend(written.iter().map(|w| w.file.clone()));
        Ok(crate::output::sink::TileFiles {
            files,
            mesh_bytes: None,
        })
    }

    fn finish(
        &self,
        out: &std::path::Path,
        manifest: &crate::output::report::Manifest,
        warnings: &mut Vec<String>,
    ) -> std::io::Result<Vec<crate::output::report::ManifestFile>> {
        crate::output::tiles3d::write_tileset(out, manifest, warnings, self.memory.as_deref())
    }
}
