//! The tree mesher shared by both growers: one [`Skeleton`] in, a level of detail out.
//!
//! - LOD0: tapered tubes with rings shared along each branch (`mesh.sides` sides, half as
//!   many on twigs), leaf cards at every tip placed by the golden angle (or needles), the
//!   turtle's leaf polygons.
//! - LOD1: three-sided tubes; branches thinner than `mesh.twig` x the trunk's radius are
//!   pruned and each pruned twig system becomes two crossed leaf cards over its extent.
//! - LOD2: two crossed billboards the size of the tree carrying the species' billboard
//!   texture (rendered from the same species by the texture maker).
//!
//! Every LOD is meshed from the same skeleton and none depends on another, so LOD0 is the
//! same whatever LODs are asked for.

use geo_types::Coord;

use smallvec::smallvec;

use super::mesh::{Frame, Mesh};
use crate::growers::lsystem::presets::GOLDEN_ANGLE;
use crate::growers::skeleton::Skeleton;
use crate::growers::v3::{self, V3};
use crate::templates::species::{LeafKind, MeshSpec, Species, SAMPLE_SEED};

/// A level of detail.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Lod {
    /// Full tubes and leaves.
    Full,
    /// Fewer sides, twigs as leaf cards.
    Reduced,
    /// Crossed billboards.
    Billboard,
}

impl Lod {
    /// 0, 1 or 2.
    pub fn number(self) -> u8 {
        match self {
            Lod::Full => 0,
            Lod::Reduced => 1,
            Lod::Billboard => 2,
        }
    }

    /// The LOD of a number from 0 to 2.
    pub fn from_number(n: u8) -> Option<Lod> {
        [Lod::Full, Lod::Reduced, Lod::Billboard]
            .get(n as usize)
            .copied()
    }
}

/// The materials and leaf size a tree is meshed with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// Bark.
    pub bark: u16,
    /// Leaves this season; `None` for bare branches.
    pub leaf: Option<u16>,
    /// A leaf card's edge, metres.
    pub leaf_size: f64,
    /// The billboard texture of LOD2.
    pub billboard: u16,
}

impl Look {
    /// A species at `height` metres in `season`: its leaf cards grow with the square root of
    /// the height (a taller tree has more, not only larger, leaves).
    pub fn of(species: &Species, height: f64, season: &str) -> Look {
        Look {
            bark: species.mesh.bark,
            leaf: species.leaf_material(season),
            leaf_size: species.mesh.leaf_size * (height / species.nominal_height()).sqrt(),
            billboard: species.billboard,
        }
    }
}

/// Where a tree stands: the skeleton's origin goes to `at` on the ground, turned by
/// `rotation` radians counter-clockwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Map point of the trunk.
    pub at: Coord<f64>,
    /// Ground elevation there.
    pub ground: f64,
    /// Turn about the vertical, radians.
    pub rotation: f64,
}

pub(super) struct Put {
    place: Placement,
    frame: Frame,
    cos: f64,
    sin: f64,
}

impl Put {
    pub(super) fn new(place: Placement, frame: Frame) -> Put {
        Put {
            place,
            frame,
            cos: place.rotation.cos(),
            sin: place.rotation.sin(),
        }
    }

    pub(super) fn vertex(&self, mesh: &mut Mesh, p: V3) -> u32 {
        let x = self.place.at.x + p[0] * self.cos - p[1] * self.sin;
        let y = self.place.at.y + p[0] * self.sin + p[1] * self.cos;
        mesh.vertex(self.frame, Coord { x, y }, self.place.ground + p[2])
    }
}

/// Meshes `sk` at `lod` into `mesh`.
pub fn mesh_tree(
    sk: &Skeleton,
    spec: &MeshSpec,
    look: Look,
    lod: Lod,
    place: Placement,
    frame: Frame,
    mesh: &mut Mesh,
) {
    let put = Put::new(place, frame);
    match lod {
        Lod::Billboard => billboard(sk, look, &put, mesh),
        Lod::Full | Lod::Reduced => {
            let shape = Shape::of(sk, spec, lod);
            tubes(sk, &shape, look, &put, mesh);
            leaves(sk, &shape, spec, look, lod, &put, mesh);
        }
    }
}

/// The frame along each branch and what a level keeps.
struct Shape {
    kids: Vec<Vec<u32>>,
    dir: Vec<V3>,
    ring_dir: Vec<V3>,
    reference: Vec<V3>,
    keep: Vec<bool>,
    sides: Vec<u8>,
    /// Distance along the branch from its root, for the bark's v coordinate.
    length: Vec<f64>,
}

impl Shape {
    fn of(sk: &Skeleton, spec: &MeshSpec, lod: Lod) -> Shape {
        let n = sk.nodes.len();
        let mut kids = vec![Vec::new(); n];
        for (i, node) in sk.nodes.iter().enumerate() {
            if let Some(p) = node.parent {
                kids[p as usize].push(i as u32);
            }
        }
        let mut dir = vec![[0.0, 0.0, 1.0]; n];
        let mut length = vec![0.0; n];
        for (i, node) in sk.nodes.iter().enumerate() {
            if let Some(p) = node.parent {
                let p = p as usize;
                let d = v3::sub(node.at, sk.nodes[p].at);
                dir[i] = v3::unit(d).unwrap_or(dir[p]);
                length[i] = length[p] + v3::norm(d);
            }
        }
        for i in 0..n {
            if sk.nodes[i].parent.is_none() {
                if let Some(&k) = kids[i].first() {
                    dir[i] = dir[k as usize];
                }
            }
        }
        let ring_dir: Vec<V3> = (0..n)
            .map(|i| match (sk.nodes[i].parent, kids[i].first()) {
                (Some(_), Some(&k)) => v3::unit(v3::add(dir[i], dir[k as usize])).unwrap_or(dir[i]),
                _ => dir[i],
            })
            .collect();
        // Parallel transport of a reference vector down each branch keeps the rings from
        // twisting.
        let mut reference = vec![[1.0, 0.0, 0.0]; n];
        for i in 0..n {
            let d = ring_dir[i];
            reference[i] = match sk.nodes[i].parent {
                None => v3::perpendicular(d),
                Some(p) => {
                    let r = reference[p as usize];
                    v3::unit(v3::sub(r, v3::scale(d, v3::dot(r, d))))
                        .unwrap_or_else(|| v3::perpendicular(d))
                }
            };
        }
        let base = sk
            .nodes
            .iter()
            .filter(|n| n.parent.is_none())
            .map(|n| n.radius)
            .fold(0.0, f64::max);
        let threshold = spec.twig * base;
        let mut keep = vec![true; n];
        let mut sides = vec![spec.sides; n];
        for i in 0..n {
            let twig = sk.nodes[i].radius < threshold;
            let parent_kept = sk.nodes[i].parent.is_none_or(|p| keep[p as usize]);
            match lod {
                Lod::Reduced => {
                    keep[i] = parent_kept && (!twig || sk.nodes[i].parent.is_none());
                    sides[i] = 3;
                }
                _ => {
                    if twig {
                        sides[i] = (spec.sides / 2).max(3);
                    }
                }
            }
        }
        Shape {
            kids,
            dir,
            ring_dir,
            reference,
            keep,
            sides,
            length,
        }
    }
}

/// Appends the corners of a ring to `pool`: position indices, in counter-clockwise order
/// about `d`. Returns where they start.
#[allow(clippy::too_many_arguments)]
fn ring(
    put: &Put,
    mesh: &mut Mesh,
    pool: &mut Vec<u32>,
    at: V3,
    d: V3,
    reference: V3,
    r: f64,
    sides: u8,
) -> usize {
    let side = v3::cross(d, reference);
    let start = pool.len();
    pool.extend((0..sides).map(|k| {
        let a = std::f64::consts::TAU * f64::from(k) / f64::from(sides);
        let off = v3::add(
            v3::scale(reference, r * a.cos()),
            v3::scale(side, r * a.sin()),
        );
        put.vertex(mesh, v3::add(at, off))
    }));
    start
}

/// One tube per kept edge, from the parent's ring (or a ring of the child's own size where it
/// forks off) to the child's ring.
fn tubes(sk: &Skeleton, s: &Shape, look: Look, put: &Put, mesh: &mut Mesh) {
    let n = sk.nodes.len();
    // Every ring's corners in one pool; `own[i]` is where node i's ring starts.
    let mut pool: Vec<u32> = Vec::new();
    let mut own: Vec<Option<usize>> = vec![None; n];
    // The bark's texture coordinates of a tube's two rings, each looked up once, in the order
    // the faces first ask for them (so they are numbered as before).
    let (mut lo, mut hi): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
    for i in 0..n {
        let Some(p) = sk.nodes[i].parent.map(|p| p as usize) else {
            continue;
        };
        if !s.keep[i] {
            continue;
        }
        let node = &sk.nodes[i];
        let sides = s.sides[i];
        let continues = s.kids[p].first() == Some(&(i as u32)) && s.sides[p] == sides;
        let start = if continues {
            match own[p] {
                Some(at) => at,
                None => {
                    let q = &sk.nodes[p];
                    let at = ring(
                        put,
                        mesh,
                        &mut pool,
                        q.at,
                        s.ring_dir[p],
                        s.reference[p],
                        q.radius,
                        sides,
                    );
                    own[p] = Some(at);
                    at
                }
            }
        } else {
            let r = node.radius.min(sk.nodes[p].radius.max(node.radius));
            ring(
                put,
                mesh,
                &mut pool,
                sk.nodes[p].at,
                s.dir[i],
                s.reference[i],
                r,
                sides,
            )
        };
        let end = ring(
            put,
            mesh,
            &mut pool,
            node.at,
            s.ring_dir[i],
            s.reference[i],
            node.radius,
            sides,
        );
        own[i] = Some(end);
        let (v0, v1) = (s.length[p] / BARK_REPEAT, s.length[i] / BARK_REPEAT);
        let m = usize::from(sides);
        lo.clear();
        lo.resize(m + 1, u32::MAX);
        hi.clear();
        hi.resize(m + 1, u32::MAX);
        let uv = |row: &mut Vec<u32>, k: usize, v: f64, mesh: &mut Mesh| {
            if row[k] == u32::MAX {
                row[k] = mesh.uv(k as f64 / m as f64, v);
            }
            row[k]
        };
        for k in 0..m {
            let corners = smallvec![
                (pool[start + k], uv(&mut lo, k, v0, mesh)),
                (pool[start + (k + 1) % m], uv(&mut lo, k + 1, v0, mesh)),
                (pool[end + (k + 1) % m], uv(&mut hi, k + 1, v1, mesh)),
                (pool[end + k], uv(&mut hi, k, v1, mesh)),
            ];
            mesh.face(look.bark, corners);
        }
    }
}

/// Metres of branch per repeat of the bark texture.
const BARK_REPEAT: f64 = 1.5;

/// A double-sided quad: centre, two half-axes.
fn card(mesh: &mut Mesh, put: &Put, material: u16, c: V3, a: V3, b: V3) {
    let p = |s: f64, t: f64| v3::add(c, v3::add(v3::scale(a, s), v3::scale(b, t)));
    let q = [
        put.vertex(mesh, p(-1.0, -1.0)),
        put.vertex(mesh, p(1.0, -1.0)),
        put.vertex(mesh, p(1.0, 1.0)),
        put.vertex(mesh, p(-1.0, 1.0)),
    ];
    let uv = [
        mesh.uv(0.0, 0.0),
        mesh.uv(1.0, 0.0),
        mesh.uv(1.0, 1.0),
        mesh.uv(0.0, 1.0),
    ];
    mesh.face(material, (0..4).map(|k| (q[k], uv[k])).collect());
    mesh.face(
        material,
        [1usize, 0, 3, 2].iter().map(|&k| (q[k], uv[k])).collect(),
    );
}

/// Leaf cards at the tips (LOD0, and LOD1's kept tips with half as many), crossed cards over
/// each pruned twig system (LOD1), and the turtle's polygons.
fn leaves(
    sk: &Skeleton,
    s: &Shape,
    spec: &MeshSpec,
    look: Look,
    lod: Lod,
    put: &Put,
    mesh: &mut Mesh,
) {
    let Some(leaf) = look.leaf else {
        return;
    };
    let size = look.leaf_size;
    let per_tip = match lod {
        Lod::Reduced => spec.per_tip.div_ceil(2),
        _ => spec.per_tip,
    };
    // Leaves on each tip and on the `leaf_nodes - 1` nodes above it, up to a fork.
    let mut leafy = vec![false; sk.nodes.len()];
    for i in 0..sk.nodes.len() {
        if s.kids[i].is_empty() && s.keep[i] {
            let mut j = i;
            for _ in 0..spec.leaf_nodes.max(1) {
                leafy[j] = true;
                match sk.nodes[j].parent {
                    Some(p) if s.kids[p as usize].len() == 1 => j = p as usize,
                    _ => break,
                }
            }
        }
    }
    for (i, &leafy) in leafy.iter().enumerate() {
        if !s.keep[i] || sk.nodes[i].parent.is_none() {
            continue;
        }
        let pruned_kids = s.kids[i].iter().any(|&k| !s.keep[k as usize]);
        if lod == Lod::Reduced && pruned_kids {
            // Roots carry no leaves: their pruned twigs become nothing.
            for &k in s.kids[i]
                .iter()
                .filter(|&&k| !s.keep[k as usize] && sk.nodes[k as usize].at[2] >= 0.0)
            {
                clump(sk, s, k as usize, leaf, size, put, mesh);
            }
        }
        // Roots carry no leaves.
        if !leafy || spec.leaf == LeafKind::None || sk.nodes[i].at[2] < 0.0 {
            continue;
        }
        let (at, d, r) = (sk.nodes[i].at, s.dir[i], s.reference[i]);
        for k in 0..per_tip {
            let theta = (f64::from(k) * GOLDEN_ANGLE).to_radians();
            let out = v3::rotate(r, d, theta);
            let t = (f64::from(k) + 0.5) / f64::from(per_tip.max(1));
            match spec.leaf {
                LeafKind::Needles => {
                    let along = v3::unit(v3::add(d, v3::scale(out, 0.6))).unwrap_or(d);
                    let c = v3::add(at, v3::scale(along, size * 0.5));
                    let across = v3::scale(v3::cross(along, out), size * 0.18);
                    card(mesh, put, leaf, c, across, v3::scale(along, size * 0.5));
                }
                _ => {
                    let c = v3::add(
                        at,
                        v3::add(
                            v3::scale(out, size * 0.45 * t.sqrt()),
                            v3::scale(d, size * 0.3 * t),
                        ),
                    );
                    let up = v3::unit(v3::add(d, out)).unwrap_or(d);
                    let side = v3::unit(v3::cross(up, out)).unwrap_or(r);
                    card(
                        mesh,
                        put,
                        leaf,
                        c,
                        v3::scale(side, size * 0.5),
                        v3::scale(up, size * 0.5),
                    );
                }
            }
        }
    }
    for poly in &sk.polygons {
        let corners: Vec<u32> = poly.corners.iter().map(|&p| put.vertex(mesh, p)).collect();
        let uv = mesh.uv(0.5, 0.5);
        mesh.face(leaf, corners.iter().map(|&c| (c, uv)).collect());
        mesh.face(leaf, corners.iter().rev().map(|&c| (c, uv)).collect());
    }
}

/// Two crossed cards over the twig system that starts at node `root`.
fn clump(sk: &Skeleton, s: &Shape, root: usize, leaf: u16, size: f64, put: &Put, mesh: &mut Mesh) {
    let mut stack = vec![root];
    let mut pts = Vec::new();
    while let Some(i) = stack.pop() {
        pts.push(sk.nodes[i].at);
        stack.extend(s.kids[i].iter().map(|&k| k as usize));
    }
    let c = v3::scale(
        pts.iter().fold([0.0; 3], |a, &p| v3::add(a, p)),
        1.0 / pts.len() as f64,
    );
    let e = pts
        .iter()
        .map(|&p| v3::dist(p, c))
        .fold(size * 0.5, f64::max);
    let d = s.dir[root];
    let a = v3::perpendicular(d);
    let b = v3::cross(d, a);
    card(mesh, put, leaf, c, v3::scale(a, e), v3::scale(d, e));
    card(mesh, put, leaf, c, v3::scale(b, e), v3::scale(d, e));
}

/// The extent LOD2 and the billboard textures frame a tree by ([`Skeleton::extent`]).
pub fn extent(sk: &Skeleton, margin: f64) -> (f64, f64) {
    sk.extent(margin)
}

/// LOD2: crossed billboards over the skeleton's extent.
fn billboard(sk: &Skeleton, look: Look, put: &Put, mesh: &mut Mesh) {
    let (r, h) = extent(sk, look.leaf.map_or(0.0, |_| look.leaf_size));
    crossed(r, h, look.billboard, put, mesh);
}

/// Two crossed quads `2 r` wide and `h` tall, each seen from both sides.
fn crossed(r: f64, h: f64, material: u16, put: &Put, mesh: &mut Mesh) {
    let r = r.max(h * 0.1);
    let c = [0.0, 0.0, h / 2.0];
    card(mesh, put, material, c, [r, 0.0, 0.0], [0.0, 0.0, h / 2.0]);
    card(mesh, put, material, c, [0.0, r, 0.0], [0.0, 0.0, h / 2.0]);
}

/// A species' billboard standing in for a grown tree: crossed quads of the crown's radius and
/// the tree's height, as LOD2 frames the same species.
pub fn billboard_of(
    crown: f64,
    height: f64,
    material: u16,
    place: Placement,
    frame: Frame,
    mesh: &mut Mesh,
) {
    crossed(crown, height, material, &Put::new(place, frame), mesh);
}

/// Triangles of a mesh's faces (a face of n corners is n - 2).
pub fn triangles(mesh: &Mesh) -> usize {
    mesh.faces.iter().map(|f| f.corners.len() - 2).sum()
}

/// The sample tree of a species (seed [`SAMPLE_SEED`], the middle of its height range, roots
/// as the city shows them) meshed at LOD0 in `season`, standing at the origin: the billboard
/// textures are rendered from it and `<out>/species/` holds it. Also its extent.
pub fn sample_lod0(species: &Species, season: &str) -> Result<(Mesh, (f64, f64)), String> {
    let h = species.nominal_height();
    let mut rng = crate::rng::feature_rng(SAMPLE_SEED, "tree", &species.name);
    let grown = species.grow_in_city(h, &mut rng)?;
    let look = Look::of(species, h, season);
    let mut mesh = Mesh::new(format!("{}_lod0", species.name));
    let place = Placement {
        at: Coord { x: 0.0, y: 0.0 },
        ground: 0.0,
        rotation: 0.0,
    };
    let frame = Frame { origin: [0.0, 0.0] };
    mesh_tree(
        &grown.skeleton,
        &species.mesh,
        look,
        Lod::Full,
        place,
        frame,
        &mut mesh,
    );
    let margin = look.leaf.map_or(0.0, |_| look.leaf_size);
    Ok((mesh.finish(), extent(&grown.skeleton, margin)))
}
