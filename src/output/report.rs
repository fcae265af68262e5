//! `report.json` and `manifest.json`: what was built, what was skipped, and how to check it.
//!
//! The manifest holds everything the report says: the input-wide part (what was read and
//! analysed) and, per tile, its files and statistics. So a report can always be rebuilt from
//! a manifest, a `--tiles` run keeps the other tiles' entries, and `merge` unions the
//! manifests of shards into exactly the manifest and report of a full build.
//! Both files are deterministic (no clock), so two builds can be compared with `diff`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

pub use crate::model::TileStats;
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
    pub footprints: usize,
    pub obj_bytes: u64,
}

/// The part of the report that comes from reading and analysis, the same for every tile.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct InputSummary {
    pub input: String,
    pub crs: String,
    pub layers: Vec<LayerInfo>,
    pub lots: usize,
    pub lots_by_use: BTreeMap<String, usize>,
    pub footprints_read: usize,
    pub frontage_fallback: usize,
    pub skipped: Vec<Skipped>,
    pub tables: Vec<TableJoin>,
    pub warnings: Vec<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub tool: String,
    pub version: String,
    /// Set on a shard's manifest: [index, count], index from 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<[usize; 2]>,
    /// Output coordinates are relative to this point, in the input's projected metres.
    pub origin: [f64; 2],
    pub frame: String,
    /// The output CRS as a proj string; empty when no layer had a `.prj`.
    pub crs: String,
    /// The lots (else footprints) layer's `.prj`, if it had one.
    pub crs_wkt: Option<String>,
    pub tile_size: f64,
    pub params: Params,
    pub input: InputSummary,
    pub tiles: Vec<ManifestTile>,
    pub textures: Vec<ManifestFile>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestTile {
    pub id: String,
    pub obj: ManifestFile,
    pub mtl: ManifestFile,
    pub stats: TileStats,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestFile {
    pub path: String,
    pub bytes: u64,
    pub sha256: String,
}

/// The report a manifest describes.
pub fn assemble_report(m: &Manifest) -> Report {
    let i = &m.input;
    let mut r = Report {
        tool: m.tool.clone(),
        version: m.version.clone(),
        input: i.input.clone(),
        crs: i.crs.clone(),
        layers: i.layers.clone(),
        tables: i.tables.clone(),
        warnings: i.warnings.clone(),
        skipped: i.skipped.clone(),
        ..Report::default()
    };
    let c = &mut r.counts;
    c.lots = i.lots;
    c.lots_by_use = i.lots_by_use.clone();
    c.footprints_read = i.footprints_read;
    c.frontage_fallback = i.frontage_fallback;
    let add = |to: &mut BTreeMap<String, usize>, from: &BTreeMap<String, usize>| {
        for (k, v) in from {
            *to.entry(k.clone()).or_default() += v;
        }
    };
    for t in &m.tiles {
        let s = &t.stats;
        c.machiya += s.machiya;
        c.footprints += s.footprints;
        c.type_given += s.type_given;
        add(&mut c.by_type, &s.by_type);
        add(&mut c.footprints_by_type, &s.footprints_by_type);
        add(&mut c.by_district, &s.by_district);
        r.skipped.extend(s.skipped.iter().cloned());
        r.tiles.push(TileReport {
            id: t.id.clone(),
            machiya: s.machiya,
            footprints: s.footprints,
            obj_bytes: t.obj.bytes,
        });
    }
    c.type_drawn = c.machiya.saturating_sub(c.type_given);
    c.tiles = m.tiles.len();
    c.skipped = r.skipped.len();
    for s in &r.skipped {
        *r.skipped_by_reason
            .entry(reason_class(&s.reason))
            .or_default() += 1;
    }
    r
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
