//! Warnings: what a build noticed and the user should know, with what they are about kept
//! apart from the text, as the skips are. report.json, `check --json` and the summary all
//! show the same list.

use serde::{Deserialize, Serialize};

/// What a warning is about, for grouping and for scripts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningClass {
    /// A layer or file as a whole: its encoding, CRS, fields, windings, DEM cells.
    Layer,
    /// An attribute table joined to a layer.
    Table,
    /// One feature: a value that was replaced, a gate that did not fit, an unknown type.
    Feature,
    /// People and trees: densities capped, textures unknown.
    Billboards,
    /// The build as a whole: nothing to build, records unaccounted (a defect of ours).
    Build,
}

/// One warning.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Warning {
    /// What the warning is about.
    pub class: WarningClass,
    /// The layer's role (`lots`, `streets`, ...), when the warning is about a layer's data.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer: Option<String>,
    /// The file it is about, as the user named it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The feature's id, when it is about one feature.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// The parameter key it is about, when there is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub key: Option<String>,
    /// The whole message, as printed: it names the file and says what to do.
    pub message: String,
}

impl Warning {
    /// A warning of `class` with its message; the builders below say what it is about.
    pub fn new(class: WarningClass, message: impl Into<String>) -> Warning {
        Warning {
            class,
            layer: None,
            file: None,
            id: None,
            key: None,
            message: message.into(),
        }
    }

    /// About a layer's file.
    pub fn layer(layer: &str, file: &str, message: impl Into<String>) -> Warning {
        Warning::new(WarningClass::Layer, message).in_layer(layer, file)
    }

    /// About one feature of a layer.
    pub fn feature(layer: &str, file: &str, id: &str, message: impl Into<String>) -> Warning {
        Warning {
            id: Some(id.to_string()),
            ..Warning::new(WarningClass::Feature, message).in_layer(layer, file)
        }
    }

    /// The same, naming the layer and file.
    pub fn in_layer(mut self, layer: &str, file: &str) -> Warning {
        self.layer = (!layer.is_empty()).then(|| layer.to_string());
        self.file = (!file.is_empty()).then(|| file.to_string());
        self
    }

    /// The same, naming a file only.
    pub fn in_file(mut self, file: &str) -> Warning {
        self.file = Some(file.to_string());
        self
    }

    /// The same, naming the parameter key.
    pub fn for_key(mut self, key: &str) -> Warning {
        self.key = Some(key.to_string());
        self
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warning_serialises_what_it_is_about_apart_from_its_text() {
        let w = Warning::feature("lots", "a/lots.shp", "7", "a/lots.shp: lot 7: no gate");
        let j = serde_json::to_value(&w).unwrap();
        assert_eq!(j["class"], "feature");
        assert_eq!(j["layer"], "lots");
        assert_eq!(j["id"], "7");
        assert!(j.get("key").is_none());
        assert_eq!(w.to_string(), "a/lots.shp: lot 7: no gate");
    }
}
