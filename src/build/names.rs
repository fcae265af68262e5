//! Names a parameter file gives that the catalog and the texture library must hold, checked
//! before anything is read: the machiya, fence, gate and kura templates, hall templates,
//! ground materials, the billboards' templates and textures (moved out of build.rs, which
//! had grown past 800 lines).

use std::path::{Path, PathBuf};

use super::BuildError;
use crate::params::Params;
use crate::templates::{Catalog, Kind};

/// A name a parameter gives that the catalog or the texture library does not hold; each
/// says the key, the name and the names there are.
#[derive(Debug, thiserror::Error)]
pub enum NameError {
    /// Not a template of the kind the key asks for (none of that name, another kind, or an
    /// abstract one).
    #[error("{key_says} `{name}`, which is not a {kind} template ({kind} templates: {})", known.join(", "))]
    NotATemplate {
        /// What the key does, e.g. "kura.template names".
        key_says: String,
        /// The name given.
        name: String,
        /// The kind asked for, e.g. "gate".
        kind: String,
        /// The buildable templates of that kind.
        known: Vec<String>,
    },
    /// A type mix names a type that has no machiya template.
    #[error("{key} names `{name}`, which has no machiya template (known types: {})", known.join(", "))]
    NoMachiya {
        /// `type_mix` or `district.<id>.type_mix`.
        key: String,
        /// The type named.
        name: String,
        /// The machiya types there are.
        known: Vec<String>,
    },
    /// Not a material of the library.
    #[error(
        "{key} names `{name}`, which is not a library material (e.g. ground, gravel, street, \
         water, moss, stone)"
    )]
    NotAMaterial {
        /// E.g. `ground.materials.street`.
        key: String,
        /// The name given.
        name: String,
    },
    /// Not a texture of the library.
    #[error("{key} names `{name}`, which is not in the texture library ({})", library.join(", "))]
    NotATexture {
        /// E.g. `people.textures`.
        key: String,
        /// The name given.
        name: String,
        /// The library's textures.
        library: Vec<String>,
    },
}

/// The buildable templates of `kind`, owned for an error.
fn known(catalog: &Catalog, kind: Kind) -> Vec<String> {
    catalog
        .names_of(kind)
        .into_iter()
        .map(String::from)
        .collect()
}

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
            return Err(NameError::NoMachiya {
                key,
                name: name.clone(),
                known: known(&catalog, Kind::Machiya),
            }
            .into());
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
        false => Err(NameError::NotATemplate {
            key_says: key_says.to_string(),
            name: name.to_string(),
            kind: what.to_string(),
            known: known(catalog, kind),
        }
        .into()),
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
            return Err(NameError::NotAMaterial {
                key: format!("ground.materials.{u}"),
                name: m.clone(),
            }
            .into());
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
        let says = format!("{table}.template names");
        template_of(catalog, template, kind, kind.name(), &says)?;
        if let Some(bad) = textures
            .iter()
            .find(|n| crate::materials::find(n).is_none())
        {
            return Err(NameError::NotATexture {
                key: format!("{table}.textures"),
                name: bad.clone(),
                library: crate::materials::names()
                    .into_iter()
                    .map(String::from)
                    .collect(),
            }
            .into());
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
            Err(BuildError::Name(e)) => e.to_string(),
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
