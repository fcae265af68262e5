//! One glTF primitive being assembled: a material's faces of a tile's objects, their vertices
//! shared by object, position, uv and normal, ordered for the GPU's cache, and written as
//! accessors with the primitive's JSON.

use serde_json::{json, Value};

use super::quantize;
use crate::generate::mesh::Mesh;
use crate::output::atlas::{self, Atlas};
use crate::output::glb::buffer::Buffer;

/// One primitive being assembled: interleaving is left to the accessors (one view each).
#[derive(Default)]
pub(super) struct Primitive {
    pub(super) positions: Vec<f32>,
    pub(super) normals: Vec<f32>,
    pub(super) uvs: Vec<f32>,
    pub(super) ids: Vec<f32>,
    /// Per vertex, the joint of a skinned primitive (a walker of the tile's crowd); empty
    /// unless faces were added with [`Primitive::joint`] set.
    pub(super) joints: Vec<f32>,
    pub(super) indices: Vec<u32>,
    /// The joint the faces added now follow, in a skinned primitive.
    pub(super) joint: Option<u8>,
    /// The vertices made so far, found by their object's position index.
    seen: Vertices,
    /// How many objects have faces here, and the last one: objects are added in order, so
    /// a new one is one not equal to the last.
    pub(super) features: usize,
    last: Option<u32>,
    /// A face's vertices, kept to save an allocation per face.
    corners: Vec<u32>,
}

/// The vertices of a primitive by (object, position index, uv index, normal bits), without
/// hashing: a vertex is one of the few made from its position (one per normal and texture
/// coordinate), so each position of the current object heads a short chain. A hash map of
/// the four was a tenth of writing a tile of grown trees, and missed the cache on every
/// corner of a tile's million.
#[derive(Default)]
struct Vertices {
    /// Per position index: (object + 1, first vertex + 1) of the object last seen there;
    /// a slot of another object is empty.
    heads: Vec<(u32, u32)>,
    /// Per vertex: the next vertex + 1 made from the same position, 0 at the end.
    next: Vec<u32>,
    /// Per vertex: its uv index (above bit 32 its material: cut-outs of several textures share
    /// the atlas's primitive) and normal bits.
    keys: Vec<(u64, [u32; 3])>,
}

impl Vertices {
    /// The vertex of `object`'s position `p` with uv `t` and normal `n`, or `None` with the
    /// vertex it would be added as registered by [`Vertices::add`].
    fn find(&mut self, object: u32, p: u32, t: u64, n: [u32; 3], positions: usize) -> Option<u32> {
        let p = p as usize;
        if self.heads.len() <= p {
            self.heads.resize(positions.max(p + 1), (0, 0));
        }
        let (owner, mut v) = self.heads[p];
        if owner != object + 1 {
            return None;
        }
        while v != 0 {
            if self.keys[v as usize - 1] == (t, n) {
                return Some(v - 1);
            }
            v = self.next[v as usize - 1];
        }
        None
    }

    /// Registers vertex `v` (the next one) as `object`'s position `p` with uv `t`, normal `n`.
    fn add(&mut self, v: u32, object: u32, p: u32, t: u64, n: [u32; 3]) {
        let slot = &mut self.heads[p as usize];
        let rest = if slot.0 == object + 1 { slot.1 } else { 0 };
        *slot = (object + 1, v + 1);
        self.next.push(rest);
        self.keys.push((t, n));
    }
}

/// The face's unit normal from its corners (Newell's method, in f64 millimetres); `None`
/// for a face with no area.
fn normal(mesh: &Mesh, corners: &[(u32, u32)]) -> Option<[f32; 3]> {
    let mut n = [0.0f64; 3];
    for k in 0..corners.len() {
        let a = mesh.positions[corners[k].0 as usize];
        let b = mesh.positions[corners[(k + 1) % corners.len()].0 as usize];
        let (a, b) = (a.map(|v| v as f64), b.map(|v| v as f64));
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    (len > 1e-9).then(|| n.map(|v| (v / len) as f32))
}

/// Where a face's texture is drawn from: its material's own, or a cell of the cut-out atlas.
#[derive(Clone, Copy)]
pub(super) struct Slot<'a> {
    /// The material's key among the tile's primitives ([`atlas::MATERIAL`] for the atlas).
    pub(super) key: u16,
    /// The atlas and the material's cell in it.
    cell: Option<(&'a Atlas, &'a atlas::Cell)>,
    /// The face's own material (told apart within the atlas's primitive).
    material: u16,
}

impl<'a> Slot<'a> {
    /// The slot of `material`: the atlas's when it has a cell for it.
    pub(super) fn of(atlas: Option<&'a Atlas>, material: u16) -> Slot<'a> {
        match atlas.and_then(|a| a.cell(material).map(|c| (a, c))) {
            Some(cell) => Slot {
                key: atlas::MATERIAL,
                cell: Some(cell),
                material,
            },
            None => Slot {
                key: material,
                cell: None,
                material,
            },
        }
    }
}

impl Primitive {
    /// Adds one face of object `object` of `mesh`, as a fan of triangles (the OBJ's faces
    /// are convex or drawn so that clients fan them).
    pub(super) fn face(
        &mut self,
        object: u32,
        mesh: &Mesh,
        corners: &[(u32, u32)],
        shift: [i64; 3],
        slot: Slot,
    ) {
        let Some(n) = normal(mesh, corners) else {
            return;
        };
        let nb = n.map(f32::to_bits);
        if self.last != Some(object) {
            self.last = Some(object);
            self.features += 1;
        }
        let mut idx = std::mem::take(&mut self.corners);
        idx.clear();
        for &(p, t) in corners {
            // The uv, then the material (cut-outs share the atlas's primitive), then the joint
            // (walkers of one figure share its positions but not their vertices).
            let tk = u64::from(t)
                | u64::from(slot.material) << 32
                | u64::from(self.joint.unwrap_or(0)) << 48;
            let v = match self.seen.find(object, p, tk, nb, mesh.positions.len()) {
                Some(v) => v,
                None => {
                    let v = (self.positions.len() / 3) as u32;
                    self.seen.add(v, object, p, tk, nb);
                    let q = mesh.positions[p as usize];
                    for k in 0..3 {
                        self.positions
                            .push(snap((q[k] - shift[k]) as f64 / 1000.0, METRE_STEPS));
                    }
                    self.normals.extend_from_slice(&n);
                    let uv = mesh.uvs.get(t as usize).copied().unwrap_or([0, 0]);
                    let mut uv = [uv[0] as f64 / 10_000.0, 1.0 - uv[1] as f64 / 10_000.0];
                    if let Some((atlas, cell)) = slot.cell {
                        uv = atlas.uv(cell, uv);
                    }
                    self.uvs.push(snap(uv[0], UV_STEPS));
                    self.uvs.push(snap(uv[1], UV_STEPS));
                    self.ids.push(object as f32);
                    if let Some(j) = self.joint {
                        self.joints.push(f32::from(j));
                    }
                    v
                }
            };
            idx.push(v);
        }
        for k in 1..idx.len().saturating_sub(1) {
            self.indices
                .extend_from_slice(&[idx[0], idx[k], idx[k + 1]]);
        }
        self.corners = idx;
    }
}

impl Primitive {
    /// Orders the triangles for the GPU's vertex cache and then the vertices by first use
    /// (meshoptimizer's two passes): the drawing is the same, the index and vertex codecs
    /// find smaller deltas, and a plain GLB gets the same order as a compressed one.
    pub(super) fn reorder(&mut self) {
        let vertices = self.ids.len();
        if vertices == 0 {
            return;
        }
        // The FIFO optimizer (tipsify): linear in the triangles whatever the mesh. The default
        // one rescores every triangle of each cached vertex per triangle emitted, quadratic
        // on a vertex shared by many (a landmark of 600,000 triangles on three vertices did
        // not finish in minutes).
        meshopt::optimize::optimize_vertex_cache_fifo_in_place(&mut self.indices, vertices, 16);
        let remap = meshopt::optimize::optimize_vertex_fetch_remap(&self.indices, vertices);
        for i in &mut self.indices {
            *i = remap[*i as usize];
        }
        let used = remap.iter().filter(|&&r| r != u32::MAX).count();
        let permute = |data: &[f32], n: usize| {
            let mut out = vec![0.0f32; used * n];
            for (old, &new) in remap.iter().enumerate() {
                if new != u32::MAX {
                    let new = new as usize;
                    out[new * n..new * n + n].copy_from_slice(&data[old * n..old * n + n]);
                }
            }
            out
        };
        self.positions = permute(&self.positions, 3);
        self.normals = permute(&self.normals, 3);
        self.uvs = permute(&self.uvs, 2);
        self.ids = permute(&self.ids, 1);
        if !self.joints.is_empty() {
            self.joints = permute(&self.joints, 1);
        }
    }
}

/// Positions are rounded to 1/1024 m (under half a millimetre from the millimetres they
/// were) and texture coordinates to 1/4096 (an eighth of a texel of a 512-pixel texture):
/// the low bits of their floats are then zero, which meshopt's vertex codec stores in next
/// to nothing. Measured on the example town: positions 326 -> 247 KB, uvs 258 -> 200 KB.
const METRE_STEPS: f64 = 1024.0;
const UV_STEPS: f64 = 4096.0;

/// `v` rounded to the nearest 1/`steps`, as f32 (exact: a float of few significant bits).
fn snap(v: f64, steps: f64) -> f32 {
    ((v * steps).round() / steps) as f32
}

/// A primitive's accessors written to `buf` (positions, normals, uvs, its objects' feature
/// ids when `featured`, indices: in that order) and its JSON; its material is given its index
/// in `used` (added at first use). An instanced model is not `featured`: its rows are its
/// instances'. Positions are shorts on `grid` when given (its node carries the grid's
/// transform), else floats (a skinned crowd: glTF ignores a skinned node's transform).
pub(super) fn primitive_json(
    p: &Primitive,
    material: u16,
    featured: bool,
    grid: Option<&quantize::Grid>,
    buf: &mut Buffer,
    used: &mut Vec<u16>,
) -> Value {
    let vertices = p.positions.len() / 3;
    let pos = match grid {
        Some(g) => buf.short_positions(&g.shorts(&p.positions)),
        None => buf.floats(&p.positions, 3, true),
    };
    let nor = buf.unit_vectors(&p.normals);
    let uv = buf.floats(&p.uvs, 2, false);
    let fid = featured.then(|| buf.floats(&p.ids, 1, false));
    let ind = buf.indices(&p.indices, vertices);
    let m = material_index(used, material);
    let mut prim = json!({
        "attributes": {"POSITION": pos, "NORMAL": nor, "TEXCOORD_0": uv},
        "indices": ind,
        "material": m,
        "mode": 4,
    });
    if !p.joints.is_empty() {
        let (joints, weights) = buf.joints(&p.joints);
        prim["attributes"]["JOINTS_0"] = json!(joints);
        prim["attributes"]["WEIGHTS_0"] = json!(weights);
    }
    if let Some(fid) = fid {
        prim["attributes"]["_FEATURE_ID_0"] = json!(fid);
        prim["extensions"] = json!({"EXT_mesh_features": {"featureIds": [{
            "featureCount": p.features,
            "attribute": 0,
            "propertyTable": 0,
        }]}});
    }
    prim
}

/// The index of `material` among the tile's materials `used` (in first-use order), added
/// at its first use.
pub(super) fn material_index(used: &mut Vec<u16>, material: u16) -> usize {
    match used.iter().position(|&u| u == material) {
        Some(m) => m,
        None => {
            used.push(material);
            used.len() - 1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertex is shared by the corners of one object with the same position, uv and normal,
    /// and by nothing else: not across uvs, normals or objects.
    #[test]
    fn vertices_are_shared_within_an_object_only() {
        let mut v = Vertices::default();
        let n = [1, 2, 3];
        assert_eq!(v.find(0, 5, 1, n, 10), None);
        v.add(0, 0, 5, 1, n);
        assert_eq!(v.find(0, 5, 1, n, 10), Some(0));
        assert_eq!(v.find(0, 5, 2, n, 10), None);
        v.add(1, 0, 5, 2, n);
        assert_eq!(v.find(0, 5, 1, n, 10), Some(0));
        assert_eq!(v.find(0, 5, 2, n, 10), Some(1));
        assert_eq!(v.find(0, 5, 1, [1, 2, 4], 10), None);
        assert_eq!(v.find(0, 6, 1, n, 10), None);
        // The next object: object 0's vertices at position 5 are not its own.
        assert_eq!(v.find(1, 5, 1, n, 10), None);
        v.add(2, 1, 5, 1, n);
        assert_eq!(v.find(1, 5, 1, n, 10), Some(2));
        assert_eq!(v.find(1, 5, 2, n, 10), None);
        // A larger mesh than the first: its positions past the first's are new.
        assert_eq!(v.find(1, 40, 1, n, 50), None);
    }
}
