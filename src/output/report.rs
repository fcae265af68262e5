//! `report.json` and `manifest.json`: what was built, what was skipped, and how to check it.
//!
//! Both are deterministic (no clock, no paths of the machine that built them beyond what the
//! user typed), so two builds of the same hypothesis can be compared with `diff`.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::model::{LayerInfo, Skipped, TableJoin};
use crate::params::Params;

#[derive(Debug, Clone, Default, Serialize)]
pub struct Counts {
    /// Lots read (after multipart lots were split), of every use.
    pub lots: usize,
    /// Lots by use (machiya, buke, kuge, jisha, other values).
    pub lots_by_use: BTreeMap<String, usize>,
    /// Machiya written (lot-filling houses).
    pub machiya: usize,
    pub by_type: BTreeMap<String, usize>,
    /// Footprints read, and built as houses.
    pub footprints_read: usize,
    pub footprints: usize,
    pub footprints_by_type: BTreeMap<String, usize>,
    /// Machiya whose type came from the data / was drawn from `type_mix`.
    pub type_given: usize,
    pub type_drawn: usize,
    /// Houses (machiya and footprints) per district; "" = no district.
    pub by_district: BTreeMap<String, usize>,
    /// Lots where no pair passed the Fig.4 test and the nearest edge was taken.
    pub frontage_fallback: usize,
    pub tiles: usize,
    pub skipped: usize,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct Report {
    pub tool: String,
    pub version: String,
    pub input: String,
    /// The CRS of the output (proj string); empty when no layer had a `.prj`.
    pub crs: String,
    pub layers: Vec<LayerInfo>,
    pub counts: Counts,
    /// Every feature left out, with file, id and reason.
    pub skipped: Vec<Skipped>,
    pub skipped_by_reason: BTreeMap<String, usize>,
    pub tables: Vec<TableJoin>,
    pub warnings: Vec<String>,
    pub tiles: Vec<TileReport>,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct TileReport {
    pub id: String,
    pub machiya: usize,
    pub obj_bytes: u64,
}

#[derive(Debug, Clone, Serialize)]
pub struct Manifest {
    pub tool: String,
    pub version: String,
    /// Output coordinates are relative to this point, in the input's projected metres.
    pub origin: [f64; 2],
    pub frame: String,
    /// The output CRS as a proj string; empty when no layer had a `.prj`.
    pub crs: String,
    /// The lots (else footprints) layer's `.prj`, if it had one.
    pub crs_wkt: Option<String>,
    pub tile_size: f64,
    pub params: Params,
    pub tiles: Vec<ManifestTile>,
    pub textures: Vec<ManifestFile>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ManifestTile {
    pub id: String,
    pub obj: ManifestFile,
    pub mtl: ManifestFile,
}

#[derive(Debug, Clone, Serialize)]
pub struct ManifestFile {
    pub path: String,
    pub bytes: u64,
    pub sha256: String,
}

/// Groups skip reasons for the summary: the reason up to its first digit or colon.
pub fn reason_class(reason: &str) -> String {
    let cut = reason
        .find(|c: char| c.is_ascii_digit() || c == ':' || c == '`')
        .unwrap_or(reason.len());
    reason[..cut].trim().trim_end_matches(',').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reasons_group_without_their_numbers() {
        assert_eq!(
            reason_class("the lot is 1.50 m deep behind its frontage"),
            "the lot is"
        );
        assert_eq!(reason_class("duplicate id: record 7"), "duplicate id");
    }
}
