//! `edo-city garden`: a dry rock garden designed by the GA of seed 000, unattended or with
//! the user choosing favourites each generation (the seed's interactive GA).

use std::io::{BufRead, IsTerminal, Write as _};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;

use edo_city::generate::garden::{self, GardenSite};
use edo_city::generate::mesh::{Frame, Mesh};
use edo_city::growers::garden::ga::{Candidate, GaParams, Population};
use edo_city::growers::garden::{rules, zipf_fit, Settings};
use edo_city::output::atomic::write_atomic;
use edo_city::output::render::{self, View};

/// The flags of `edo-city garden`.
#[derive(Args)]
pub struct GardenArgs {
    /// Seed of the first generation and of every draw of the GA.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Generations after the first.
    #[arg(long, default_value_t = 50)]
    pub generations: usize,
    /// Layouts per generation (the seed's: 100).
    #[arg(long, default_value_t = 100)]
    pub population: usize,
    /// Garden width along the viewing side, metres (the seed's: 25).
    #[arg(long, default_value_t = 25.0)]
    pub width: f64,
    /// Garden depth away from the viewing side, metres (the seed's: 25; Ryoanji's: 10).
    #[arg(long, default_value_t = 25.0)]
    pub depth: f64,
    /// Start from gathered groups rather than the seed's uniform scatter (converges sooner).
    #[arg(long)]
    pub gathered: bool,
    /// Show each generation's best candidates and breed from the numbers you pick.
    #[arg(long)]
    pub interactive: bool,
    /// Candidates shown per generation in interactive mode.
    #[arg(long, default_value_t = 8)]
    pub show: usize,
    /// Where the contact sheet of each generation is written (interactive mode).
    #[arg(long, default_value = "garden-candidates.png")]
    pub sheet: PathBuf,
    /// Write the best garden as OBJ + MTL + textures.
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Write the design's numbers as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Draw the best garden from above and from the viewpoint's side (PNG).
    #[arg(long)]
    pub png: Option<PathBuf>,
}

/// The most generations and the largest population `garden` runs.
const MAX_GENERATIONS: usize = 100_000;
const MAX_POPULATION: usize = 10_000;

/// `edo-city garden`.
pub fn garden_command(args: GardenArgs) -> Result<()> {
    if args.generations > MAX_GENERATIONS
        || args.population == 0
        || args.population > MAX_POPULATION
    {
        bail!("--generations must be at most {MAX_GENERATIONS} and --population from 1 to {MAX_POPULATION}");
    }
    let s = Settings::sized(args.width, args.depth);
    if let Some(p) = s.problem() {
        bail!("{p} (--width, --depth)");
    }
    let p = GaParams {
        population: args.population,
        gathered: args.gathered,
        ..GaParams::default()
    };
    let mut rng = edo_city::rng::feature_rng(args.seed, "garden", "");
    let mut pop = Population::random(&s, &p, &mut rng);
    let mut history = vec![pop.best().fitness];
    let stdin = std::io::stdin();
    let mut lines = stdin.lock().lines();
    let mut attended = args.interactive;
    for generation in 1..=args.generations {
        let picks = if attended {
            match ask(&pop, &s, &args, generation, &mut lines)? {
                Some(p) => p,
                None => {
                    attended = false;
                    Vec::new()
                }
            }
        } else {
            Vec::new()
        };
        pop = if picks.is_empty() {
            pop.next(&s, &p, &mut rng)
        } else {
            pop.next_from(&picks, &s, &p, &mut rng)
        };
        history.push(pop.best().fitness);
    }
    let best = pop.best().clone();
    let meshes = garden_meshes(&best, &s, args.seed);
    if let Some(path) = &args.output {
        edo_city::output::write_model(path, &meshes, "")?;
    }
    if let Some(path) = &args.png {
        let png = views(&meshes, &s, 640).context("cannot draw the garden")?;
        write_atomic(path, &png).with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report(&best, &s, &history, args.seed))? + "\n";
        write_atomic(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    say!(
        "garden {} x {} m, {} stones in {} groups, seed {}: best fitness {:.4} after {} generations ({})",
        s.width,
        s.depth,
        best.layout.stones.len(),
        best.layout.groups().len(),
        args.seed,
        best.fitness,
        args.generations,
        score_line(&best)
    );
    Ok(())
}

fn score_line(c: &Candidate) -> String {
    rules::WEIGHTS
        .iter()
        .zip(c.scores)
        .map(|((name, _), d)| format!("{name} {d:.3}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// One interactive round: the contact sheet and the list, then the user's picks (numbers
/// from 1). `None` when the input ends or says `q`: the rest runs unattended.
fn ask(
    pop: &Population,
    s: &Settings,
    args: &GardenArgs,
    generation: usize,
    lines: &mut impl Iterator<Item = std::io::Result<String>>,
) -> Result<Option<Vec<usize>>> {
    let shown = args.show.clamp(1, 32).min(pop.members.len());
    let cells: Vec<(String, image::RgbaImage)> = pop.members[..shown]
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let meshes = garden_meshes(c, s, args.seed);
            (format!("{}", k + 1), cell(&meshes, s, 256))
        })
        .collect();
    let png = render::sheet(&cells, 4).context("cannot draw the candidates")?;
    write_atomic(&args.sheet, &png)
        .with_context(|| format!("cannot write {}", args.sheet.display()))?;
    let mut err = std::io::stderr();
    writeln!(
        err,
        "generation {generation}: candidates drawn in {} (top and side views)",
        args.sheet.display()
    )?;
    open_viewer(&args.sheet, generation);
    for (k, c) in pop.members[..shown].iter().enumerate() {
        writeln!(
            err,
            "  {:>2}  fitness {:8.4}  {}",
            k + 1,
            c.fitness,
            score_line(c)
        )?;
    }
    write!(
        err,
        "pick favourites (numbers; empty: let the GA choose; q: stop asking): "
    )?;
    err.flush()?;
    let Some(line) = lines.next() else {
        return Ok(None);
    };
    let line = line?;
    if line.trim() == "q" {
        return Ok(None);
    }
    let mut picks = Vec::new();
    for word in line
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|w| !w.is_empty())
    {
        match word.parse::<usize>() {
            Ok(n) if (1..=shown).contains(&n) => picks.push(n - 1),
            _ => writeln!(
                err,
                "  `{word}` is not a candidate from 1 to {shown}; ignored"
            )?,
        }
    }
    Ok(Some(picks))
}

/// Opens the sheet in the machine's viewer once, when a person is at a terminal with a display.
fn open_viewer(sheet: &Path, generation: usize) {
    if generation == 1 && std::io::stdin().is_terminal() && std::env::var_os("DISPLAY").is_some() {
        let _ = std::process::Command::new("xdg-open")
            .arg(sheet)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn();
    }
}

/// A candidate's meshes (with its wall), in garden coordinates as map metres.
fn garden_meshes(c: &Candidate, s: &Settings, seed: u64) -> Vec<Mesh> {
    let site = GardenSite {
        corner: geo_types::Coord { x: 0.0, y: 0.0 },
        angle: 0.0,
        ground: 0.0,
    };
    garden::build(
        &edo_city::model::object::Owner::of(Default::default(), "garden"),
        &c.layout,
        s,
        site,
        true,
        Frame { origin: [0.0, 0.0] },
        &mut |k| edo_city::rng::feature_rng(seed, "garden/stone", &k.to_string()),
    )
}

/// The top view over the side view, `w` pixels wide.
fn cell(meshes: &[Mesh], s: &Settings, w: u32) -> image::RgbaImage {
    let m = 0.05 * s.width;
    let top_h = ((f64::from(w) * (s.depth + 2.0 * m) / (s.width + 2.0 * m)).round() as u32).max(8);
    let top = render::render(
        meshes,
        View::Top,
        [-m, s.width + m, -m, s.depth + m],
        (w, top_h),
        &render::shipped_texture,
    );
    let side_h = (w / 4).max(8);
    let side = render::render(
        meshes,
        View::South,
        [-m, s.width + m, -0.3, (s.width + 2.0 * m) / 4.0 - 0.3],
        (w, side_h),
        &render::shipped_texture,
    );
    let mut out = image::RgbaImage::new(w, top_h + side_h);
    image::imageops::overlay(&mut out, &top, 0, 0);
    image::imageops::overlay(&mut out, &side, 0, i64::from(top_h));
    out
}

fn views(meshes: &[Mesh], s: &Settings, w: u32) -> Option<Vec<u8>> {
    render::sheet(&[("TOP / SIDE".to_string(), cell(meshes, s, w))], 1)
}

fn report(best: &Candidate, s: &Settings, history: &[f64], seed: u64) -> serde_json::Value {
    let (slope, r2) = zipf_fit(&best.layout);
    json!({
        "seed": seed,
        "width": s.width,
        "depth": s.depth,
        "viewpoint": { "x": s.viewpoint[0], "y": s.viewpoint[1] },
        "weights": rules::WEIGHTS.iter().map(|(n, w)| (n.to_string(), json!(w))).collect::<serde_json::Map<_, _>>(),
        "rule_scores": rules::WEIGHTS.iter().zip(best.scores).map(|((n, _), d)| (n.to_string(), json!(d))).collect::<serde_json::Map<_, _>>(),
        "fitness": best.fitness,
        "fitness_history": history,
        "stones": best.layout.stones.iter().map(|st| json!({
            "x": st.x, "y": st.y, "size": st.size, "group": st.group + 1, "role": st.role.name(),
        })).collect::<Vec<_>>(),
        "zipf": { "slope": slope, "r2": r2 },
    })
}
