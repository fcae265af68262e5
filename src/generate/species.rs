//! The models `<out>/species/` holds, made by generation so that the writer only writes: the
//! LOD0 sample of every species the build planted and, with `trees.variants`, every variant a
//! grown tree of the city is (the build's one model of it, [`Variants`], which the tiles then
//! take instead of growing it again).

use std::collections::BTreeSet;
use std::sync::Arc;

use rayon::prelude::*;

use super::mesh::Mesh;
use super::tree;
use super::variant::{variant_of, Variants};
use crate::model::{Plan, PlannedBillboard, TreeForm};
use crate::params::Params;
use crate::templates::Catalog;

/// A species' sample tree for `species/`.
pub struct Sample {
    /// The species' name.
    pub name: String,
    /// Its sample tree at LOD0 ([`tree::sample_lod0`]).
    pub mesh: Mesh,
    /// Its nominal height, metres: a placement's scale is a tree's height over it.
    pub height: f64,
}

/// Everything `species/` shows of a build's trees.
pub struct SpeciesModels {
    /// A sample of every species the plan plants (grown or billboard), by name; none for a
    /// species the catalog lacks or that cannot grow.
    pub samples: Vec<Sample>,
    /// Every variant a grown tree is, by (species, variant).
    pub variants: Vec<(String, u32, Arc<Mesh>)>,
    seed: u64,
    per_species: u32,
}

impl SpeciesModels {
    /// The variant tree `b` of form `t` is, when it is grown and there are variants.
    pub fn variant_of(&self, b: &PlannedBillboard, t: &TreeForm) -> Option<u32> {
        t.grown
            .then(|| variant_of(self.seed, &b.id, self.per_species))
            .flatten()
    }
}

/// Every tree of the plan (a billboard with a tree form), in the plan's order.
pub fn planted_trees(plan: &Plan) -> Vec<(&PlannedBillboard, &TreeForm)> {
    plan.billboards
        .values()
        .flatten()
        .filter_map(|b| b.tree.as_ref().map(|t| (b, t)))
        .collect()
}

/// The samples of the species `trees` name and the variants their grown trees are, grown
/// in parallel into `variants`. A species that is not in the catalog or cannot grow has no
/// files (its trees are skipped with the reason where the tiles meet them).
pub fn species_models(
    trees: &[(&PlannedBillboard, &TreeForm)],
    catalog: &Catalog,
    params: &Params,
    variants: &Variants,
) -> SpeciesModels {
    let mut models = SpeciesModels {
        samples: Vec::new(),
        variants: Vec::new(),
        seed: params.seed_for("trees"),
        per_species: params.trees.variants,
    };
    let used: BTreeSet<&str> = trees.iter().map(|(_, t)| t.species.as_str()).collect();
    models.samples = used
        .into_par_iter()
        .filter_map(|name| {
            let s = catalog.species.get(name)?;
            let (mesh, _) = tree::sample_lod0(s, &params.trees.season).ok()?;
            Some(Sample {
                name: s.name.clone(),
                mesh,
                height: s.nominal_height(),
            })
        })
        .collect();
    let keys: BTreeSet<(&str, u32)> = trees
        .iter()
        .filter_map(|(b, t)| Some((t.species.as_str(), models.variant_of(b, t)?)))
        .collect();
    models.variants = keys
        .into_par_iter()
        .filter_map(|(name, k)| {
            let s = catalog.species.get(name)?;
            let mesh = variants.model(s, k).ok()?;
            Some((name.to_string(), k, mesh))
        })
        .collect();
    models
}
