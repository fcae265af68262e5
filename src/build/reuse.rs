//! Rebuilding only what changed (issue 61): a build into the directory of the build before
//! it keeps each tile whose files would come out the same, and makes the others.
//!
//! A tile's files are a function of three things, each hashed:
//!
//! - the **city**: the parameters generation and the formats read (all of them but
//!   [`ANALYSIS_ONLY`], whose every effect on a tile is in its plan), the output origin, the
//!   landmarks' palette and textures, and the streets a house's frontage is named after;
//! - the tile's **plan** ([`generate::TilePlan`]: its houses, fences, people and trees,
//!   walks, gardens, halls, landmarks, ground);
//! - its **owners**: the lot and house record behind each object the tile drew last time
//!   (the metadata rows read them: a lot's use or district edited in the workbench changes
//!   the rows of every tile that draws something of that lot, and only those).
//!
//! Equal hashes, the previous manifest's entry and its files on disk: the tile is kept as it
//! is. Anything else: the tile is made again. The property test `tests/workbench_reuse.rs`
//! checks that random edit sequences give, file for file, what a full build gives.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::generate::TilePlan;
use crate::model::{Dataset, Plan};
use crate::output::{features::Directory, listed, plan, report, tiles3d::memory::Memory};
use crate::params::Params;

/// Parameters only the analysis reads: a change to one remakes the tiles whose plan it
/// changes and no others. Each is a key or a table of keys, spelled as in the TOML.
pub const ANALYSIS_ONLY: &[&str] = &[
    "type_mix",
    "simplify",
    "frontage",
    "garden",
    "crowd",
    "kura.min_frontage",
    "kura.depth_ratio",
    "kura.width",
    "kura.depth",
    "kura.min_width",
    "kura.min_depth",
    "kura.gap",
    "kura.back_margin",
    "kura.side_margin",
    "kura.overlap_tolerance",
    "people.per_100m",
    "people.edge_margin",
    "people.min_spacing",
    "people.clearance",
    "trees.uses",
    "trees.per_ha",
    "trees.per_ha_machiya",
    "trees.min_spacing",
    "trees.clearance",
    "trees.species",
    "input",
];

/// What each tile of a build was made from.
#[derive(Debug, Clone, Default)]
pub struct Fingerprints {
    city: [u8; 32],
    tiles: BTreeMap<String, TileMark>,
    /// The parents of the levels of detail, carried from build to build.
    lod: Arc<Memory>,
    /// plan.png as drawn last, strip by strip.
    plan: Arc<plan::Kept>,
}

impl Fingerprints {
    /// The levels of detail's parents as the build before left them.
    pub fn levels_of_detail(&self) -> &Arc<Memory> {
        &self.lod
    }

    /// plan.png's image as the build before drew it.
    pub fn plan_image(&self) -> &plan::Kept {
        &self.plan
    }

    /// How many tiles it knows.
    pub fn len(&self) -> usize {
        self.tiles.len()
    }

    /// Whether it knows no tile (a first build).
    pub fn is_empty(&self) -> bool {
        self.tiles.is_empty()
    }
}

/// One tile's plan and owners, as hashed, and the owners' ids.
#[derive(Debug, Clone)]
struct TileMark {
    plan: [u8; 32],
    owners: [u8; 32],
    owner_ids: Vec<String>,
}

/// The hash of the whole-city part of every tile.
pub fn city_hash(params: &Params, data: &Dataset, plan: &Plan) -> [u8; 32] {
    let mut v = serde_json::to_value(params).expect("parameters serialise");
    for key in ANALYSIS_ONLY {
        remove_key(&mut v, key);
    }
    let mut h = Sha256::new();
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    h.update(v.to_string().as_bytes());
    feed(&mut h, &plan.origin);
    feed(&mut h, &plan.palette);
    for (name, bytes) in &plan.model_textures {
        h.update(name.as_bytes());
        h.update(Sha256::digest(bytes.as_slice()));
    }
    feed(&mut h, &data.streets);
    feed(
        &mut h,
        &[
            data.people.is_some(),
            data.trees.is_some(),
            data.dem.is_some(),
        ],
    );
    h.finalize().into()
}

/// `key` (dotted) taken out of a JSON object.
fn remove_key(v: &mut serde_json::Value, key: &str) {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().unwrap_or_default();
    let mut at = v;
    for p in parts {
        match at.get_mut(p) {
            Some(next) => at = next,
            None => return,
        }
    }
    if let Some(map) = at.as_object_mut() {
        map.remove(last);
    }
}

/// `value` in postcard's bytes into `h`.
fn feed<T: Serialize + ?Sized>(h: &mut Sha256, value: &T) {
    let bytes = postcard::to_stdvec(value).unwrap_or_default();
    h.update((bytes.len() as u64).to_le_bytes());
    h.update(&bytes);
}

/// The hash of a tile's plan.
fn plan_hash(tile: &TilePlan) -> [u8; 32] {
    let mut h = Sha256::new();
    feed(&mut h, tile.lots);
    feed(&mut h, tile.fences);
    feed(&mut h, tile.billboards);
    feed(&mut h, tile.walks);
    feed(&mut h, tile.gardens);
    feed(&mut h, tile.halls);
    feed(&mut h, tile.landmarks);
    feed(&mut h, &tile.surface);
    h.finalize().into()
}

/// The hash of the records behind `owners` (sorted ids) as the metadata rows read them.
fn owners_hash(owners: &[String], directory: &Directory) -> [u8; 32] {
    let mut h = Sha256::new();
    for id in owners {
        h.update(id.as_bytes());
        let (lot, house) = directory.records(id);
        feed(&mut h, &lot);
        feed(&mut h, &house);
    }
    h.finalize().into()
}

/// The decisions of one build: the previous build's fingerprints and manifest entries
/// against this build's city.
pub struct Reuse<'a> {
    before: &'a Fingerprints,
    city: [u8; 32],
    previous: BTreeMap<String, report::ManifestTile>,
}

impl<'a> Reuse<'a> {
    /// Against `before`, for a build whose city hashes to `city`, into `out` (whose
    /// manifest, when it has one, gives the entries of the tiles kept).
    pub fn new(before: &'a Fingerprints, city: [u8; 32], out: &Path) -> Reuse<'a> {
        let previous = match !before.is_empty() {
            true => super::shards::read_manifest(&out.join("manifest.json"))
                .map(|m| m.tiles.into_iter().map(|t| (t.id.clone(), t)).collect())
                .unwrap_or_default(),
            false => BTreeMap::new(),
        };
        Reuse {
            before,
            city,
            previous,
        }
    }

    /// The previous entry of tile `id` when its files would come out the same, with the
    /// tile's fingerprint carried over.
    pub fn kept(
        &self,
        id: &str,
        tile: &TilePlan,
        directory: &Directory,
        out: &Path,
    ) -> Option<(report::ManifestTile, Mark)> {
        if self.before.city != self.city {
            return None;
        }
        let mark = self.before.tiles.get(id)?;
        let entry = self.previous.get(id)?;
        let same = mark.plan == plan_hash(tile)
            && mark.owners == owners_hash(&mark.owner_ids, directory)
            && entry.files().all(|f| listed::at_size(out, f));
        same.then(|| (entry.clone(), Mark(mark.clone())))
    }

    /// The fingerprint of tile `id` just made, whose objects belong to `owners`.
    pub fn made(tile: &TilePlan, mut owners: Vec<String>, directory: &Directory) -> Mark {
        owners.sort_unstable();
        owners.dedup();
        Mark(TileMark {
            plan: plan_hash(tile),
            owners: owners_hash(&owners, directory),
            owner_ids: owners,
        })
    }

    /// The fingerprints of this build, from each tile's mark.
    pub fn fingerprints(&self, marks: Vec<(String, Mark)>) -> Fingerprints {
        Fingerprints {
            city: self.city,
            tiles: marks.into_iter().map(|(id, m)| (id, m.0)).collect(),
            lod: self.before.lod.clone(),
            plan: self.before.plan.clone(),
        }
    }
}

/// A tile's fingerprint, between [`Reuse`] and the build.
#[derive(Debug, Clone)]
pub struct Mark(TileMark);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analysis_only_keys_leave_the_city_hash_alone() {
        let (data, plan) = (Dataset::default(), Plan::default());
        let base = Params::default();
        let city = city_hash(&base, &data, &plan);
        let mut p = base.clone();
        p.type_mix.insert("sangai".into(), 5.0);
        p.kura.gap = 2.5;
        p.trees.per_ha = 10.0;
        assert_eq!(city_hash(&p, &data, &plan), city);
        let mut p = base.clone();
        p.seed = 2;
        assert_ne!(
            city_hash(&p, &data, &plan),
            city,
            "generation draws from the seed"
        );
        let mut p = base;
        p.kura.collision = false;
        assert_ne!(city_hash(&p, &data, &plan), city);
    }

    #[test]
    fn every_analysis_only_key_names_a_parameter() {
        let v = serde_json::to_value(Params::default()).unwrap();
        for key in ANALYSIS_ONLY.iter().filter(|k| **k != "input") {
            let mut at = &v;
            for p in key.split('.') {
                at = at
                    .get(p)
                    .unwrap_or_else(|| panic!("`{key}` is no parameter"));
            }
        }
    }
}
