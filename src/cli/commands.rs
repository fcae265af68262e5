//! One function a command: each takes its parsed flags, resolves its parameters once, calls
//! the library and prints what the user reads.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use super::args::*;
use super::progress::Bars;
use super::summary::{print_check, print_summary};
use super::Problems;
use edo_city::build::{build, shards, BuildOptions, NoProgress, Selection};
use edo_city::params::Params;

/// `edo-city build`.
pub fn build_command(args: BuildArgs) -> Result<()> {
    let BuildArgs {
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
        format,
    } = args;
    let mut params = load_params(params.as_deref())?;
    if let Some(formats) = format {
        edo_city::params::output::check_formats(&formats)
            .map_err(|e| anyhow::anyhow!("--format: {e}"))?;
        params.output.formats = formats;
    }
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
        cache: edo_city::build::cache::dir_from(|k| std::env::var_os(k)),
        reuse: None,
    };
    let bars = Bars::new(quiet || !std::io::stderr().is_terminal());
    let outcome = build(&opts, &bars).context("the build did not finish")?;
    if !quiet {
        print_summary(&opts, &outcome)?;
    }
    if timings {
        let t = &outcome.timings;
        let read_and_analyse = match outcome.cache {
            edo_city::build::cache::CacheUse::Reused => format!(
                "read and analyse {:.3} s from the cache",
                t.analyse.as_secs_f64()
            ),
            _ => format!(
                "read {:.3} s, analyse {:.3} s (kura plots and R-tree {:.3} s, people and trees {:.3} s)",
                t.read.as_secs_f64(),
                t.analyse.as_secs_f64(),
                t.kura.as_secs_f64(),
                t.billboards.as_secs_f64()
            ),
        };
        tell!(
            "timings: {read_and_analyse}, generate+write {:.3} s (cpu: generate {:.3} s, format+write {:.3} s), plan {:.3} s, plan.gpkg {:.3} s beside the tiles + {:.3} s after, total {:.3} s",
            t.generate_and_write.as_secs_f64(),
            t.generate_cpu.as_secs_f64(),
            t.write_cpu.as_secs_f64(),
            t.plan.as_secs_f64(),
            t.gpkg[0].as_secs_f64(),
            t.gpkg[1].as_secs_f64(),
            t.total.as_secs_f64()
        );
        let stages: Vec<String> = (t.stages.iter())
            .map(|s| {
                format!(
                    "{} {:.3} s (cpu/wall {:.2})",
                    s.name,
                    s.wall.as_secs_f64(),
                    s.busy()
                )
            })
            .collect();
        tell!("timings of the stages: {}", stages.join(", "));
        // "people and trees" above is every step after the fences; here each of them.
        let steps: Vec<String> = t
            .steps
            .iter()
            .map(|(name, d)| format!("{name} {:.3} s", d.as_secs_f64()))
            .collect();
        if !steps.is_empty() {
            tell!("timings of the steps after fences: {}", steps.join(", "));
        }
    }
    Ok(())
}

/// `edo-city synth`.
pub fn synth_command(args: SynthArgs) -> Result<()> {
    let SynthArgs {
        dir,
        lots,
        seed,
        profile,
        force,
    } = args;
    let profile = edo_city::synth::Profile::parse(&profile)?;
    let s = edo_city::synth::write_town(&dir, lots, seed, profile, force)?;
    say!(
        "wrote {}: {} lots ({} machiya, {} samurai estates), {} blocks, {} streets{}",
        dir.display(),
        s.lots,
        s.machiya,
        s.estates,
        s.blocks,
        s.streets,
        if s.repeated_ids > 0 {
            format!(
                "; {} records repeat the id before them (the build lists them as skipped)",
                s.repeated_ids
            )
        } else {
            String::new()
        }
    );
    Ok(())
}

/// `edo-city tiles`.
pub fn tiles_command(args: TilesArgs) -> Result<()> {
    let TilesArgs {
        input,
        params,
        json,
    } = args;
    let params = load_params(params.as_deref())?;
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

/// `edo-city check`.
pub fn check_command(args: CheckArgs) -> Result<()> {
    let CheckArgs {
        input,
        params,
        templates,
        json,
        gpkg,
    } = args;
    let params = load_params(params.as_deref())?;
    let r = edo_city::build::check(&input, &params, templates.as_deref(), gpkg.as_deref())?;
    if json {
        say!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print_check(&r)?;
        if let Some(path) = &gpkg {
            say!(
                "wrote {} ({} problem(s) at their places, {} warning(s)): open it in QGIS",
                path.display(),
                r.skipped.len(),
                r.warnings.len()
            );
        }
    }
    let problems = r.counts.skipped + r.warnings.len();
    if problems > 0 {
        return Err(Problems(problems).into());
    }
    Ok(())
}

/// `edo-city compare`.
pub fn compare_command(args: CompareArgs) -> Result<()> {
    let CompareArgs {
        a,
        b,
        json,
        plan,
        gpkg,
    } = args;
    let c = edo_city::compare::compare(&a, &b)?;
    if json {
        say!("{}", serde_json::to_string_pretty(&c)?);
    } else {
        print!("{}", edo_city::compare::render(&c));
    }
    if let Some(path) = plan {
        let reads = [(a.as_path(), "build A"), (b.as_path(), "build B")];
        edo_city::output::target::check(&path, edo_city::output::target::Kind::Png, &reads)?;
        let png = edo_city::compare::difference_map(&c, &a)?;
        edo_city::output::atomic::write_atomic(&path, &png)
            .with_context(|| format!("cannot write {}", path.display()))?;
        if !json {
            say!("wrote {}", path.display());
        }
    }
    if let Some(path) = gpkg {
        let lots = edo_city::compare::write_gpkg(&c, &a, &b, &path)?;
        if !json {
            say!(
                "wrote {}: {lots} lots and {} tiles differ",
                path.display(),
                c.tiles.differ.len() + c.tiles.only_a.len() + c.tiles.only_b.len()
            );
        }
    }
    Ok(())
}

/// `edo-city plan`.
pub fn plan_command(args: PlanArgs) -> Result<()> {
    let PlanArgs {
        out,
        output,
        tile,
        input,
        templates,
        params,
    } = args;
    let mut reads = vec![(out.as_path(), "the build")];
    reads.extend(input.as_deref().map(|i| (i, "the input directory")));
    edo_city::output::target::check(&output, edo_city::output::target::Kind::Png, &reads)?;
    let params = params.map(|p| load_params(Some(&p))).transpose()?;
    let png = edo_city::build::draw_plan_of(
        &out,
        tile.as_deref(),
        input.as_deref(),
        templates.as_deref(),
        params.as_ref(),
    )?;
    edo_city::output::atomic::write_atomic(&output, &png)
        .with_context(|| format!("cannot write {}", output.display()))?;
    say!("wrote {}", output.display());
    Ok(())
}

/// `edo-city merge`.
pub fn merge_command(args: MergeArgs) -> Result<()> {
    let MergeArgs { dirs, no_plan } = args;
    let report = edo_city::build::merge::merge(&dirs, !no_plan)?;
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

/// `edo-city init`.
pub fn init_command(args: InitArgs) -> Result<()> {
    let InitArgs { dir, output, force } = args;
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
        let word = |p: &std::path::Path| edo_city::init::shell_word(&p.display().to_string());
        say!(
            "wrote {}: check the guesses, then run\n  edo-city build {} --params {} --out out\nand look at out/plan.png",
            output.display(),
            word(&dir),
            word(&output)
        );
    }
    Ok(())
}

/// `edo-city params`.
pub fn params_command() -> Result<()> {
    print!("{}", edo_city::params::DEFAULT_TOML);
    Ok(())
}

/// `edo-city template`.
pub fn template_command(args: TemplateArgs) -> Result<()> {
    let TemplateArgs {
        name,
        width,
        depth,
        output,
        params,
        templates,
        set,
    } = args;
    template_alone(name, width, depth, &output, params, templates, &set)
}

/// The parameter file given with `--params`, resolved and checked (every key, range and
/// `extends`), else the defaults: the one place a command gets its parameters.
fn load_params(path: Option<&Path>) -> Result<Params> {
    Ok(match path {
        Some(p) => Params::from_path(p)?,
        None => Params::default(),
    })
}

/// `edo-city template`: list the templates, or build one alone.
fn template_alone(
    name: Option<String>,
    width: Option<f64>,
    depth: Option<f64>,
    output: &Path,
    params: Option<PathBuf>,
    templates: Option<PathBuf>,
    set: &[String],
) -> anyhow::Result<()> {
    let params = load_params(params.as_deref())?;
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
    // A hall is tried on the plot it asks for; every other template on a 3-ken town lot.
    let plot = |key: &str, fallback: f64| t.param(&[], key).unwrap_or(fallback);
    let width = width.unwrap_or_else(|| plot("plot_width", 5.454));
    let depth = depth.unwrap_or_else(|| plot("plot_depth", 20.0));
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
    let alone = edo_city::author::build_alone(&catalog, t, width, depth, &params, &sets)?;
    let n = edo_city::author::write(&alone, output, &params.textures)?;
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

/// The most agents and steps `boids` simulates (a million agents would take hours a step in
/// the exact order parameters' sample; the city runs far fewer per street).
const MAX_BOIDS: usize = 100_000;
const MAX_BOID_STEPS: usize = 1_000_000;

/// `edo-city boids`: the seed's demo of Oyama et al., its order parameters per step.
pub fn boids_command(args: BoidsArgs) -> Result<()> {
    use edo_city::growers::boids::{BoidParams, Flock, Lambdas};
    if args.agents > MAX_BOIDS || args.steps > MAX_BOID_STEPS {
        anyhow::bail!("--agents must be at most {MAX_BOIDS} and --steps at most {MAX_BOID_STEPS}");
    }
    let space_ok = |v: f64| v.is_finite() && v > 0.0 && v <= 1e7;
    if !(space_ok(args.width) && space_ok(args.height)) {
        anyhow::bail!("--width and --height must be positive numbers up to 1e7");
    }
    let params = BoidParams {
        r0: args.r0,
        r1: args.r1,
        r2: args.r2,
        ..BoidParams::seed()
    };
    if let Some(why) = params.problem() {
        anyhow::bail!("{why} (--r0, --r1, --r2)");
    }
    // Each system's lambdas at step 0 (the random start) and after every step.
    let run = |rules: bool| -> (Vec<Lambdas>, Flock) {
        let mut f = Flock::random(
            args.agents,
            args.width,
            args.height,
            params,
            rules,
            args.seed,
        );
        let mut out = Vec::with_capacity(args.steps + 1);
        out.push(f.lambdas());
        for _ in 0..args.steps {
            f.step();
            out.push(f.lambdas());
        }
        (out, f)
    };
    let (series, flock) = run(!args.no_rules);
    let mut csv = String::from("step,lambda1,lambda2,lambda3\n");
    for (i, l) in series.iter().enumerate() {
        csv.push_str(&format!(
            "{i},{:.6},{:.6},{:.6}\n",
            l.lambda1, l.lambda2, l.lambda3
        ));
    }
    match &args.csv {
        Some(path) => edo_city::output::atomic::write_atomic(path, csv.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?,
        None => print!("{csv}"),
    }
    if let Some(path) = &args.plot {
        // Both systems from the same seed, as fig. 8 shows them.
        let (boid_series, random_series) = match args.no_rules {
            false => (series.clone(), run(false).0),
            true => (run(true).0, series.clone()),
        };
        let pick = |s: &[Lambdas], k: usize| -> Vec<f64> {
            s.iter()
                .map(|l| [l.lambda1, l.lambda2, l.lambda3][k])
                .collect()
        };
        let colours = [[200, 60, 40], [40, 110, 200], [40, 150, 70]];
        let values: Vec<(String, [u8; 3], bool, Vec<f64>)> = (0..3)
            .flat_map(|k| {
                [
                    (
                        format!("B-lambda{}", k + 1),
                        colours[k],
                        false,
                        pick(&boid_series, k),
                    ),
                    (
                        format!("R-lambda{}", k + 1),
                        colours[k],
                        true,
                        pick(&random_series, k),
                    ),
                ]
            })
            .collect();
        let lines: Vec<edo_city::output::chart::Series> = values
            .iter()
            .map(|(label, rgb, dashed, v)| edo_city::output::chart::Series {
                label,
                rgb: *rgb,
                dashed: *dashed,
                values: v,
            })
            .collect();
        let title = format!(
            "lambda1-3, {} agents, seed {} (B: boids, R: random)",
            args.agents, args.seed
        );
        let png = edo_city::output::chart::line_chart(&title, &lines, -1.0, 1.0)
            .context("cannot draw the plot")?;
        edo_city::output::atomic::write_atomic(path, &png)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.svg {
        let svg = edo_city::output::chart::flock_svg(
            &flock.boids,
            args.width,
            args.height,
            args.r0,
            args.r1,
        );
        edo_city::output::atomic::write_atomic(path, svg.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if args.csv.is_some() {
        let tail = &series[series.len().saturating_sub(100)..];
        let mean = |k: usize| {
            tail.iter()
                .map(|l| [l.lambda1, l.lambda2, l.lambda3][k])
                .sum::<f64>()
                / tail.len().max(1) as f64
        };
        say!(
            "{} agents, {} steps ({}): mean over the last {} steps lambda1 {:.3}, lambda2 {:.3}, lambda3 {:.3}",
            args.agents,
            args.steps,
            if args.no_rules { "random system" } else { "boids" },
            tail.len(),
            mean(0),
            mean(1),
            mean(2)
        );
    }
    Ok(())
}
