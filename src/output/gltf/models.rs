//! Shared models (`tiles/models/<species>_<k>.bin`): the vertex and index data of each grown
//! tree variant, written once per build, which every leaf that plants the variant references
//! as an external glTF buffer (`"uri": "models/<name>.bin"`) instead of carrying its own copy.
//!
//! A variant is the same bytes in every tile (it is grown from its species, the seed and k
//! alone), so a copy per tile made the grown trees most of a city's GLB bytes: 85 of 149 MB
//! at 30,052 lots with every feature. The 3D Tiles way of sharing a model between tiles is
//! an external resource of the glTF content, resolved relative to the tile (as its textures
//! are); a browser fetches the file once and revalidates it, CesiumJS caches it by URI.
//!
//! Each tile still carries the model's views and accessors (JSON, a few hundred bytes) and,
//! with meshopt, the decoded size of its compressed views in its own fallback buffer: the
//! extension decodes from the shared buffer into the tile's.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use serde_json::{json, Value};

use super::quantize::Grid;
use super::{Primitive, Slot};
use crate::generate::mesh::Mesh;
use crate::output::glb::{self, buffer::Buffer, MODELS_DIR};
use crate::output::report::ManifestFile;

/// One model encoded as a buffer of its own.
pub struct Model {
    /// The file's URI relative to `tiles/` (`models/<name>.bin`).
    pub uri: String,
    /// Metres a unit of its positions (shorts around the trunk's foot): each instance's
    /// scale is multiplied by it.
    pub step: f32,
    /// The buffer's bytes (compressed views when meshopt is on).
    pub bin: Vec<u8>,
    /// The views into `bin`: a plain view's `buffer` and a compressed view's extension
    /// `buffer` are 0 here, the model's own buffer; [`graft`] renumbers them.
    views: Vec<Value>,
    /// The accessors over `views`.
    accessors: Vec<Value>,
    /// Per primitive: its material (library id) and its JSON, accessors numbered in
    /// `accessors`, no material yet.
    primitives: Vec<(u16, Value)>,
}

/// `model` as a buffer of its own: a primitive per material (the cut-outs in the atlas's
/// primitive), vertices ordered for the cache, no feature ids (its rows are its instances').
pub fn encode(model: &Mesh, atlas: Option<&crate::output::atlas::Atlas>, meshopt: bool) -> Model {
    let mut prims: BTreeMap<u16, Primitive> = BTreeMap::new();
    for f in &model.faces {
        let slot = Slot::of(atlas, f.material);
        prims
            .entry(slot.key)
            .or_default()
            .face(0, model, &f.corners, [0, 0, 0], slot);
    }
    let mut buf = Buffer::new(meshopt);
    let mut primitives = Vec::new();
    for p in prims.values_mut() {
        p.reorder();
    }
    let grid = Grid::at_origin(prims.values().flat_map(|p| p.positions.iter().copied()));
    for (&material, p) in &prims {
        if p.indices.is_empty() {
            continue;
        }
        // The material is the tile's to number: given at graft.
        let mut used = Vec::new();
        let mut prim = super::primitive_json(p, material, false, Some(&grid), &mut buf, &mut used);
        if let Some(o) = prim.as_object_mut() {
            o.remove("material");
        }
        primitives.push((material, prim));
    }
    Model {
        uri: glb::uri_of(&model.name),
        step: grid.step,
        bin: buf.bin,
        views: buf.views,
        accessors: buf.accessors,
        primitives,
    }
}

impl Model {
    /// Whether the model draws nothing.
    pub fn is_empty(&self) -> bool {
        self.primitives.is_empty()
    }

    /// The file's path relative to the output directory.
    pub fn path(&self) -> String {
        format!("tiles/{}", self.uri)
    }
}

/// Adds `model`'s views and accessors to the tile's `buf`, over an external buffer naming
/// its file; returns its primitives' JSON with the tile's accessor and material numbers
/// (`used`: the tile's materials in first-use order).
pub fn graft(model: &Model, buf: &mut Buffer, used: &mut Vec<u16>) -> Vec<Value> {
    let external = buf.external(&model.uri, model.bin.len());
    let first_view = buf.views.len() as u64;
    for v in &model.views {
        let mut v = v.clone();
        match v
            .get_mut("extensions")
            .and_then(|e| e.get_mut(crate::geom::meshopt::EXTENSION))
        {
            Some(e) => {
                // Compressed: decoded from the shared buffer into the tile's fallback.
                e["buffer"] = json!(external);
                let length = v["byteLength"].as_u64().unwrap_or(0) as usize;
                v["buffer"] = json!(1);
                v["byteOffset"] = json!(buf.reserve_fallback(length));
            }
            None => v["buffer"] = json!(external),
        }
        buf.views.push(v);
    }
    let first_accessor = buf.accessors.len() as u64;
    for a in &model.accessors {
        let mut a = a.clone();
        if let Some(view) = a["bufferView"].as_u64() {
            a["bufferView"] = json!(view + first_view);
        }
        buf.accessors.push(a);
    }
    let renumber = |v: &Value| json!(v.as_u64().unwrap_or(0) + first_accessor);
    let mut out = Vec::new();
    for (material, prim) in &model.primitives {
        let mut prim = prim.clone();
        if let Some(attributes) = prim["attributes"].as_object_mut() {
            for a in attributes.values_mut() {
                *a = renumber(a);
            }
        }
        prim["indices"] = renumber(&prim["indices"]);
        prim["material"] = json!(super::material_index(used, *material));
        out.push(prim);
    }
    out
}

/// The models a build's GLB tiles share: each encoded once and written once, however many
/// tiles (on however many threads) plant it. A variant is the same model in every tile, so
/// its name is its key.
#[derive(Default)]
pub struct Shared {
    models: Mutex<BTreeMap<String, Arc<Written>>>,
}

/// A model and its file, once written.
pub struct Written {
    /// The model.
    pub model: Model,
    /// Its file as the manifest lists it.
    pub file: ManifestFile,
}

impl Shared {
    /// `model` encoded and written under `out` (the first time it is asked for).
    pub fn get(
        &self,
        out: &std::path::Path,
        model: &Mesh,
        atlas: Option<&crate::output::atlas::Atlas>,
        meshopt: bool,
    ) -> std::io::Result<Arc<Written>> {
        // Held while the first encodes and writes: the others need the same model and would
        // only do the same work.
        let mut models = self.models.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(w) = models.get(&model.name) {
            return Ok(w.clone());
        }
        let encoded = encode(model, atlas, meshopt);
        // The tile's writer names the tile if this fails: say which file it was.
        let named = |e: std::io::Error| {
            std::io::Error::new(
                e.kind(),
                format!("{}: {e}", out.join(encoded.path()).display()),
            )
        };
        std::fs::create_dir_all(out.join(MODELS_DIR)).map_err(named)?;
        let file =
            crate::output::write_listed(out, encoded.path(), &[&encoded.bin]).map_err(named)?;
        let w = Arc::new(Written {
            model: encoded,
            file,
        });
        models.insert(model.name.clone(), w.clone());
        Ok(w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::mesh::Mesh;

    /// A quad in two materials' worth of faces, named like a variant.
    fn model() -> Mesh {
        let mut m = Mesh::new("matsu_3".into());
        let frame = crate::generate::mesh::Frame { origin: [0.0, 0.0] };
        let at = |x: f64, y: f64| geo::Coord { x, y };
        let a = m.vertex(frame, at(0.0, 0.0), 0.0);
        let b = m.vertex(frame, at(1.0, 0.0), 0.0);
        let c = m.vertex(frame, at(1.0, 0.0), 2.0);
        let d = m.vertex(frame, at(0.0, 0.0), 2.0);
        let t = m.uv(0.0, 0.0);
        m.face(1, [(a, t), (b, t), (c, t)].into_iter().collect());
        m.face(2, [(a, t), (c, t), (d, t)].into_iter().collect());
        m.finish()
    }

    #[test]
    fn a_grafted_model_points_at_its_file_and_the_tiles_numbers() {
        for meshopt in [false, true] {
            let encoded = encode(&model(), None, meshopt);
            assert_eq!(encoded.path(), "tiles/models/matsu_3.bin");
            let mut buf = Buffer::new(meshopt);
            // Something of the tile's own first.
            buf.floats(&[0.0, 1.0, 2.0], 3, true);
            let mut used = vec![2];
            let prims = graft(&encoded, &mut buf, &mut used);
            assert_eq!(prims.len(), 2);
            // Material 2 was the tile's first; 1 is added after it.
            assert_eq!(used, [2, 1]);
            assert_eq!(prims[0]["material"], 1);
            assert_eq!(prims[1]["material"], 0);
            let buffers = buf.buffers_json();
            let external = buffers
                .as_array()
                .unwrap()
                .iter()
                .position(|b| b["uri"] == "models/matsu_3.bin")
                .expect("the model's buffer");
            assert_eq!(buffers[external]["byteLength"], encoded.bin.len());
            // Every accessor the primitives name is the tile's, over a view of the model's
            // buffer (plain) or decoded from it (compressed).
            for p in &prims {
                for a in p["attributes"]
                    .as_object()
                    .unwrap()
                    .values()
                    .chain([&p["indices"]])
                {
                    let a = &buf.accessors[a.as_u64().unwrap() as usize];
                    let v = &buf.views[a["bufferView"].as_u64().unwrap() as usize];
                    let source = match meshopt {
                        true => &v["extensions"]["EXT_meshopt_compression"]["buffer"],
                        false => &v["buffer"],
                    };
                    assert_eq!(source, &json!(external), "{v}");
                }
            }
            // The tile's own view kept its place.
            assert_eq!(buf.accessors[0]["bufferView"], 0);
        }
    }
}
