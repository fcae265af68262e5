//! Every parameter with its section, type, default and doc, read from the one place they are
//! defined, `params/default.toml` (the text `edo-city params` prints): its keys, values and
//! the comments above and beside each key. The workbench's panel (`GET /api/params`, issue
//! 61) lists them; nothing keeps a second list.

use serde::Serialize;

use super::DEFAULT_TOML;

/// Tables given whole: a user who lists them means exactly those entries (see
/// `resolve::merge`), so the panel sets them as one value.
pub const WHOLE: &[&str] = &["type_mix", "values", "constants"];

/// Tables a parameter file may add keys of any name to: `[seeds] trees = 1`, `[district.<id>]`,
/// `[landmarks.models] pagoda = "pagoda.glb"`, a use in `[halls.uses]`.
pub const OPEN: &[&str] = &[
    "seeds",
    "district",
    "fence.types",
    "halls.uses",
    "ground.materials",
    "landmarks.models",
    "trees.species",
];
/// The most dotted parts a key may have: `district.<id>.template.<name>.<param>` has five.
pub const MAX_KEY_PARTS: usize = 6;
/// The longest key, in bytes.
pub const MAX_KEY_BYTES: usize = 256;

/// Whether `key` can name a parameter: one of the catalogue's, or one under an [`OPEN`]
/// table, within [`MAX_KEY_PARTS`] and [`MAX_KEY_BYTES`]. Asked before anything is built from
/// a key a page sends (a key of 30,000 dotted parts made a document 30,000 tables deep,
/// which overflowed the server's stack: issue 74); whether its value is right is the build's
/// to say.
pub fn knows(key: &str) -> bool {
    let parts: Vec<&str> = key.split('.').collect();
    if key.len() > MAX_KEY_BYTES
        || parts.len() > MAX_KEY_PARTS
        || parts
            .iter()
            .any(|p| p.is_empty() || p.chars().any(char::is_control))
    {
        return false;
    }
    let open = OPEN.iter().any(|t| {
        key.strip_prefix(t)
            .is_some_and(|rest| rest.starts_with('.'))
    });
    open || catalogue().iter().any(|p| p.key == key)
}

/// Where a path-valued parameter's relative path is taken from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathBase {
    /// The input directory (`layers.*.file`, `layers.*.table`).
    Input,
    /// The parameter file's directory (`input.overrides`, `garden.designs`, `extends`).
    ParamsFile,
    /// The directory the build is run from (`textures`, `machiya.templates`,
    /// `landmarks.models_dir`).
    WorkingDir,
    /// `landmarks.models_dir` (the input directory when it is "").
    Models,
}

/// Where `key`'s value is a path from, when it names a file or a directory.
pub fn path_base(key: &str) -> Option<PathBase> {
    match key {
        "textures" | "machiya.templates" | "landmarks.models_dir" => Some(PathBase::WorkingDir),
        "input.overrides" | "garden.designs" | "extends" => Some(PathBase::ParamsFile),
        k if k.starts_with("landmarks.models.") => Some(PathBase::Models),
        k if k.starts_with("layers.") && (k.ends_with(".file") || k.ends_with(".table")) => {
            Some(PathBase::Input)
        }
        _ => None,
    }
}

/// One parameter as the defaults document it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamDoc {
    /// Its key as the TOML spells it (`seed`, `trees.style`).
    pub key: String,
    /// Its table (`trees`, `layers.lots.fields`); `general` for the top-level keys.
    pub section: String,
    /// `integer`, `float`, `string`, `boolean`, `array` or `table`.
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// The default value.
    pub default: serde_json::Value,
    /// The comments above it and beside it in `params/default.toml`, without their `#`.
    pub doc: String,
}

/// Every parameter of `params/default.toml`, in the file's order.
pub fn catalogue() -> Vec<ParamDoc> {
    let doc: toml_edit::DocumentMut = DEFAULT_TOML.parse().expect("the shipped defaults parse");
    let mut out = Vec::new();
    walk(doc.as_table(), "", "", &mut out);
    out
}

/// The parameters of `table` (at the key `at`) into `out`. A key's doc is the comment
/// above it and the one beside it; a key with no comment above it that follows the one
/// before without a blank line is of that key's group and shares its comment (`x_field`,
/// `y_field` under the comment that says what both are); a key of no group has the comment
/// of its table, `section`, the one above the table's header.
fn walk(table: &toml_edit::Table, at: &str, section_doc: &str, out: &mut Vec<ParamDoc>) {
    let section = match at {
        "" => "general",
        s => s,
    };
    let mut group = String::new();
    for (name, item) in table.iter() {
        let key = match at {
            "" => name.to_string(),
            _ => format!("{at}.{name}"),
        };
        let raw = table
            .key(name)
            .and_then(|k| k.leaf_decor().prefix())
            .and_then(|p| p.as_str())
            .unwrap_or_default();
        let above = comment(raw);
        if !above.is_empty() {
            group = above.clone();
        } else if raw.lines().any(|l| l.trim().is_empty()) {
            group.clear();
        }
        // A key's own comment (above or beside) is its doc; else its group's, else its
        // table's.
        let own_or_group = |beside: &str| {
            let own = [above.as_str(), beside].join("\n").trim().to_string();
            match (own.is_empty(), group.is_empty()) {
                (false, _) => own,
                (true, false) => group.clone(),
                (true, true) => section_doc.to_string(),
            }
        };
        match item {
            toml_edit::Item::Table(t) if !WHOLE.contains(&name) => {
                let own = table_doc(t);
                let inherited = match own.is_empty() {
                    true => section_doc.to_string(),
                    false => own,
                };
                walk(t, &key, &inherited, out);
            }
            toml_edit::Item::Table(t) => out.push(ParamDoc {
                key,
                section: section.to_string(),
                kind: "table",
                default: json_of(&t.clone().into_inline_table().into()),
                doc: own_or_group(&table_doc(t)),
            }),
            toml_edit::Item::Value(v) => {
                let beside = v.decor().suffix().and_then(|s| s.as_str()).map(comment);
                out.push(ParamDoc {
                    key,
                    section: section.to_string(),
                    kind: kind_of(v),
                    default: json_of(v),
                    doc: own_or_group(&beside.unwrap_or_default()),
                });
            }
            _ => {}
        }
    }
}

/// The comments above a table's header.
fn table_doc(t: &toml_edit::Table) -> String {
    t.decor()
        .prefix()
        .and_then(|p| p.as_str())
        .map(comment)
        .unwrap_or_default()
}

/// The last block of comment lines (after the last blank line: a file's or a group's
/// heading above it is not its doc), without their `#`, one text.
fn comment(raw: &str) -> String {
    let lines: Vec<&str> = raw.lines().map(str::trim).collect();
    let start = lines
        .iter()
        .rposition(|l| l.is_empty())
        .map_or(0, |i| i + 1);
    lines[start..]
        .iter()
        .filter_map(|l| l.strip_prefix('#'))
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .collect::<Vec<_>>()
        .join("\n")
}

fn kind_of(v: &toml_edit::Value) -> &'static str {
    match v {
        toml_edit::Value::Integer(_) => "integer",
        toml_edit::Value::Float(_) => "float",
        toml_edit::Value::String(_) => "string",
        toml_edit::Value::Boolean(_) => "boolean",
        toml_edit::Value::Array(_) => "array",
        toml_edit::Value::InlineTable(_) => "table",
        toml_edit::Value::Datetime(_) => "string",
    }
}

/// A TOML value as JSON (through its text, which `toml` reads).
fn json_of(v: &toml_edit::Value) -> serde_json::Value {
    let text = format!("x = {}", v.to_string().trim());
    toml::from_str::<toml::Table>(&text)
        .ok()
        .and_then(|t| t.get("x").cloned())
        .and_then(|x| serde_json::to_value(x).ok())
        .unwrap_or(serde_json::Value::Null)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_known_before_anything_is_built_from_them() {
        for k in [
            "seed",
            "kura.gap",
            "type_mix",
            "seeds.trees",
            "district.a.trees_per_ha",
        ] {
            assert!(knows(k), "{k}");
        }
        assert!(knows("landmarks.models.pagoda"));
        for k in [
            "",
            "nope",
            "kura.nope",
            "kura..gap",
            "seeds",
            ".seed",
            "seed.",
        ] {
            assert!(!knows(k), "{k}");
        }
        assert!(!knows(&vec!["district"; 30_000].join(".")));
        assert!(!knows(&format!("district.{}", "x".repeat(300))));
        assert!(!knows("district.a.b.c.d.e.f"));
        assert_eq!(path_base("layers.lots.file"), Some(PathBase::Input));
        assert_eq!(path_base("layers.lots.table"), Some(PathBase::Input));
        assert_eq!(path_base("machiya.templates"), Some(PathBase::WorkingDir));
        assert_eq!(path_base("input.overrides"), Some(PathBase::ParamsFile));
        assert_eq!(path_base("landmarks.models.pagoda"), Some(PathBase::Models));
        assert_eq!(path_base("layers.lots.encoding"), None);
        // Every catalogue key that names a file is one of these.
        for p in catalogue() {
            let doc = p.doc.to_lowercase();
            if p.kind == "string" && (p.key.ends_with(".file") || doc.contains("directory of")) {
                assert!(path_base(&p.key).is_some(), "{}", p.key);
            }
        }
    }

    #[test]
    fn every_default_is_listed_with_its_doc() {
        let all = catalogue();
        let get = |k: &str| {
            all.iter()
                .find(|p| p.key == k)
                .unwrap_or_else(|| panic!("{k}"))
        };
        let seed = get("seed");
        assert_eq!((seed.section.as_str(), seed.kind), ("general", "integer"));
        assert_eq!(seed.default, serde_json::json!(1));
        assert!(
            seed.doc.starts_with("Seed of every random choice"),
            "{}",
            seed.doc
        );
        let style = get("trees.style");
        assert_eq!((style.section.as_str(), style.kind), ("trees", "string"));
        assert_eq!(style.default, "billboard");
        let gap = get("kura.gap");
        assert_eq!(gap.kind, "float");
        assert!(
            gap.doc.contains("courtyard"),
            "the comment beside it: {}",
            gap.doc
        );
        let mix = get("type_mix");
        assert_eq!(mix.kind, "table");
        assert_eq!(mix.default["hiraya"], 86.0);
        assert!(get("layers.lots.fields.mtype").doc.contains("machiya type"));
        // Every key is one the parameters have: the defaults round-trip through them.
        let defaults = serde_json::to_value(crate::params::Params::default()).unwrap();
        for p in &all {
            let v = p.key.split('.').fold(&defaults, |v, k| &v[k]);
            // (A key left out of a manifest when unset reads as null.)
            let unset = p.default == "" || p.default == false;
            assert!(!v.is_null() || unset, "{} is no parameter", p.key);
        }
        assert!(all.len() > 100, "{}", all.len());
    }
}

#[cfg(test)]
mod every_key_explained {
    use super::catalogue;

    /// Every row of the workbench's panel says what its key does (issue 76: 90 of 186 had
    /// no doc): each key's comment in params/default.toml, above or beside it, else the
    /// comment of the group of keys it follows without a blank line, else its table's.
    #[test]
    fn every_parameter_has_a_doc() {
        let all = catalogue();
        let missing: Vec<&str> = (all.iter())
            .filter(|p| p.doc.trim().is_empty())
            .map(|p| p.key.as_str())
            .collect();
        assert!(missing.is_empty(), "no doc: {}", missing.join(", "));
        let doc = |k: &str| {
            all.iter()
                .find(|p| p.key == k)
                .unwrap_or_else(|| panic!("{k}"))
                .doc
                .clone()
        };
        // The keys the issue named, each with words of its own.
        assert!(
            doc("output.formats").contains("\"obj\""),
            "{}",
            doc("output.formats")
        );
        assert!(
            doc("kura.enabled").contains("storehouses"),
            "{}",
            doc("kura.enabled")
        );
        assert!(
            doc("trees.height").contains("metres"),
            "{}",
            doc("trees.height")
        );
        for layer in ["lots", "blocks", "streets", "people", "trees", "footprints"] {
            let d = doc(&format!("layers.{layer}.encoding"));
            assert!(d.contains("encoding"), "layers.{layer}.encoding: {d}");
        }
        // A key with a comment beside it is not given its group's as well.
        assert!(!doc("ground.texture_size").contains("centrelines"));
        assert_eq!(
            doc("kura.min_width"),
            "a narrower lot shrinks its kura down to this, then gets none"
        );
    }
}
