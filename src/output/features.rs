//! What each object of a tile is, for the formats that carry metadata (the GLB's
//! `EXT_structural_metadata` table, the viewer's info panel): its kind and owner as
//! generation set them (`Mesh::kind`, `Mesh::owner`), and the owner's attributes from the
//! plan. Format-neutral: every sink gets the same list, one [`Feature`] per mesh.

use std::collections::{HashMap, HashSet};

use crate::generate::mesh::Mesh;
use crate::model::object::{ObjectKind, OwnerLayer};
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
    /// The owner's record in its layer file, when it is a lot or footprint.
    pub record: Option<usize>,
    /// For a house: the street its frontage faces (the nearest street's id), else empty.
    pub street: String,
}

/// The lookup from names to lots and houses, built once per build.
pub struct Directory<'a> {
    lots: HashMap<&'a str, &'a crate::model::Lot>,
    houses: HashMap<&'a str, &'a crate::model::PlannedHouse>,
    /// Every street's segments, the street's index in `value`: the street a frontage faces.
    streets: rstar::RTree<crate::geom::segment::Segment>,
    street_ids: Vec<&'a str>,
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
            streets: rstar::RTree::bulk_load(
                (data.streets.iter().enumerate())
                    .flat_map(|(i, st)| {
                        st.line
                            .0
                            .windows(2)
                            .map(move |w| crate::geom::segment::Segment {
                                a: [w[0].x, w[0].y],
                                b: [w[1].x, w[1].y],
                                value: i as f64,
                            })
                    })
                    .collect(),
            ),
            street_ids: data.streets.iter().map(|s| s.id.as_str()).collect(),
        }
    }

    /// The lot and the house of id `id`, as the metadata rows read them (`build::reuse`
    /// hashes them for each tile that draws something of theirs).
    pub fn records(
        &self,
        id: &str,
    ) -> (
        Option<&'a crate::model::Lot>,
        Option<&'a crate::model::PlannedHouse>,
    ) {
        (self.lots.get(id).copied(), self.houses.get(id).copied())
    }

    /// The id of the street nearest the middle of a house's frontage.
    fn street_of(&self, house: &crate::model::PlannedHouse) -> String {
        let (a, b) = (house.frontage.a, house.frontage.b);
        let mid = [(a.x + b.x) / 2.0, (a.y + b.y) / 2.0];
        (self.streets.nearest_neighbor(&mid))
            .and_then(|s| self.street_ids.get(s.value as usize))
            .map_or(String::new(), |id| id.to_string())
    }

    /// One feature per mesh, in the meshes' order.
    pub fn features(&self, meshes: &[Mesh]) -> Vec<Feature> {
        let with_kura: HashSet<&str> = meshes
            .iter()
            .filter(|m| m.kind == ObjectKind::Kura)
            .map(|m| m.owner.id.as_str())
            .collect();
        meshes.iter().map(|m| self.feature(m, &with_kura)).collect()
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

    fn feature(&self, m: &Mesh, with_kura: &HashSet<&str>) -> Feature {
        let l = &self.params.layers;
        let id = m.owner.id.as_str();
        let mut f = Feature {
            name: m.name.clone(),
            kind: m.kind.name().to_string(),
            lot: id.to_string(),
            ..Feature::default()
        };
        f.source = match (m.kind, m.owner.layer) {
            (ObjectKind::People | ObjectKind::Walkers, _) if self.given[0] => l.people.file.clone(),
            (ObjectKind::Trees | ObjectKind::GrownTrees, _) if self.given[1] => {
                l.trees.file.clone()
            }
            (_, OwnerLayer::None | OwnerLayer::People | OwnerLayer::Trees) => String::new(),
            (_, OwnerLayer::Lots) => l.lots.file.clone(),
            (_, OwnerLayer::Footprints) => l.footprints.file.clone(),
            (_, OwnerLayer::Fences) => l.fences.file.clone(),
            (_, OwnerLayer::Gardens) => l.gardens.file.clone(),
            (_, OwnerLayer::Landmarks) => l.landmarks.file.clone(),
        };
        if m.kind == ObjectKind::Landmark {
            // Its own layer's id: no lot, type or use of ours.
            return f;
        }
        if let Some(house) = self.houses.get(id) {
            f.mtype = house.mtype.clone();
            f.district = house.district.clone().unwrap_or_default();
            f.record = Some(house.record);
            if m.kind.is_building() {
                f.street = self.street_of(house);
            }
        }
        if let Some(lot) = self.lots.get(id) {
            f.record = f.record.or(Some(lot.record));
            f.lot_use = lot.lot_use.name().to_string();
            if f.district.is_empty() {
                f.district = lot.district.clone().unwrap_or_default();
            }
        }
        f.kura = with_kura.contains(id);
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_owners_give_the_columns() {
        use crate::model::object::Owner;
        let (data, plan, params) = (Dataset::default(), Plan::default(), Params::default());
        let dir = Directory::of(&data, &plan, &params);
        let kura: HashSet<&str> = ["12_3"].into_iter().collect();
        let mesh = |name: &str, kind, layer, id: &str| {
            Mesh::object(name.into(), kind, Owner::of(layer, id))
        };
        let f = |m: Mesh| dir.feature(&m, &kura);
        let house = f(mesh(
            "machiya_12_3",
            ObjectKind::Machiya,
            OwnerLayer::Lots,
            "12_3",
        ));
        assert_eq!(
            (house.kind.as_str(), house.lot.as_str()),
            ("machiya", "12_3")
        );
        assert!(house.kura);
        assert_eq!(house.source, "lots.shp");
        assert!(
            !f(mesh(
                "machiya_4",
                ObjectKind::Machiya,
                OwnerLayer::Lots,
                "4"
            ))
            .kura
        );
        let gate = f(mesh(
            "gateline_7_2",
            ObjectKind::Gate,
            OwnerLayer::Fences,
            "7",
        ));
        assert_eq!((gate.kind.as_str(), gate.lot.as_str()), ("gate", "7"));
        assert_eq!(gate.source, params.layers.fences.file);
        let stone = f(mesh(
            "stone_area-g1_2_soe_5",
            ObjectKind::Stone,
            OwnerLayer::Gardens,
            "area-g1",
        ));
        assert_eq!(
            (stone.lot.as_str(), stone.source.as_str()),
            ("area-g1", "gardens.shp")
        );
        let trees = f(mesh(
            "trees_grown",
            ObjectKind::GrownTrees,
            OwnerLayer::None,
            "",
        ));
        assert_eq!((trees.kind.as_str(), trees.lot.as_str()), ("trees", ""));
        let walkers = f(mesh(
            "people_walking",
            ObjectKind::Walkers,
            OwnerLayer::None,
            "",
        ));
        assert_eq!(walkers.kind, "people");
        let hall = f(mesh(
            "hall_4_2_goju-no-to",
            ObjectKind::Hall,
            OwnerLayer::Lots,
            "4_2",
        ));
        assert_eq!((hall.kind.as_str(), hall.lot.as_str()), ("hall", "4_2"));
        let landmark = f(mesh(
            "landmark_nijo-keep",
            ObjectKind::Landmark,
            OwnerLayer::Landmarks,
            "nijo-keep",
        ));
        assert_eq!(
            (landmark.kind.as_str(), landmark.lot.as_str()),
            ("landmark", "nijo-keep")
        );
        let ground = f(mesh("ground", ObjectKind::Ground, OwnerLayer::None, ""));
        assert_eq!(
            (ground.kind.as_str(), ground.source.as_str()),
            ("ground", "")
        );
    }
}
