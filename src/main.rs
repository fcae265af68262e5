//! The `edo-city` command line: parses flags into validated options and calls the library.
//! Everything the user sees (progress bars, the summary, error context) lives here.

#![forbid(unsafe_code)]

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use edo_city::build::{build, shards, BuildOptions, NoProgress, Selection};
use edo_city::params::Params;

/// `println!` that returns the error instead of panicking: a reader that stops early
/// (`edo-city tiles out | head`) closes the pipe, and that is no failure of ours.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*)?
    }};
}

mod cli;

use cli::progress::Bars;
use cli::summary::{print_check, print_summary};

#[derive(Parser)]
#[command(
    name = "edo-city",
    version,
    about = "GIS lots and streets in, a tiled 3D city of Edo-era Kyoto townhouses out (Kosaka et al. 2008)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build a tiled OBJ/MTL city from a shapefile directory.
    Build {
        /// Input directory (lots.shp, blocks.shp and/or streets.shp, lots.csv/.xlsx).
        input: PathBuf,
        /// Output directory; tiles go to <out>/tiles, textures to <out>/textures.
        #[arg(short, long, default_value = "out")]
        out: PathBuf,
        /// Parameter file (TOML); keys it leaves out keep the defaults of params/default.toml.
        #[arg(short, long)]
        params: Option<PathBuf>,
        /// Directory of template files (*.toml), added to the shipped ones; a file of a shipped
        /// template's name replaces that template.
        #[arg(long)]
        templates: Option<PathBuf>,
        /// Worker threads (0 = one per core). The output does not depend on it.
        #[arg(short = 'j', long, default_value_t = 0)]
        threads: usize,
        /// No progress bars and no summary.
        #[arg(short, long)]
        quiet: bool,
        /// Print the time of each stage.
        #[arg(long)]
        timings: bool,
        /// Do not draw <out>/plan.png (lots by type, streets, each house's frontage, tiles).
        #[arg(long)]
        no_plan: bool,
        /// Rewrite only these tiles (comma-separated ids) of an earlier full build in --out;
        /// each comes out byte-identical to the same tile of a full build.
        #[arg(long, value_delimiter = ',', conflicts_with = "shard")]
        tiles: Option<Vec<String>>,
        /// Build the I-th of N balanced, disjoint sets of tiles (e.g. 2/8), for a cluster;
        /// `edo-city merge` then writes the whole city's manifest and report.
        #[arg(long, value_parser = parse_shard)]
        shard: Option<(usize, usize)>,
        /// Replace an output directory that holds a build of other parameters or input.
        #[arg(long)]
        force: bool,
    },
    /// Compare two builds (two hypotheses): parameters, counts per type and district, tiles.
    Compare {
        a: PathBuf,
        b: PathBuf,
        /// Machine-readable output.
        #[arg(long)]
        json: bool,
        /// Also draw a map of the tiles that changed.
        #[arg(long)]
        plan: Option<PathBuf>,
    },
    /// Draw the plan of a build: lots by type, streets, frontages, tiles, legend, scale.
    Plan {
        /// The output directory of a build (its manifest names the input and parameters).
        out: PathBuf,
        /// Image to write.
        #[arg(short, long, default_value = "plan.png")]
        output: PathBuf,
        /// Only this tile, at full resolution.
        #[arg(long)]
        tile: Option<String>,
    },
    /// Check an input directory without building: layers, counts, CRS, encodings and every
    /// problem. Exit 0 when all would be built, 1 when something would be skipped or warned
    /// about, 2 on an error.
    Check {
        input: PathBuf,
        #[arg(short, long)]
        params: Option<PathBuf>,
        #[arg(long)]
        templates: Option<PathBuf>,
        /// Machine-readable output (the report a build would write).
        #[arg(long)]
        json: bool,
    },
    /// List the tiles a build would write, with feature counts and bounds (for scripts).
    Tiles {
        input: PathBuf,
        #[arg(short, long)]
        params: Option<PathBuf>,
        /// Machine-readable output.
        #[arg(long)]
        json: bool,
    },
    /// Merge shard outputs (`build --shard I/N`) into the first directory: copies the other
    /// directories' tiles, writes manifest.json and report.json for the whole city.
    Merge {
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Do not draw plan.png (it re-reads the input named in the manifests).
        #[arg(long)]
        no_plan: bool,
    },
    /// Write a Kyoto-like shapefile directory of synthetic lots, blocks and streets.
    Synth {
        /// Output directory.
        dir: PathBuf,
        /// Number of lots.
        #[arg(long, default_value_t = 500)]
        lots: usize,
        /// Seed of the town's layout.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Write into a directory that already holds files (files of the same names are
        /// replaced; the others stay, and a lots.csv there is joined by `build`).
        #[arg(long)]
        force: bool,
    },
    /// Print the default parameter file (documented key by key).
    Params,
    /// Build one template alone on a rectangular lot and write it as OBJ + MTL + textures,
    /// for authoring templates; without a name, list the templates.
    Template {
        /// Template name (machiya type, kura, fence, tsuiji, gate, tree, person or your own).
        name: Option<String>,
        /// Frontage width of the site, metres (the u axis).
        #[arg(long, default_value_t = 5.454)]
        width: f64,
        /// Depth of the site, metres (the v axis).
        #[arg(long, default_value_t = 20.0)]
        depth: f64,
        /// The OBJ to write; its MTL and a textures/ directory go beside it.
        #[arg(short, long, default_value = "template.obj")]
        output: PathBuf,
        /// Parameter file: its `[template.<name>]` values and texture set apply.
        #[arg(short, long)]
        params: Option<PathBuf>,
        /// Directory of your own template files (added to the shipped ones).
        #[arg(long)]
        templates: Option<PathBuf>,
        /// Set a template parameter, e.g. `--set eave_height=6.1` (repeatable).
        #[arg(long = "set", value_name = "PARAM=VALUE")]
        set: Vec<String>,
    },
    /// Inspect a directory of shapefiles and write a starting parameter file with guesses.
    Init {
        /// The data directory.
        dir: PathBuf,
        /// Where to write the parameter file ("-" = standard output).
        #[arg(short, long, default_value = "edo-city.toml")]
        output: PathBuf,
        /// Replace an existing file.
        #[arg(long)]
        force: bool,
    },
}

/// `check` found features it would skip or warnings: not an error, exit code 1.
#[derive(Debug)]
struct Problems(usize);

impl std::fmt::Display for Problems {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} problem(s) found", self.0)
    }
}

impl std::error::Error for Problems {}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if closed_pipe(&e) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<Problems>().is_some() => {
            eprintln!("{e}");
            ExitCode::from(1)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Whether `e` is stdout's reader having gone away.
fn closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Build {
            input,
            out,
            params,
            templates,
            threads,
            quiet,
            timings,
            no_plan,
            tiles,
            shard,
            force,
        } => {
            let params = match &params {
                Some(p) => Params::from_path(p)?,
                None => Params::default(),
            };
            let opts = BuildOptions {
                input,
                out,
                params,
                templates,
                threads,
                // A plan of the whole city; shards and single tiles leave it to the full build.
                plan_image: !no_plan && tiles.is_none() && shard.is_none(),
                selection: match (tiles, shard) {
                    (Some(t), _) => Selection::Tiles(t),
                    (_, Some((index, count))) => Selection::Shard { index, count },
                    _ => Selection::All,
                },
                force,
            };
            let bars = Bars::new(quiet || !std::io::stderr().is_terminal());
            let outcome = build(&opts, &bars).context("the build did not finish")?;
            if !quiet {
                print_summary(&opts, &outcome)?;
            }
            if timings {
                let t = &outcome.timings;
                eprintln!(
                    "timings: read {:.3} s, analyse {:.3} s (kura plots and R-tree {:.3} s, people and trees {:.3} s), generate+write {:.3} s (cpu: generate {:.3} s, format+write {:.3} s), plan {:.3} s, total {:.3} s",
                    t.read.as_secs_f64(),
                    t.analyse.as_secs_f64(),
                    t.kura.as_secs_f64(),
                    t.billboards.as_secs_f64(),
                    t.generate_and_write.as_secs_f64(),
                    t.generate_cpu.as_secs_f64(),
                    t.write_cpu.as_secs_f64(),
                    t.plan.as_secs_f64(),
                    t.total.as_secs_f64()
                );
            }
            Ok(())
        }
        Command::Synth {
            dir,
            lots,
            seed,
            force,
        } => {
            let s =
                edo_city::synth::write_town(&dir, lots, seed, force).map_err(anyhow::Error::msg)?;
            say!(
                "wrote {}: {} lots ({} machiya), {} blocks, {} streets",
                dir.display(),
                s.lots,
                s.machiya,
                s.blocks,
                s.streets
            );
            Ok(())
        }
        Command::Tiles {
            input,
            params,
            json,
        } => {
            let params = match &params {
                Some(p) => Params::from_path(p)?,
                None => Params::default(),
            };
            let catalog = edo_city::build::load_catalog(&params, None)?;
            let (_, plan, _, _) =
                edo_city::build::read_and_analyse(&input, &params, &catalog, &NoProgress)?;
            let tiles = shards::list_tiles(&plan, params.tile_size, params.tile_origin);
            if json {
                say!("{}", serde_json::to_string_pretty(&tiles)?);
            } else {
                say!("tile\tmachiya\tfootprints\txmin\tymin\txmax\tymax");
                for t in tiles {
                    say!(
                        "{}\t{}\t{}\t{:.3}\t{:.3}\t{:.3}\t{:.3}",
                        t.id,
                        t.machiya,
                        t.footprints,
                        t.bounds[0],
                        t.bounds[1],
                        t.bounds[2],
                        t.bounds[3]
                    );
                }
            }
            Ok(())
        }
        Command::Check {
            input,
            params,
            templates,
            json,
        } => {
            let params = match &params {
                Some(p) => Params::from_path(p)?,
                None => Params::default(),
            };
            let r = edo_city::build::check(&input, &params, templates.as_deref())?;
            if json {
                say!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                print_check(&r)?;
            }
            let problems = r.counts.skipped + r.warnings.len();
            if problems > 0 {
                return Err(Problems(problems).into());
            }
            Ok(())
        }
        Command::Compare { a, b, json, plan } => {
            let c = edo_city::compare::compare(&a, &b)?;
            if json {
                say!("{}", serde_json::to_string_pretty(&c)?);
            } else {
                print!("{}", edo_city::compare::render(&c));
            }
            if let Some(path) = plan {
                let png = edo_city::compare::difference_map(&c, &a)?;
                edo_city::output::atomic::write_atomic(&path, &png)
                    .with_context(|| format!("cannot write {}", path.display()))?;
                if !json {
                    say!("wrote {}", path.display());
                }
            }
            Ok(())
        }
        Command::Plan { out, output, tile } => {
            let png = edo_city::build::draw_plan_of(&out, tile.as_deref())?;
            edo_city::output::atomic::write_atomic(&output, &png)
                .with_context(|| format!("cannot write {}", output.display()))?;
            say!("wrote {}", output.display());
            Ok(())
        }
        Command::Merge { dirs, no_plan } => {
            let report = shards::merge(&dirs, !no_plan)?;
            say!(
                "merged into {}: {} tiles, {} machiya, {} footprints, {} skipped",
                dirs[0].display(),
                report.counts.tiles,
                report.counts.machiya,
                report.counts.footprints,
                report.counts.skipped
            );
            Ok(())
        }
        Command::Init { dir, output, force } => {
            if !dir.is_dir() {
                anyhow::bail!("{} is not a directory", dir.display());
            }
            let text = edo_city::init::params_text(&dir);
            if output.as_os_str() == "-" {
                print!("{text}");
            } else {
                if output.exists() && !force {
                    anyhow::bail!(
                        "{} exists; give --force to replace it, or -o another file",
                        output.display()
                    );
                }
                edo_city::output::atomic::write_atomic(&output, text.as_bytes())
                    .with_context(|| format!("cannot write {}", output.display()))?;
                let word =
                    |p: &std::path::Path| edo_city::init::shell_word(&p.display().to_string());
                say!(
                    "wrote {}: check the guesses, then run\n  edo-city build {} --params {} --out out\nand look at out/plan.png",
                    output.display(),
                    word(&dir),
                    word(&output)
                );
            }
            Ok(())
        }
        Command::Params => {
            print!("{}", edo_city::params::DEFAULT_TOML);
            Ok(())
        }
        Command::Template {
            name,
            width,
            depth,
            output,
            params,
            templates,
            set,
        } => template_command(name, width, depth, &output, params, templates, &set),
    }
}

/// Parses `I/N` for `--shard`.
fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("`{s}`: give the shard as I/N, e.g. 2/8"))?;
    let (i, n): (usize, usize) = (
        i.trim()
            .parse()
            .map_err(|_| format!("`{i}` is not a number"))?,
        n.trim()
            .parse()
            .map_err(|_| format!("`{n}` is not a number"))?,
    );
    let max = edo_city::build::MAX_SHARDS;
    if n == 0 || i == 0 || i > n || n > max {
        return Err(format!("`{s}`: need 1 <= I <= N <= {max}"));
    }
    Ok((i, n))
}

/// `edo-city template`: list the templates, or build one alone.
fn template_command(
    name: Option<String>,
    width: f64,
    depth: f64,
    output: &Path,
    params: Option<PathBuf>,
    templates: Option<PathBuf>,
    set: &[String],
) -> anyhow::Result<()> {
    let params = match &params {
        Some(p) => Params::from_path(p)?,
        None => Params::default(),
    };
    let catalog = edo_city::build::load_catalog(&params, templates.as_deref())?;
    let Some(name) = name else {
        say!("template\tkind\tkanji\tfile\tparameters");
        for t in catalog.templates.values() {
            let kind = if t.is_abstract {
                format!("{} (abstract)", t.kind.name())
            } else {
                t.kind.name().to_string()
            };
            say!(
                "{}\t{kind}\t{}\t{}\t{}",
                t.name,
                t.kanji,
                t.file,
                t.param_names().join(" ")
            );
        }
        return Ok(());
    };
    let t = match catalog
        .get(&name)
        .or_else(|| catalog.resolve(&name).and_then(|n| catalog.get(n)))
    {
        Some(t) => t,
        None => anyhow::bail!(
            "no template `{name}` (templates: {})",
            catalog
                .templates
                .keys()
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut sets = Vec::new();
    for s in set {
        let (k, v) = s
            .split_once('=')
            .ok_or_else(|| anyhow::anyhow!("--set {s}: write PARAM=VALUE"))?;
        let v: f64 = v
            .trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("--set {s}: `{v}` is not a number"))?;
        sets.push((k.trim().to_string(), v));
    }
    let alone = edo_city::author::build_alone(&catalog, t, width, depth, &params, &sets)
        .map_err(anyhow::Error::msg)?;
    let n =
        edo_city::author::write(&alone, output, &params.textures).map_err(anyhow::Error::msg)?;
    say!(
        "{} ({}) on a {width} x {depth} m lot: {} vertices, {} faces, parts {}",
        t.name,
        t.kind.name(),
        alone.mesh.positions.len(),
        alone.mesh.faces.len(),
        alone.parts.join(", ")
    );
    match alone.declared_height {
        Some(h) => say!("height {:.3} m (declared {h:.3} m)", alone.top),
        None => say!("height {:.3} m", alone.top),
    }
    say!(
        "{}; wrote {} with its .mtl and {n} textures in {}",
        if edo_city::author::is_closed(&alone.mesh) {
            "closed shell"
        } else {
            "open surfaces (billboards or a fence panel)"
        },
        output.display(),
        output
            .parent()
            .unwrap_or(Path::new("."))
            .join("textures")
            .display()
    );
    Ok(())
}
