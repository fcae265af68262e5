//! A person's parameter file edited in place: one key set or removed at a time with
//! `toml_edit`, so their comments, order and layout stay where they wrote them.

use toml_edit::{DocumentMut, Item, Table, Value};

/// Sets `key` (dotted, as the TOML spells it) to `value` in `text`, or removes it when
/// `value` is null (the default then holds); the new text. Tables on the way are made as
/// `[table]` headers, not dotted keys, as a person would write them.
pub fn set_key(text: &str, key: &str, value: &serde_json::Value) -> Result<String, String> {
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e| format!("the parameter file does not parse: {e}"))?;
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts
        .pop()
        .filter(|l| !l.is_empty())
        .ok_or("an empty key")?;
    let mut table: &mut Table = doc.as_table_mut();
    for p in parts {
        if p.is_empty() {
            return Err(format!("`{key}` is not a key"));
        }
        let entry = table.entry(p).or_insert_with(|| {
            let mut t = Table::new();
            t.set_implicit(true);
            Item::Table(t)
        });
        if let Item::Value(Value::InlineTable(inline)) = entry {
            *entry = Item::Table(inline.clone().into_table());
        }
        table = entry
            .as_table_mut()
            .ok_or_else(|| format!("`{p}` of `{key}` is a value in the file, not a table"))?;
    }
    if value.is_null() {
        table.remove(last);
    } else {
        let item = match to_toml(value)? {
            // A table given whole (`type_mix`) as a `[table]` of its own.
            Value::InlineTable(t) if table.get(last).is_none_or(Item::is_table) => {
                Item::Table(t.into_table())
            }
            v => Item::Value(v),
        };
        match table.get_mut(last) {
            // The value replaced, the comment beside it kept.
            Some(Item::Value(old)) if item.is_value() => {
                let decor = old.decor().clone();
                *old = item.into_value().map_err(|_| "not a value")?;
                *old.decor_mut() = decor;
            }
            _ => {
                table.insert(last, item);
            }
        }
    }
    Ok(doc.to_string())
}

/// A JSON value as a TOML one: numbers keep their kind (an integer stays one).
fn to_toml(v: &serde_json::Value) -> Result<Value, String> {
    use serde_json::Value as J;
    Ok(match v {
        J::Bool(b) => Value::from(*b),
        J::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => Value::from(i),
            (None, Some(f)) if f.is_finite() => Value::from(f),
            _ => return Err(format!("{n} is not a number TOML can hold")),
        },
        J::String(s) => Value::from(s.as_str()),
        J::Array(items) => {
            let mut a = toml_edit::Array::new();
            for i in items {
                a.push(to_toml(i)?);
            }
            Value::Array(a)
        }
        J::Object(map) => {
            let mut t = toml_edit::InlineTable::new();
            for (k, v) in map {
                t.insert(k, to_toml(v)?);
            }
            Value::InlineTable(t)
        }
        J::Null => return Err("null is no value (send it to reset a key)".into()),
    })
}

/// The value of `key` in `text`, as JSON, when the file sets it.
pub fn get_key(text: &str, key: &str) -> Option<serde_json::Value> {
    let table: toml::Table = text.parse().ok()?;
    let mut at = toml::Value::Table(table);
    for p in key.split('.') {
        at = at.as_table()?.get(p)?.clone();
    }
    serde_json::to_value(at).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn comments_and_order_stay_where_the_person_wrote_them() {
        let text = "# my hypothesis\nseed = 3 # lucky\n\n[kura]\n# wider courtyards\ngap = 2.0\n";
        let t = set_key(text, "kura.gap", &json!(2.5)).unwrap();
        assert_eq!(
            t,
            "# my hypothesis\nseed = 3 # lucky\n\n[kura]\n# wider courtyards\ngap = 2.5\n"
        );
        let t = set_key(&t, "seed", &json!(4)).unwrap();
        assert!(t.contains("seed = 4 # lucky"), "{t}");
        let t = set_key(&t, "trees.style", &json!("lsystem")).unwrap();
        assert!(t.ends_with("[trees]\nstyle = \"lsystem\"\n"), "{t}");
        let t = set_key(&t, "type_mix", &json!({"sangai": 1.0, "hiraya": 2})).unwrap();
        assert!(t.contains("[type_mix]\n"), "{t}");
        assert_eq!(
            get_key(&t, "type_mix"),
            Some(json!({"hiraya": 2, "sangai": 1.0}))
        );
        let t = set_key(&t, "kura.gap", &serde_json::Value::Null).unwrap();
        assert!(!t.contains("gap"), "{t}");
        assert!(t.contains("# my hypothesis"));
        assert!(set_key("seed = 1\n", "seed.x", &json!(1)).is_err());
        assert!(set_key("x = [", "seed", &json!(1)).is_err());
    }
}
