//! `[input]`: what a build reads beyond the layers: the per-lot overrides a person made in
//! the browser's workbench (`edo-city serve --edit`, issue 61), one row an edit.

use serde::{Deserialize, Serialize};

/// The input's extra files.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputParams {
    /// The overrides table (CSV `lot,field,value`), "" for none; resolved against the
    /// directory of the parameter file that names it, as `garden.designs` is.
    #[serde(default)]
    pub overrides: String,
    /// With a GeoPackage `overrides` (a build's plan.gpkg edited in QGIS): the layer whose
    /// rows are the overrides; "" = `lots`.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub overrides_layer: String,
    /// The overrides given in memory instead of read from `overrides` (the workbench's
    /// edits not saved yet, which a build must show as `build --params` will once they
    /// are): never in a parameter file or a manifest.
    #[serde(skip)]
    pub rows: Option<std::sync::Arc<Vec<crate::model::overrides::Override>>>,
}

impl InputParams {
    /// Whether nothing is set: such a section is left out of a manifest, so builds without
    /// overrides publish the parameters they always did.
    pub fn is_empty(&self) -> bool {
        self.overrides.is_empty()
    }
}

/// The same table with every field optional, for checking a user's partial file.
pub(super) mod partial {
    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    pub struct Input {
        overrides: Option<String>,
        overrides_layer: Option<String>,
    }
}
