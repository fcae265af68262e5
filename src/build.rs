//! The whole pipeline, one line: read inputs => analyse => generate => write.
//!
//! ```text
//! input::read_dataset -> analyse::analyse -> (per selected tile, in parallel)
//!     generate::generate_tile -> output::write_tile
//! -> report.json, manifest.json (last)
//! ```
//! Tiles are independent once analysis is done: each is generated and written by one rayon
//! task and dropped, so memory holds one tile's meshes per thread, never the whole city.
//! Reading and analysis always cover the whole input, so a tile built alone (`--tiles`) or in
//! a shard (`--shard`) sees its neighbours and comes out byte-identical to a full build's.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::analyse;
use crate::generate;
use crate::input;
use crate::model::{Dataset, LotUse, Plan};
use crate::output::{self, report};
use crate::params::Params;
use crate::templates::Catalog;

pub mod cache;
mod check;
mod city;
mod clock;
mod error;
pub mod merge;
mod names;
mod plan_files;
pub mod reuse;
pub mod shards;
mod writing;

pub use check::check;
pub use clock::{StageClock, StageTime};
use error::write_err;
pub use error::{BuildError, OptionsError};
pub use names::{load_catalog, NameError};
pub use plan_files::{draw_plan_from, draw_plan_of, merge_plan_files, ReplayError};

/// Progress of the long stages; the CLI draws bars, tests pass [`NoProgress`].
pub trait Progress: Sync {
    /// A stage of `total` steps (0 = unknown) begins.
    fn start(&self, stage: &str, total: u64);
    /// `n` more steps of the stage are done.
    fn inc(&self, n: u64);
    /// The stage is over.
    fn finish(&self);
}

/// No progress shown (tests, `check`, `plan`).
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _: &str, _: u64) {}
    fn inc(&self, _: u64) {}
    fn finish(&self) {}
}

/// Which tiles a run writes.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum Selection {
    /// Every tile; report and manifest describe the whole city.
    #[default]
    All,
    /// Only these tiles, rewritten inside an earlier full build (its manifest is updated).
    Tiles(Vec<String>),
    /// The I-th (from 1) of N balanced sets of tiles; writes `manifest.shard-I-of-N.json`.
    Shard {
        /// I, from 1.
        index: usize,
        /// N.
        count: usize,
    },
}

impl Selection {
    /// Whether this run is one shard of several writing into one directory at once: it shares
    /// the output lock and leaves the others' temporaries alone.
    pub fn is_shard(&self) -> bool {
        matches!(self, Selection::Shard { .. })
    }
}

/// What to build, already validated by the CLI.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    /// The input directory.
    pub input: PathBuf,
    /// The output directory.
    pub out: PathBuf,
    /// The resolved, checked parameters.
    pub params: Params,
    /// Machiya type directory; `None` = `machiya.templates`, else the shipped types.
    pub templates: Option<PathBuf>,
    /// Worker threads; 0 = one per core.
    pub threads: usize,
    /// Also draw `<out>/plan.png`.
    pub plan_image: bool,
    /// Which tiles to write.
    pub selection: Selection,
    /// Replace an output directory built from other parameters or input.
    pub force: bool,
    /// The analysis cache's directory (`cache::dir_from` the environment, at the command
    /// line); `None`: no cache.
    pub cache: Option<PathBuf>,
    /// The fingerprints of the build before this one in the same directory, when this build
    /// may keep the tiles that would come out the same (`reuse`: the workbench's rebuilds;
    /// an empty set makes every tile and starts the record). The directory is then the
    /// caller's: a build of other parameters in it is replaced, as with `force`.
    pub reuse: Option<std::sync::Arc<reuse::Fingerprints>>,
}

/// Wall time of each stage.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    /// Reading every layer.
    pub read: Duration,
    /// Analysis (frontage, types, kura, fences, people and trees).
    pub analyse: Duration,
    /// Of `analyse`: kura placement, the R-tree of provisional plots and its queries.
    pub kura: Duration,
    /// Of `analyse`: halls, gardens, people and trees, ground (obstacle R-trees, the
    /// gardens' GA, Poisson draws, thinning).
    pub billboards: Duration,
    /// Of `billboards`, step by step.
    pub steps: Vec<(&'static str, Duration)>,
    /// Generating and writing the selected tiles (wall time).
    pub generate_and_write: Duration,
    /// Drawing plan.png.
    pub plan: Duration,
    /// Writing plan.gpkg: its layers written beside the tiles, then the ones after them.
    pub gpkg: [Duration; 2],
    /// Time spent generating meshes and formatting + writing files, summed over threads.
    pub generate_cpu: Duration,
    /// Formatting and writing the files, summed over threads.
    pub write_cpu: Duration,
    /// The whole run.
    pub total: Duration,
    /// Wall and processor time of each stage in order: read and analyse, the tiles (with
    /// plan.png and plan.gpkg beside them), the whole-city files (levels of detail, city
    /// model), the plan files and report.
    pub stages: Vec<StageTime>,
}

/// What a finished build returns to the CLI.
#[derive(Debug)]
pub struct BuildOutcome {
    /// The report, as written to report.json.
    pub report: report::Report,
    /// The time of each stage (`--timings`).
    pub timings: Timings,
    /// Bytes of tiles this run wrote.
    pub bytes_written: u64,
    /// Tiles written by this run.
    pub tiles_written: usize,
    /// Whether the analysis ran or came from the cache.
    pub cache: cache::CacheUse,
    /// With [`BuildOptions::reuse`]: what each tile was made from, for the next build, and
    /// the tiles this one made (the others were kept).
    pub fingerprints: Option<(reuse::Fingerprints, Vec<String>)>,
}

/// Reads and analyses the input: the part of a build every tile depends on. Returns the
/// time each took.
pub fn read_and_analyse(
    input: &Path,
    params: &Params,
    catalog: &Catalog,
    progress: &dyn Progress,
) -> Result<(Dataset, Plan, Duration, Duration), BuildError> {
    let t = Instant::now();
    progress.start("reading", 0);
    let data = input::read_dataset(input, params)?;
    progress.finish();
    let read = t.elapsed();
    let touched = analyse::ground::tiles_touched(&data, params, MAX_TILES);
    if touched > MAX_TILES {
        return Err(OptionsError::TooManyTiles(params.tile_size).into());
    }
    let t = Instant::now();
    let lots_file = input.join(&params.layers.lots.file).display().to_string();
    let machiya_lots = data
        .lots
        .iter()
        .filter(|l| l.lot_use == LotUse::Machiya)
        .count();
    progress.start("analysing", machiya_lots as u64);
    let mut plan = analyse::analyse(&data, params, catalog, &lots_file, &|n| progress.inc(n));
    progress.finish();
    let houses = data.lots.len() + data.footprints.len();
    if plan.tiles.len() > houses.max(TILES_BEFORE_A_WARNING) {
        plan.warnings.push(crate::model::Warning::new(
            crate::model::WarningClass::Build,
            format!(
                "`tile_size` = {} m makes {} tiles for {houses} lots and footprints: a tile \
                 should hold many houses (the default 250 m holds hundreds); raise `tile_size`",
                params.tile_size,
                plan.tiles.len()
            ),
        ));
    }
    Ok((data, plan, read, t.elapsed()))
}

/// The most tiles a city may be cut into (`tile_size`): each is a file of every format, a
/// node of the tileset and a row of its plan; a million lots at 250 m make about 2,000.
pub const MAX_TILES: usize = 200_000;
/// Tiles past which a city of fewer houses than tiles is warned of (`tile_size` too small).
const TILES_BEFORE_A_WARNING: usize = 1000;

/// The most shards a city may be split into (`--shard I/N`).
pub const MAX_SHARDS: usize = 10_000;
/// The most worker threads a build starts (`-j`).
pub const MAX_THREADS: usize = 1024;

/// Refuses a build whose overrides lie inside its own output directory: a build's plan.gpkg
/// edited in QGIS and named as the overrides of the next build into the same --out would be
/// written over by the build that reads it (issue 77).
fn reads_no_file_it_writes(opts: &BuildOptions) -> Result<(), BuildError> {
    let name = &opts.params.input.overrides;
    if name.is_empty() {
        return Ok(());
    }
    let (Ok(file), Ok(out)) = (
        std::fs::canonicalize(name),
        std::fs::canonicalize(&opts.out),
    ) else {
        return Ok(());
    };
    match file.starts_with(&out) {
        true => Err(BuildError::ReadsItsOutput {
            path: name.clone(),
            out: opts.out.display().to_string(),
        }),
        false => Ok(()),
    }
}

/// Runs the pipeline.
pub fn build(opts: &BuildOptions, progress: &dyn Progress) -> Result<BuildOutcome, BuildError> {
    let t0 = Instant::now();
    if opts.threads > MAX_THREADS {
        return Err(OptionsError::Threads(opts.threads).into());
    }
    reads_no_file_it_writes(opts)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(OptionsError::Pool)?;
    pool.install(|| {
        // Two independent loads side by side (a tenth of a `--tiles` run each); a broken
        // template is still the error named first.
        let (catalog, textures) = rayon::join(
            || load_catalog(&opts.params, opts.templates.as_deref()),
            || {
                let glb = opts.params.output.formats.iter().any(|f| f == "glb");
                output::texture_library(&opts.params.textures)
                    .and_then(output::with_masks)
                    .and_then(|lib| Ok(output::atlas::with_atlas(lib, glb)?))
            },
        );
        let catalog = catalog?;
        let (textures, atlas, no_atlas) = textures?;
        let library = Library {
            textures: &textures,
            atlas: atlas.as_ref(),
            no_atlas,
        };
        run(opts, &catalog, &library, progress, t0)
    })
}

/// A GeoPackage that could not be written, as any other file.
fn gpkg_err(e: output::gpkg::GpkgError) -> BuildError {
    let (path, cause) = e.into_io();
    write_err(&path, cause)
}

/// The textures a build writes, and the cut-out atlas among them for the GLB tiles.
struct Library<'a> {
    textures: &'a [output::Texture],
    atlas: Option<&'a output::atlas::Atlas>,
    /// Why the cut-outs have no atlas (too large), for the report's warnings.
    no_atlas: Option<String>,
}

fn run(
    opts: &BuildOptions,
    catalog: &Catalog,
    library: &Library,
    progress: &dyn Progress,
    t0: Instant,
) -> Result<BuildOutcome, BuildError> {
    let params = &opts.params;
    let mut timings = Timings::default();
    // `--tiles` into a directory of another hypothesis is refused before a minute of reading
    // and analysis at a million lots, not after (checked again under the lock below); a
    // missing input is still reported as that.
    if matches!(opts.selection, Selection::Tiles(_)) && opts.input.is_dir() {
        shards::check_out_dir(opts)?;
    }
    // A build caches its input and plan; `--tiles` of the same key reads them instead of
    // reading the input and analysing it.
    let cache = match opts.selection {
        Selection::Shard { .. } => None,
        _ => (opts.cache.as_deref())
            .and_then(|dir| Some((cache::file_for(dir, &opts.out), cache::key(opts)?))),
    };
    let t = Instant::now();
    let clock = StageClock::start();
    let cached = match (&opts.selection, &cache) {
        (Selection::Tiles(_), Some((file, key))) => {
            progress.start("reading the analysis cache", 0);
            let cached = cache::load(file, key);
            progress.finish();
            cached
        }
        _ => None,
    };
    let reused = cached.is_some();
    let (data, plan, read, analysed) = match cached {
        // The analysis's time is then the time of reading both back.
        Some((data, plan)) => (data, plan, Duration::ZERO, t.elapsed()),
        None => read_and_analyse(&opts.input, params, catalog, progress)?,
    };
    // Any whole analysis is worth keeping (a `--tiles` after an edit of the input, too).
    let store = cache.as_ref().filter(|_| !reused);
    timings.read = read;
    timings.analyse = analysed;
    timings.stages.push(clock.stop(if reused {
        "analysis from the cache"
    } else {
        "read and analyse"
    }));
    timings.kura = plan.kura_time;
    timings.billboards = plan.billboards_time;
    timings.steps = plan.step_times.clone();
    // After reading (a mistyped input is reported as that), before writing anything: one
    // run at a time in the directory, and never a second hypothesis in it.
    let existed = opts.out.exists();
    std::fs::create_dir_all(&opts.out).map_err(|e| write_err(&opts.out, e))?;
    // Shards of one city write disjoint tiles: they share the directory.
    let lock = match opts.selection.is_shard() {
        true => output::lock::OutLock::acquire_shared(&opts.out),
        false => output::lock::OutLock::acquire(&opts.out),
    };
    let lock = lock.map_err(|e| {
        if !existed {
            let _ = std::fs::remove_dir(&opts.out);
        }
        BuildError::Lock(e)
    })?;
    // The plan is cached while the tiles are written (it is the input's, whatever happens
    // to the writing), once the directory is known to be this build's.
    let checked = shards::check_out_dir(opts)
        .and_then(|()| shards::refuse_empty(opts, &plan))
        .and_then(|()| writing::begin(opts));
    // Shared with the cache's writer; `write_city` lets go of its own as soon as it can.
    let (data, plan) = (std::sync::Arc::new(data), std::sync::Arc::new(plan));
    let written = checked.and_then(|()| {
        std::thread::scope(|s| {
            if let Some((file, key)) = store {
                let (data, plan) = (data.clone(), plan.clone());
                s.spawn(move || cache::store(file, key, &data, &plan));
            }
            write_city(
                opts, catalog, library, progress, data, plan, timings, t0, reused,
            )
        })
    });
    let written = written.map(|o| BuildOutcome {
        cache: match (reused, &cache) {
            (true, _) => cache::CacheUse::Reused,
            (false, Some(_)) => cache::CacheUse::Analysed,
            (false, None) => cache::CacheUse::Off,
        },
        ..o
    });
    if written.is_ok() || !existed {
        writing::end(opts);
    }
    drop(lock);
    if written.is_err() && !existed {
        // Leave no directory behind that the user did not have before (only empty ones go).
        for dir in [
            opts.out.join(output::TEXTURE_DIR),
            opts.out.join("tiles"),
            opts.out.clone(),
        ] {
            let _ = std::fs::remove_dir(dir);
        }
    }
    written
}

/// Generates and writes the tiles, the plan, the manifest and the report of an analysed city
/// into a locked output directory, by the steps of [`city::CityWriter`].
#[allow(clippy::too_many_arguments)]
fn write_city(
    opts: &BuildOptions,
    catalog: &Catalog,
    library: &Library,
    progress: &dyn Progress,
    data: std::sync::Arc<Dataset>,
    plan: std::sync::Arc<Plan>,
    mut timings: Timings,
    t0: Instant,
    reused: bool,
) -> Result<BuildOutcome, BuildError> {
    let params = &opts.params;
    let t = Instant::now();
    let selected = shards::select(&plan, &opts.selection)?;
    let previous = match &opts.selection {
        Selection::Tiles(_) => Some(shards::previous_manifest(
            &opts.out,
            "--tiles rewrites tiles of an earlier full build",
        )?),
        _ => None,
    };
    let writer = city::CityWriter::prepare(opts, catalog, library, &plan)?;
    let directory = output::features::Directory::of(&data, &plan, params);
    let tiles: Vec<&String> = (plan.tiles.iter())
        .filter(|id| selected.contains(id.as_str()))
        .collect();
    let reuse = (opts.reuse.as_deref()).map(|before| {
        let city = reuse::city_hash(params, &data, &plan);
        reuse::Reuse::new(before, city, &opts.out)
    });
    progress.start("writing tiles", tiles.len() as u64);
    let make_tiles = || -> Vec<Result<city::Made, BuildError>> {
        tiles
            .par_iter()
            .map(|&id| {
                let made = writer.made(id, &data, &plan, &directory, reuse.as_ref());
                progress.inc(1);
                made
            })
            .collect()
    };
    // Beside the tiles, on the cores they leave: plan.png's image (drawn on one thread; it
    // used to follow them, a third of a build on one core) and plan.gpkg's layers that
    // analysis alone decides. A `--tiles` run whose analysis came from the cache leaves the
    // full build's plan.gpkg as it is: the same analysis wrote it.
    let gpkg_path = opts.out.join(output::PLAN_GPKG);
    let band = |m: &crate::model::PlannedHouse| analyse::house::house_band(m, catalog, params);
    let sources = output::gpkg::PlanSources {
        data: &data,
        plan: &plan,
        params,
        band: &band,
    };
    let want_gpkg = params.output.formats.iter().any(|f| f == "gpkg")
        && !opts.selection.is_shard()
        && !(reused && gpkg_path.is_file());
    let start_gpkg = || {
        let t = Instant::now();
        let started = want_gpkg
            .then(|| output::gpkg::PlanWriter::start(&gpkg_path, &sources).map_err(gpkg_err));
        (started, t.elapsed())
    };
    // The workbench's image of the rebuild before: only the strips that changed are drawn.
    let kept = opts.reuse.as_deref().map(|f| f.plan_image());
    let draw = || city::draw_plan(&data, &plan, params, opts.plan_image, kept);
    // What follows the tiles and needs only them: the fingerprints, the manifest, links.json.
    let settle = |results: Vec<Result<city::Made, BuildError>>| -> Result<_, BuildError> {
        let made = results.into_iter().collect::<Result<Vec<_>, _>>()?;
        let fingerprints = reuse.as_ref().map(|r| city::fingerprints(r, &made));
        let written: Vec<report::ManifestTile> = made.into_iter().map(|m| m.entry).collect();
        let counts = city::Counts::of(&written, fingerprints.as_ref().map(|(_, r)| &r[..]));
        let mut manifest = writer.manifest(&data, &plan, written, previous);
        writer.links(&mut manifest, &data)?;
        Ok((fingerprints, counts, manifest))
    };
    // A build that keeps tiles (the workbench's) makes its levels of detail as soon as its
    // tiles are written, beside plan.gpkg's first layers: a lot's edit makes one tile and
    // its parents, and plan.gpkg's layers take as long. A whole build makes them after,
    // once the analysis is let go (at a million lots it was most of what was live).
    let lod_beside = opts.reuse.is_some();
    let clock = StageClock::start();
    let (((image, plan_time), (gpkg, gpkg_time)), tiles_done) = rayon::join(
        || rayon::join(draw, start_gpkg),
        || {
            let results = make_tiles();
            progress.finish();
            let (fingerprints, counts, manifest) = settle(results)?;
            let with_lod = lod_beside
                .then(|| {
                    let mut m = manifest.clone();
                    writer.formats(&mut m).map(|()| m)
                })
                .transpose()?;
            Ok::<_, BuildError>((fingerprints, counts, manifest, with_lod))
        },
    );
    // With what is drawn beside them: a lot's edit makes one tile, then waits for those.
    timings.stages.push(clock.stop(match lod_beside {
        true => "tiles and levels of detail",
        false => "tiles",
    }));
    let (fingerprints, counts, manifest, with_lod) = tiles_done?;
    // Its maps of every lot and house are not needed by the levels of detail (1,000,000
    // lots: tens of MB).
    drop(directory);
    (timings.generate_cpu, timings.write_cpu) = writer.cpu();
    let clock = StageClock::start();
    let beside = city::Beside { image, gpkg };
    let (gpkg_after, png_time) = writer.plan_files(&manifest, beside, &sources)?;
    timings.stages.push(clock.stop("manifest and plan files"));
    // Freeing the analysis's millions of small allocations takes a moment nobody waits for.
    std::thread::spawn(move || drop((data, plan)));
    let clock = StageClock::start();
    // plan.gpkg was finished from the manifest of the tiles alone, as a whole build has it.
    let manifest = match with_lod {
        Some(m) => m,
        None => {
            let mut manifest = manifest;
            writer.formats(&mut manifest)?;
            manifest
        }
    };
    let (report, stale_time) = writer.close(manifest)?;
    timings
        .stages
        .push(clock.stop("whole-city files and report"));
    timings.gpkg = [gpkg_time, gpkg_after];
    timings.generate_and_write = t.elapsed() - png_time - stale_time;
    // Drawn beside the tiles: its own time, not the wall time it added.
    timings.plan = plan_time + png_time + stale_time;
    timings.total = t0.elapsed();
    Ok(BuildOutcome {
        report,
        timings,
        bytes_written: counts.bytes,
        tiles_written: counts.tiles,
        cache: cache::CacheUse::Off,
        fingerprints,
    })
}

/// The DEM and a tile's bounds, when `terrain = true` and there is a DEM.
fn terrain_of<'a>(
    data: &'a Dataset,
    params: &Params,
    tile: &'a str,
) -> Option<(&'a crate::model::dem::Dem, &'a str, [f64; 4])> {
    let dem = data.dem.as_ref().filter(|_| params.terrain)?;
    let b = crate::model::tile::tile_bounds(tile, params.tile_size, params.tile_origin)?;
    Some((dem, tile, b))
}

/// The files each layer's features come from, for skip reports.
fn layer_files(input: &Path, params: &Params) -> generate::LayerFiles {
    let l = &params.layers;
    let path = |f: &str| input.join(f).display().to_string();
    generate::LayerFiles {
        lots: path(&l.lots.file),
        footprints: path(&l.footprints.file),
        fences: path(&l.fences.file),
        people: path(&l.people.file),
        trees: path(&l.trees.file),
    }
}

/// How plan.png shows kura: not at all, or built ones filled and (with avoidance) refused
/// ones outlined.
fn kura_view(params: &Params) -> Option<bool> {
    params.kura.enabled.then_some(params.kura.collision)
}

/// `path` made absolute, so that a manifest names its input wherever `merge`, `plan` or a
/// later `--tiles` run is started from.
pub fn absolute(path: &Path) -> PathBuf {
    std::fs::canonicalize(path)
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}
