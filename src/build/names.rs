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
            template_of(
                &catalog,
                name,
                Kind::Fence,
                "fence",
                "fence.types / fence.default_type name",
            )?;
        }
        let g = &f.gate_template;
        template_of(&catalog, g, Kind::Gate, "gate", "fence.gate_template names")?;
    }
    if params.kura.enabled {
        let k = &params.kura.template;
        template_of(&catalog, k, Kind::Kura, "kura", "kura.template names")?;
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

/// `name` (which `key_says`, e.g. "kura.template names") is a template of `kind` that can be
/// built (not abstract); else the error listing the `what` templates there are.
fn template_of(
    catalog: &Catalog,
    name: &str,
    kind: Kind,
    what: &str,
    key_says: &str,
) -> Result<(), BuildError> {
    match catalog
        .get(name)
        .is_some_and(|t| t.kind == kind && !t.is_abstract)
    {
        true => Ok(()),
        false => Err(BuildError::Config(format!(
            "{key_says} `{name}`, which is not a {what} template ({what} templates: {})",
            catalog.names_of(kind).join(", ")
        ))),
    }
}

/// `halls.uses` names hall templates, and `ground.materials` library materials.
pub(super) fn check_halls_and_ground(catalog: &Catalog, params: &Params) -> Result<(), BuildError> {
    if params.halls.enabled {
        for (u, names) in &params.halls.uses {
            for name in names {
                let says = format!("halls.uses.{u} names");
                template_of(catalog, name, Kind::Hall, "hall", &says)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A parameter naming a template of another kind, or none, is refused with the key, the
    /// name and the templates of the kind asked for.
    #[test]
    fn a_template_of_the_wrong_kind_is_named_with_the_ones_there_are() {
        let refused = |toml: &str| match load_catalog(
            &Params::from_toml_str(toml, "p.toml").unwrap(),
            None,
        ) {
            Err(BuildError::Config(m)) => m,
            other => panic!("{toml}: {:?}", other.map(|_| ())),
        };
        let m = refused("[fence]\ngate_template = \"nope\"\n");
        assert!(
            m.starts_with(
                "fence.gate_template names `nope`, which is not a gate template (gate templates: "
            ),
            "{m}"
        );
        let m = refused("[fence]\ndefault_type = \"nope\"\n");
        assert!(
            m.starts_with(
                "fence.types / fence.default_type name `nope`, which is not a fence template"
            ),
            "{m}"
        );
        let kura = refused("[kura]\ntemplate = \"nope\"\n");
        assert!(
            kura.contains("which is not a kura template (kura templates: "),
            "{kura}"
        );
        let halls = refused("[halls.uses]\njisha = [\"nope\"]\n");
        assert!(
            halls.starts_with("halls.uses.jisha names `nope`, which is not a hall template"),
            "{halls}"
        );
        assert!(load_catalog(&Params::default(), None).is_ok());
    }
}
