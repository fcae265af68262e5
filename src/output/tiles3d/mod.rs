//! `tileset.json` (3D Tiles 1.1) over the GLB tiles, from the manifest alone (so `merge` and
//! `--tiles` rewrite it from the whole city).
//!
//! An explicit quadtree: leaves are the tiles (content `tiles/<id>.glb`, geometric error 0,
//! each with its own `transform`: the frame of the globe at its centre, relative to the
//! root's), grouped 4 x 4 per level up to one root, whose `transform` is the frame at the
//! output origin in WGS84 ECEF (see [`globe`]). Bounding volumes are boxes that hold their
//! content (leaves: the tile's extent, padded 5 cm) and every child (inner nodes, in the
//! root's frame); geometric error doubles the node's width up the tree; `refine` is `ADD`.
//! Without a CRS and without `origin_lonlat` the root's transform is the identity and a
//! warning says the city is not placed on the globe.

pub mod globe;

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::{json, Value};

use super::report::{Manifest, ManifestFile, ManifestTile};
use globe::{Affine, Globe};

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
        let crs = crate::geom::crs::Crs::from_user(&manifest.crs)?;
        if !crs.is_geographic() {
            let lonlat = crate::geom::crs::Crs::from_user("+proj=longlat +datum=WGS84 +no_defs")?;
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

/// The tileset's JSON for `manifest` (see the module docs); `warnings` gets why the city is
/// not on the globe, when it is not.
pub fn tileset(manifest: &Manifest, warnings: &mut Vec<String>) -> Result<Value, String> {
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
    // Level 0: the leaves as nodes (box in the root frame for grouping, JSON).
    let mut nodes: Vec<((i64, i64), Aabb, Value)> = leaves
        .iter()
        .map(|l| {
            let in_root = Aabb::of(l.local.corners().map(|p| l.transform.apply(p)));
            let json = json!({
                "boundingVolume": {"box": l.local.as_box()},
                "geometricError": 0.0,
                "transform": l.transform.column_major(),
                "content": {"uri": l.tile.glb.as_ref().map(|f| f.path.clone())},
            });
            (l.cell, in_root, json)
        })
        .collect();
    let mut width = size;
    while nodes.len() > 1 {
        width *= FANOUT as f64;
        let mut groups: BTreeMap<(i64, i64), Vec<(Aabb, Value)>> = BTreeMap::new();
        for ((c, r), b, j) in nodes {
            let key = (c.div_euclid(FANOUT), r.div_euclid(FANOUT));
            groups.entry(key).or_default().push((b, j));
        }
        nodes = groups
            .into_iter()
            .map(|(cell, children)| {
                let b = Aabb::of(
                    children
                        .iter()
                        .flat_map(|(b, _)| b.corners().collect::<Vec<_>>()),
                );
                let json = json!({
                    "boundingVolume": {"box": b.as_box()},
                    "geometricError": width,
                    "children": children.into_iter().map(|(_, j)| j).collect::<Vec<_>>(),
                });
                (cell, b, json)
            })
            .collect();
    }
    let mut root = match nodes.pop() {
        Some((_, _, j)) if j.get("children").is_some() => j,
        // One tile (or none): the root is a group over it.
        Some((_, b, j)) => json!({
            "boundingVolume": {"box": b.as_box()},
            "geometricError": width,
            "children": [j],
        }),
        None => json!({
            "boundingVolume": {"box": [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]},
            "geometricError": 0.0,
        }),
    };
    root["refine"] = json!("ADD");
    root["transform"] = json!(root_frame.column_major());
    let top = root["geometricError"].as_f64().unwrap_or(0.0) * 2.0;
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
        },
    }))
}

/// Writes `<out>/tileset.json`; returns its manifest entry.
pub fn write_tileset(
    out: &Path,
    manifest: &Manifest,
    warnings: &mut Vec<String>,
) -> std::io::Result<ManifestFile> {
    let json = tileset(manifest, warnings).map_err(std::io::Error::other)?;
    let bytes = serde_json::to_vec_pretty(&json).expect("serialises");
    super::write_listed(out, "tileset.json".into(), &[&bytes])
}
