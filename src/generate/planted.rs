//! The grown trees of a tile (`trees.style = "lsystem"` or `"colonization"`): tallest first,
//! each meshed at LOD1 while the tile's `trees.max_tile_bytes` allows; a tree that does not
//! fit is drawn as its species' billboard. All grown trees of a tile are one object,
//! `trees_grown`.
//!
//! A tree is one of its species' `trees.variants`: the variant is grown once per build at the
//! species' nominal height from its own key and meshed ([`Variants`]), and every
//! tree of it is a copy scaled to the tree's height (its crown narrowed by the squeeze),
//! turned and moved ([`variant::place_copy`]). The OBJ gets the copies (`trees_grown`); formats
//! that instance (GLB) get each variant once with where its trees stand ([`Instanced`]).
//! Growing scales a skeleton to its height at the end, so the variant scaled is what growing
//! the tree at its height from the variant's key gives (the leaf cards then grow with the
//! height, not its square root). With `variants = 0` every tree is grown from its own key
//! (`feature_rng(seed, "tree", id)`) and meshed on its own; nothing is instanced.
//!
//! The budget counts each tree's OBJ bytes as [`Mesh::obj_bytes_estimate`] estimates them
//! (a little above what the writer prints), so a tile never holds more than
//! `max_tile_bytes` of grown trees. A tree whose species' trees met so far in the tile say
//! it would not fit is not grown (the most bytes per square metre of height seen).

use std::sync::Arc;

use super::mesh::{Frame, Mesh};
use super::tree::{self, Lod, Look, Placement};
use super::variant::{self, Stance, Variants};
use crate::model::{PlannedBillboard, Skipped, TileStats};
use crate::params::Params;
use crate::templates::Catalog;

/// A tile's trees of one variant, for a format that draws a model many times (GLB's
/// `EXT_mesh_gpu_instancing`): the variant's model once and where each tree stands.
#[derive(Debug, Clone)]
pub struct Instanced {
    /// The variant at its species' nominal height ([`variant::variant_model`]), named
    /// `<species>_<k>`, its foot at the origin: the build's one model of it ([`Variants`]).
    pub model: Arc<Mesh>,
    /// Its trees, in the order they were meshed into `trees_grown`.
    pub trees: Vec<InstancedTree>,
}

/// One tree of an [`Instanced`] variant.
#[derive(Debug, Clone)]
pub struct InstancedTree {
    /// The tree's id (`tree_<id>` in the metadata).
    pub id: String,
    /// The lot it stands in, if any.
    pub lot: Option<String>,
    /// Where and how it stands.
    pub stance: Stance,
}

/// A species' name and a variant of it.
type VariantKey<'a> = (&'a str, u32);

/// What became of a tile's grown trees.
pub struct Planted<'a> {
    /// Their meshes, one object (the instanced trees' copies among them).
    pub mesh: Option<Mesh>,
    /// The trees of each variant, for formats that instance (empty with `variants = 0`).
    pub instanced: Vec<Instanced>,
    /// The trees the budget left to billboards (in no particular order).
    pub billboards: Vec<&'a PlannedBillboard>,
}

/// Grows and meshes `trees` (all with a grown [`crate::model::TreeForm`]).
pub fn build<'a>(
    trees: Vec<&'a PlannedBillboard>,
    catalog: &Catalog,
    params: &Params,
    grown: &Variants,
    frame: Frame,
    file: &str,
    stats: &mut TileStats,
) -> Planted<'a> {
    let mut order = trees;
    order.sort_by(|a, b| b.height.total_cmp(&a.height).then_with(|| a.id.cmp(&b.id)));
    let kind = crate::model::object::ObjectKind::GrownTrees;
    let mut mesh = Mesh::object("trees_grown".into(), kind, Default::default());
    let mut used = 0u64;
    let mut rest = Vec::new();
    // Bytes per square metre of height of the trees of each species meshed so far: once the
    // budget is nearly spent, a tree expected not to fit is not grown at all.
    let mut density: std::collections::HashMap<&str, f64> = std::collections::HashMap::new();
    // The variants met so far in this tile, by (species, k): the model (or why it cannot be
    // grown) and its trees, in the order first met.
    let mut variants: Vec<(VariantKey, Result<Instanced, String>)> = Vec::new();
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
        let place = Placement {
            at: b.at,
            ground: b.ground,
            rotation: b.facing,
        };
        let stance = Stance {
            place,
            scale: b.height / species.nominal_height(),
            squeeze: form.squeeze,
        };
        one.clear();
        let variant = variant::variant_of(params.seed_for("trees"), &b.id, params.trees.variants);
        let meshed = match variant {
            Some(k) => {
                let key = (species.name.as_str(), k);
                let at = match variants.iter().position(|(v, _)| *v == key) {
                    Some(i) => i,
                    None => {
                        let model = grown.model(species, k).map(|model| Instanced {
                            model,
                            trees: Vec::new(),
                        });
                        variants.push((key, model));
                        variants.len() - 1
                    }
                };
                match &variants[at].1 {
                    Ok(v) => {
                        variant::place_copy(&v.model, stance, frame, &mut one);
                        Ok(Some(at))
                    }
                    Err(e) => Err(e.clone()),
                }
            }
            None => {
                own_tree(b, species, params, place, form.squeeze, frame, &mut one).map(|()| None)
            }
        };
        let at = match meshed {
            Ok(at) => at,
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
        if let Some(Ok(v)) = at.map(|i| &mut variants[i].1) {
            v.trees.push(InstancedTree {
                id: b.id.clone(),
                lot: form.lot.clone(),
                stance,
            });
        }
        *stats
            .trees_by_species
            .entry(species.name.clone())
            .or_default()
            .entry("lod1".into())
            .or_default() += 1;
    }
    Planted {
        mesh: (!mesh.faces.is_empty()).then(|| mesh.finish()),
        instanced: variants
            .into_iter()
            .filter_map(|(_, v)| v.ok())
            .filter(|v| !v.trees.is_empty())
            .collect(),
        billboards: rest,
    }
}

/// A tree grown from its own key (`variants = 0`) and meshed into `one`.
fn own_tree(
    b: &PlannedBillboard,
    species: &crate::templates::species::Species,
    params: &Params,
    place: Placement,
    squeeze: f64,
    frame: Frame,
    one: &mut Mesh,
) -> Result<(), String> {
    let mut rng = crate::rng::feature_rng(params.seed_for("trees"), "tree", &b.id);
    let mut skeleton = species.grow_in_city(b.height, &mut rng)?.skeleton;
    skeleton.squeeze(squeeze);
    let look = Look::of(species, b.height, &params.trees.season);
    tree::mesh_tree(
        &skeleton,
        &species.mesh,
        look,
        Lod::Reduced,
        place,
        frame,
        one,
    );
    Ok(())
}
