//! What each object of a tile is, for the formats that carry metadata (the GLB's
//! `EXT_structural_metadata` table, the viewer's info panel): its kind, its lot and the lot's
//! attributes, read back from the object's name and the plan. Format-neutral: every sink
//! gets the same list, one [`Feature`] per mesh.

use std::collections::{HashMap, HashSet};

use crate::generate::mesh::Mesh;
use crate::model::{Dataset, Plan};
use crate::params::Params;

/// One object of a tile, described.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Feature {
    /// The object's name (`machiya_<lot>`, `kura_<lot>`, `people`, ...).
    pub name: String,
    /// What it is: `machiya`, `footprint`, `kura`, `fence`, `gate`, `people`, `trees`,
    /// `garden`, `stone`, `terrain`, ...: the name's first word (`trees_grown` is `trees`,
    /// `fenceline` is `fence`, `gateline` is `gate`).
    pub kind: String,
    /// The lot (or footprint, or fence line) it belongs to; empty for people and trees.
    pub lot: String,
    /// The machiya type (for houses).
    pub mtype: String,
    /// The lot's district, if it has one.
    pub district: String,
    /// The lot's use (`machiya`, `buke`, `kuge`, `jisha`, ...).
    pub lot_use: String,
    /// Whether the lot has a kura in this tile.
    pub kura: bool,
    /// The layer file (relative to the input directory) the object came from.
    pub source: String,
}

/// The kinds an object name can start with, longest first where one is a prefix of another.
const KINDS: &[(&str, &str)] = &[
    ("trees_grown", "trees"),
    ("people_walking", "people"),
    ("fenceline_", "fence"),
    ("gateline_", "gate"),
    ("machiya_", "machiya"),
    ("footprint_", "footprint"),
    ("kura_", "kura"),
    ("fence_", "fence"),
    ("gate_", "gate"),
    ("garden_", "garden"),
    ("stone_", "stone"),
    ("hall_", "hall"),
    ("landmark_", "landmark"),
];

/// The lookup from names to lots and houses, built once per build.
pub struct Directory<'a> {
    lots: HashMap<&'a str, &'a crate::model::Lot>,
    houses: HashMap<&'a str, &'a crate::model::PlannedHouse>,
    params: &'a Params,
    /// Whether people and trees came from point layers (else they were drawn: no source).
    given: [bool; 2],
}

impl<'a> Directory<'a> {
    /// The directory of a dataset and its plan.
    pub fn of(data: &'a Dataset, plan: &'a Plan, params: &'a Params) -> Directory<'a> {
        Directory {
            lots: data.lots.iter().map(|l| (l.id.as_str(), l)).collect(),
            houses: plan
                .houses
                .values()
                .flatten()
                .map(|h| (h.id.as_str(), h))
                .collect(),
            params,
            given: [data.people.is_some(), data.trees.is_some()],
        }
    }

    /// One feature per mesh, in the meshes' order.
    pub fn features(&self, meshes: &[Mesh]) -> Vec<Feature> {
        let with_kura: HashSet<&str> = meshes
            .iter()
            .filter_map(|m| m.name.strip_prefix("kura_"))
            .collect();
        meshes
            .iter()
            .map(|m| self.feature(&m.name, &with_kura))
            .collect()
    }

    /// One feature per instanced grown tree, variant by variant in the order given:
    /// `tree_<id>`, kind `trees`, with its lot (a click on one tree names its lot).
    pub fn instance_features(
        &self,
        groups: &[crate::generate::planted::Instanced],
    ) -> Vec<Feature> {
        groups
            .iter()
            .flat_map(|g| &g.trees)
            .map(|t| {
                let lot = t.lot.as_deref().and_then(|id| self.lots.get(id));
                Feature {
                    name: format!("tree_{}", t.id),
                    kind: "trees".into(),
                    lot: t.lot.clone().unwrap_or_default(),
                    lot_use: lot.map_or(String::new(), |l| l.lot_use.name().to_string()),
                    district: lot.and_then(|l| l.district.clone()).unwrap_or_default(),
                    source: if self.given[1] {
                        self.params.layers.trees.file.clone()
                    } else {
                        String::new()
                    },
                    ..Feature::default()
                }
            })
            .collect()
    }

    fn feature(&self, name: &str, with_kura: &HashSet<&str>) -> Feature {
        let l = &self.params.layers;
        let (kind, rest) = KINDS
            .iter()
            .find_map(|(prefix, kind)| name.strip_prefix(prefix).map(|r| (*kind, r)))
            .unwrap_or((name, ""));
        // The id inside the name: gates end in `_<edge>`, halls in `_<template>`, stones in
        // `_<group>_<role>_<k>`.
        let id = match kind {
            "gate" | "hall" => drop_words(rest, 1),
            "stone" => drop_words(rest, 3),
            _ => rest,
        };
        let mut f = Feature {
            name: name.to_string(),
            kind: kind.to_string(),
            lot: id.to_string(),
            ..Feature::default()
        };
        if kind == "landmark" {
            // Its own layer's id: no lot, type or use of ours.
            f.source = l.landmarks.file.clone();
            return f;
        }
        let drawn = id.strip_prefix("area-");
        f.source = match (name.split('_').next().unwrap_or(""), drawn) {
            ("people", _) if self.given[0] => l.people.file.clone(),
            ("trees", _) if self.given[1] => l.trees.file.clone(),
            ("people" | "trees", _) => String::new(),
            ("fenceline" | "gateline", _) => l.fences.file.clone(),
            ("footprint", _) => l.footprints.file.clone(),
            (_, Some(_)) => l.gardens.file.clone(),
            _ if id.is_empty() => String::new(),
            _ => l.lots.file.clone(),
        };
        if matches!(kind, "people" | "trees") {
            f.lot.clear();
        }
        if let Some(house) = self.houses.get(id) {
            f.mtype = house.mtype.clone();
            f.district = house.district.clone().unwrap_or_default();
        }
        if let Some(lot) = self.lots.get(id) {
            f.lot_use = lot.lot_use.name().to_string();
            if f.district.is_empty() {
                f.district = lot.district.clone().unwrap_or_default();
            }
        }
        f.kura = with_kura.contains(id);
        f
    }
}

/// `s` without its last `n` `_`-separated words.
fn drop_words(s: &str, n: usize) -> &str {
    let mut end = s.len();
    for _ in 0..n {
        match s[..end].rfind('_') {
            Some(i) => end = i,
            None => return s,
        }
    }
    &s[..end]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_give_their_kind_and_lot() {
        let (data, plan, params) = (Dataset::default(), Plan::default(), Params::default());
        let dir = Directory::of(&data, &plan, &params);
        let kura: HashSet<&str> = ["12_3"].into_iter().collect();
        let f = |n: &str| dir.feature(n, &kura);
        assert_eq!(
            (f("machiya_12_3").kind, f("machiya_12_3").lot),
            ("machiya".into(), "12_3".into())
        );
        assert!(f("machiya_12_3").kura);
        assert!(!f("machiya_4").kura);
        assert_eq!(f("gate_7_2").lot, "7");
        assert_eq!(f("gateline_7_2").kind, "gate");
        assert_eq!(f("stone_area-g1_2_soe_5").lot, "area-g1");
        assert_eq!(f("stone_area-g1_2_soe_5").source, "gardens.shp");
        assert_eq!(f("trees_grown").kind, "trees");
        assert_eq!(f("trees_grown").lot, "");
        assert_eq!(f("people").kind, "people");
        assert_eq!(f("kura_9").source, "lots.shp");
        assert_eq!(f("hall_4_2_goju-no-to").kind, "hall");
        assert_eq!(f("hall_4_2_goju-no-to").lot, "4_2");
        assert_eq!(f("landmark_nijo-keep").kind, "landmark");
        assert_eq!(f("landmark_nijo-keep").lot, "nijo-keep");
        assert_eq!(f("ground").kind, "ground");
        assert_eq!(f("streets").source, "");
    }
}
