//! A feature's attributes as text, by field name.

use std::sync::Arc;

/// Every attribute of one feature, as text by field name, kept sorted by name (the order a
/// `BTreeMap` would give, so "the first field that ..." means the same everywhere).
///
/// Why not a `BTreeMap<String, String>`: a layer has a handful of fields and a million
/// features. A map per feature allocates a 500-byte node and copies every field name into
/// every feature; at a million lots that was over half a gigabyte. Here the names are shared
/// (`Arc<str>`, one per layer field, see [`FieldNames`]) and the pairs sit in one vector.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Attrs(Vec<(Arc<str>, Box<str>)>);

impl Attrs {
    /// The value of field `name`, if the feature has that field.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.find(name).ok().map(|i| &*self.0[i].1)
    }

    /// Sets field `name` to `value`, replacing the value it had.
    pub fn insert(&mut self, name: Arc<str>, value: impl Into<Box<str>>) {
        match self.find(&name) {
            Ok(i) => self.0[i].1 = value.into(),
            Err(i) => self.0.insert(i, (name, value.into())),
        }
    }

    /// The fields and their values, sorted by field name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &str)> {
        self.0.iter().map(|(k, v)| (&**k, &**v))
    }

    /// How many fields the feature has.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether the feature has no fields.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Makes its names the shared ones of `names` (a deserialized feature has its own
    /// copies; the analysis cache reads a million of them back).
    pub fn share_names(&mut self, names: &mut FieldNames) {
        for (k, _) in &mut self.0 {
            *k = names.intern(k);
        }
    }

    fn find(&self, name: &str) -> Result<usize, usize> {
        self.0.binary_search_by(|(k, _)| (**k).cmp(name))
    }
}

/// Builds from pairs in any order; where a name comes twice the later value wins (as a map's
/// `insert` would have it).
impl FromIterator<(Arc<str>, Box<str>)> for Attrs {
    fn from_iter<I: IntoIterator<Item = (Arc<str>, Box<str>)>>(pairs: I) -> Self {
        let mut v: Vec<(Arc<str>, Box<str>)> = pairs.into_iter().collect();
        // A stable sort keeps equal names in input order; the loop keeps the last of a run.
        v.sort_by(|a, b| a.0.cmp(&b.0));
        let mut out: Vec<(Arc<str>, Box<str>)> = Vec::with_capacity(v.len());
        for pair in v {
            match out.last_mut() {
                Some(last) if last.0 == pair.0 => *last = pair,
                _ => out.push(pair),
            }
        }
        out.shrink_to_fit();
        Attrs(out)
    }
}

/// A layer's field names, each allocated once and shared by every feature's [`Attrs`].
/// (A set, not a list: an attribute table may have hundreds of columns.)
#[derive(Clone, Debug, Default)]
pub struct FieldNames(std::collections::HashSet<Arc<str>>);

impl FieldNames {
    /// The shared name equal to `name`, made (once) if it is new.
    pub fn intern(&mut self, name: &str) -> Arc<str> {
        if let Some(n) = self.0.get(name) {
            return n.clone();
        }
        let n: Arc<str> = Arc::from(name);
        self.0.insert(n.clone());
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attrs(pairs: &[(&str, &str)]) -> Attrs {
        pairs
            .iter()
            .map(|(k, v)| (Arc::from(*k), Box::from(*v)))
            .collect()
    }

    #[test]
    fn iterates_in_name_order_like_a_btreemap() {
        let pairs = [
            ("use", "kura"),
            ("id", "7"),
            ("District", "x"),
            ("\u{0}b", ""),
        ];
        let map: std::collections::BTreeMap<&str, &str> = pairs.iter().copied().collect();
        let a = attrs(&pairs);
        assert_eq!(
            a.iter().collect::<Vec<_>>(),
            map.into_iter().collect::<Vec<_>>()
        );
        assert_eq!(a.len(), 4);
    }

    #[test]
    fn the_later_of_two_equal_names_wins() {
        let a = attrs(&[("id", "1"), ("use", "a"), ("id", "2"), ("id", "3")]);
        assert_eq!(a.get("id"), Some("3"));
        assert_eq!(a.len(), 2);
    }

    #[test]
    fn insert_replaces_or_adds_in_order() {
        let mut a = attrs(&[("b", "1")]);
        a.insert(Arc::from("b"), "2");
        a.insert(Arc::from("a"), "0");
        a.insert(Arc::from("c"), "3");
        assert_eq!(
            a.iter().collect::<Vec<_>>(),
            [("a", "0"), ("b", "2"), ("c", "3")]
        );
        assert_eq!(a.get("d"), None);
        assert!(!a.is_empty() && Attrs::default().is_empty());
    }

    #[test]
    fn field_names_are_shared() {
        let mut names = FieldNames::default();
        let a = names.intern("mtype");
        let b = names.intern("mtype");
        assert!(Arc::ptr_eq(&a, &b));
        assert!(!Arc::ptr_eq(&a, &names.intern("use")));
    }
}
