//! Every parameter with its section, type, default and doc, read from the one place they are
//! defined, `params/default.toml` (the text `edo-city params` prints): its keys, values and
//! the comments above and beside each key. The workbench's panel (`GET /api/params`, issue
//! 61) lists them; nothing keeps a second list.

use serde::Serialize;

use super::DEFAULT_TOML;

/// Tables given whole: a user who lists them means exactly those entries (see
/// `resolve::merge`), so the panel sets them as one value.
pub const WHOLE: &[&str] = &["type_mix", "values", "constants"];

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
    walk(doc.as_table(), "", &mut out);
    out
}

fn walk(table: &toml_edit::Table, at: &str, out: &mut Vec<ParamDoc>) {
    let section = match at {
        "" => "general",
        s => s,
    };
    for (name, item) in table.iter() {
        let key = match at {
            "" => name.to_string(),
            _ => format!("{at}.{name}"),
        };
        let above = table
            .key(name)
            .and_then(|k| k.leaf_decor().prefix())
            .and_then(|p| p.as_str())
            .map(comment)
            .unwrap_or_default();
        match item {
            toml_edit::Item::Table(t) if !WHOLE.contains(&name) => walk(t, &key, out),
            toml_edit::Item::Table(t) => out.push(ParamDoc {
                key,
                section: section.to_string(),
                kind: "table",
                default: json_of(&t.clone().into_inline_table().into()),
                doc: [table_doc(t), above].concat().trim().to_string(),
            }),
            toml_edit::Item::Value(v) => {
                let beside = v.decor().suffix().and_then(|s| s.as_str()).map(comment);
                out.push(ParamDoc {
                    key,
                    section: section.to_string(),
                    kind: kind_of(v),
                    default: json_of(v),
                    doc: [above, beside.unwrap_or_default()]
                        .join("\n")
                        .trim()
                        .to_string(),
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
