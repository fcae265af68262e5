//! Templates: one file per model (machiya types, kura, fence, gate, tree and person
//! billboards), written by historians, read at run time.
//!
//! The paper kept each building type as a spreadsheet whose cells computed vertex coordinates
//! from parameters, so that a type could be changed without programming. A template here is a
//! TOML file of parameters, derived values (arithmetic expressions) and parts: prisms cut from
//! the lot and extruded under a roof line, or explicit vertices and faces. `docs/templates.md`
//! describes the format. A user adds a type by dropping a file into a directory given with
//! `--templates` (or `machiya.templates`) and naming it in `type_mix`.

mod compile;
pub(crate) mod dir;
pub mod expr;
pub mod file;
pub mod species;
pub mod template;

use std::collections::BTreeMap;
use std::path::Path;

use thiserror::Error;

pub use species::Species;
pub use template::{Kind, Template};

/// The types shipped with the tool, compiled in so the binary works anywhere.
pub const BUILTIN: &[(&str, &str)] = &[
    (
        "machiya/machiya.toml",
        include_str!("../../templates/machiya/machiya.toml"),
    ),
    (
        "machiya/hiraya.toml",
        include_str!("../../templates/machiya/hiraya.toml"),
    ),
    (
        "machiya/naka-nikai-small.toml",
        include_str!("../../templates/machiya/naka-nikai-small.toml"),
    ),
    (
        "machiya/naka-nikai-large.toml",
        include_str!("../../templates/machiya/naka-nikai-large.toml"),
    ),
    (
        "machiya/sou-nikai.toml",
        include_str!("../../templates/machiya/sou-nikai.toml"),
    ),
    (
        "machiya/sangai.toml",
        include_str!("../../templates/machiya/sangai.toml"),
    ),
    (
        "machiya/shimoutaya.toml",
        include_str!("../../templates/machiya/shimoutaya.toml"),
    ),
    (
        "machiya/heitsuki.toml",
        include_str!("../../templates/machiya/heitsuki.toml"),
    ),
    (
        "machiya/kanban-gatera.toml",
        include_str!("../../templates/machiya/kanban-gatera.toml"),
    ),
    ("kura.toml", include_str!("../../templates/kura.toml")),
    ("fence.toml", include_str!("../../templates/fence.toml")),
    ("tsuiji.toml", include_str!("../../templates/tsuiji.toml")),
    ("gate.toml", include_str!("../../templates/gate.toml")),
    ("tree.toml", include_str!("../../templates/tree.toml")),
    ("person.toml", include_str!("../../templates/person.toml")),
    (
        "halls/hondo.toml",
        include_str!("../../templates/halls/hondo.toml"),
    ),
    (
        "halls/sanmon.toml",
        include_str!("../../templates/halls/sanmon.toml"),
    ),
    (
        "halls/goju-no-to.toml",
        include_str!("../../templates/halls/goju-no-to.toml"),
    ),
    (
        "halls/omoya.toml",
        include_str!("../../templates/halls/omoya.toml"),
    ),
    (
        "halls/shinden.toml",
        include_str!("../../templates/halls/shinden.toml"),
    ),
];

/// The tree species shipped with the tool (`templates/trees/`), compiled in.
pub const BUILTIN_SPECIES: &[(&str, &str)] = &[
    (
        "matsu.toml",
        include_str!("../../templates/trees/matsu.toml"),
    ),
    (
        "momiji.toml",
        include_str!("../../templates/trees/momiji.toml"),
    ),
    (
        "yanagi.toml",
        include_str!("../../templates/trees/yanagi.toml"),
    ),
    (
        "sakura.toml",
        include_str!("../../templates/trees/sakura.toml"),
    ),
    ("sugi.toml", include_str!("../../templates/trees/sugi.toml")),
    ("take.toml", include_str!("../../templates/trees/take.toml")),
    ("ume.toml", include_str!("../../templates/trees/ume.toml")),
    ("kusu.toml", include_str!("../../templates/trees/kusu.toml")),
    (
        "matsu_kaze.toml",
        include_str!("../../templates/trees/matsu_kaze.toml"),
    ),
    (
        "shidare_zakura.toml",
        include_str!("../../templates/trees/shidare_zakura.toml"),
    ),
];

/// Why the templates cannot be used: the build stops before it reads any data.
#[derive(Debug, Error)]
pub enum TemplateError {
    /// Already `file:line:column: message`.
    #[error("{0}")]
    Invalid(String),
    /// A `--templates` directory cannot be read.
    #[error("cannot read template directory {dir}: {cause}")]
    Io {
        /// The directory.
        dir: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
}

/// All loaded templates, by name.
#[derive(Debug, Clone, Default)]
pub struct Catalog {
    /// Every template, by name.
    pub templates: BTreeMap<String, Template>,
    /// Normalised spelling -> machiya type name.
    aliases: BTreeMap<String, String>,
    /// Param values from the parameter file: template -> (slot, value).
    overrides: BTreeMap<String, Vec<(usize, f64)>>,
    /// The same per district: (district, template) -> (slot, value), on top of `overrides`.
    district_overrides: BTreeMap<(String, String), Vec<(usize, f64)>>,
    /// The tree species, by name: the shipped ones, then a user's `trees/` directory.
    pub species: BTreeMap<String, Species>,
}

/// Folds the spellings users write: case, hyphens, spaces, brackets.
fn normalise(s: &str) -> String {
    s.trim()
        .to_lowercase()
        .chars()
        .filter(|c| {
            !matches!(
                c,
                '-' | '_' | ' ' | '\u{3000}' | '(' | ')' | '\u{ff08}' | '\u{ff09}'
            )
        })
        .collect()
}

/// The shipped species, then each `*.toml` of `<dir>/trees/` (replacing a shipped species of
/// the same name).
fn load_species(dir: Option<&Path>) -> Result<BTreeMap<String, Species>, TemplateError> {
    let mut out = BTreeMap::new();
    for (name, text) in BUILTIN_SPECIES {
        let s = species::parse(&format!("templates/trees/{name}"), text)
            .map_err(TemplateError::Invalid)?;
        out.insert(s.name.clone(), s);
    }
    let Some(dir) = dir.map(|d| d.join("trees")).filter(|d| d.is_dir()) else {
        return Ok(out);
    };
    let paths = dir::toml_files(&dir, "", false)?;
    let mut seen = BTreeMap::new();
    for p in paths {
        let text = dir::read(&p)?;
        let file = p.display().to_string();
        let s = species::parse(&file, &text).map_err(TemplateError::Invalid)?;
        if let Some(other) = seen.insert(s.name.clone(), file.clone()) {
            return Err(TemplateError::Invalid(format!(
                "{file}: species `{}` is already defined in {other}",
                s.name
            )));
        }
        out.insert(s.name.clone(), s);
    }
    Ok(out)
}

impl Catalog {
    /// The shipped templates, then those of `dir` (a file of the same name replaces a shipped
    /// one; any other file adds a template).
    pub fn load(dir: Option<&Path>) -> Result<Catalog, TemplateError> {
        let mut sources = BTreeMap::new();
        for (name, text) in BUILTIN {
            let s =
                file::parse(&format!("templates/{name}"), text).map_err(TemplateError::Invalid)?;
            sources.insert(s.name.value.clone(), s);
        }
        if let Some(dir) = dir {
            // Tree species live in `trees/`, in their own format.
            let paths = dir::toml_files(dir, "trees", true)?;
            let mut seen = BTreeMap::new();
            for p in paths {
                let text = dir::read(&p)?;
                let file = p.display().to_string();
                let s = file::parse(&file, &text).map_err(TemplateError::Invalid)?;
                if let Some(other) = seen.insert(s.name.value.clone(), file.clone()) {
                    return Err(TemplateError::Invalid(format!(
                        "{}: template `{}` is already defined in {other}",
                        s.name.loc, s.name.value
                    )));
                }
                sources.insert(s.name.value.clone(), s);
            }
        }
        let mut cat = Catalog::default();
        for name in sources.keys() {
            let merged = resolve_extends(&sources, name)?;
            let t = compile::compile_template(&merged).map_err(TemplateError::Invalid)?;
            if t.kind == Kind::Machiya && !t.is_abstract {
                for spelling in [&t.name, &t.kanji].into_iter().chain(&t.aliases) {
                    if spelling.is_empty() {
                        continue;
                    }
                    if let Some(other) = cat.aliases.insert(normalise(spelling), t.name.clone()) {
                        if other != t.name {
                            return Err(TemplateError::Invalid(format!(
                                "{}: the spelling `{spelling}` is already used by type `{other}`",
                                t.file
                            )));
                        }
                    }
                }
            }
            cat.templates.insert(t.name.clone(), t);
        }
        cat.species = load_species(dir)?;
        Ok(cat)
    }

    /// The machiya type a user's spelling names: romaji, kanji or alias.
    ///
    /// ```
    /// let cat = edo_city::templates::Catalog::load(None).unwrap();
    /// assert_eq!(cat.resolve("総二階"), Some("sou-nikai"));
    /// assert_eq!(cat.resolve("Naka Nikai (small)"), Some("naka-nikai-small"));
    /// assert_eq!(cat.resolve("castle"), None);
    /// ```
    pub fn resolve(&self, spelling: &str) -> Option<&str> {
        self.aliases.get(&normalise(spelling)).map(String::as_str)
    }

    /// A template by name (abstract ones included).
    pub fn get(&self, name: &str) -> Option<&Template> {
        self.templates.get(name)
    }

    /// A machiya type that can be built (not abstract).
    pub fn machiya(&self, name: &str) -> Option<&Template> {
        self.get(name)
            .filter(|t| t.kind == Kind::Machiya && !t.is_abstract)
    }

    /// Names of the buildable templates of a kind.
    pub fn names_of(&self, kind: Kind) -> Vec<&str> {
        self.templates
            .values()
            .filter(|t| t.kind == kind && !t.is_abstract)
            .map(|t| t.name.as_str())
            .collect()
    }

    /// Takes the `[template.<name>]` and `[district.<id>.template.<name>]` values of the
    /// parameter file; an unknown template or parameter name is an error.
    pub fn configure(
        &mut self,
        global: &BTreeMap<String, BTreeMap<String, f64>>,
        districts: &BTreeMap<String, BTreeMap<String, BTreeMap<String, f64>>>,
    ) -> Result<(), TemplateError> {
        let slots = |cat: &Catalog, where_: &str, name: &str, values: &BTreeMap<String, f64>| {
            let t = cat.get(name).ok_or_else(|| {
                TemplateError::Invalid(format!(
                    "parameter file: [{where_}template.{name}]: there is no template `{name}` \
                     (templates: {})",
                    cat.templates.keys().cloned().collect::<Vec<_>>().join(", ")
                ))
            })?;
            values
                .iter()
                .map(|(k, v)| {
                    let slot = t
                        .params
                        .clone()
                        .find(|s| t.names[*s] == *k)
                        .ok_or_else(|| {
                            TemplateError::Invalid(format!(
                            "parameter file: [{where_}template.{name}] sets `{k}`, which is not \
                             a parameter of {} (its parameters: {})",
                            t.file,
                            t.param_names().join(", ")
                        ))
                        })?;
                    if let Some(why) = file::value_problem(*v) {
                        return Err(TemplateError::Invalid(format!(
                            "parameter file: [{where_}template.{name}] `{k}` = {v} {why}"
                        )));
                    }
                    Ok((slot, *v))
                })
                .collect::<Result<Vec<_>, _>>()
        };
        let mut overrides = BTreeMap::new();
        for (name, values) in global {
            overrides.insert(name.clone(), slots(self, "", name, values)?);
        }
        let mut by_district = BTreeMap::new();
        for (district, templates) in districts {
            for (name, values) in templates {
                let at = format!("district.{district}.");
                by_district.insert(
                    (district.clone(), name.clone()),
                    slots(self, &at, name, values)?,
                );
            }
        }
        self.overrides = overrides;
        self.district_overrides = by_district;
        Ok(())
    }

    /// The param values the parameter file sets for `template` in `district`.
    pub fn overrides(&self, template: &str, district: Option<&str>) -> Vec<(usize, f64)> {
        let mut out = self.overrides.get(template).cloned().unwrap_or_default();
        if let Some(d) = district {
            if let Some(more) = self
                .district_overrides
                .get(&(d.to_string(), template.to_string()))
            {
                out.extend(more.iter().copied());
            }
        }
        out
    }
}

/// A template with the chain of templates it extends merged in.
fn resolve_extends(
    sources: &BTreeMap<String, file::Source>,
    name: &str,
) -> Result<file::Source, TemplateError> {
    let mut chain = vec![&sources[name]];
    while let Some(base) = &chain.last().expect("not empty").extends {
        let b = sources.get(&base.value).ok_or_else(|| {
            TemplateError::Invalid(format!(
                "{}: extends `{}`, which is not a template",
                base.loc, base.value
            ))
        })?;
        if chain.iter().any(|c| c.name.value == b.name.value) {
            return Err(TemplateError::Invalid(format!(
                "{}: `extends` goes round in a circle through `{}`",
                base.loc, base.value
            )));
        }
        chain.push(b);
    }
    let mut merged = chain.pop().expect("not empty").clone();
    while let Some(child) = chain.pop() {
        merged = file::merge(&merged, child);
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_types_cover_the_paper() {
        let cat = Catalog::load(None).unwrap();
        for kanji in [
            "総二階",
            "中二階",
            "平屋",
            "三階",
            "仕舞屋",
            "塀付",
            "看板建",
        ] {
            assert!(cat.resolve(kanji).is_some(), "{kanji}");
        }
        for name in ["hiraya", "naka-nikai-small", "naka-nikai-large"] {
            assert!(cat.get(name).is_some(), "{name}");
        }
    }

    #[test]
    fn a_user_directory_adds_types_and_errors_point_at_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let good =
            "name = \"tall\"\nkanji = \"高\"\nextends = \"machiya\"\n[params]\neave_height = 9.0\n";
        std::fs::write(dir.path().join("tall.toml"), good).unwrap();
        let cat = Catalog::load(Some(dir.path())).unwrap();
        assert!(cat.machiya("tall").is_some() && cat.machiya("hiraya").is_some());
        assert_eq!(cat.resolve("高"), Some("tall"));

        let cases = [
            ("[materials]\nfacade = \"no_such\"\n", "tall.toml:7:10", "no_such"),
            ("[derived]\nx = \"eave_height +\"\n", "tall.toml:7:5", "lacks an operand"),
            ("[derived]\nx = \"bogus * 2\"\n", "tall.toml:7:5", "unknown name `bogus`"),
            ("[derived]\nx = \"y\"\ny = \"x\"\n", "tall.toml:7:5", "cycle"),
            ("[[part]]\nname = \"p\"\nclosed = false\nvertices = [[0,0,0],[1,0,0],[0,1,0]]\nfaces = [{ corners = [1, 2, 4], material = \"wood\" }]\n", "tall.toml:10:29", "out of range"),
        ];
        let typo = format!("typo = 1\n{good}");
        for (extra, at, what) in cases {
            std::fs::write(dir.path().join("tall.toml"), format!("{good}{extra}")).unwrap();
            let Err(err) = Catalog::load(Some(dir.path())) else {
                panic!("{extra}: loaded");
            };
            let err = err.to_string();
            assert!(err.contains(at) && err.contains(what), "{extra}: {err}");
        }
        std::fs::write(dir.path().join("tall.toml"), typo).unwrap();
        let Err(err) = Catalog::load(Some(dir.path())) else {
            panic!("typo loaded");
        };
        let err = err.to_string();
        assert!(
            err.contains("tall.toml:1:1") && err.contains("unknown field"),
            "{err}"
        );
    }
}
