//! A mesh object as it will be written: positions in millimetres, shared within the object.
//!
//! Positions are rounded to whole millimetres when they are added, and equal positions share
//! one index. That makes shells closed by construction (two faces meeting at an edge use the
//! same two indices), keeps files small, and lets the OBJ writer print integers.

use geo_types::Coord;

use crate::model::object::{ObjectKind, Owner};

/// The positions or texture coordinates of a mesh by value: a table of indices into the
/// mesh's own list, hashed by [`word`]. An entry is 4 bytes, not the key's 24 plus the
/// index: a tile of grown trees holds a million positions, and a map of keys missed the
/// cache on every corner. Only lookups go through it, so no output depends on the hash.
type IndexTable = hashbrown::HashTable<u32>;

/// A key's hash: its coordinates spread by odd multipliers and folded into one word, then
/// mixed (the table takes its bucket from the low bits and its tag from the top seven).
fn word<const N: usize>(key: [i64; N]) -> u64 {
    const K: [u64; 3] = [
        0x9E37_79B9_7F4A_7C15,
        0xC2B2_AE3D_27D4_EB4F,
        0x1656_67B1_9E37_79F9,
    ];
    let mut w = (key.iter().zip(K)).fold(0u64, |w, (&c, k)| {
        w.rotate_left(23) ^ (c as u64).wrapping_mul(k)
    });
    // The finaliser of MurmurHash3: every bit of the word reaches every bit of the hash.
    w ^= w >> 33;
    w = w.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    w ^= w >> 33;
    w = w.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    w ^ (w >> 33)
}

/// The index of `key` in `list`, added to both when new.
fn index_of<const N: usize, T: Copy + PartialEq>(
    table: &mut IndexTable,
    list: &mut Vec<T>,
    key: T,
    wide: impl Fn(T) -> [i64; N],
) -> u32 {
    let next = list.len() as u32;
    if next == 0 && table.capacity() == 0 {
        // A house or a tree has hundreds of corners: grown from nothing, the table
        // rehashed six times.
        table.reserve(256, |&i| word(wide(list[i as usize])));
    }
    let hash = word(wide(key));
    let found = {
        let list = &*list;
        match table.entry(
            hash,
            |&i| list[i as usize] == key,
            |&i| word(wide(list[i as usize])),
        ) {
            hashbrown::hash_table::Entry::Occupied(e) => Some(*e.get()),
            hashbrown::hash_table::Entry::Vacant(v) => {
                v.insert(next);
                None
            }
        }
    };
    found.unwrap_or_else(|| {
        list.push(key);
        next
    })
}

/// A face's corners: up to four kept in the face itself, more on the heap.
pub type Corners = smallvec::SmallVec<[(u32, u32); 4]>;

/// One face: a material and its corners as (position index, uv index), counter-clockwise
/// seen from outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// The material's id in the library.
    pub material: u16,
    /// The corners: (position index, texture coordinate index), counter-clockwise seen from
    /// outside.
    pub corners: Corners,
}

/// One OBJ object (`o <name>`).
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    /// The OBJ object's name (`machiya_<id>`, `kura_<id>`, `people`, ...): what the files
    /// call it, never parsed back.
    pub name: String,
    /// What it is.
    pub kind: ObjectKind,
    /// Whose it is (its lot, footprint, fence line, garden area or landmark).
    pub owner: Owner,
    /// Its template's parts as built, each from its first face to the next one's.
    pub parts: Vec<MeshPart>,
    /// What a city model says of a building (houses, kura, halls).
    pub building: Option<BuildingFacts>,
    /// Output frame, millimetres: x east, y up, z south, relative to the dataset origin.
    pub positions: Vec<[i64; 3]>,
    /// Texture coordinates in units of 1/10000.
    pub uvs: Vec<[i32; 2]>,
    /// The faces, in the order they were built.
    pub faces: Vec<Face>,
    pos_index: IndexTable,
    uv_index: IndexTable,
}

/// One part of a template as built into a mesh: its faces run from `first_face` to the next
/// part's first face (or the mesh's end).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshPart {
    /// The part's name in its template.
    pub name: String,
    /// Its first face.
    pub first_face: u32,
    /// Whether a city model holds it as an installation (the template says so).
    pub installation: bool,
}

/// What a city model says of a building, from its template and its feature.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BuildingFacts {
    /// Storeys above ground (the data's, else the template's), when known.
    pub storeys: Option<u32>,
    /// The roof's form (the template's `roof_type`), when it says.
    pub roof_type: Option<String>,
    /// The ground it stands on, metres.
    pub ground: f64,
    /// The template it was built from.
    pub template: String,
}

/// Converts map coordinates (east, north, height; metres) to the output frame.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// The dataset origin (projected metres) the output coordinates are relative to.
    pub origin: [f64; 2],
}

impl Mesh {
    /// An empty mesh named `name`, of no kind (a template or tree alone).
    pub fn new(name: String) -> Mesh {
        Mesh {
            name,
            ..Mesh::default()
        }
    }

    /// An empty mesh of a city's object: named `name`, of `kind`, `owner`'s.
    pub fn object(name: String, kind: ObjectKind, owner: Owner) -> Mesh {
        Mesh {
            name,
            kind,
            owner,
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
        index_of(&mut self.pos_index, &mut self.positions, key, |k| k)
    }

    /// Adds (or finds) a texture coordinate.
    pub fn uv(&mut self, u: f64, v: f64) -> u32 {
        let key = [(u * 10_000.0).round() as i32, (v * 10_000.0).round() as i32];
        self.uv_index_of(key)
    }

    /// The index of a texture coordinate, added when new.
    fn uv_index_of(&mut self, key: [i32; 2]) -> u32 {
        index_of(&mut self.uv_index, &mut self.uvs, key, |k| k.map(i64::from))
    }

    /// Adds a face, dropping corners that collapsed onto their neighbour when rounded to
    /// millimetres; a face left with fewer than three corners is not added.
    pub fn face(&mut self, material: u16, corners: Corners) {
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
        self.pos_index = IndexTable::default();
        self.uv_index = IndexTable::default();
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
    // Every house part is checked, and a map of edge counts (grown, filled and walked per
    // part) was a twentieth of a build's CPU. Instead the edges running from a lower to a
    // higher index and those running back, each as the pair (lower, higher) in one word, are
    // sorted: the shell is closed when the two lists are equal (as many edges each way
    // between every two corners), and where they differ the run counts show which pair.
    let (mut up, mut down) = (Vec::new(), Vec::new());
    for f in faces {
        let n = f.corners.len();
        for i in 0..n {
            let (a, b) = (f.corners[i].0, f.corners[(i + 1) % n].0);
            match a.cmp(&b) {
                std::cmp::Ordering::Less => up.push(pair(a, b)),
                std::cmp::Ordering::Greater => down.push(pair(b, a)),
                // An edge from a corner to itself is its own opposite.
                std::cmp::Ordering::Equal => {}
            }
        }
    }
    up.sort_unstable();
    down.sort_unstable();
    if up == down {
        return Vec::new();
    }
    let mut bad = Vec::new();
    let (mut i, mut j) = (0, 0);
    loop {
        let next = match (up.get(i), down.get(j)) {
            (Some(&u), Some(&d)) => u.min(d),
            (Some(&e), None) | (None, Some(&e)) => e,
            (None, None) => break,
        };
        let nu = up[i..].iter().take_while(|&&e| e == next).count();
        let nd = down[j..].iter().take_while(|&&e| e == next).count();
        if nu != nd {
            let (lo, hi) = ((next >> 32) as u32, next as u32);
            if nu > 0 {
                bad.push((lo, hi));
            }
            if nd > 0 {
                bad.push((hi, lo));
            }
        }
        (i, j) = (i + nu, j + nd);
    }
    bad.sort_unstable();
    bad
}

/// Two corner indices in one word, the first in the high half (so words sort as pairs).
fn pair(lo: u32, hi: u32) -> u64 {
    (u64::from(lo) << 32) | u64::from(hi)
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Directed edges not matched by as many opposite ones, counted with a map: what
    /// [`open_edges_of`] computes by sorting.
    fn open_edges_by_counting(faces: &[Face]) -> Vec<(u32, u32)> {
        let mut count = std::collections::BTreeMap::<(u32, u32), i32>::new();
        for f in faces {
            let n = f.corners.len();
            for i in 0..n {
                *count
                    .entry((f.corners[i].0, f.corners[(i + 1) % n].0))
                    .or_default() += 1;
            }
        }
        count
            .iter()
            .filter(|&(&(a, b), n)| count.get(&(b, a)) != Some(n))
            .map(|(&e, _)| e)
            .collect()
    }

    #[test]
    fn a_cube_is_closed_and_loses_its_closure_with_a_face() {
        let quad = |c: [u32; 4]| Face {
            material: 0,
            corners: c.iter().map(|&p| (p, 0)).collect(),
        };
        // Corners 0-3 the bottom, 4-7 the top; every face counter-clockwise from outside.
        let mut cube = vec![
            quad([0, 3, 2, 1]),
            quad([4, 5, 6, 7]),
            quad([0, 1, 5, 4]),
            quad([1, 2, 6, 5]),
            quad([2, 3, 7, 6]),
            quad([3, 0, 4, 7]),
        ];
        assert_eq!(open_edges_of(&cube), vec![]);
        cube.pop();
        assert_eq!(open_edges_of(&cube), vec![(0, 3), (3, 7), (4, 0), (7, 4)]);
    }

    proptest! {
        /// Sorting finds exactly the edges a count by map finds, with edges used several
        /// times each way (a pinched shell) and faces that repeat.
        #[test]
        fn open_edges_by_sorting_match_a_count(
            faces in proptest::collection::vec(proptest::collection::vec(0u32..6, 3..6), 0..12)
        ) {
            let faces: Vec<Face> = faces
                .iter()
                .map(|c| Face { material: 0, corners: c.iter().map(|&p| (p, 0)).collect() })
                .collect();
            prop_assert_eq!(open_edges_of(&faces), open_edges_by_counting(&faces));
        }

        /// The index tables number positions and texture coordinates by first use, equal keys
        /// share an index and unequal ones never do (a small range makes most keys repeat,
        /// and a thousand keys make the table grow), and a cleared mesh starts again from 0.
        #[test]
        fn equal_keys_share_an_index_in_order_of_first_use(
            keys in proptest::collection::vec((-3i64..3, -3i64..3, -3i64..3), 1..1000)
        ) {
            let mut mesh = Mesh::new("t".into());
            for round in 0..2 {
                let mut first: Vec<[i64; 3]> = Vec::new();
                for &(x, y, z) in &keys {
                    let key = [x * 1_000_003, y, z];
                    let i = mesh.position_index(key);
                    let t = mesh.uv_index_of([x as i32, (y + z) as i32]);
                    let expect = first.iter().position(|&k| k == key).unwrap_or_else(|| {
                        first.push(key);
                        first.len() - 1
                    });
                    prop_assert_eq!(i as usize, expect, "round {}", round);
                    prop_assert_eq!(mesh.uvs[t as usize], [x as i32, (y + z) as i32]);
                }
                prop_assert_eq!(&mesh.positions, &first);
                mesh.clear();
            }
        }
    }
}
