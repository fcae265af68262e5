//! `tileset.json` (3D Tiles 1.1) over the GLB tiles, from the manifest alone (so `merge` and
//! `--tiles` rewrite it from the whole city).
//!
//! An explicit quadtree: leaves are the tiles (content `tiles/<id>.glb`, geometric error 0,
//! each with its own `transform`: the frame of the globe at its centre, relative to the
//! root's), grouped 4 x 4 per level up to one root, whose `transform` is the frame at the
//! output origin in WGS84 ECEF (see [`globe`]). Bounding volumes are boxes that hold their
//! content (leaves: the tile's extent, padded 5 cm) and every child (inner nodes, in the
//! root's frame); every inner node has content of its own ([`lod`]), with its measured
//! geometric error, which its children replace (`refine: REPLACE`). The parents are made
//! depth first, each as soon as its children are.
//! Without a CRS and without `origin_lonlat` the root's transform is the identity and a
//! warning says the city is not placed on the globe.

pub mod globe;
pub mod lod;
pub mod memory;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

use rayon::prelude::*;
use serde_json::{json, Value};

use super::report::{Manifest, ManifestFile, ManifestTile};
use globe::{Affine, Globe};
use memory::{Keys, Memory, Remembered};

/// Tiles per side of a group, at every level.
const FANOUT: i64 = 4;
/// Padding of a leaf's box beyond its content, metres.
const PAD: f64 = 0.05;

/// An axis-aligned box in some frame: min and max corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub lo: [f64; 3],
    /// Maximum corner.
    pub hi: [f64; 3],
}

impl Aabb {
    /// The box holding every point.
    fn of(points: impl IntoIterator<Item = [f64; 3]>) -> Aabb {
        let mut b = Aabb {
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
        };
        for p in points {
            for (k, v) in p.into_iter().enumerate() {
                b.lo[k] = b.lo[k].min(v);
                b.hi[k] = b.hi[k].max(v);
            }
        }
        b
    }

    /// Its eight corners.
    fn corners(&self) -> impl Iterator<Item = [f64; 3]> + '_ {
        (0..8).map(move |i| {
            [0, 1, 2].map(|k| {
                if i >> k & 1 == 0 {
                    self.lo[k]
                } else {
                    self.hi[k]
                }
            })
        })
    }

    /// As a 3D Tiles `box`: centre and three half-axes (at least 1 cm each).
    fn as_box(&self) -> Vec<f64> {
        let c = [0, 1, 2].map(|k| (self.lo[k] + self.hi[k]) / 2.0);
        let h = [0, 1, 2].map(|k| ((self.hi[k] - self.lo[k]) / 2.0).max(0.01));
        vec![
            c[0], c[1], c[2], h[0], 0.0, 0.0, 0.0, h[1], 0.0, 0.0, 0.0, h[2],
        ]
    }
}

/// How the city is placed: the globe's frames, or none (with the warning why).
pub fn placement(manifest: &Manifest) -> Result<Option<Globe>, String> {
    let h = manifest.params.origin_lonlat.map_or(0.0, |o| o[2]);
    if !manifest.crs.is_empty() {
        let user = |s: &str| crate::geom::crs::Crs::from_user(s).map_err(|e| e.to_string());
        let crs = user(&manifest.crs)?;
        if !crs.is_geographic() {
            let lonlat = user("+proj=longlat +datum=WGS84 +no_defs")?;
            return Ok(Some(Globe::Projected {
                crs: Box::new(crs),
                lonlat: Box::new(lonlat),
                h,
            }));
        }
    }
    Ok(manifest.params.origin_lonlat.map(Globe::Placed))
}

/// One leaf: its grid cell, frame relative to the root and box in its own frame.
struct Leaf<'a> {
    cell: (i64, i64),
    tile: &'a ManifestTile,
    transform: Affine,
    local: Aabb,
}

/// Where the parents' content goes, relative to the output directory.
pub const LOD_DIR: &str = "tiles/lod";

/// The smallest geometric error of a parent, metres: its surfaces lose their textures for
/// their mean colours, whose drawn detail (a lattice, a row of tiles) is about this size,
/// even where no surface moved.
const MIN_ERROR: f64 = 0.5;

/// The simplification asked of a level: its width over this (1 km groups: 4 m).
const TARGET_PER_WIDTH: f64 = 256.0;

/// A node of the tree being built: its box in the root's frame, JSON, and what its parent
/// is made from.
struct Node {
    bounds: Aabb,
    json: Value,
    source: Source,
}

/// What a parent reads of a child.
enum Source {
    /// A leaf's GLB (path relative to the output) and its frame in the root's.
    Leaf(String, Affine),
    /// A parent's content, made on the level below.
    Made(lod::Content),
}

/// The tileset's JSON for `manifest` (see the module docs), writing the parents' content
/// into `out` (listed in `files`); `warnings` gets why the city is not on the globe, when it
/// is not. With `memory`, a parent made from what it was made from before is taken from
/// it, and it is left holding this tileset's parents ([`memory`]).
pub fn tileset(
    out: &Path,
    manifest: &Manifest,
    warnings: &mut Vec<String>,
    files: &mut Vec<ManifestFile>,
    memory: Option<&Memory>,
) -> Result<Value, String> {
    let globe = placement(manifest)?;
    let origin = manifest.origin;
    let root_frame = match &globe {
        Some(g) => g.frame(origin)?,
        None => {
            warnings.push(
                "tileset.json: the output has no CRS and the parameters no `origin_lonlat`, so \
                 the city is not placed on the globe (identity transform): set `crs`, or \
                 `origin_lonlat = [longitude, latitude, height]` for a local grid"
                    .into(),
            );
            Affine::IDENTITY
        }
    };
    let to_root = root_frame.inverse();
    let size = manifest.tile_size;
    let mut leaves = Vec::new();
    for t in manifest.tiles.iter().filter(|t| t.glb.is_some()) {
        let Some(b) = t.bounds else { continue };
        let [ce, cn] = t.centre;
        let transform = match &globe {
            Some(g) => to_root.then(&g.frame([origin[0] + ce, origin[1] + cn])?),
            None => Affine::translation([ce, cn, 0.0]),
        };
        let local = Aabb {
            lo: [b[0] - ce - PAD, b[1] - cn - PAD, b[2] - PAD],
            hi: [b[3] - ce + PAD, b[4] - cn + PAD, b[5] + PAD],
        };
        let cell = (
            ((origin[0] + ce - manifest.params.tile_origin[0]) / size).floor() as i64,
            ((origin[1] + cn - manifest.params.tile_origin[1]) / size).floor() as i64,
        );
        leaves.push(Leaf {
            cell,
            tile: t,
            transform,
            local,
        });
    }
    // Cells counted from the city's first column and row, so that the groups of every
    // level start at its edge and the root is reached in as few levels as the city's width
    // asks (a city straddling a multiple of 4^n would otherwise take levels of one group).
    let first = (
        leaves.iter().map(|l| l.cell.0).min().unwrap_or(0),
        leaves.iter().map(|l| l.cell.1).min().unwrap_or(0),
    );
    for l in &mut leaves {
        l.cell = (l.cell.0 - first.0, l.cell.1 - first.1);
    }
    let groups = hierarchy(&leaves.iter().map(|l| l.cell).collect::<Vec<_>>());
    let meshopt = manifest.params.output.glb_compression == "meshopt";
    let tree = Tree {
        out,
        leaves: &leaves,
        size,
        meshopt,
        sources: OnceLock::new(),
        memory,
        keys: memory.map(|_| Keys::of(manifest, &leaves, &groups, meshopt)),
        before: memory.map(Memory::take).unwrap_or_default(),
        now: Mutex::default(),
        kept: Default::default(),
        groups,
    };
    let level = tree.groups.len();
    // No level above the leaves: one leaf or none.
    let top = if level == 0 {
        leaves.first().map(leaf_node)
    } else {
        let (node, mut made) = tree.node(level, 0)?;
        // In the order the levels were once made one after the other: the first level's
        // groups by cell, then the second's, ... (a level's groups are in cell order).
        made.sort_by_key(|(level, cell, _)| (*level, *cell));
        files.extend(made.into_iter().map(|(_, _, file)| file));
        Some(node)
    };
    if let Some(memory) = memory {
        let kept = tree.kept.load(std::sync::atomic::Ordering::Relaxed);
        memory.put(
            tree.now.into_inner().unwrap_or_else(|e| e.into_inner()),
            kept,
        );
    }
    let mut root = match top {
        Some(n) if n.json.get("children").is_some() => n.json,
        // One tile (or none): the root is a group over it.
        Some(n) => json!({
            "boundingVolume": {"box": n.bounds.as_box()},
            "geometricError": MIN_ERROR,
            "children": [n.json],
        }),
        None => json!({
            "boundingVolume": {"box": [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]},
            "geometricError": 0.0,
        }),
    };
    root["refine"] = json!("REPLACE");
    root["transform"] = json!(root_frame.column_major());
    // The error of drawing nothing at all is the whole city: the root box's diagonal. A
    // smaller figure makes CesiumJS skip the tileset from afar (it draws a tileset only
    // while this error spans more than its 16 pixels; twice the root's 5 m hid a 500 m town
    // seen whole from 770 m: tests/cesium.rs).
    let top = root["geometricError"]
        .as_f64()
        .unwrap_or(0.0)
        .max(box_diagonal(&root["boundingVolume"]["box"]));
    Ok(json!({
        "asset": {
            "version": "1.1",
            "generator": format!("edo-city {}", env!("CARGO_PKG_VERSION")),
        },
        "geometricError": top,
        "root": root,
        "extras": {
            "origin": origin,
            "crs": manifest.crs,
            "placed": globe.is_some(),
            "tiles": leaves.len(),
            "levels": level,
        },
    }))
}

/// The length of a 3D Tiles box's diagonal (twice the length of its three half-axes summed as
/// vectors; they are orthogonal); 0 for a malformed box.
fn box_diagonal(b: &serde_json::Value) -> f64 {
    let v: Vec<f64> = b
        .as_array()
        .map(|a| a.iter().filter_map(|x| x.as_f64()).collect())
        .unwrap_or_default();
    if v.len() != 12 {
        return 0.0;
    }
    2.0 * v[3..].iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The groups of each level above the leaves at `cells`, until one is left: a group's cell
/// and its children's places on the level below (the leaves' in the manifest's order),
/// groups in cell order.
fn hierarchy(cells: &[(i64, i64)]) -> Vec<Vec<Group>> {
    let mut levels = Vec::new();
    let mut cells = cells.to_vec();
    while cells.len() > 1 {
        let mut groups: BTreeMap<(i64, i64), Vec<usize>> = BTreeMap::new();
        for (i, c) in cells.iter().enumerate() {
            let key = (c.0.div_euclid(FANOUT), c.1.div_euclid(FANOUT));
            groups.entry(key).or_default().push(i);
        }
        let level: Vec<Group> = groups.into_iter().collect();
        cells = level.iter().map(|(cell, _)| *cell).collect();
        levels.push(level);
    }
    levels
}

/// A parent's cell and its children's places on the level below.
type Group = ((i64, i64), Vec<usize>);

/// What making the parents needs.
struct Tree<'a> {
    out: &'a Path,
    leaves: &'a [Leaf<'a>],
    /// [`hierarchy`]: `groups[l - 1]` are the parents of level `l`.
    groups: Vec<Vec<Group>>,
    size: f64,
    meshopt: bool,
    /// Read when the first parent is made (none may be).
    sources: OnceLock<lod::read::Sources>,
    /// The memory the textures' colours are carried in, with the parents.
    memory: Option<&'a Memory>,
    /// With a [`Memory`]: every node's key, the parents remembered from the build before and
    /// the ones of this build.
    keys: Option<Keys>,
    before: BTreeMap<String, Remembered>,
    now: Mutex<BTreeMap<String, Remembered>>,
    kept: std::sync::atomic::AtomicUsize,
}

impl Tree<'_> {
    /// The node at `index` of `level` (0 the leaves) with the parents' files made under it,
    /// each with its level and index.
    ///
    /// Depth first, so that a level's contents are held only until their parent is made,
    /// not all of them until the whole next level is (1,000,000 lots: the first level's
    /// contents alone held 1.1 GB). The first level's groups under one second-level node
    /// are made side by side, and a parent reads its leaves and masses its buildings side
    /// by side; nothing else is, so that at most one second-level group is under way (a
    /// thread waiting for its siblings would take up another group, and the resident set
    /// grew all along the parents: 1.63 -> 2.36 GB at 1,000,000 lots).
    fn node(&self, level: usize, index: usize) -> Result<(Node, Vec<Made>), String> {
        if level == 0 {
            return Ok((leaf_node(&self.leaves[index]), Vec::new()));
        }
        let (cell, children) = &self.groups[level - 1][index];
        let name = parent_name(level, *cell);
        let key = self.keys.as_ref().map(|k| k.get(level, index));
        if let Some(r) =
            (self.before.get(&name)).filter(|r| Some(r.key) == key && r.on_disk(self.out))
        {
            // Its subtree is kept whole, so a later edit under it finds its other parents.
            for (l, c, _) in &r.made {
                let below = parent_name(*l, *c);
                if let Some(kept) = self.before.get(&below) {
                    self.remember(below, kept.clone());
                    self.kept.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                }
            }
            let node = Node {
                bounds: r.bounds,
                json: r.json.clone(),
                source: Source::Made(r.content.clone()),
            };
            return Ok((node, r.made.clone()));
        }
        let below: Vec<Result<(Node, Vec<Made>), String>> = if level == 2 {
            children
                .par_iter()
                .map(|&c| self.node(level - 1, c))
                .collect()
        } else {
            children.iter().map(|&c| self.node(level - 1, c)).collect()
        };
        let mut nodes = Vec::with_capacity(below.len());
        let mut made = Vec::new();
        for b in below {
            let (node, files) = b?;
            nodes.push(node);
            made.extend(files);
        }
        let width = (0..level).fold(self.size, |w, _| w * FANOUT as f64);
        let target = width / TARGET_PER_WIDTH;
        let sources = self
            .sources
            .get_or_init(|| lod::read::Sources::of(self.out, self.memory.map(Memory::colours)));
        let (node, file) = parent(
            self.out,
            &name,
            nodes,
            level as u32,
            target,
            self.meshopt,
            sources,
        )?;
        made.push((level, *cell, file));
        if let (Some(key), Source::Made(content)) = (key, &node.source) {
            let r = Remembered {
                key,
                bounds: node.bounds,
                json: node.json.clone(),
                content: content.clone(),
                made: made.clone(),
            };
            self.remember(name, r);
        }
        Ok((node, made))
    }

    /// Keeps parent `name` for the next build (with a memory).
    fn remember(&self, name: String, r: Remembered) {
        let mut now = self.now.lock().unwrap_or_else(|e| e.into_inner());
        now.insert(name, r);
    }
}

/// A parent's name, its file's stem: `<level>_<x>_<y>`.
fn parent_name(level: usize, cell: (i64, i64)) -> String {
    format!("{level}_{}_{}", cell.0, cell.1)
}

/// A parent's file with its level and cell there.
type Made = (usize, (i64, i64), ManifestFile);

/// A leaf as a node: its box in the root frame (for its parent's), its JSON.
fn leaf_node(l: &Leaf) -> Node {
    let path = l
        .tile
        .glb
        .as_ref()
        .map(|f| f.path.clone())
        .unwrap_or_default();
    let json = json!({
        "boundingVolume": {"box": l.local.as_box()},
        "geometricError": 0.0,
        "transform": l.transform.column_major(),
        "content": {"uri": path},
    });
    Node {
        bounds: Aabb::of(l.local.corners().map(|p| l.transform.apply(p))),
        json,
        source: Source::Leaf(path, l.transform),
    }
}

/// The parent `name` (`<level>_<x>_<y>`) of `level` over `children`: its content made and
/// written, its node.
fn parent(
    out: &Path,
    name: &str,
    children: Vec<Node>,
    level: u32,
    target: f64,
    meshopt: bool,
    reading: &lod::read::Sources,
) -> Result<(Node, ManifestFile), String> {
    let mut bounds = Vec::new();
    let mut json_children = Vec::with_capacity(children.len());
    let mut sources = Vec::with_capacity(children.len());
    for c in children {
        bounds.extend(c.bounds.corners());
        json_children.push(c.json);
        sources.push(c.source);
    }
    let contents: Vec<lod::Content> = sources
        .into_par_iter()
        .map(|source| match source {
            Source::Made(content) => Ok(content),
            Source::Leaf(path, transform) => {
                let bytes = lod::read::read_listed(out, &path).map_err(|e| {
                    format!("{path}: cannot read it back for the levels of detail: {e}")
                })?;
                lod::read::leaf(&bytes, &path, &transform, reading)
            }
        })
        .collect::<Vec<Result<_, String>>>()
        // The first error in the children's order, whichever thread met it first.
        .into_iter()
        .collect::<Result<_, _>>()?;
    let mut content = lod::coarsen(contents, level, target);
    let glb = lod::write::content_glb(name, &content, level, meshopt);
    let path = format!("{LOD_DIR}/{name}.glb");
    let file =
        super::write_listed(out, path.clone(), &glb.parts()).map_err(|e| format!("{path}: {e}"))?;
    bounds.extend(content_points(&content));
    let bounds = Aabb::of(bounds);
    let error = content.error.max(MIN_ERROR);
    lod::shed(&mut content, target * FANOUT as f64);
    let json = json!({
        "boundingVolume": {"box": bounds.as_box()},
        "geometricError": error,
        "content": {"uri": path},
        "children": json_children,
    });
    Ok((
        Node {
            bounds,
            json,
            source: Source::Made(content),
        },
        file,
    ))
}

/// Every corner the content's cut-outs reach (the only surfaces that grow past their
/// children's boxes: a kept card is scaled up).
fn content_points(content: &lod::Content) -> Vec<[f64; 3]> {
    content
        .cutouts
        .values()
        .flat_map(|c| c.part.positions.iter().copied())
        .collect()
}

/// Writes `<out>/tileset.json` and the parents' content; returns their manifest entries.
/// With `memory`, the parents made as before are kept ([`memory`]).
pub fn write_tileset(
    out: &Path,
    manifest: &Manifest,
    warnings: &mut Vec<String>,
    memory: Option<&Memory>,
) -> std::io::Result<Vec<ManifestFile>> {
    let mut files = Vec::new();
    std::fs::create_dir_all(out.join(LOD_DIR))?;
    let json =
        tileset(out, manifest, warnings, &mut files, memory).map_err(std::io::Error::other)?;
    let bytes = serde_json::to_vec_pretty(&json).expect("serialises");
    files.push(super::write_listed(out, "tileset.json".into(), &[&bytes])?);
    Ok(files)
}
