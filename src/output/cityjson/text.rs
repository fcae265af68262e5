//! CityJSON written as text: the large arrays of a feature (its vertices, its surfaces'
//! rings, their semantics and materials) are numbers written straight into the line with
//! `itoa`, not built as `serde_json` values first, which took most of a model's time
//! (30,052 lots: a third more than the build without the model). Strings still go through
//! serde_json's escaping; keys are written in the order serde_json writes a map's (sorted),
//! so the whole file reads as one serializer wrote it.

/// Writes `s` as a JSON string.
pub fn string(out: &mut String, s: &str) {
    out.push_str(&serde_json::to_string(s).expect("a string serialises"));
}

/// Writes an integer.
pub fn int(out: &mut String, v: impl itoa::Integer) {
    out.push_str(itoa::Buffer::new().format(v));
}

/// Writes `[a,b,...]`, each item by `each`.
pub fn array<T>(
    out: &mut String,
    items: impl IntoIterator<Item = T>,
    mut each: impl FnMut(&mut String, T),
) {
    out.push('[');
    for (i, item) in items.into_iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        each(out, item);
    }
    out.push(']');
}

/// Writes `[a,b,...]` of integers.
pub fn ints<T: itoa::Integer + Copy>(out: &mut String, values: &[T]) {
    array(out, values, |out, v| int(out, *v));
}

/// Writes `[x,y,z]` of a vertex.
pub fn vertex(out: &mut String, v: [i64; 3]) {
    ints(out, &v);
}

/// Writes `"key":` (a key of ours: letters, no escaping needed).
pub fn key(out: &mut String, k: &str) {
    out.push('"');
    out.push_str(k);
    out.push_str("\":");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_is_written_is_what_serde_json_writes() {
        let mut s = String::from("{");
        key(&mut s, "a");
        ints(&mut s, &[1u32, 20, 300]);
        s.push(',');
        key(&mut s, "b");
        string(&mut s, "下京 \"x\"");
        s.push(',');
        key(&mut s, "v");
        vertex(&mut s, [-1, 0, 7]);
        s.push('}');
        let want = serde_json::json!({"a": [1, 20, 300], "b": "下京 \"x\"", "v": [-1, 0, 7]});
        assert_eq!(s, want.to_string());
    }
}
