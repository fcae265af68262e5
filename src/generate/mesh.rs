//! A mesh object as it will be written: positions in millimetres, shared within the object.
//!
//! Positions are rounded to whole millimetres when they are added, and equal positions share
//! one index. That makes shells closed by construction (two faces meeting at an edge use the
//! same two indices), keeps files small, and lets the OBJ writer print integers.

use std::collections::HashMap;

use geo_types::Coord;

/// The vertex and edge maps of a mesh: a fast non-cryptographic hash with a fixed seed
/// (foldhash, hashbrown's own). SipHash spent about a tenth of a single-thread build here;
/// only lookups go through these maps, so no output depends on the hash.
type FastMap<K, V> = HashMap<K, V, foldhash::fast::FixedState>;

/// One face: a material and its corners as (position index, uv index), counter-clockwise
/// seen from outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The material's id in the library.
    pub material: u16,
    /// The corners: (position index, texture coordinate index), counter-clockwise seen from
    /// outside.
    pub corners: Vec<(u32, u32)>,
}

/// One OBJ object (`o <name>`).
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// The OBJ object's name (`machiya_<id>`, `kura_<id>`, `people`, ...).
    pub name: String,
    /// Output frame, millimetres: x east, y up, z south, relative to the dataset origin.
    pub positions: Vec<[i64; 3]>,
    /// Texture coordinates in units of 1/10000.
    pub uvs: Vec<[i32; 2]>,
    /// The faces, in the order they were built.
    pub faces: Vec<Face>,
    pos_index: FastMap<Key<3>, u32>,
    uv_index: FastMap<Key<2>, u32>,
}

/// A map key hashed as one word: an array is hashed as a slice (its length, then its bytes
/// through foldhash's long-input path), which was a tenth of a build with grown trees.
/// Equal keys give equal words; unequal keys may too, which only costs a comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Key<const N: usize>([i64; N]);

impl<const N: usize> std::hash::Hash for Key<N> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        // Odd multipliers spread each coordinate over the word before they are combined.
        const K: [u64; 3] = [
            0x9E37_79B9_7F4A_7C15,
            0xC2B2_AE3D_27D4_EB4F,
            0x1656_67B1_9E37_79F9,
        ];
        let word = (self.0.iter().zip(K)).fold(0u64, |w, (&c, k)| {
            w.rotate_left(23) ^ (c as u64).wrapping_mul(k)
        });
        state.write_u64(word);
    }
}

/// Converts map coordinates (east, north, height; metres) to the output frame.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// The dataset origin (projected metres) the output coordinates are relative to.
    pub origin: [f64; 2],
}

impl Mesh {
    /// An empty mesh named `name`.
    pub fn new(name: String) -> Mesh {
        Mesh {
            name,
            ..Mesh::default()
        }
    }

    /// Adds (or finds) the vertex at map point `p`, height `h`.
    pub fn vertex(&mut self, frame: Frame, p: Coord<f64>, h: f64) -> u32 {
        let key = [
            mm(p.x - frame.origin[0]),
            mm(h),
            mm(-(p.y - frame.origin[1])),
        ];
        self.position_index(key)
    }

    /// The index of a position, added when new.
    fn position_index(&mut self, key: [i64; 3]) -> u32 {
        let next = self.positions.len() as u32;
        if next == 0 {
            // A house or a tree has hundreds of corners: grown from nothing, the map
            // rehashed six times.
            self.pos_index.reserve(256);
        }
        *self.pos_index.entry(Key(key)).or_insert_with(|| {
            self.positions.push(key);
            next
        })
    }

    /// Adds (or finds) a texture coordinate.
    pub fn uv(&mut self, u: f64, v: f64) -> u32 {
        let key = [(u * 10_000.0).round() as i32, (v * 10_000.0).round() as i32];
        self.uv_index_of(key)
    }

    /// The index of a texture coordinate, added when new.
    fn uv_index_of(&mut self, key: [i32; 2]) -> u32 {
        let next = self.uvs.len() as u32;
        if next == 0 {
            self.uv_index.reserve(64);
        }
        *self
            .uv_index
            .entry(Key(key.map(i64::from)))
            .or_insert_with(|| {
                self.uvs.push(key);
                next
            })
    }

    /// Adds a face, dropping corners that collapsed onto their neighbour when rounded to
    /// millimetres; a face left with fewer than three corners is not added.
    pub fn face(&mut self, material: u16, corners: Vec<(u32, u32)>) {
        // In place: a second vector per face was an allocation per face of the whole city.
        let mut c = corners;
        c.dedup_by_key(|k| k.0);
        while c.len() > 1 && c.first().map(|f| f.0) == c.last().map(|l| l.0) {
            c.pop();
        }
        if c.len() >= 3 {
            self.faces.push(Face {
                material,
                corners: c,
            });
        }
    }

    /// Empties the mesh for the next one of the same kind, keeping its storage (a tile's
    /// grown trees are meshed one by one into the same scratch mesh).
    pub fn clear(&mut self) {
        self.positions.clear();
        self.uvs.clear();
        self.faces.clear();
        self.pos_index.clear();
        self.uv_index.clear();
    }

    /// Releases the lookup tables once the mesh is complete.
    pub fn finish(mut self) -> Mesh {
        self.pos_index = FastMap::default();
        self.uv_index = FastMap::default();
        self
    }
}

/// Rounds metres to whole millimetres.
pub fn mm(v: f64) -> i64 {
    (v * 1000.0).round() as i64
}

/// Directed edges not matched by as many opposite edges: empty for a closed, consistently
/// oriented (watertight) mesh. An edge used twice each way is allowed: a lot whose outline
/// touches itself at a point (a pinch) gives a house whose shell meets itself there.
pub fn open_edges(mesh: &Mesh) -> Vec<(u32, u32)> {
    open_edges_of(&mesh.faces)
}

/// [`open_edges`] of some of a mesh's faces (one part of a model).
pub fn open_edges_of(faces: &[Face]) -> Vec<(u32, u32)> {
    let mut count: FastMap<(u32, u32), i32> = FastMap::default();
    for f in faces {
        let n = f.corners.len();
        for i in 0..n {
            let (a, b) = (f.corners[i].0, f.corners[(i + 1) % n].0);
            *count.entry((a, b)).or_default() += 1;
        }
    }
    let mut bad: Vec<(u32, u32)> = count
        .iter()
        .filter(|((a, b), n)| count.get(&(*b, *a)) != Some(*n))
        .map(|(e, _)| *e)
        .collect();
    bad.sort();
    bad
}

impl Mesh {
    /// Adds every face of `other` (a mesh in the same frame), sharing equal positions and
    /// texture coordinates with those already here.
    pub fn append(&mut self, other: &Mesh) {
        let pos: Vec<u32> = other
            .positions
            .iter()
            .map(|&key| self.position_index(key))
            .collect();
        let uv: Vec<u32> = other.uvs.iter().map(|&key| self.uv_index_of(key)).collect();
        for f in &other.faces {
            self.faces.push(Face {
                material: f.material,
                corners: f
                    .corners
                    .iter()
                    .map(|&(p, t)| (pos[p as usize], uv[t as usize]))
                    .collect(),
            });
        }
    }

    /// About how many bytes the mesh takes in an OBJ file (a vertex line ~26 bytes, a
    /// texture coordinate ~17, a face corner ~14): what a tile's budget is counted in.
    pub fn obj_bytes_estimate(&self) -> u64 {
        let corners: usize = self.faces.iter().map(|f| f.corners.len()).sum();
        (26 * self.positions.len() + 17 * self.uvs.len() + 14 * corners + 2 * self.faces.len())
            as u64
    }
}
