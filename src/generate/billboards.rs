//! People and trees (section 4.4): every billboard of a tile is its template built on its
//! point, people in one object `people` and trees in one object `trees`, so a viewer can hide
//! either at once. The template's `picture` material slot takes the texture drawn for each.

use super::mesh::{Frame, Mesh};
use crate::materials;
use crate::model::{BillboardKind, PlannedBillboard, Skipped, TileStats};
use crate::params::Params;
use crate::templates::Catalog;

/// What [`build`] made of a tile's people and trees.
pub struct Built {
    /// Up to four meshes: people, people walking (at time 0), billboard trees, grown trees.
    pub meshes: Vec<Mesh>,
    /// The grown trees by variant, for formats that instance.
    pub instanced: Vec<super::planted::Instanced>,
    /// The walkers with their clips, for formats that animate.
    pub crowd: Option<super::crowd::Crowd>,
}

/// Builds the people and the trees of a tile: up to four meshes (people, people walking,
/// billboard trees, grown trees), the grown trees by variant for formats that instance and
/// the walkers for formats that animate. A billboard whose template fails is skipped with
/// the reason.
pub fn build(
    tile: &super::TilePlan,
    catalog: &Catalog,
    params: &Params,
    variants: &super::variant::Variants,
    frame: Frame,
    files: &super::LayerFiles,
    stats: &mut TileStats,
) -> Built {
    let (billboards, walks) = (tile.billboards, tile.walks);
    let mut out = Vec::new();
    let walkers: std::collections::HashSet<&str> = walks.iter().map(|w| w.id.as_str()).collect();
    let grown: Vec<&PlannedBillboard> = billboards
        .iter()
        .filter(|b| b.tree.as_ref().is_some_and(|t| t.grown))
        .collect();
    let planted = (!grown.is_empty()).then(|| {
        super::planted::build(grown, catalog, params, variants, frame, &files.trees, stats)
    });
    let left: std::collections::HashSet<*const PlannedBillboard> = planted
        .iter()
        .flat_map(|p| p.billboards.iter().map(|b| *b as *const PlannedBillboard))
        .collect();
    for kind in [BillboardKind::Person, BillboardKind::Tree] {
        let (template, file) = match kind {
            BillboardKind::Person => (&params.people.template, &files.people),
            BillboardKind::Tree => (&params.trees.template, &files.trees),
        };
        use crate::model::object::ObjectKind;
        let object = match kind {
            BillboardKind::Person => ObjectKind::People,
            BillboardKind::Tree => ObjectKind::Trees,
        };
        let mut still = Mesh::object(kind.layer().to_string(), object, Default::default());
        let mut walking =
            Mesh::object(WALKING.to_string(), ObjectKind::Walkers, Default::default());
        for b in billboards.iter().filter(|b| b.kind == kind) {
            let mesh = match kind == BillboardKind::Person && walkers.contains(b.id.as_str()) {
                true => &mut walking,
                false => &mut still,
            };
            let meshed = b.tree.as_ref().is_some_and(|t| t.grown)
                && !left.contains(&(b as *const PlannedBillboard));
            let built = match &b.tree {
                _ if meshed => Ok(()),
                Some(form) => {
                    species_billboard(b, form, catalog, frame, mesh);
                    *stats
                        .trees_by_species
                        .entry(form.species.clone())
                        .or_default()
                        .entry("billboard".into())
                        .or_default() += 1;
                    Ok(())
                }
                None => {
                    let section = match kind {
                        BillboardKind::Person => "people",
                        BillboardKind::Tree => "trees",
                    };
                    let seed = params.seed_for(section);
                    super::figure::build_one(b, template, catalog, seed, frame, mesh)
                }
            };
            match built {
                Ok(()) => {
                    let district = b.district.clone().unwrap_or_default();
                    let by_district = match kind {
                        BillboardKind::Person => &mut stats.people_by_district,
                        BillboardKind::Tree => &mut stats.trees_by_district,
                    };
                    *by_district.entry(district).or_default() += 1;
                    *stats
                        .billboard_textures
                        .entry(b.texture.clone())
                        .or_default() += 1;
                }
                Err(reason) => stats.skipped.push(Skipped {
                    layer: kind.layer().into(),
                    file: file.clone(),
                    id: b.id.clone(),
                    record: None,
                    reason,
                }),
            }
        }
        for mesh in [still, walking] {
            if !mesh.faces.is_empty() {
                out.push(mesh.finish());
            }
        }
    }
    let (mesh, instanced) = planted.map_or((None, Vec::new()), |p| (p.mesh, p.instanced));
    out.extend(mesh);
    let people: Vec<&PlannedBillboard> = billboards
        .iter()
        .filter(|b| b.kind == BillboardKind::Person && walkers.contains(b.id.as_str()))
        .collect();
    Built {
        meshes: out,
        instanced,
        crowd: super::crowd::build(&people, walks, catalog, params),
    }
}

/// The object of the people who walk, where they stand at time 0: the OBJ's; a format that
/// animates draws [`super::crowd::Crowd`] instead.
pub const WALKING: &str = "people_walking";

/// A tree of a species drawn as its species' billboard: crossed quads the size of its crown.
fn species_billboard(
    b: &PlannedBillboard,
    form: &crate::model::TreeForm,
    catalog: &Catalog,
    frame: Frame,
    mesh: &mut Mesh,
) {
    let material = catalog
        .species
        .get(&form.species)
        .map_or_else(|| materials::id("tree_01"), |s| s.billboard);
    let place = super::tree::Placement {
        at: b.at,
        ground: b.ground,
        rotation: b.facing,
    };
    super::tree::billboard_of(form.crown, b.height, material, place, frame, mesh);
}
