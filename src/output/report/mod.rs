//! `report.json` and `manifest.json`: what was built, what was skipped, and how to check it.
//!
//! The manifest holds everything the report says: the input-wide part (what was read and
//! analysed) and, per tile, its files and statistics. So a report can always be rebuilt from
//! a manifest, a `--tiles` run keeps the other tiles' entries, and `merge` unions the
//! manifests of shards into exactly the manifest and report of a full build.
//! Both files are deterministic (no clock), so two builds can be compared with `diff`.

mod manifest;
pub use manifest::*;

use std::collections::BTreeMap;

use serde::Serialize;

pub use crate::model::TileStats;
use crate::model::{KuraCounts, LayerInfo, Skipped, TableJoin};

/// The counts of a build, as report.json and the summary give them.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Counts {
    /// Lots read (after multipart lots were split), of every use.
    pub lots: usize,
    /// Lots by use (machiya, buke, kuge, jisha, other values).
    pub lots_by_use: BTreeMap<String, usize>,
    /// Machiya written (lot-filling houses).
    pub machiya: usize,
    /// Machiya per type.
    pub by_type: BTreeMap<String, usize>,
    /// Footprints read, and built as houses.
    pub footprints_read: usize,
    /// Footprint houses built.
    pub footprints: usize,
    /// Footprint houses per type.
    pub footprints_by_type: BTreeMap<String, usize>,
    /// Machiya whose type came from the data / was drawn from `type_mix`.
    pub type_given: usize,
    /// Machiya whose type was drawn from `type_mix`.
    pub type_drawn: usize,
    /// Houses (machiya and footprints) per district; "" = no district.
    pub by_district: BTreeMap<String, usize>,
    /// Machiya types drawn from the type mix (not given by the data), per district.
    pub drawn_by_district: BTreeMap<String, BTreeMap<String, usize>>,
    /// Lots where no pair passed the Fig.4 test and the nearest edge was taken.
    pub frontage_fallback: usize,
    /// Tiles written.
    pub tiles: usize,
    /// Kura (storehouses) built.
    pub kura: usize,
    /// Fence segments and gates built, and metres of wall per fence template (to the mm).
    pub fence_segments: usize,
    /// Gates built.
    pub gates: usize,
    /// Metres of wall per fence template, to the millimetre.
    pub wall_metres: BTreeMap<String, f64>,
    /// People and trees built (billboards), per district ("" = none) and per texture.
    pub people: usize,
    /// Trees built.
    pub trees: usize,
    /// People per district ("" = none).
    pub people_by_district: BTreeMap<String, usize>,
    /// Trees per district.
    pub trees_by_district: BTreeMap<String, usize>,
    /// Billboards per texture.
    pub billboard_textures: BTreeMap<String, usize>,
    /// Features left out, of every stage (each listed in `skipped`).
    pub skipped: usize,
}

/// The paper's Table 2: kura per machiya, without and with collision avoidance.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Table2 {
    /// Machiya built.
    pub machiya: usize,
    /// Of them candidates for a kura (frontage and depth rule).
    pub kura_candidates: usize,
    /// Kura built with `kura.collision = false`.
    pub kura_without_avoidance: usize,
    /// Kura built with the collision avoidance of Fig.7.
    pub kura_with_avoidance: usize,
    /// kura / machiya.
    pub ratio_without: f64,
    /// kura with avoidance / machiya.
    pub ratio_with: f64,
}

impl Table2 {
    fn of(c: &KuraCounts) -> Table2 {
        let ratio = |k: usize| {
            if c.machiya == 0 {
                0.0
            } else {
                // Four decimals keep report.json stable and readable.
                (k as f64 / c.machiya as f64 * 10_000.0).round() / 10_000.0
            }
        };
        Table2 {
            machiya: c.machiya,
            kura_candidates: c.candidates,
            kura_without_avoidance: c.without_avoidance,
            kura_with_avoidance: c.with_avoidance,
            ratio_without: ratio(c.without_avoidance),
            ratio_with: ratio(c.with_avoidance),
        }
    }
}

/// Table 2 for the whole city and per district ("" = lots without a district).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Table2Report {
    /// The whole city (its keys at the top of `table2`).
    #[serde(flatten)]
    pub all: Table2,
    /// Per district.
    pub by_district: BTreeMap<String, Table2>,
    /// The paper's figures, for comparison.
    pub paper: PaperTable2,
}

/// Table 2 of Kosaka et al. 2008: all of Kyoto, and the Rakuchu-rakugai-zu screen.
#[derive(Debug, Clone, Serialize)]
pub struct PaperTable2 {
    /// Machiya of all Kyoto.
    pub machiya: usize,
    /// Kura without avoidance.
    pub kura_without_avoidance: usize,
    /// Kura with avoidance.
    pub kura_with_avoidance: usize,
    /// kura / machiya without avoidance.
    pub ratio_without: f64,
    /// kura / machiya with avoidance.
    pub ratio_with: f64,
    /// Machiya on the Rakuchu-rakugai-zu screen.
    pub painting_machiya: usize,
    /// Kura on the screen.
    pub painting_kura: usize,
    /// kura / machiya on the screen.
    pub painting_ratio: f64,
}

impl Default for PaperTable2 {
    fn default() -> Self {
        PaperTable2 {
            machiya: 30_052,
            kura_without_avoidance: 16_664,
            kura_with_avoidance: 2_824,
            ratio_without: 0.554,
            ratio_with: 0.094,
            painting_machiya: 236,
            painting_kura: 33,
            painting_ratio: 0.140,
        }
    }
}

/// report.json: what a build read, built and left out, assembled from its manifest.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Report {
    /// `edo-city`.
    pub tool: String,
    /// The tool's version.
    pub version: String,
    /// The input directory, absolute.
    pub input: String,
    /// The CRS of the output (proj string); empty when no layer had a `.prj`.
    pub crs: String,
    /// Every layer read.
    pub layers: Vec<LayerInfo>,
    /// The counts.
    pub counts: Counts,
    /// The paper's Table 2, for this build and as published.
    pub table2: Table2Report,
    /// Every feature left out, with file, id and reason.
    pub skipped: Vec<Skipped>,
    /// Skips per cause (the reason up to its first number).
    pub skipped_by_reason: BTreeMap<String, usize>,
    /// How each attribute table matched its layer.
    pub tables: Vec<TableJoin>,
    /// What the build noticed.
    pub warnings: Vec<crate::model::Warning>,
    /// Per layer: records read, built, skipped, and unaccounted (always 0; see
    /// [`super::accounting`]).
    pub accounting: Vec<super::accounting::Account>,
    /// The street crowds, per street stretch and per district (`people.motion = "boids"`).
    #[serde(skip_serializing_if = "Crowds::is_empty")]
    pub crowds: Crowds,
    /// The rock gardens of temple lots, one entry per lot (placed or skipped, with why).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gardens: Vec<crate::model::GardenStat>,
    /// The halls of estates and temples, one entry per hall a lot's use asked for (placed
    /// with its plot, or not with why).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub halls: Vec<crate::model::HallStat>,
    /// The landmarks: placed (with tile and box), displaced features, and skipped records
    /// with why.
    #[serde(skip_serializing_if = "landmarks_empty")]
    pub landmarks: crate::model::LandmarkReport,
    /// Trees of a species: by species and how each was drawn, and bytes of tree geometry per
    /// tile (absent when no tree has a species).
    #[serde(skip_serializing_if = "TreesReport::is_empty")]
    pub trees: TreesReport,
    /// Per tile: houses and bytes.
    pub tiles: Vec<TileReport>,
}

/// The trees of a species (`trees.style`, seeds 003 and 001).
#[derive(Debug, Clone, Default, Serialize)]
pub struct TreesReport {
    /// Per species: how many were meshed (`lod1`) and how many drawn as its billboard.
    pub by_species: BTreeMap<String, BTreeMap<String, usize>>,
    /// The same summed over the species.
    pub by_lod: BTreeMap<String, usize>,
    /// Bytes of tree geometry (objects `trees` and `trees_grown`) per tile.
    pub tile_bytes: BTreeMap<String, u64>,
    /// The largest of them.
    pub largest_tile_bytes: u64,
}

impl TreesReport {
    /// Whether no tree had a species.
    pub fn is_empty(&self) -> bool {
        self.by_species.is_empty()
    }
}

/// The street crowds of a build: how busy and how grouped each street is (seed 004).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Crowds {
    /// Per street stretch, in street order.
    pub streets: Vec<crate::model::CrowdStat>,
    /// Per district ("" = none): walkers, and each lambda averaged over its stretches
    /// weighted by their walkers.
    pub by_district: BTreeMap<String, DistrictCrowd>,
}

impl Crowds {
    /// Whether the build walked no crowd (then report.json leaves the key out).
    pub fn is_empty(&self) -> bool {
        self.streets.is_empty()
    }

    /// The report of the stretches' statistics.
    fn of(streets: &[crate::model::CrowdStat]) -> Crowds {
        let mut by_district: BTreeMap<String, DistrictCrowd> = BTreeMap::new();
        // Each stretch counts in every district it has walkers in, by their number.
        for (s, (district, n)) in streets
            .iter()
            .flat_map(|s| s.districts.iter().map(move |d| (s, d)))
        {
            let d = by_district.entry(district.clone()).or_default();
            let w = *n as f64;
            d.agents += n;
            d.lambda1 += w * s.lambda1;
            d.lambda2 += w * s.lambda2;
            d.lambda3 += w * s.lambda3;
            d.mean.lambda1 += w * s.mean.lambda1;
            d.mean.lambda2 += w * s.mean.lambda2;
            d.mean.lambda3 += w * s.mean.lambda3;
        }
        // Four decimals, as Table 2's ratios: stable bytes and readable.
        let r = |v: f64, n: usize| (v / n.max(1) as f64 * 10_000.0).round() / 10_000.0;
        for d in by_district.values_mut() {
            let n = d.agents;
            d.lambda1 = r(d.lambda1, n);
            d.lambda2 = r(d.lambda2, n);
            d.lambda3 = r(d.lambda3, n);
            d.mean.lambda1 = r(d.mean.lambda1, n);
            d.mean.lambda2 = r(d.mean.lambda2, n);
            d.mean.lambda3 = r(d.mean.lambda3, n);
        }
        Crowds {
            streets: streets.to_vec(),
            by_district,
        }
    }
}

/// One district's crowds.
#[derive(Debug, Clone, Default, Serialize)]
pub struct DistrictCrowd {
    /// Walkers simulated in the district.
    pub agents: usize,
    /// lambda1 at time 0, weighted by walkers.
    pub lambda1: f64,
    /// lambda2 at time 0.
    pub lambda2: f64,
    /// lambda3 at time 0.
    pub lambda3: f64,
    /// The same averaged over the clip.
    pub mean: crate::model::MeanLambdas,
}

/// One tile of the report.
#[derive(Debug, Clone, Default, Serialize)]
pub struct TileReport {
    /// The tile's id.
    pub id: String,
    /// Machiya in it.
    pub machiya: usize,
    /// Footprint houses in it.
    pub footprints: usize,
    /// Bytes of its OBJ (0 when `obj` was not written).
    pub obj_bytes: u64,
    /// Bytes of its GLB (0 when `glb` was not written).
    pub glb_bytes: u64,
    /// Of the OBJ's, bytes of its trees.
    pub tree_bytes: u64,
    /// Of the OBJ's, bytes of its ground (objects `ground` and `streets`).
    #[serde(default)]
    pub ground_bytes: u64,
    /// Its halls, per template.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub halls: std::collections::BTreeMap<String, usize>,
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
    let mut kura_all = KuraCounts::default();
    let mut kura_by_district: BTreeMap<String, KuraCounts> = BTreeMap::new();
    for t in &m.tiles {
        let s = &t.stats;
        c.kura += s.kura;
        c.fence_segments += s.fence_segments;
        c.gates += s.gates;
        for (t, mm) in &s.wall_mm {
            *c.wall_metres.entry(t.clone()).or_default() += *mm as f64 / 1000.0;
        }
        for (d, k) in &s.kura_counts {
            kura_all.add(k);
            kura_by_district.entry(d.clone()).or_default().add(k);
        }
        add(&mut c.people_by_district, &s.people_by_district);
        add(&mut c.trees_by_district, &s.trees_by_district);
        add(&mut c.billboard_textures, &s.billboard_textures);
        c.people += s.people_by_district.values().sum::<usize>();
        c.trees += s.trees_by_district.values().sum::<usize>();
        c.machiya += s.machiya;
        c.footprints += s.footprints;
        c.type_given += s.type_given;
        add(&mut c.by_type, &s.by_type);
        add(&mut c.footprints_by_type, &s.footprints_by_type);
        add(&mut c.by_district, &s.by_district);
        for (d, types) in &s.drawn_by_district {
            add(c.drawn_by_district.entry(d.clone()).or_default(), types);
        }
        r.skipped.extend(s.skipped.iter().cloned());
        r.tiles.push(TileReport {
            id: t.id.clone(),
            machiya: s.machiya,
            footprints: s.footprints,
            obj_bytes: t.obj.as_ref().map_or(0, |f| f.bytes),
            glb_bytes: t.glb.as_ref().map_or(0, |f| f.bytes),
            tree_bytes: s.tree_bytes,
            ground_bytes: s.ground_bytes,
            halls: s.halls.clone(),
        });
        for (species, lods) in &s.trees_by_species {
            add(r.trees.by_species.entry(species.clone()).or_default(), lods);
            add(&mut r.trees.by_lod, lods);
        }
        if !s.trees_by_species.is_empty() {
            r.trees.tile_bytes.insert(t.id.clone(), s.tree_bytes);
            r.trees.largest_tile_bytes = r.trees.largest_tile_bytes.max(s.tree_bytes);
        }
    }
    r.table2 = Table2Report {
        all: Table2::of(&kura_all),
        by_district: kura_by_district
            .iter()
            .map(|(d, k)| (d.clone(), Table2::of(k)))
            .collect(),
        paper: PaperTable2::default(),
    };
    let c = &mut r.counts;
    for m in c.wall_metres.values_mut() {
        *m = (*m * 1000.0).round() / 1000.0;
    }
    c.type_drawn = c.machiya.saturating_sub(c.type_given);
    c.tiles = m.tiles.len();
    c.skipped = r.skipped.len();
    r.accounting = super::accounting::close(&i.ledgers, &r.skipped, &mut r.warnings);
    r.crowds = Crowds::of(&i.crowds);
    r.gardens = i.gardens.clone();
    r.halls = i.halls.clone();
    r.landmarks = crate::model::LandmarkReport {
        placed: m
            .tiles
            .iter()
            .flat_map(|t| t.stats.landmarks.iter().cloned())
            .collect(),
        ..i.landmarks.clone()
    };
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

    #[test]
    fn paths_outside_the_input_are_published_by_name_and_fingerprint() {
        let mut v = serde_json::json!({
            "layers": {"lots": {"file": "lots.shp"}, "dem": {"file": "../dem/kyoto.tif"}},
            "models": ["/home/alice/m", "~/x", "C:\\Users\\a\\y", "sub/ok.obj"],
            "name": "machiya",
        });
        publish_paths(&mut v);
        let once = v.clone();
        publish_paths(&mut v);
        assert_eq!(v, once, "the same when applied twice");
        assert_eq!(v["layers"]["lots"]["file"], "lots.shp");
        assert_eq!(v["models"][3], "sub/ok.obj");
        assert_eq!(v["name"], "machiya");
        let dem = v["layers"]["dem"]["file"].as_str().unwrap();
        assert!(dem.starts_with("(not published) kyoto.tif#"), "{dem}");
        for i in 0..3 {
            let s = v["models"][i].as_str().unwrap();
            assert!(s.starts_with(UNPUBLISHED) && !s.contains("alice"), "{s}");
        }
        let mut keys = Vec::new();
        unpublished_keys(&v, "", &mut keys);
        assert_eq!(
            keys,
            ["layers.dem.file", "models.0", "models.1", "models.2"]
        );
    }
}
