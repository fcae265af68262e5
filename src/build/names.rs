//! Names a parameter file gives that the catalog and the texture library must hold, checked
//! before anything is read: the machiya, fence, gate and kura templates, hall templates,
//! ground materials, the billboards' templates and textures (moved out of build.rs, which
//! had grown past 800 lines).

use std::path::{Path, PathBuf};

use super::BuildError;
use crate::params::Params;
use crate::templates::{Catalog, Kind};

/// Loads the machiya types and checks `type_mix` against them.
pub fn load_catalog(params: &Params, templates: Option<&Path>) -> Result<Catalog, BuildError> {
    let dir = templates.map(Path::to_path_buf).or_else(|| {
        (!params.machiya.templates.is_empty()).then(|| PathBuf::from(&params.machiya.templates))
    });
    let mut catalog = Catalog::load(dir.as_deref())?;
    catalog.configure(&params.template, &params.district_templates())?;
    if params.fence.enabled {
        let f = &params.fence;
        let named = f.types.values().chain([&f.default_type]);
        for name in named {
            if catalog
                .get(name)
                .is_none_or(|t| t.kind != Kind::Fence || t.is_abstract)
            {
                return Err(BuildError::Config(format!(
                    "fence.types / fence.default_type name `{name}`, which is not a fence template \
                     (fence templates: {})",
                    catalog.names_of(Kind::Fence).join(", ")
                )));
            }
        }
        let g = &f.gate_template;
        if catalog
            .get(g)
            .is_none_or(|t| t.kind != Kind::Gate || t.is_abstract)
        {
            return Err(BuildError::Config(format!(
                "fence.gate_template names `{g}`, which is not a gate template (gate templates: {})",
                catalog.names_of(Kind::Gate).join(", ")
            )));
        }
    }
    if params.kura.enabled {
        let k = &params.kura.template;
        if catalog
            .get(k)
            .is_none_or(|t| t.kind != Kind::Kura || t.is_abstract)
        {
            return Err(BuildError::Config(format!(
                "kura.template names `{k}`, which is not a kura template (kura templates: {})",
                catalog.names_of(Kind::Kura).join(", ")
            )));
        }
    }
    check_billboards(&catalog, params)?;
    check_halls_and_ground(&catalog, params)?;
    let mixes = std::iter::once(("type_mix".to_string(), &params.type_mix)).chain(
        params
            .district
            .iter()
            .filter_map(|(id, d)| Some((format!("district.{id}.type_mix"), d.type_mix.as_ref()?))),
    );
    for (key, name) in mixes.flat_map(|(key, mix)| mix.keys().map(move |n| (key.clone(), n))) {
        if catalog.machiya(name).is_none() {
            return Err(BuildError::Config(format!(
                "{key} names `{name}`, which has no machiya template (known types: {})",
                catalog.names_of(Kind::Machiya).join(", ")
            )));
        }
    }
    Ok(catalog)
}

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
