//! The whole pipeline, one line: read inputs => analyse => generate => write.
//!
//! ```text
//! input::read_dataset -> analyse::analyse -> (per tile, in parallel)
//!     generate::generate_tile -> output::write_tile
//! -> report.json, manifest.json (last)
//! ```
//! Tiles are independent once analysis is done: each is generated and written by one rayon
//! task and dropped, so memory holds one tile's meshes per thread, never the whole city.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rayon::prelude::*;
use thiserror::Error;

use crate::analyse;
use crate::generate;
use crate::input::{self, InputError};
use crate::model::LotUse;
use crate::output::{self, report};
use crate::params::{Params, ParamsError};
use crate::templates::{Catalog, TemplateError};

/// Progress of the long stages; the CLI draws bars, tests pass [`NoProgress`].
pub trait Progress: Sync {
    fn start(&self, stage: &str, total: u64);
    fn inc(&self, n: u64);
    fn finish(&self);
}

pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _: &str, _: u64) {}
    fn inc(&self, _: u64) {}
    fn finish(&self) {}
}

#[derive(Debug, Error)]
pub enum BuildError {
    #[error(transparent)]
    Params(#[from] ParamsError),
    #[error(transparent)]
    Templates(#[from] TemplateError),
    #[error(transparent)]
    Input(#[from] InputError),
    #[error("{0}")]
    Config(String),
    #[error("cannot write {path}: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
}

/// What to build, already validated by the CLI.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    pub input: PathBuf,
    pub out: PathBuf,
    pub params: Params,
    /// Machiya type directory; `None` = `machiya.templates`, else the shipped types.
    pub templates: Option<PathBuf>,
    /// Worker threads; 0 = one per core.
    pub threads: usize,
    /// Also draw `<out>/plan.png`.
    pub plan_image: bool,
}

/// Wall time of each stage.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    pub read: Duration,
    pub analyse: Duration,
    pub generate_and_write: Duration,
    pub total: Duration,
}

#[derive(Debug)]
pub struct BuildOutcome {
    pub report: report::Report,
    pub timings: Timings,
    pub bytes_written: u64,
}

/// Runs the pipeline.
pub fn build(opts: &BuildOptions, progress: &dyn Progress) -> Result<BuildOutcome, BuildError> {
    let t0 = Instant::now();
    let params = &opts.params;
    let template_dir = opts.templates.clone().or_else(|| {
        (!params.machiya.templates.is_empty()).then(|| PathBuf::from(&params.machiya.templates))
    });
    let catalog = Catalog::load(template_dir.as_deref())?;
    for name in params.type_mix.keys() {
        if catalog.get(name).is_none() {
            return Err(BuildError::Config(format!(
                "type_mix names `{name}`, which has no machiya type file (known types: {})",
                catalog.types.keys().cloned().collect::<Vec<_>>().join(", ")
            )));
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| BuildError::Config(format!("cannot start worker threads: {e}")))?;
    pool.install(|| run(opts, &catalog, progress, t0))
}

fn run(
    opts: &BuildOptions,
    catalog: &Catalog,
    progress: &dyn Progress,
    t0: Instant,
) -> Result<BuildOutcome, BuildError> {
    let params = &opts.params;
    let mut timings = Timings::default();

    progress.start("reading", 0);
    let data = input::read_dataset(&opts.input, params)?;
    progress.finish();
    timings.read = t0.elapsed();

    let t = Instant::now();
    let lots_file = opts
        .input
        .join(&params.layers.lots.file)
        .display()
        .to_string();
    let machiya_lots = data
        .lots
        .iter()
        .filter(|l| l.lot_use == LotUse::Machiya)
        .count();
    progress.start("analysing", machiya_lots as u64);
    let plan = analyse::analyse(&data, params, catalog, &lots_file, &|n| progress.inc(n));
    progress.finish();
    timings.analyse = t.elapsed();

    let t = Instant::now();
    let write_err = |path: &Path, source| BuildError::Write {
        path: path.display().to_string(),
        source,
    };
    let tiles_dir = opts.out.join("tiles");
    std::fs::create_dir_all(&tiles_dir).map_err(|e| write_err(&tiles_dir, e))?;
    let textures = output::write_textures(&opts.out).map_err(|e| write_err(&opts.out, e))?;

    let files = generate::LayerFiles {
        lots: lots_file.clone(),
        footprints: opts
            .input
            .join(&params.layers.footprints.file)
            .display()
            .to_string(),
    };
    let tiles: Vec<_> = plan.tiles.iter().collect();
    progress.start("writing tiles", tiles.len() as u64);
    let results: Vec<_> = tiles
        .par_iter()
        .map(|(id, lots)| {
            let meshes = generate::generate_tile(lots, catalog, params, plan.origin, &files);
            let written = output::write_tile(&opts.out, id, plan.origin, &meshes.meshes)
                .map_err(|e| write_err(&tiles_dir.join(format!("{id}.obj")), e));
            progress.inc(1);
            written.map(|m| (m, meshes.skipped, meshes.types, meshes.districts))
        })
        .collect();
    progress.finish();
    timings.generate_and_write = t.elapsed();

    let mut rep = report::Report {
        tool: "edo-city".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        input: opts.input.display().to_string(),
        crs: data.crs.clone(),
        layers: data.layers.clone(),
        ..Default::default()
    };
    rep.counts.footprints_read = data.footprints.len();
    rep.counts.lots = data.lots.len();
    for lot in &data.lots {
        *rep.counts
            .lots_by_use
            .entry(lot.lot_use.name().to_string())
            .or_default() += 1;
    }
    rep.skipped = data.skipped.clone();
    rep.skipped.extend(plan.skipped.iter().cloned());
    rep.warnings = data.warnings.clone();
    rep.warnings.extend(plan.warnings.iter().cloned());
    rep.tables = data.joins.clone();
    rep.counts.frontage_fallback = plan.frontage_fallback;
    let given: BTreeMap<&str, bool> = plan
        .tiles
        .values()
        .flatten()
        .filter(|m| m.height.is_none())
        .map(|m| (m.id.as_str(), m.type_given))
        .collect();

    let mut manifest_tiles = Vec::new();
    let mut bytes_written = 0;
    for (result, (id, _)) in results.into_iter().zip(&tiles) {
        let (mt, skipped, types, districts) = result?;
        for d in districts {
            *rep.counts.by_district.entry(d).or_default() += 1;
        }
        rep.tiles.push(report::TileReport {
            id: (*id).clone(),
            machiya: types.iter().filter(|t| !t.1).count(),
            obj_bytes: mt.obj.bytes,
        });
        bytes_written += mt.obj.bytes + mt.mtl.bytes;
        for (t, footprint) in types {
            let map = if footprint {
                &mut rep.counts.footprints_by_type
            } else {
                &mut rep.counts.by_type
            };
            *map.entry(t).or_default() += 1;
        }
        rep.skipped.extend(skipped);
        manifest_tiles.push(mt);
    }
    rep.counts.machiya = rep.counts.by_type.values().sum();
    rep.counts.footprints = rep.counts.footprints_by_type.values().sum();
    let skipped_ids: std::collections::HashSet<&str> =
        rep.skipped.iter().map(|s| s.id.as_str()).collect();
    rep.counts.type_given = given
        .iter()
        .filter(|(id, g)| **g && !skipped_ids.contains(**id))
        .count();
    rep.counts.type_drawn = rep.counts.machiya.saturating_sub(rep.counts.type_given);
    rep.counts.tiles = manifest_tiles.len();
    rep.counts.skipped = rep.skipped.len();
    for s in &rep.skipped {
        *rep.skipped_by_reason
            .entry(report::reason_class(&s.reason))
            .or_default() += 1;
    }

    if opts.plan_image {
        if let Some(png) = output::plan::draw_plan(&data, &plan) {
            let path = opts.out.join("plan.png");
            output::atomic::write_atomic(&path, &png).map_err(|e| write_err(&path, e))?;
        }
    }
    let report_path = opts.out.join("report.json");
    let report_json = serde_json::to_vec_pretty(&rep).expect("report serialises");
    output::atomic::write_atomic(&report_path, &report_json)
        .map_err(|e| write_err(&report_path, e))?;

    let manifest = report::Manifest {
        tool: "edo-city".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        origin: plan.origin,
        frame: "x = east - origin[0], y = up, z = -(north - origin[1]); metres".into(),
        crs: data.crs.clone(),
        crs_wkt: data.crs_wkt.clone(),
        tile_size: params.tile_size,
        params: params.clone(),
        tiles: manifest_tiles,
        textures,
    };
    let manifest_path = opts.out.join("manifest.json");
    remove_stale_tiles(&manifest_path, &opts.out, &manifest.tiles);
    let manifest_json = serde_json::to_vec_pretty(&manifest).expect("manifest serialises");
    output::atomic::write_atomic(&manifest_path, &manifest_json)
        .map_err(|e| write_err(&manifest_path, e))?;
    bytes_written += (report_json.len() + manifest_json.len()) as u64;
    timings.total = t0.elapsed();
    Ok(BuildOutcome {
        report: rep,
        timings,
        bytes_written,
    })
}

/// Deletes the tiles a previous build into the same directory listed in its manifest that
/// this build did not write, so the directory holds one consistent city. Files the tool did
/// not write itself are never touched.
fn remove_stale_tiles(manifest_path: &Path, out: &Path, tiles: &[report::ManifestTile]) {
    let Ok(bytes) = std::fs::read(manifest_path) else {
        return;
    };
    let Ok(old) = serde_json::from_slice::<serde_json::Value>(&bytes) else {
        return;
    };
    let current: std::collections::HashSet<&str> = tiles
        .iter()
        .flat_map(|t| [t.obj.path.as_str(), t.mtl.path.as_str()])
        .collect();
    for tile in old["tiles"].as_array().into_iter().flatten() {
        for kind in ["obj", "mtl"] {
            if let Some(path) = tile[kind]["path"].as_str() {
                let safe = path.starts_with("tiles/") && !path.contains("..");
                if safe && !current.contains(path) {
                    let _ = std::fs::remove_file(out.join(path));
                }
            }
        }
    }
}
