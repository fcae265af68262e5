//! Names a parameter file gives that the catalog and the texture library must hold, checked
//! before anything is read: hall templates, ground materials, the billboards' templates and
//! textures (moved out of build.rs, which had grown past 800 lines).

use super::BuildError;
use crate::params::Params;
use crate::templates::{Catalog, Kind};

/// `halls.uses` names hall templates, and `ground.materials` library materials.
pub(super) fn check_halls_and_ground(catalog: &Catalog, params: &Params) -> Result<(), BuildError> {
    if params.halls.enabled {
        for (u, names) in &params.halls.uses {
            for name in names {
                if catalog
                    .get(name)
                    .is_none_or(|t| t.kind != Kind::Hall || t.is_abstract)
                {
                    return Err(BuildError::Config(format!(
                        "halls.uses.{u} names `{name}`, which is not a hall template (hall \
                         templates: {})",
                        catalog.names_of(Kind::Hall).join(", ")
                    )));
                }
            }
        }
    }
    for (u, m) in &params.ground.materials {
        if crate::materials::find(m).is_none() {
            return Err(BuildError::Config(format!(
                "ground.materials.{u} names `{m}`, which is not a library material (e.g. \
                 ground, gravel, street, water, moss, stone)"
            )));
        }
    }
    Ok(())
}

/// `people.template` / `trees.template` name templates of their kind, and every texture
/// they list is in the library.
pub(super) fn check_billboards(catalog: &Catalog, params: &Params) -> Result<(), BuildError> {
    let p = &params.people;
    let t = &params.trees;
    for (table, enabled, template, kind, textures) in [
        ("people", p.enabled, &p.template, Kind::Person, &p.textures),
        ("trees", t.enabled, &t.template, Kind::Tree, &t.textures),
    ] {
        if !enabled {
            continue;
        }
        if catalog
            .get(template)
            .is_none_or(|t| t.kind != kind || t.is_abstract)
        {
            return Err(BuildError::Config(format!(
                "{table}.template names `{template}`, which is not a {} template ({} templates: {})",
                kind.name(),
                kind.name(),
                catalog.names_of(kind).join(", ")
            )));
        }
        if let Some(bad) = textures
            .iter()
            .find(|n| crate::materials::find(n).is_none())
        {
            return Err(BuildError::Config(format!(
                "{table}.textures names `{bad}`, which is not in the texture library ({})",
                crate::materials::names().join(", ")
            )));
        }
    }
    Ok(())
}
