//! What an object of a tile is and whose it is, said once where generation makes it and
//! read by every format, the report and plan.gpkg (issue 58: output parsed `kura_<lot>`
//! and `trees_grown` back out of the names). The name stays what the files call the object;
//! nothing downstream takes it apart.

/// What an object of a tile is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ObjectKind {
    /// A machiya on its lot.
    Machiya,
    /// A house on a building footprint.
    Footprint,
    /// A storehouse behind a house.
    Kura,
    /// A lot's walls, or a fence line's.
    Fence,
    /// A gate in a wall.
    Gate,
    /// A rock garden's bed.
    Garden,
    /// One stone of a rock garden.
    Stone,
    /// A hall of a temple or an estate.
    Hall,
    /// A landmark's model.
    Landmark,
    /// People standing (billboards).
    People,
    /// People walking (their clip's first frame; animated by the formats that can).
    Walkers,
    /// Trees drawn as billboards.
    Trees,
    /// Trees grown from their species (instanced by the formats that can).
    GrownTrees,
    /// The ground: water, estate ground, lots, open ground.
    Ground,
    /// The street surfaces.
    Streets,
    /// The DEM's terrain (without `[ground]`).
    Terrain,
    /// Anything else (a template or tree alone, outside a city).
    #[default]
    Other,
}

impl ObjectKind {
    /// The kind as the metadata, the viewer and plan.gpkg name it: walkers are `people`
    /// and grown trees `trees`, as their billboards are.
    pub fn name(self) -> &'static str {
        match self {
            ObjectKind::Machiya => "machiya",
            ObjectKind::Footprint => "footprint",
            ObjectKind::Kura => "kura",
            ObjectKind::Fence => "fence",
            ObjectKind::Gate => "gate",
            ObjectKind::Garden => "garden",
            ObjectKind::Stone => "stone",
            ObjectKind::Hall => "hall",
            ObjectKind::Landmark => "landmark",
            ObjectKind::People | ObjectKind::Walkers => "people",
            ObjectKind::Trees | ObjectKind::GrownTrees => "trees",
            ObjectKind::Ground => "ground",
            ObjectKind::Streets => "streets",
            ObjectKind::Terrain => "terrain",
            ObjectKind::Other => "",
        }
    }

    /// Whether it is a building (a house, kura, hall or landmark): what the levels of
    /// detail mass and a city model calls a building.
    pub fn is_building(self) -> bool {
        matches!(
            self,
            ObjectKind::Machiya
                | ObjectKind::Footprint
                | ObjectKind::Kura
                | ObjectKind::Hall
                | ObjectKind::Landmark
        )
    }
}

/// The layer an object's owner was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum OwnerLayer {
    /// No layer: people and trees drawn by the build, the ground.
    #[default]
    None,
    /// The lots layer.
    Lots,
    /// The footprints layer.
    Footprints,
    /// The fence lines layer.
    Fences,
    /// The gardens layer (a garden drawn as its own polygon, `area-<id>`).
    Gardens,
    /// The landmarks layer.
    Landmarks,
    /// The people point layer.
    People,
    /// The trees point layer.
    Trees,
}

/// Whose an object is: the id of its lot (footprint, fence line, garden area, landmark) in
/// `layer`; empty for objects of no one (people, trees, the ground).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct Owner {
    /// The feature's id in its layer.
    pub id: String,
    /// The layer.
    pub layer: OwnerLayer,
}

impl Owner {
    /// The feature `id` of `layer`.
    pub fn of(layer: OwnerLayer, id: &str) -> Owner {
        Owner {
            id: id.to_string(),
            layer,
        }
    }

    /// No one's.
    pub fn none() -> Owner {
        Owner::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walkers_and_grown_trees_are_named_as_their_billboards() {
        assert_eq!(ObjectKind::Walkers.name(), ObjectKind::People.name());
        assert_eq!(ObjectKind::GrownTrees.name(), "trees");
        assert!(ObjectKind::Kura.is_building() && !ObjectKind::Fence.is_building());
        assert_eq!(Owner::of(OwnerLayer::Lots, "12").id, "12");
        assert_eq!(Owner::none().layer, OwnerLayer::None);
    }
}
