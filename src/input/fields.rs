//! Finding the user's field names in a layer, and turning raw values into edo-city's.
//!
//! Japanese municipal shapefiles have Japanese field names cut to the DBF's 10 bytes, often in
//! the middle of a Shift_JIS character (`所在地市区町村` is stored as `所在地市区`). A user may
//! write the whole name; we match it the way the file was cut.

use std::collections::BTreeMap;

/// The layer's field that `wanted` names: exact, then ASCII case-insensitive, then as the DBF
/// would have truncated it to 10 bytes in the layer's encoding.
///
/// ```
/// use edo_city::input::fields::resolve_field;
/// let fields = vec!["任意ID".to_string(), "所在地市区".to_string()];
/// let sjis = Some(encoding_rs::SHIFT_JIS);
/// assert_eq!(resolve_field("所在地市区町村", &fields, sjis), Some("所在地市区"));
/// assert_eq!(resolve_field("任意id", &fields, sjis), Some("任意ID"));
/// assert_eq!(resolve_field("名称", &fields, sjis), None);
/// ```
pub fn resolve_field<'a>(
    wanted: &str,
    fields: &'a [String],
    encoding: Option<&'static encoding_rs::Encoding>,
) -> Option<&'a str> {
    if wanted.is_empty() {
        return None;
    }
    if let Some(f) = fields.iter().find(|f| *f == wanted) {
        return Some(f);
    }
    if let Some(f) = fields.iter().find(|f| f.eq_ignore_ascii_case(wanted)) {
        return Some(f);
    }
    let enc = encoding.unwrap_or(encoding_rs::UTF_8);
    let (bytes, _, _) = enc.encode(wanted);
    if bytes.len() <= 10 {
        return None;
    }
    let cut = enc.decode(&bytes[..10]).0;
    let cut = cut.trim_end_matches('\u{fffd}');
    fields
        .iter()
        .find(|f| f.trim_end_matches('\u{fffd}') == cut)
        .map(String::as_str)
}

/// How one attribute is read: which field, what to use when it is empty, how to map values.
#[derive(Debug, Clone, Default)]
pub struct AttributeRule {
    /// The layer's field holding the attribute, if it has one.
    pub field: Option<String>,
    /// The constant of the parameter file, used where the field is empty or missing.
    pub constant: Option<String>,
    /// The value map of the parameter file (the data's codes to edo-city's names).
    pub values: BTreeMap<String, String>,
}

impl AttributeRule {
    /// The attribute's value for a feature: the field (trimmed), else the constant, then the
    /// value map applied. `None` when all are empty.
    pub fn value(&self, attrs: &crate::model::Attrs) -> Option<String> {
        let raw = self
            .field
            .as_ref()
            .and_then(|f| attrs.get(f))
            .map(|v| v.trim().to_string())
            .filter(|v| !v.is_empty())
            .or_else(|| self.constant.clone())?;
        Some(self.values.get(&raw).cloned().unwrap_or(raw))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_map_and_constant() {
        let rule = AttributeRule {
            field: Some("youto".into()),
            constant: Some("machiya".into()),
            values: [("1".to_string(), "buke".to_string())].into(),
        };
        let mut attrs = crate::model::Attrs::default();
        assert_eq!(rule.value(&attrs).as_deref(), Some("machiya"));
        attrs.insert("youto".into(), " 1 ");
        assert_eq!(rule.value(&attrs).as_deref(), Some("buke"));
        attrs.insert("youto".into(), "7");
        assert_eq!(rule.value(&attrs).as_deref(), Some("7"));
    }

    #[test]
    fn a_name_cut_inside_a_character_still_matches() {
        // 10 bytes of Shift_JIS end in the middle of the 6th character: the DBF keeps 5 and a
        // half characters, decoded with a replacement character.
        let fields = vec!["管理都道府\u{fffd}".to_string()];
        let sjis = Some(encoding_rs::SHIFT_JIS);
        assert!(resolve_field("管理都道府県", &fields, sjis).is_some());
    }
}
