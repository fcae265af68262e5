//! The flags of each command, as clap parses them.

use std::path::PathBuf;

use clap::Args;

/// The flags of `edo-city build`.
#[derive(Args)]
pub struct BuildArgs {
    /// Input directory (lots.shp, blocks.shp and/or streets.shp, lots.csv/.xlsx).
    pub input: PathBuf,
    /// Output directory; tiles go to <out>/tiles, textures to <out>/textures.
    #[arg(short, long, default_value = "out")]
    pub out: PathBuf,
    /// Parameter file (TOML); keys it leaves out keep the defaults of params/default.toml.
    #[arg(short, long)]
    pub params: Option<PathBuf>,
    /// Directory of template files (*.toml), added to the shipped ones; a file of a shipped
    /// template's name replaces that template.
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// Worker threads (0 = one per core). The output does not depend on it.
    #[arg(short = 'j', long, default_value_t = 0)]
    pub threads: usize,
    /// No progress bars and no summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the time of each stage, then of each step after the fences (obstacles, halls,
    /// gardens, people and trees, ground).
    #[arg(long)]
    pub timings: bool,
    /// Do not draw <out>/plan.png (lots by type, streets, each house's frontage, tiles).
    #[arg(long)]
    pub no_plan: bool,
    /// Rewrite only these tiles (comma-separated ids) of an earlier full build in --out;
    /// each comes out byte-identical to the same tile of a full build. The full build's
    /// input and analysis are read back from ~/.cache/edo-city when nothing changed
    /// (EDO_CITY_CACHE=off: read and analyse again).
    #[arg(long, value_delimiter = ',', conflicts_with = "shard")]
    pub tiles: Option<Vec<String>>,
    /// Build the I-th of N balanced, disjoint sets of tiles (e.g. 2/8), for a cluster;
    /// `edo-city merge` then writes the whole city's manifest and report.
    #[arg(long, value_parser = parse_shard)]
    pub shard: Option<(usize, usize)>,
    /// Replace an output directory that holds a build of other parameters or input.
    #[arg(long)]
    pub force: bool,
    /// The formats, comma-separated: obj (OBJ + MTL), glb (binary glTF + tileset.json), gpkg
    /// (plan.gpkg, the decisions as GIS layers); wins over `output.formats` of the parameter
    /// file (default: all three).
    #[arg(long, value_delimiter = ',')]
    pub format: Option<Vec<String>>,
}

/// The flags of `edo-city compare`.
#[derive(Args)]
pub struct CompareArgs {
    pub a: PathBuf,
    pub b: PathBuf,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    /// Also draw a map of the tiles that changed.
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// Also write the differences as a GeoPackage for QGIS, from the two builds'
    /// plan.gpkg: layer `lots` (type, kura, house or trees differ, with both values) and
    /// `tiles` (the tiles that differ).
    #[arg(long, value_name = "FILE")]
    pub gpkg: Option<PathBuf>,
}

/// The flags of `edo-city plan`.
#[derive(Args)]
pub struct PlanArgs {
    /// The output directory of a build (its manifest holds the parameters).
    pub out: PathBuf,
    /// The input directory the build read (its published manifest names it, but not where
    /// it is); checked against the build's fingerprint of it.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// The `--templates` directory the build used, if any.
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// The build's parameter file: needed when it named files outside the input by path
    /// (the published manifest leaves those out); checked against the build's.
    #[arg(short, long)]
    pub params: Option<PathBuf>,
    /// Image to write.
    #[arg(short, long, default_value = "plan.png")]
    pub output: PathBuf,
    /// Only this tile, at full resolution.
    #[arg(long)]
    pub tile: Option<String>,
}

/// The flags of `edo-city check`.
#[derive(Args)]
pub struct CheckArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub params: Option<PathBuf>,
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// Machine-readable output (the report a build would write).
    #[arg(long)]
    pub json: bool,
    /// Also write the problems as a GeoPackage for QGIS: layer `problems` (each record a
    /// build would skip, where it is) and `warnings`.
    #[arg(long, value_name = "FILE")]
    pub gpkg: Option<PathBuf>,
}

/// The flags of `edo-city tiles`.
#[derive(Args)]
pub struct TilesArgs {
    pub input: PathBuf,
    #[arg(short, long)]
    pub params: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

/// The flags of `edo-city merge`.
#[derive(Args)]
pub struct MergeArgs {
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Do not draw plan.png (it re-reads the input named in the manifests).
    #[arg(long)]
    pub no_plan: bool,
}

/// The flags of `edo-city synth`.
#[derive(Args)]
pub struct SynthArgs {
    /// Output directory.
    pub dir: PathBuf,
    /// Number of lots.
    #[arg(long, default_value_t = 500)]
    pub lots: usize,
    /// Seed of the town's layout.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The kind of town: `grid` (the first synthetic town: narrow lots, few kura, a few
    /// whole-block estates) or `kyoto` (what real towns hold: quarters of walled samurai
    /// estates with gates and halls, a kura behind about half the houses, repeated ids; what
    /// `make bench` builds).
    #[arg(long, default_value = "grid", value_parser = ["grid", "kyoto"])]
    pub profile: String,
    /// Write into a directory that already holds files (files of the same names are
    /// replaced; the others stay, and a lots.csv there is joined by `build`).
    #[arg(long)]
    pub force: bool,
}

/// The flags of `edo-city template`.
#[derive(Args)]
pub struct TemplateArgs {
    /// Template name (machiya type, kura, fence, tsuiji, gate, tree, person or your own).
    pub name: Option<String>,
    /// Frontage width of the site, metres (the u axis); default 5.454 (3 ken), or a hall's
    /// own `plot_width`.
    #[arg(long)]
    pub width: Option<f64>,
    /// Depth of the site, metres (the v axis); default 20, or a hall's `plot_depth`.
    #[arg(long)]
    pub depth: Option<f64>,
    /// The OBJ to write; its MTL and a textures/ directory go beside it.
    #[arg(short, long, default_value = "template.obj")]
    pub output: PathBuf,
    /// Parameter file: its `[template.<name>]` values and texture set apply.
    #[arg(short, long)]
    pub params: Option<PathBuf>,
    /// Directory of your own template files (added to the shipped ones).
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// Set a template parameter, e.g. `--set eave_height=6.1` (repeatable).
    #[arg(long = "set", value_name = "PARAM=VALUE")]
    pub set: Vec<String>,
}

/// The flags of `edo-city init`.
#[derive(Args)]
pub struct InitArgs {
    /// The data directory.
    pub dir: PathBuf,
    /// Where to write the parameter file ("-" = standard output).
    #[arg(short, long, default_value = "edo-city.toml")]
    pub output: PathBuf,
    /// Replace an existing file.
    #[arg(long)]
    pub force: bool,
}

/// Parses `I/N` for `--shard`.
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
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

/// The flags of `edo-city boids`.
#[derive(Args)]
pub struct BoidsArgs {
    /// Seed of the starting places and every agent's random motion.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Time steps to simulate.
    #[arg(long, default_value_t = 1000)]
    pub steps: usize,
    /// Number of agents (the seed's Table 1: 10).
    #[arg(long, default_value_t = 10)]
    pub agents: usize,
    /// Width of the space.
    #[arg(long, default_value_t = 500.0)]
    pub width: f64,
    /// Height of the space.
    #[arg(long, default_value_t = 300.0)]
    pub height: f64,
    /// Separation zone.
    #[arg(long, default_value_t = 20.0)]
    pub r0: f64,
    /// Alignment zone (also the distance scale of lambda2 and lambda3).
    #[arg(long, default_value_t = 80.0)]
    pub r1: f64,
    /// Cohesion zone; beyond it agents move at random.
    #[arg(long, default_value_t = 100.0)]
    pub r2: f64,
    /// The seed's random system: no rules, every agent moves at random (its R-lambdas).
    #[arg(long)]
    pub no_rules: bool,
    /// Write `step,lambda1,lambda2,lambda3` per step here (else to standard output).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Draw lambda1-3 of the BOID system and of the random system over the steps (fig. 8).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Write the crowd after the last step as SVG.
    #[arg(long)]
    pub svg: Option<PathBuf>,
}
