//! Machiya type files: one TOML file per type in `templates/machiya/`.
//!
//! The paper kept each type as a spreadsheet of parameters so that historians could change a
//! type without programming. Here a type is a small file of heights and materials that the
//! generator turns into a house; a user adds a type by dropping a file into a directory given
//! with `--templates` (or `machiya.templates`) and naming it in `type_mix`.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::generate::materials;

/// The types shipped with the tool, compiled in so the binary works anywhere.
pub const BUILTIN: &[(&str, &str)] = &[
    (
        "hiraya.toml",
        include_str!("../templates/machiya/hiraya.toml"),
    ),
    (
        "naka-nikai-small.toml",
        include_str!("../templates/machiya/naka-nikai-small.toml"),
    ),
    (
        "naka-nikai-large.toml",
        include_str!("../templates/machiya/naka-nikai-large.toml"),
    ),
    (
        "sou-nikai.toml",
        include_str!("../templates/machiya/sou-nikai.toml"),
    ),
    (
        "sangai.toml",
        include_str!("../templates/machiya/sangai.toml"),
    ),
    (
        "shimoutaya.toml",
        include_str!("../templates/machiya/shimoutaya.toml"),
    ),
    (
        "heitsuki.toml",
        include_str!("../templates/machiya/heitsuki.toml"),
    ),
    (
        "kanban-gatera.toml",
        include_str!("../templates/machiya/kanban-gatera.toml"),
    ),
];

#[derive(Debug, Error)]
pub enum TemplateError {
    #[error("machiya type file {file}: {message}")]
    Invalid { file: String, message: String },
    #[error("cannot read machiya type directory {dir}: {source}")]
    Io { dir: String, source: std::io::Error },
}

/// One machiya type: the heights and materials of its parts. Lengths in metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachiyaType {
    /// Name used in `type_mix` and reports (romaji).
    pub name: String,
    /// The name in kanji, as the machiya database spells it.
    pub kanji: String,
    /// Other spellings accepted in the `mtype` attribute.
    #[serde(default)]
    pub aliases: Vec<String>,
    /// Height of the front wall, where the main roof's eaves start.
    pub eave_height: f64,
    /// Rise of the roof per metre of run (e.g. 0.45 = a 4.5-sun pitch).
    pub roof_pitch: f64,
    /// Height of the street-side pent roof (ichi-no-hisashi 一の庇); 0 = none.
    #[serde(default)]
    pub hisashi_height: f64,
    /// How far the pent roof reaches over the street.
    #[serde(default = "default_hisashi_depth")]
    pub hisashi_depth: f64,
    /// Distance of the house behind the frontage (heitsuki 塀付: behind a front wall).
    #[serde(default)]
    pub setback: f64,
    /// Height of a wall along the frontage; 0 = none.
    #[serde(default)]
    pub front_wall_height: f64,
    /// Height of a flat board facade rising above the eaves (kanban-gatera 看板建); 0 = none.
    #[serde(default)]
    pub parapet_height: f64,
    /// Depth of the main building; 0 = `machiya.depth` of the parameter file.
    #[serde(default)]
    pub depth: f64,
    /// Materials, by name from the texture library.
    pub facade_material: String,
    #[serde(default = "default_wall")]
    pub wall_material: String,
    #[serde(default = "default_roof")]
    pub roof_material: String,
    /// Width of one repeat of the facade texture along the street.
    #[serde(default = "default_facade_base")]
    pub facade_base: f64,
}

fn default_hisashi_depth() -> f64 {
    0.6
}
fn default_wall() -> String {
    "shikkui_wall".into()
}
fn default_roof() -> String {
    "kawara_roof".into()
}
fn default_facade_base() -> f64 {
    1.818
}

/// All loaded types, by name.
#[derive(Debug, Clone, Default)]
pub struct Catalog {
    pub types: BTreeMap<String, MachiyaType>,
    /// Normalised spelling -> type name.
    aliases: BTreeMap<String, String>,
}

/// Folds the spellings users write: case, hyphens, spaces, brackets.
fn normalise(s: &str) -> String {
    s.trim()
        .to_lowercase()
        .chars()
        .filter(|c| !matches!(c, '-' | '_' | ' ' | '　' | '(' | ')' | '（' | '）'))
        .collect()
}

impl Catalog {
    /// The shipped types, or those of `dir` when it is given.
    pub fn load(dir: Option<&Path>) -> Result<Catalog, TemplateError> {
        let mut files = Vec::new();
        match dir {
            None => {
                for (name, text) in BUILTIN {
                    files.push((format!("templates/machiya/{name}"), text.to_string()));
                }
            }
            Some(dir) => {
                let io = |source| TemplateError::Io {
                    dir: dir.display().to_string(),
                    source,
                };
                let mut paths: Vec<_> = std::fs::read_dir(dir)
                    .map_err(io)?
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                    .collect();
                paths.sort();
                for p in paths {
                    let text = std::fs::read_to_string(&p).map_err(io)?;
                    files.push((p.display().to_string(), text));
                }
            }
        }
        let mut cat = Catalog::default();
        for (file, text) in files {
            let t: MachiyaType = toml::from_str(&text).map_err(|e| TemplateError::Invalid {
                file: file.clone(),
                message: e.to_string(),
            })?;
            check(&t).map_err(|message| TemplateError::Invalid {
                file: file.clone(),
                message,
            })?;
            for spelling in [&t.name, &t.kanji].into_iter().chain(&t.aliases) {
                if let Some(other) = cat.aliases.insert(normalise(spelling), t.name.clone()) {
                    if other != t.name {
                        return Err(TemplateError::Invalid {
                            file,
                            message: format!(
                                "the spelling `{spelling}` is already used by type `{other}`"
                            ),
                        });
                    }
                }
            }
            if cat.types.insert(t.name.clone(), t).is_some() {
                return Err(TemplateError::Invalid {
                    file,
                    message: "a type of this name is already loaded".into(),
                });
            }
        }
        if cat.types.is_empty() {
            return Err(TemplateError::Invalid {
                file: dir.map(|d| d.display().to_string()).unwrap_or_default(),
                message: "no machiya type files (*.toml) found".into(),
            });
        }
        Ok(cat)
    }

    /// The type a user's spelling names: romaji, kanji or alias.
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

    pub fn get(&self, name: &str) -> Option<&MachiyaType> {
        self.types.get(name)
    }
}

fn check(t: &MachiyaType) -> Result<(), String> {
    let nonneg = [
        ("eave_height", t.eave_height),
        ("roof_pitch", t.roof_pitch),
        ("hisashi_height", t.hisashi_height),
        ("hisashi_depth", t.hisashi_depth),
        ("setback", t.setback),
        ("front_wall_height", t.front_wall_height),
        ("parapet_height", t.parapet_height),
        ("depth", t.depth),
    ];
    for (key, v) in nonneg {
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!("`{key}` must be a number >= 0, got {v}"));
        }
    }
    if t.eave_height < 1.0 {
        return Err(format!("`eave_height` {} is below 1 m", t.eave_height));
    }
    if t.hisashi_height > t.eave_height {
        return Err("`hisashi_height` is above `eave_height`".into());
    }
    if !(t.facade_base.is_finite() && t.facade_base > 0.0) {
        return Err("`facade_base` must be positive".into());
    }
    for (key, m) in [
        ("facade_material", &t.facade_material),
        ("wall_material", &t.wall_material),
        ("roof_material", &t.roof_material),
    ] {
        if materials::find(m).is_none() {
            return Err(format!(
                "`{key}` names `{m}`, which is not in the texture library ({})",
                materials::names().join(", ")
            ));
        }
    }
    Ok(())
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
    fn a_user_directory_replaces_the_types_and_is_checked() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("tall.toml"),
            "name = \"tall\"\nkanji = \"高\"\neave_height = 9.0\nroof_pitch = 0.4\nfacade_material = \"no_such\"\n",
        )
        .unwrap();
        let err = Catalog::load(Some(dir.path())).unwrap_err().to_string();
        assert!(
            err.contains("tall.toml") && err.contains("no_such"),
            "{err}"
        );
    }
}
