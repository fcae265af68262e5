//! The `edo-city` command line: parses flags into validated options and calls the library.
//! Everything the user sees (progress bars, the summary, error context) lives here.

#![forbid(unsafe_code)]

use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};

/// `println!` that returns the error instead of panicking: a reader that stops early
/// (`edo-city tiles out | head`) closes the pipe, and that is no failure of ours.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*)?
    }};
}

/// `eprintln!` that never panics: with stderr closed (`2>&1 | head -c 10`) a message that
/// cannot be shown is dropped, and the exit code still tells what happened.
macro_rules! tell {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod cli;

/// mimalloc instead of the system allocator: a build makes and drops millions of small
/// vectors (vertices, faces, names), and glibc's malloc/free were a sixth of its time.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use cli::args::*;
use cli::commands::*;
use cli::garden::*;
use cli::plants::*;
use cli::serve::*;
use cli::Problems;

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
    ///
    /// Writes into --out only: tiles/ (OBJ + MTL, GLB, textures, shared models, the levels of
    /// detail), crowds/, species/, tileset.json, links.json, plan.png, plan.gpkg, report.json
    /// and manifest.json (last), each file through a temporary name renamed when complete.
    /// Outside it only the analysis cache (~/.cache/edo-city, or $EDO_CITY_CACHE). Never
    /// into the input.
    Build(BuildArgs),
    /// Compare two builds (two hypotheses): parameters, counts per type and district, tiles.
    ///
    /// Writes nothing but what --plan (a PNG) and --gpkg (a GeoPackage) name: never inside
    /// either build, and never over a file of another kind.
    Compare(CompareArgs),
    /// Draw the plan of a build: lots by type, streets, frontages, tiles, legend, scale.
    ///
    /// Writes the one PNG -o names: never inside the build or the input, never over a file
    /// that is not a PNG.
    Plan(PlanArgs),
    /// Check an input directory without building: layers, counts, CRS, encodings and every
    /// problem. Exit 0 when all would be built, 1 when something would be skipped or warned
    /// about, 2 on an error.
    ///
    /// Writes nothing but the GeoPackage --gpkg names: never inside the input or templates
    /// directory, never over a file that is not a GeoPackage.
    Check(CheckArgs),
    /// List the tiles a build would write, with feature counts and bounds (for scripts).
    ///
    /// Writes nothing: prints to standard output.
    Tiles(TilesArgs),
    /// Merge shard outputs (`build --shard I/N`) into the first directory: copies the other
    /// directories' tiles, writes manifest.json and report.json for the whole city.
    ///
    /// Writes into the first directory only: the other shards' tiles and shared models, each
    /// checked against its shard's manifest (a plain path inside that shard, its size and
    /// sha256) and copied through a temporary name, renamed once all are in; then
    /// tileset.json, plan.png, plan.gpkg, report.json and manifest.json. Removes the shard
    /// manifests and reports.
    Merge(MergeArgs),
    /// Write a Kyoto-like shapefile directory of synthetic lots, blocks and streets.
    ///
    /// Writes the town's shapefiles (.shp, .shx, .dbf, .cpg, .prj) into the directory given,
    /// which must be new or empty unless --force.
    Synth(SynthArgs),
    /// Print the default parameter file (documented key by key).
    ///
    /// Writes nothing: prints to standard output.
    Params,
    /// Build one template alone on a rectangular lot and write it as OBJ + MTL + textures,
    /// for authoring templates; without a name, list the templates.
    ///
    /// Writes the OBJ -o names, its MTL and a textures/ directory beside it.
    Template(TemplateArgs),
    /// Inspect a directory of shapefiles and write a starting parameter file with guesses.
    ///
    /// Writes the parameter file -o names (or standard output with `-`), never over an
    /// existing file without --force.
    Init(InitArgs),
    /// Simulate the crowd model alone (boids of Oyama et al., seed 004) and write its order
    /// parameters lambda1-3 per step: the seed's demo.
    ///
    /// Writes only the files --csv, --plot and --svg name (the series to standard output
    /// without --csv).
    Boids(BoidsArgs),
    /// Expand an L-system and read it with the 3D turtle (seed 003): print the string, write
    /// the turtle's mesh or an SVG; `--preset` gives the seed's examples.
    ///
    /// Writes only what -o (OBJ + MTL + textures/ beside it) and --svg name.
    Lsystem(LsystemArgs),
    /// Grow one tree of a species and write a level of detail (OBJ) and its numbers (JSON);
    /// without `--species`, list the species.
    ///
    /// Writes only what -o (OBJ + MTL + textures/ beside it), --report and --png name.
    Tree(TreeArgs),
    /// Design a dry rock garden (karesansui) by the GA of seed 000 with the Ryoanji rules;
    /// `--interactive` shows each generation's best and breeds from your picks.
    ///
    /// Writes only what -o (OBJ + MTL + textures/ beside it), --report, --png and, with
    /// --interactive, --sheet name.
    Garden(GardenArgs),
    /// Serve the web viewer and one or more builds (hypotheses) on 127.0.0.1.
    ///
    /// Writes nothing but the designs file --designs names, and that only at a request of
    /// this server's own page (same host and origin, JSON, the page's token). Answers no
    /// request that names another host.
    Serve(ServeArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if closed_pipe(&e) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<Problems>().is_some() => {
            tell!("{e}");
            ExitCode::from(1)
        }
        Err(e) => {
            tell!("error: {e:#}");
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
        Command::Build(args) => build_command(args),
        Command::Synth(args) => synth_command(args),
        Command::Tiles(args) => tiles_command(args),
        Command::Check(args) => check_command(args),
        Command::Compare(args) => compare_command(args),
        Command::Plan(args) => plan_command(args),
        Command::Merge(args) => merge_command(args),
        Command::Boids(args) => boids_command(args),
        Command::Lsystem(args) => lsystem_command(args),
        Command::Tree(args) => tree_command(args),
        Command::Garden(args) => garden_command(args),
        Command::Serve(args) => serve_command(args),
        Command::Init(args) => init_command(args),
        Command::Params => params_command(),
        Command::Template(args) => template_command(args),
    }
}
