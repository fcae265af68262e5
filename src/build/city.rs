//! Writing an analysed city into its locked output directory, a step at a time (issue 58:
//! this was one function of 314 lines and 9 parameters):
//!
//! 1. [`CityWriter::prepare`]: the tile directories, a killed run's temporaries swept, the
//!    textures and the species written;
//! 2. [`CityWriter::tile`], one tile at a time on every core: generated, written by each
//!    format's sink, its walkers' clips; its manifest entry returned;
//! 3. beside the tiles, [`Beside`]: plan.png drawn and plan.gpkg's first layers written;
//! 4. [`CityWriter::manifest`]: the manifest of what this run wrote (and, for `--tiles`, the
//!    earlier build's other tiles);
//! 5. [`CityWriter::links`], links.json;
//! 6. [`CityWriter::plan_files`], plan.gpkg, plan.png; then the caller lets the analysis go;
//! 7. [`CityWriter::formats`], each format's whole-build files (the tileset and its levels of
//!    detail);
//! 8. [`CityWriter::close`], stale files removed, report and manifest.
//!
//! The steps take plain data and return it; [`Timings`] is filled by the caller from what
//! each returns.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use super::reuse::{Fingerprints, Mark, Reuse};
use super::{
    check::input_summary, shards, write_err, BuildError, BuildOptions, Library, Selection,
};
use crate::generate::{self, mesh::Mesh};
use crate::model::object::ObjectKind;
use crate::model::{Dataset, Plan};
use crate::output::{self, report, sink::Sink};
use crate::params::Params;
use crate::templates::Catalog;

/// One run's writer of a city: what every tile needs, made once.
pub(super) struct CityWriter<'a> {
    opts: &'a BuildOptions,
    catalog: &'a Catalog,
    library: &'a Library<'a>,
    tiles_dir: PathBuf,
    sinks: Vec<Box<dyn Sink>>,
    files: generate::LayerFiles,
    textures: Vec<report::ManifestFile>,
    species: Vec<report::ManifestFile>,
    /// The tree variants, grown once for `species/` and every tile.
    variants: generate::variant::Variants,
    /// Nanoseconds generating and writing, summed over threads (`--timings`' CPU figures).
    generate_ns: AtomicU64,
    write_ns: AtomicU64,
}

impl<'a> CityWriter<'a> {
    /// Makes the directories, sweeps what a killed run left (a full build or merge only:
    /// shards leave the temporaries of the shards beside them), writes the textures and the
    /// species.
    pub fn prepare(
        opts: &'a BuildOptions,
        catalog: &'a Catalog,
        library: &'a Library<'a>,
        plan: &Plan,
    ) -> Result<Self, BuildError> {
        let params = &opts.params;
        let tiles_dir = opts.out.join("tiles");
        std::fs::create_dir_all(&tiles_dir).map_err(|e| write_err(&tiles_dir, e))?;
        let crowds_dir = opts.out.join(output::crowds::DIR);
        if !plan.walks.is_empty() {
            std::fs::create_dir_all(&crowds_dir).map_err(|e| write_err(&crowds_dir, e))?;
        }
        let alone = !opts.selection.is_shard();
        if alone {
            for dir in [
                &opts.out,
                &tiles_dir,
                &opts.out.join(output::TEXTURE_DIR),
                &opts.out.join(output::glb::MODELS_DIR),
                &opts.out.join(output::cityjson::TEMPLATES_DIR),
                &crowds_dir,
            ] {
                output::atomic::remove_leftover_temporaries(dir);
            }
        }
        let texture_err = |e| write_err(&opts.out.join(output::TEXTURE_DIR), e);
        let mut textures =
            output::write_textures(&opts.out, library.textures).map_err(texture_err)?;
        textures.extend(
            output::write_model_textures(&opts.out, &plan.model_textures).map_err(texture_err)?,
        );
        let variants = generate::variant::Variants::of(params);
        let trees = generate::species::planted_trees(plan);
        let models = generate::species::species_models(&trees, catalog, params, &variants);
        let species =
            output::species::write_species(&opts.out, plan, &trees, &models, catalog, alone)
                .map_err(|e| write_err(&opts.out.join("species"), e))?;
        Ok(CityWriter {
            opts,
            catalog,
            library,
            tiles_dir,
            sinks: output::sinks(
                &params.output,
                library.atlas,
                &report::params_id(params),
                None,
            ),
            files: super::layer_files(&opts.input, params),
            textures,
            species,
            variants,
            generate_ns: AtomicU64::new(0),
            write_ns: AtomicU64::new(0),
        })
    }

    /// Tile `id`: kept as the build before left it when `reuse` says its files would come
    /// out the same, else generated and written.
    pub fn made(
        &self,
        id: &str,
        data: &Dataset,
        plan: &Plan,
        directory: &output::features::Directory,
        reuse: Option<&Reuse>,
    ) -> Result<Made, BuildError> {
        let tile = generate::TilePlan {
            ground: super::terrain_of(data, &self.opts.params, id),
            ..generate::TilePlan::of(plan, id)
        };
        let Some(reuse) = reuse else {
            let (entry, _) = self.tile(id, &tile, plan, directory, false)?;
            return Ok(Made { entry, mark: None });
        };
        if let Some((entry, mark)) = reuse.kept(id, &tile, directory, &self.opts.out) {
            return Ok(Made {
                entry,
                mark: Some((mark, false)),
            });
        }
        let (entry, owners) = self.tile(id, &tile, plan, directory, true)?;
        let mark = Reuse::made(&tile, owners, directory);
        Ok(Made {
            entry,
            mark: Some((mark, true)),
        })
    }

    /// Generates tile `id` and writes it in every format, with its walkers' clips; its
    /// manifest entry, and with `owners` the ids of the lots, houses and others its objects
    /// belong to.
    fn tile(
        &self,
        id: &str,
        tile: &generate::TilePlan,
        plan: &Plan,
        directory: &output::features::Directory,
        owners: bool,
    ) -> Result<(report::ManifestTile, Vec<String>), BuildError> {
        let (params, out) = (&self.opts.params, &self.opts.out);
        let t = Instant::now();
        let mut meshes = generate::generate_tile(
            tile,
            self.catalog,
            params,
            &self.variants,
            plan.origin,
            &self.files,
        );
        self.generate_ns
            .fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        let t = Instant::now();
        let features = directory.features(&meshes.meshes);
        let instance_features = directory.instance_features(&meshes.instanced);
        let extent = output::sink::union(
            output::sink::extent(&meshes.meshes),
            meshes.crowd.as_ref().and_then(|c| c.reach(plan.origin)),
        );
        let centre = output::sink::tile_centre(
            id,
            plan.origin,
            params.tile_size,
            params.tile_origin,
            extent,
        );
        let content = output::sink::TileContent {
            id,
            origin: plan.origin,
            centre,
            meshes: &meshes.meshes,
            features: &features,
            instanced: &meshes.instanced,
            instance_features: &instance_features,
            crowd: meshes.crowd.as_ref(),
            palette: output::palette::Palette::new(&plan.palette),
        };
        let mut entry = entry(id, extent, centre);
        let mut mesh_bytes = None;
        for sink in &self.sinks {
            let w = sink.write_tile(out, &content).map_err(|e| {
                write_err(&self.tiles_dir.join(format!("{id}.{}", sink.format())), e)
            })?;
            entry.add_files(w.files);
            mesh_bytes = mesh_bytes.or(w.mesh_bytes);
        }
        if let Some(walks) = plan.walks.get(id).filter(|w| !w.is_empty()) {
            let path = output::crowds::path(id);
            let text = output::crowds::csv(walks);
            let f = output::write_listed(out, path, &[text.as_bytes()])
                .map_err(|e| write_err(&out.join(output::crowds::path(id)), e))?;
            entry.crowds = Some(f);
        }
        self.write_ns
            .fetch_add(t.elapsed().as_nanos() as u64, Ordering::Relaxed);
        let bytes_of = |names| object_bytes(&meshes.meshes, mesh_bytes.as_deref(), names);
        meshes.stats.tree_bytes = bytes_of([ObjectKind::Trees, ObjectKind::GrownTrees]);
        meshes.stats.ground_bytes = bytes_of([ObjectKind::Ground, ObjectKind::Streets]);
        entry.stats = meshes.stats;
        let owners = match owners {
            true => (meshes.meshes.iter().map(|m| m.owner.id.clone()))
                .chain(
                    (meshes.instanced.iter())
                        .flat_map(|g| g.trees.iter().filter_map(|t| t.lot.clone())),
                )
                .collect(),
            false => Vec::new(),
        };
        Ok((entry, owners))
    }

    /// The CPU time generating and writing the tiles took, summed over threads.
    pub fn cpu(&self) -> (Duration, Duration) {
        (
            Duration::from_nanos(self.generate_ns.load(Ordering::Relaxed)),
            Duration::from_nanos(self.write_ns.load(Ordering::Relaxed)),
        )
    }

    /// The manifest of this run: the tiles it wrote, and for `--tiles` the earlier build's
    /// entries (`previous`) of the tiles it did not touch, in the plan's order.
    pub fn manifest(
        &self,
        data: &Dataset,
        plan: &Plan,
        written: Vec<report::ManifestTile>,
        previous: Option<report::Manifest>,
    ) -> report::Manifest {
        let opts = self.opts;
        let params = &opts.params;
        let tiles = match previous {
            Some(prev) => {
                let mut new: BTreeMap<String, report::ManifestTile> =
                    written.into_iter().map(|t| (t.id.clone(), t)).collect();
                let mut out = Vec::new();
                for id in &plan.tiles {
                    if let Some(t) = new.remove(id) {
                        out.push(t);
                    } else if let Some(t) = prev.tiles.iter().find(|t| &t.id == id) {
                        out.push(t.clone());
                    }
                }
                out
            }
            None => written,
        };
        let mut manifest = report::Manifest {
            tool: "edo-city".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            shard: match opts.selection {
                Selection::Shard { index, count } => Some([index, count]),
                _ => None,
            },
            origin: plan.origin,
            frame: "x = east - origin[0], y = up, z = -(north - origin[1]); metres".into(),
            crs: data.crs.clone(),
            crs_wkt: data.crs_wkt.clone(),
            tile_size: params.tile_size,
            params: params.clone(),
            input: input_summary(&opts.input, opts.templates.as_deref(), data, plan),
            tiles,
            formats: self.sinks.iter().map(|s| s.format().to_string()).collect(),
            files: Vec::new(),
            textures: self.textures.clone(),
            species: self.species.clone(),
        };
        if let Some(why) = &self.library.no_atlas {
            manifest.input.warnings.push(crate::model::Warning::new(
                crate::model::WarningClass::Build,
                why.clone(),
            ));
        }
        manifest
    }

    /// Writes links.json (the build's own file, first in the manifest's list).
    pub fn links(&self, manifest: &mut report::Manifest, data: &Dataset) -> Result<(), BuildError> {
        let out = &self.opts.out;
        let links = output::links::write_links(out, data, manifest.origin)
            .map_err(|e| write_err(&out.join("links.json"), e))?;
        manifest.files.extend(links);
        Ok(())
    }

    /// Writes what follows the tiles and needs the analysis: plan.gpkg's last layers and
    /// plan.png; their times. The analysis may be let go after it: the levels of detail read
    /// the leaves back, and at a million lots it was most of what was live while the
    /// parents were made.
    pub fn plan_files(
        &self,
        manifest: &report::Manifest,
        beside: Beside,
        sources: &output::gpkg::PlanSources,
    ) -> Result<(Duration, Duration), BuildError> {
        let opts = self.opts;
        let t = Instant::now();
        let gpkg_path = opts.out.join(output::PLAN_GPKG);
        match beside.gpkg {
            Some(writer) => writer?.finish(sources, manifest).map_err(super::gpkg_err)?,
            // A whole build without gpkg leaves no plan.gpkg of an earlier one beside its tiles.
            None if opts.selection == Selection::All => {
                let _ = std::fs::remove_file(&gpkg_path);
            }
            None => {}
        }
        let gpkg_after = t.elapsed();
        let t = Instant::now();
        if let Some(png) = beside.image {
            let path = opts.out.join("plan.png");
            output::atomic::write_atomic(&path, &png).map_err(|e| write_err(&path, e))?;
        }
        Ok((gpkg_after, t.elapsed()))
    }

    /// Writes each format's whole-build files: the tileset and its levels of detail, the
    /// city model (a shard leaves them to `merge`).
    pub fn formats(&self, manifest: &mut report::Manifest) -> Result<(), BuildError> {
        if manifest.shard.is_none() {
            let memory = self.opts.reuse.as_ref().map(|r| r.levels_of_detail());
            shards::finish_formats(&self.opts.out, manifest, memory)?;
        }
        Ok(())
    }

    /// Removes the stale files of an earlier build, writes the report and the manifest
    /// (last); the report, and the time the stale files took.
    pub fn close(
        self,
        manifest: report::Manifest,
    ) -> Result<(report::Report, Duration), BuildError> {
        let opts = self.opts;
        let t = Instant::now();
        if opts.selection == Selection::All {
            shards::remove_stale_tiles(&opts.out, &manifest);
            shards::remove_stale_textures(&opts.out, &manifest.textures);
        }
        let stale = t.elapsed();
        let report = shards::write_manifest_and_report(&opts.out, &manifest)?;
        Ok((report, stale))
    }
}

/// What a run wrote: the tiles it made (a build that may keep tiles kept the others as they
/// were) and their bytes, each shared model once however many tiles draw it.
pub(super) struct Counts {
    pub tiles: usize,
    pub bytes: u64,
}

impl Counts {
    /// Of the entries `written`; `remade` (sorted) the tiles made when the build kept others.
    pub fn of(written: &[report::ManifestTile], remade: Option<&[String]>) -> Counts {
        let made_here =
            |t: &&report::ManifestTile| remade.is_none_or(|r| r.binary_search(&t.id).is_ok());
        let models: BTreeMap<&str, u64> = (written.iter().filter(made_here))
            .flat_map(|t| t.models.iter().map(|f| (f.path.as_str(), f.bytes)))
            .collect();
        Counts {
            tiles: remade.map_or(written.len(), <[String]>::len),
            bytes: (written.iter().filter(made_here))
                .map(|t| t.bytes())
                .sum::<u64>()
                + models.values().sum::<u64>(),
        }
    }
}

/// A tile of this build: its manifest entry and, when the build may keep tiles, its
/// fingerprint and whether it was made (else kept).
pub(super) struct Made {
    pub entry: report::ManifestTile,
    pub mark: Option<(Mark, bool)>,
}

/// The fingerprints of a build that may keep tiles, and the tiles it made.
pub(super) fn fingerprints(reuse: &Reuse, made: &[Made]) -> (Fingerprints, Vec<String>) {
    let mut marks = Vec::new();
    let mut remade = Vec::new();
    for m in made {
        if let Some((mark, new)) = &m.mark {
            marks.push((m.entry.id.clone(), mark.clone()));
            if *new {
                remade.push(m.entry.id.clone());
            }
        }
    }
    remade.sort_unstable();
    (reuse.fingerprints(marks), remade)
}

/// What is made beside the tiles, on the cores the tiles leave: plan.png's image (written
/// after them) and plan.gpkg with the layers analysis alone decides (finished after them).
pub(super) struct Beside {
    pub image: Option<Vec<u8>>,
    pub gpkg: Option<Result<output::gpkg::PlanWriter, BuildError>>,
}

/// A tile's manifest entry before its files are written: its extent (output frame, mm) as
/// east, north, up metres, its centre.
fn entry(id: &str, extent: Option<([i64; 3], [i64; 3])>, centre: [i64; 3]) -> report::ManifestTile {
    report::ManifestTile {
        id: id.to_string(),
        obj: None,
        mtl: None,
        glb: None,
        crowds: None,
        cityjson: None,
        models: Vec::new(),
        bounds: extent.map(|(lo, hi)| {
            // Output frame (x east, y up, z south) to east, north, up.
            let m = |v: i64| v as f64 / 1000.0;
            [m(lo[0]), -m(hi[2]), m(lo[1]), m(hi[0]), -m(lo[2]), m(hi[1])]
        }),
        centre: [centre[0] as f64 / 1000.0, -(centre[2] as f64) / 1000.0],
        stats: Default::default(),
    }
}

/// The bytes the objects of `kinds` take in the OBJ, exactly: the OBJ writer's count of
/// each mesh when it wrote one (`sizes`), else counted.
fn object_bytes(meshes: &[Mesh], sizes: Option<&[usize]>, kinds: [ObjectKind; 2]) -> u64 {
    let of = |m: &Mesh| kinds.contains(&m.kind);
    match sizes {
        Some(sizes) => meshes
            .iter()
            .zip(sizes)
            .filter(|(m, _)| of(m))
            .map(|(_, &n)| n as u64)
            .sum(),
        None => output::obj_bytes(meshes.iter().filter(|m| of(m))) as u64,
    }
}

/// The image of plan.png for this build, when it draws one, and the time it took.
pub(super) fn draw_plan(
    data: &Dataset,
    plan: &Plan,
    params: &Params,
    wanted: bool,
    kept: Option<&output::plan::Kept>,
) -> (Option<Vec<u8>>, Duration) {
    let t = Instant::now();
    let image = wanted
        .then(|| {
            let grid = (params.tile_size, params.tile_origin);
            output::plan::View::fit(data, None).and_then(|view| {
                output::plan::draw_plan(data, plan, &view, grid, super::kura_view(params), kept)
            })
        })
        .flatten();
    (image, t.elapsed())
}
