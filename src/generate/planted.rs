//! The grown trees of a tile (`trees.style = "lsystem"` or `"colonization"`): tallest first,
//! each meshed at LOD1 while the tile's `trees.max_tile_bytes` allows; a tree that does not
//! fit is drawn as its species' billboard. All grown trees of a tile are one object,
//! `trees_grown`.
//!
//! A tree's skeleton is one of its species' `trees.variants` (grown once per tile at the
//! species' nominal height from the variant's own key, [`tree::grow_variant`]) scaled to the
//! tree's height, which is what growing it at that height from the variant's key gives: a
//! grower's skeleton is scaled to its height at the end. With `variants = 0` every tree is
//! grown from its own key (`feature_rng(seed, "tree", id)`).
//!
//! The budget counts each tree's OBJ bytes as [`Mesh::obj_bytes_estimate`] estimates them
//! (a little above what the writer prints), so a tile never holds more than
//! `max_tile_bytes` of grown trees. A tree whose species' trees met so far in the tile say
//! it would not fit is not grown (the most bytes per square metre of height seen).

use super::mesh::{Frame, Mesh};
use super::tree::{self, Lod, Look, Placement};
use crate::model::{PlannedBillboard, Skipped, TileStats};
use crate::params::Params;
use crate::templates::Catalog;

/// What became of a tile's grown trees.
pub struct Planted<'a> {
    /// Their meshes, one object.
    pub mesh: Option<Mesh>,
    /// The trees the budget left to billboards (in no particular order).
    pub billboards: Vec<&'a PlannedBillboard>,
}

/// Grows and meshes `trees` (all with a grown [`crate::model::TreeForm`]).
pub fn build<'a>(
    trees: Vec<&'a PlannedBillboard>,
    catalog: &Catalog,
    params: &Params,
    frame: Frame,
    file: &str,
    stats: &mut TileStats,
) -> Planted<'a> {
    let mut order = trees;
    order.sort_by(|a, b| b.height.total_cmp(&a.height).then_with(|| a.id.cmp(&b.id)));
    let mut mesh = Mesh::new("trees_grown".into());
    let mut used = 0u64;
    let mut rest = Vec::new();
    // Bytes per square metre of height of the trees of each species meshed so far: once the
    // budget is nearly spent, a tree expected not to fit is not grown at all.
    let mut density: std::collections::HashMap<&str, f64> = std::collections::HashMap::new();
    // The species' variants grown so far in this tile (or why one cannot be).
    let mut variants: std::collections::HashMap<
        (&str, u32),
        Result<crate::growers::skeleton::Skeleton, String>,
    > = std::collections::HashMap::new();
    // One scratch mesh for every tree: its storage and maps are grown once, not per tree.
    let mut one = Mesh::new(String::new());
    for b in order {
        let Some(form) = &b.tree else { continue };
        let Some(species) = catalog.species.get(&form.species) else {
            rest.push(b);
            continue;
        };
        let expected = density
            .get(species.name.as_str())
            .map_or(0.0, |d| d * b.height * b.height);
        if used as f64 + expected > params.trees.max_tile_bytes as f64 {
            rest.push(b);
            continue;
        }
        let grown = match tree::variant_of(params.seed, &b.id, params.trees.variants) {
            Some(k) => variants
                .entry((species.name.as_str(), k))
                .or_insert_with(|| tree::grow_variant(species, params.seed, k))
                .clone()
                .map(|mut sk| {
                    sk.scale(b.height / species.nominal_height());
                    sk
                }),
            None => {
                let mut rng = crate::rng::feature_rng(params.seed, "tree", &b.id);
                species.grow_in_city(b.height, &mut rng).map(|g| g.skeleton)
            }
        };
        let mut skeleton = match grown {
            Ok(sk) => sk,
            Err(reason) => {
                stats.skipped.push(Skipped {
                    layer: "trees".into(),
                    file: file.to_string(),
                    id: b.id.clone(),
                    record: None,
                    reason,
                });
                continue;
            }
        };
        skeleton.squeeze(form.squeeze);
        one.clear();
        let place = Placement {
            at: b.at,
            ground: b.ground,
            rotation: b.facing,
        };
        let look = Look::of(species, b.height, &params.trees.season);
        tree::mesh_tree(
            &skeleton,
            &species.mesh,
            look,
            Lod::Reduced,
            place,
            frame,
            &mut one,
        );
        let bytes = one.obj_bytes_estimate();
        if used + bytes > params.trees.max_tile_bytes {
            rest.push(b);
            continue;
        }
        used += bytes;
        let d = bytes as f64 / (b.height * b.height).max(1e-6);
        density
            .entry(species.name.as_str())
            .and_modify(|x| *x = x.max(d))
            .or_insert(d);
        mesh.append(&one);
        *stats
            .trees_by_species
            .entry(species.name.clone())
            .or_default()
            .entry("lod1".into())
            .or_default() += 1;
    }
    Planted {
        mesh: (!mesh.faces.is_empty()).then(|| mesh.finish()),
        billboards: rest,
    }
}
