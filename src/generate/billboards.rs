//! People and trees (section 4.4): every billboard of a tile is its template built on its
//! point, people in one object `people` and trees in one object `trees`, so a viewer can hide
//! either at once. The template's `picture` material slot takes the texture drawn for each.

use geo_types::Coord;

use super::clip::LocalPoly;
use super::instance::{instantiate, Local, Site};
use super::mesh::{Frame, Mesh};
use crate::materials;
use crate::model::{BillboardKind, PlannedBillboard, Skipped, TileStats};
use crate::params::Params;
use crate::templates::expr::Lot;
use crate::templates::template::SiteInputs;
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
    billboards: &[PlannedBillboard],
    walks: &[crate::model::Walk],
    catalog: &Catalog,
    params: &Params,
    frame: Frame,
    files: &super::LayerFiles,
    stats: &mut TileStats,
) -> Built {
    let mut out = Vec::new();
    let walkers: std::collections::HashSet<&str> = walks.iter().map(|w| w.id.as_str()).collect();
    let grown: Vec<&PlannedBillboard> = billboards
        .iter()
        .filter(|b| b.tree.as_ref().is_some_and(|t| t.grown))
        .collect();
    let planted = (!grown.is_empty())
        .then(|| super::planted::build(grown, catalog, params, frame, &files.trees, stats));
    let left: std::collections::HashSet<*const PlannedBillboard> = planted
        .iter()
        .flat_map(|p| p.billboards.iter().map(|b| *b as *const PlannedBillboard))
        .collect();
    for kind in [BillboardKind::Person, BillboardKind::Tree] {
        let (template, file) = match kind {
            BillboardKind::Person => (&params.people.template, &files.people),
            BillboardKind::Tree => (&params.trees.template, &files.trees),
        };
        let mut still = Mesh::new(kind.layer().to_string());
        let mut walking = Mesh::new(WALKING.to_string());
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
                None => build_one(b, template, catalog, params.seed, frame, mesh),
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

/// One billboard into `mesh`: the template on a site whose v axis is the facing direction,
/// centred on the point, its picture slot given the billboard's texture.
pub(super) fn build_one(
    b: &PlannedBillboard,
    template: &str,
    catalog: &Catalog,
    seed: u64,
    frame: Frame,
    mesh: &mut Mesh,
) -> Result<(), String> {
    let t = catalog
        .get(template)
        .ok_or_else(|| format!("billboard template `{template}` does not exist"))?;
    let picture = materials::find(&b.texture)
        .ok_or_else(|| format!("texture `{}` is not in the library", b.texture))?;
    let v = Coord {
        x: b.facing.cos(),
        y: b.facing.sin(),
    };
    let u = Coord { x: v.y, y: -v.x };
    let site = Site {
        lot: LocalPoly::simple(vec![[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]),
        local: Local { a: b.at, u, v },
        ground: b.ground,
        slope: 0.0,
    };
    let x = SiteInputs {
        width: 0.0,
        lot_depth: 0.0,
        a: b.at,
        b: b.at,
        centroid: b.at,
        ground: b.ground,
        id: &b.id,
        district: b.district.as_deref(),
        random: super::template_random(seed, b.kind.layer(), &b.id),
        billboard_height: b.height,
        ..SiteInputs::default()
    }
    .slots();
    let overrides = catalog.overrides(&t.name, b.district.as_deref());
    let slots = t.evaluate(&x, &overrides, &[], &site as &dyn Lot)?;
    let first = mesh.faces.len();
    if let Err(e) = instantiate(t, &slots, &site, frame, mesh) {
        mesh.faces.truncate(first);
        return Err(e);
    }
    if let Some(slot) = t.material_slot("picture") {
        for f in mesh.faces[first..]
            .iter_mut()
            .filter(|f| f.material == slot)
        {
            f.material = picture;
        }
    }
    Ok(())
}
