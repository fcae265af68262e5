//! A field kept as JSON text inside a binary encoding of its struct.
//!
//! The report's types skip empty fields when written (`skip_serializing_if`, so that
//! report.json stays readable), which a format without field names, such as the analysis
//! cache's, cannot read back: it would take the next field's bytes for the skipped one.
//! Their JSON is what report.json holds anyway, and serde_json reads every float back to
//! the same bits (the `float_roundtrip` feature).

use serde::de::{DeserializeOwned, Deserializer, Error as _};
use serde::ser::{Error as _, Serializer};
use serde::{Deserialize, Serialize};

/// Writes `value` as one string of JSON.
pub fn serialize<T: Serialize, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
    let text = serde_json::to_string(value).map_err(S::Error::custom)?;
    s.serialize_str(&text)
}

/// Reads a value written by [`serialize`].
pub fn deserialize<'de, T: DeserializeOwned, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
    let text = String::deserialize(d)?;
    serde_json::from_str(&text).map_err(D::Error::custom)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Sparse {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        note: Option<String>,
        size: f64,
    }

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Outer {
        #[serde(with = "super")]
        inner: Vec<Sparse>,
        after: u32,
    }

    #[test]
    fn skipped_fields_survive_a_format_without_names() {
        let v = Outer {
            inner: vec![
                Sparse {
                    note: None,
                    size: 0.1 + 0.2,
                },
                Sparse {
                    note: Some("x".into()),
                    size: 1e-300,
                },
            ],
            after: 7,
        };
        let bytes = postcard::to_stdvec(&v).unwrap();
        let back: Outer = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(back, v);
        assert_eq!(back.inner[0].size.to_bits(), (0.1f64 + 0.2).to_bits());
    }
}
