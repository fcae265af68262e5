//! The levels of detail (詳細度) above the leaf tiles: each inner node of the tileset has
//! content of its own, made from its children's (the leaves' GLB files read back, or the
//! level below's content), which its children replace as the viewer comes closer
//! (`refine: REPLACE`).
//!
//! What a parent holds: houses, kura and halls as massing ([`massing`]: walls and a gable
//! roof on the first level, flat-topped boxes above it), the other surfaces (ground,
//! streets, walls, bark, stones) simplified by meshoptimizer with small parts pruned, the
//! cut-outs (leaves, billboards) thinned to a quarter of their cards per level (or fewer,
//! for cards so small they stay within the level's target) with each kept card scaled to
//! cover as much, no people, and no building within half the level's target. Surfaces are
//! coloured per vertex (a texture by its mean colour) and drawn by one primitive; each
//! cut-out material keeps its texture.
//! Every object drawn keeps its metadata row (and only those keep theirs), so a click on a
//! distant house names its lot.
//!
//! The `geometricError` of a parent is measured, not guessed: the largest of its children's
//! errors, plus the largest distance this level moves a surface (a building's vertex from
//! its massing, meshoptimizer's own error, half a kept card's size, the people and the
//! buildings left out).

pub mod colours;
mod hidden;
pub mod massing;
pub mod read;
mod simplify;
pub mod write;

use std::collections::BTreeMap;

use rayon::prelude::*;

use crate::output::features::Feature;
use massing::Mass;

/// The kinds drawn as massing on the levels above the leaves.
pub const MASSED: &[&str] = &["machiya", "kura", "hall", "footprint"];

/// Cards kept per level: one in this many at least, each scaled by its square root.
const THINNING: usize = 4;

/// The most cards one kept card stands for on a level.
const MAX_THINNING: usize = 64;

/// One card kept in how many, for a card of `size` metres on a level simplified to `target`:
/// [`THINNING`], or as many more as keep the scaled card within `target`.
fn thinning(size: f64, target: f64) -> usize {
    if size <= 0.0 {
        return MAX_THINNING;
    }
    let k = (target / size).powi(2).floor();
    (k.min(MAX_THINNING as f64) as usize).max(THINNING)
}

/// Triangles with per-vertex data; positions in the root's frame (z up, metres).
#[derive(Debug, Clone, Default)]
pub struct Part {
    /// Root frame, z up, metres.
    pub positions: Vec<[f64; 3]>,
    /// Linear RGBA (solid surfaces).
    pub colours: Vec<[u8; 4]>,
    /// Texture coordinates (cut-outs).
    pub uvs: Vec<[f32; 2]>,
    /// Each vertex's row in the metadata table.
    pub ids: Vec<u32>,
    /// Triangles, three vertices each.
    pub indices: Vec<u32>,
}

impl Part {
    /// Appends vertex `v` of `from` to the triangle list (its position, colour or texture
    /// coordinates, whichever `from` has, and row, once: `seen` maps `from`'s vertices to
    /// those added, `u32::MAX` for none yet).
    fn keep(&mut self, from: &Part, v: u32, seen: &mut [u32]) {
        let v = v as usize;
        if seen[v] == u32::MAX {
            seen[v] = self.positions.len() as u32;
            self.positions.push(from.positions[v]);
            self.colours.extend(from.colours.get(v));
            self.uvs.extend(from.uvs.get(v));
            self.ids.push(from.ids[v]);
        }
        self.indices.push(seen[v]);
    }

    /// Appends `other`, its rows shifted by `rows`.
    fn append(&mut self, other: Part, rows: u32) {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.colours.extend(other.colours);
        self.uvs.extend(other.uvs);
        self.ids.extend(other.ids.into_iter().map(|i| i + rows));
        self.indices
            .extend(other.indices.into_iter().map(|i| i + base));
    }
}

/// A cut-out material's cards and its texture (URI relative to `tiles/`).
#[derive(Debug, Clone, Default)]
pub struct Cutout {
    /// The texture, relative to `tiles/`.
    pub uri: String,
    /// The cards.
    pub part: Part,
}

/// What a tile holds, for the levels above it.
#[derive(Debug, Clone, Default)]
pub struct Content {
    /// The metadata table's rows.
    pub features: Vec<Feature>,
    /// Buildings as massing (empty in a leaf).
    pub masses: Vec<Mass>,
    /// Every other opaque surface.
    pub solid: Part,
    /// Cut-out cards by material name.
    pub cutouts: BTreeMap<String, Cutout>,
    /// The largest size of what was left out (people; buildings shed for the parent), metres.
    pub dropped: f64,
    /// The content's geometric error: 0 for a leaf.
    pub error: f64,
}

/// The largest leaf GLB, shared model or texture file read back.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// The mean colour of each texture by its URI relative to `tiles/` (linear RGBA).
#[derive(Debug, Clone, Default)]
pub struct TextureColours(pub BTreeMap<String, [f32; 4]>);

impl TextureColours {
    /// The mean colour of `uri`, mid grey for a texture the library does not hold.
    pub fn mean(&self, uri: &str) -> [f32; 4] {
        self.0.get(uri).copied().unwrap_or([0.5, 0.5, 0.5, 1.0])
    }
}

/// The content of a parent of `children` at `level` (1 above the leaves), simplified to
/// about `target` metres.
pub fn coarsen(children: Vec<Content>, level: u32, target: f64) -> Content {
    let mut out = Content::default();
    let mut child_error = 0.0f64;
    let mut dropped = 0.0f64;
    for c in children {
        let rows = out.features.len() as u32;
        child_error = child_error.max(c.error);
        dropped = dropped.max(c.dropped);
        out.features.extend(c.features);
        out.masses.extend(c.masses.into_iter().map(|m| Mass {
            id: m.id + rows,
            ..m
        }));
        out.solid.append(c.solid, rows);
        for (name, cut) in c.cutouts {
            let e = out.cutouts.entry(name).or_insert_with(|| Cutout {
                uri: cut.uri.clone(),
                part: Part::default(),
            });
            e.part.append(cut.part, rows);
        }
    }
    let (masses, rest) = split_buildings(std::mem::take(&mut out.solid), &out.features);
    let mut level_error = dropped;
    for m in &masses {
        level_error = level_error.max(m.gable_error);
    }
    out.masses.extend(masses);
    level_error = level_error.max(leave_out_small(&mut out.masses, target));
    if level > 1 {
        for m in &out.masses {
            level_error = level_error.max(m.flat_error);
        }
    }
    let (solid, e) = simplify::simplify(rest, target);
    out.solid = solid;
    level_error = level_error.max(e);
    for cut in out.cutouts.values_mut() {
        let (part, e) = thin(std::mem::take(&mut cut.part), target);
        cut.part = part;
        level_error = level_error.max(e);
    }
    out.error = child_error + level_error;
    compact(&mut out);
    out
}

/// Leaves out of `content`, before its parent (simplified to `target`) takes it up, what the
/// parent would leave out anyway: the buildings within half that target and their rows. The
/// parent's error still counts them (`dropped`), so it is made as it would be otherwise.
///
/// A level's contents wait for their siblings: at 1,000,000 lots the second level held every
/// machiya of the city (their rows, 400 bytes each) until the root took them up, to leave
/// them out.
pub fn shed(content: &mut Content, target: f64) {
    let error = leave_out_small(&mut content.masses, target);
    content.dropped = content.dropped.max(error);
    compact(content);
}

/// Leaves out the buildings whose largest size (long side or height) is at most half of
/// `target`; the error of that is the tallest one's height, since each of its vertices
/// stands at most so far above the ground beneath it, which is drawn.
///
/// Without it every level held every building of the city: the root of 1,000,000 lots was
/// 106 MB (1.15 million boxes and their rows), the levels above the first twice the time
/// and memory of the first. A building left out is within half the level's target, as the
/// simplified ground, the thinned cards and the kept boxes are.
fn leave_out_small(masses: &mut Vec<Mass>, target: f64) -> f64 {
    let mut error = 0.0f64;
    masses.retain(|m| {
        let keep = m.size() > target / 2.0;
        if !keep {
            error = error.max(m.ridge - m.base);
        }
        keep
    });
    error
}

/// Keeps only the metadata rows that something drawn in `content` still names (not the
/// people's, nor those of buildings left out), renumbered in their order.
fn compact(content: &mut Content) {
    let mut used = vec![false; content.features.len()];
    let ids = (content.masses.iter().map(|m| m.id))
        .chain(content.solid.ids.iter().copied())
        .chain(
            content
                .cutouts
                .values()
                .flat_map(|c| c.part.ids.iter().copied()),
        );
    for id in ids {
        if let Some(u) = used.get_mut(id as usize) {
            *u = true;
        }
    }
    let mut row = vec![0u32; used.len()];
    let mut kept = 0u32;
    for (r, &u) in row.iter_mut().zip(&used) {
        *r = kept;
        kept += u32::from(u);
    }
    let renumber = |id: &mut u32| *id = row.get(*id as usize).copied().unwrap_or(*id);
    content.masses.iter_mut().for_each(|m| renumber(&mut m.id));
    content.solid.ids.iter_mut().for_each(renumber);
    for c in content.cutouts.values_mut() {
        c.part.ids.iter_mut().for_each(renumber);
    }
    let mut used = used.into_iter();
    content.features.retain(|_| used.next().unwrap_or(false));
}

/// The buildings of `solid` (triangles of a [`MASSED`] kind) as massing, and the rest.
fn split_buildings(solid: Part, features: &[Feature]) -> (Vec<Mass>, Part) {
    let massed = |id: u32| {
        features
            .get(id as usize)
            .is_some_and(|f| MASSED.contains(&f.kind.as_str()))
    };
    type Tri = ([[f64; 3]; 3], [u8; 4]);
    let mut buildings: BTreeMap<u32, Vec<Tri>> = BTreeMap::new();
    let mut rest = Part::default();
    let mut seen: Vec<u32> = vec![u32::MAX; solid.positions.len()];
    for t in solid.indices.chunks_exact(3) {
        let id = solid.ids[t[0] as usize];
        if massed(id) {
            let corners = [0, 1, 2].map(|k| solid.positions[t[k] as usize]);
            buildings
                .entry(id)
                .or_default()
                .push((corners, solid.colours[t[0] as usize]));
            continue;
        }
        for &v in t {
            rest.keep(&solid, v, &mut seen);
        }
    }
    let buildings: Vec<_> = buildings.into_iter().collect();
    let masses = buildings
        .par_iter()
        .filter_map(|(id, tris)| massing::mass(*id, tris))
        .collect();
    (masses, rest)
}

/// The connected parts of a triangle list over `n` vertices (vertices joined by a triangle),
/// each as its vertices, in order of their first vertex; unused vertices are parts alone.
pub fn components(indices: &[u32], n: usize) -> Vec<Vec<u32>> {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    for t in indices.chunks_exact(3) {
        for k in 1..3 {
            let (a, b) = (root(&mut parent, t[0]), root(&mut parent, t[k]));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut part_of: Vec<u32> = vec![u32::MAX; n];
    let mut parts: Vec<Vec<u32>> = Vec::new();
    for v in 0..n as u32 {
        let r = root(&mut parent, v) as usize;
        if part_of[r] == u32::MAX {
            part_of[r] = parts.len() as u32;
            parts.push(Vec::new());
        }
        parts[part_of[r] as usize].push(v);
    }
    parts
}

/// One in `k` of the cards of `part` kept (a card: triangles joined by their vertices), each
/// scaled about its centre by the square root of `k` so the cards cover as much as before;
/// cards larger than `target` are all kept as they are. `k` is [`THINNING`], or more for a
/// card so small that even scaled it stays within `target` (a grown tree's leaf cards: at
/// one in four a level, the root of 30,052 lots kept 58,266 of them, 173,288 triangles, a
/// third of its own; the card's own size decides, so the large billboards thin as before).
/// The error is the largest half-size of a kept card (at `k` = 4 the thinned card's own
/// size): how far the covering card reaches past where its neighbours were. It stays
/// within half the target, under what the level's massing and simplification already cost.
fn thin(part: Part, target: f64) -> (Part, f64) {
    let n = part.positions.len();
    let cards = components(&part.indices, n);
    let mut moved: Vec<Option<[f64; 3]>> = vec![None; n];
    let mut error = 0.0f64;
    for (i, card) in cards.iter().enumerate() {
        let points: Vec<[f64; 3]> = card.iter().map(|&v| part.positions[v as usize]).collect();
        let size = read::extent(&points);
        if size > target {
            for &v in card {
                moved[v as usize] = Some(part.positions[v as usize]);
            }
            continue;
        }
        let k = thinning(size, target);
        let scale = (k as f64).sqrt();
        error = error.max(size * scale / 2.0);
        if i % k != 0 {
            continue;
        }
        let c = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).sum::<f64>() / points.len() as f64);
        for &v in card {
            let p = part.positions[v as usize];
            moved[v as usize] = Some([0, 1, 2].map(|k| c[k] + (p[k] - c[k]) * scale));
        }
    }
    let mut out = Part::default();
    let mut seen = vec![u32::MAX; n];
    for t in part.indices.chunks_exact(3) {
        if moved[t[0] as usize].is_none() {
            continue;
        }
        for &v in t {
            let v = v as usize;
            if seen[v] == u32::MAX {
                seen[v] = out.positions.len() as u32;
                out.positions.push(moved[v].unwrap_or(part.positions[v]));
                out.uvs.push(part.uvs.get(v).copied().unwrap_or_default());
                out.ids.push(part.ids[v]);
            }
            out.indices.push(seen[v]);
        }
    }
    (out, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` square cards of `size` metres in a row, two triangles each.
    fn cards(n: usize, size: f64) -> Part {
        let mut p = Part::default();
        for i in 0..n {
            let x = i as f64 * 2.0 * size;
            let v = p.positions.len() as u32;
            for (dx, dz) in [(0.0, 0.0), (size, 0.0), (size, size), (0.0, size)] {
                p.positions.push([x + dx, 0.0, dz]);
                p.uvs.push([0.0, 0.0]);
                p.ids.push(i as u32);
            }
            p.indices.extend([v, v + 1, v + 2, v, v + 2, v + 3]);
        }
        p
    }

    #[test]
    fn small_cards_thin_until_a_kept_card_is_the_target() {
        // Billboards (over half the target): one in four, as before.
        assert_eq!(thinning(9.5, 15.6), 4);
        // Leaf cards of 3 m at the root (15.6 m): 27 of them to one of 15.6 m.
        assert_eq!(thinning(3.0, 15.6), 27);
        assert_eq!(thinning(0.3, 3.9), MAX_THINNING);
        assert_eq!(thinning(0.0, 1.0), MAX_THINNING);
    }

    #[test]
    fn thinned_cards_cover_what_they_replace_and_the_error_is_a_kept_cards_reach() {
        let (out, error) = thin(cards(128, 0.3), 2.0);
        // One in 44 kept (cards 0, 44, 88), each sqrt(44) times as wide: 132 cards' worth.
        assert_eq!(thinning(0.3, 2.0), 44);
        assert_eq!(out.indices.len(), 3 * 6);
        let area = |p: &Part| -> f64 {
            p.indices
                .chunks_exact(3)
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| p.positions[t[k] as usize]);
                    let (u, v) = ([b[0] - a[0], b[2] - a[2]], [c[0] - a[0], c[2] - a[2]]);
                    (u[0] * v[1] - u[1] * v[0]).abs() / 2.0
                })
                .sum()
        };
        assert!((area(&out) - area(&cards(132, 0.3))).abs() < 1e-9);
        // A card's size is its largest extent along an axis.
        assert!((error - 0.3 * 44f64.sqrt() / 2.0).abs() < 1e-9, "{error}");
        // Cards larger than the target stay as they are.
        let (big, e) = thin(cards(8, 5.0), 3.9);
        assert_eq!((big.indices.len(), e), (8 * 6, 0.0));
    }

    /// A person, a kura (7 m), a long machiya, the ground, a tall hall.
    fn town() -> Content {
        let row = |name: &str, kind: &str| Feature {
            name: name.into(),
            kind: kind.into(),
            ..Feature::default()
        };
        let house = |id: u32, long: f64, height: f64| Mass {
            id,
            rect: [[0.0, 0.0], [long, 0.0], [long, 4.0], [0.0, 4.0]],
            base: 1.0,
            eave: 1.0 + height / 2.0,
            ridge: 1.0 + height,
            flat: 1.0 + height,
            wall: [0; 4],
            roof: [0; 4],
            gable_error: 0.0,
            flat_error: 0.0,
        };
        Content {
            features: vec![
                row("people", "people"),
                row("kura_1", "kura"),
                row("machiya_2", "machiya"),
                row("terrain", "terrain"),
                row("hall_3", "hall"),
            ],
            masses: vec![house(1, 6.0, 7.0), house(2, 18.0, 7.5), house(4, 5.0, 9.0)],
            solid: Part {
                positions: vec![[0.0; 3], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0]],
                colours: vec![[0; 4]; 3],
                ids: vec![3; 3],
                indices: vec![0, 1, 2],
                ..Part::default()
            },
            ..Content::default()
        }
    }

    /// A level leaves out the buildings within half its target (the error is the tallest's
    /// height) and keeps only the rows its surfaces name, renumbered in order.
    #[test]
    fn small_buildings_and_their_rows_leave_the_coarse_levels() {
        let mut content = town();
        // Target 16 m: the kura (7 m) goes, the machiya (18 m long) and the hall (9 m tall)
        // stay.
        let e = leave_out_small(&mut content.masses, 16.0);
        assert_eq!(e, 7.0);
        assert_eq!(content.masses.len(), 2);
        compact(&mut content);
        let names: Vec<&str> = content.features.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["machiya_2", "terrain", "hall_3"]);
        let ids: Vec<u32> = content.masses.iter().map(|m| m.id).collect();
        assert_eq!(ids, [0, 2]);
        assert_eq!(content.solid.ids, [1, 1, 1]);
        // Nothing small enough: nothing leaves, and nothing is renumbered.
        assert_eq!(leave_out_small(&mut content.masses, 10.0), 0.0);
        assert_eq!(content.masses.len(), 2);
    }

    /// Children shed for their parent (what it leaves out anyway, before they wait for
    /// their siblings) make the same parent: its rows, buildings and error.
    #[test]
    fn a_child_shed_for_its_parent_makes_the_same_parent() {
        let whole = coarsen(vec![town(), town()], 3, 16.0);
        let shed_children: Vec<Content> = [town(), town()]
            .into_iter()
            .map(|mut c| {
                shed(&mut c, 16.0);
                c
            })
            .collect();
        assert_eq!(shed_children[0].masses.len(), 2, "the kura is shed");
        assert_eq!(
            shed_children[0].features.len(),
            3,
            "with its row and the people's"
        );
        assert_eq!(shed_children[0].dropped, 7.0);
        let made = coarsen(shed_children, 3, 16.0);
        assert_eq!(made.features, whole.features);
        assert_eq!(made.masses, whole.masses);
        assert_eq!(made.error.to_bits(), whole.error.to_bits());
        assert!(whole.error >= 7.0, "{}", whole.error);
    }
}
