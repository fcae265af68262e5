//! `edo-city lsystem` and `edo-city tree`: the growers alone, for the seed's examples and for
//! authoring species files.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde_json::json;

use edo_city::generate::mesh::{Frame, Mesh};
use edo_city::generate::tree::{self, Lod, Look, Placement};
use edo_city::growers::lsystem::{presets, turtle, LSystem, TurtleParams, DEFAULT_MAX_SYMBOLS};
use edo_city::output::atomic::write_atomic;
use edo_city::templates::species::SEASONS;
use edo_city::templates::Catalog;

/// The flags of `edo-city lsystem`.
#[derive(Args)]
pub struct LsystemArgs {
    /// One of the seed's examples: fffa, koch, sierpinski, phyllotaxis (the flags below
    /// replace its values).
    #[arg(long)]
    pub preset: Option<String>,
    /// The axiom (the seed's "premise").
    #[arg(long)]
    pub axiom: Option<String>,
    /// A rule `A=successor`, `A:weight=successor` or `A(l)=F(l*0.8)`; repeat for more.
    #[arg(long = "rule")]
    pub rules: Vec<String>,
    /// The turning angle, degrees.
    #[arg(long)]
    pub angle: Option<f64>,
    /// Generations (parallel rewrites).
    #[arg(long)]
    pub generations: Option<usize>,
    /// Length of `F`, metres.
    #[arg(long, default_value_t = 1.0)]
    pub step: f64,
    /// Starting branch width, metres (tubes of the OBJ).
    #[arg(long, default_value_t = 0.1)]
    pub width: f64,
    /// Seed of the stochastic rules' draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The largest word allowed.
    #[arg(long, default_value_t = DEFAULT_MAX_SYMBOLS)]
    pub max_symbols: usize,
    /// Print the expanded string on one line.
    #[arg(long)]
    pub string: bool,
    /// Write the turtle's mesh (tubes for `F`) as OBJ + MTL + textures.
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Draw the turtle's lines seen from the south (for 2D systems, the figure) as SVG.
    #[arg(long)]
    pub svg: Option<PathBuf>,
}

/// `edo-city lsystem`.
pub fn lsystem_command(args: LsystemArgs) -> Result<()> {
    let preset = match &args.preset {
        Some(name) => Some(presets::preset(name).with_context(|| {
            format!(
                "--preset {name}: no such example (there are {})",
                presets::PRESETS
                    .iter()
                    .map(|p| p.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })?),
        None => None,
    };
    let axiom = match (&args.axiom, preset) {
        (Some(a), _) => a.clone(),
        (None, Some(p)) => p.axiom.to_string(),
        (None, None) => bail!("give --axiom (with --rule and --angle) or --preset"),
    };
    let rules: Vec<String> = match (args.rules.is_empty(), preset) {
        (false, _) | (true, None) => args.rules.clone(),
        (true, Some(p)) => p.rules.iter().map(|r| r.to_string()).collect(),
    };
    let angle = args.angle.or(preset.map(|p| p.angle)).unwrap_or(90.0);
    let generations = args
        .generations
        .or(preset.map(|p| p.generations))
        .unwrap_or(1);
    for (flag, v, hi) in [
        ("--angle", angle, 360.0),
        ("--step", args.step, 1000.0),
        ("--width", args.width, 100.0),
    ] {
        if !(v.is_finite() && v.abs() <= hi) {
            bail!("{flag} must be a number of at most {hi} in size, got {v}");
        }
    }
    let system = LSystem::parse(&axiom, &rules, generations, args.max_symbols)?;
    let mut rng = edo_city::rng::feature_rng(args.seed, "lsystem", &axiom);
    let word = system.expand(&mut rng)?;
    let params = TurtleParams {
        step: args.step,
        angle,
        width: args.width,
        ..TurtleParams::default()
    };
    let sk = turtle::interpret(&word, &params);
    if args.string {
        say!("{}", word.to_text());
    }
    if let Some(path) = &args.svg {
        let title = format!("{axiom} {} ({generations} generations)", rules.join(" "));
        let svg = edo_city::output::sketch::skeleton_svg(&sk, 800.0, &title);
        write_atomic(path, svg.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.output {
        let spec = edo_city::templates::species::MeshSpec {
            sides: 6,
            twig: 0.0,
            bark: edo_city::materials::id("bark"),
            leaf: edo_city::templates::species::LeafKind::None,
            leaf_size: 0.0,
            per_tip: 0,
            leaf_nodes: 1,
        };
        let look = Look {
            bark: spec.bark,
            leaf: Some(edo_city::materials::id("leaf_broad")),
            leaf_size: args.step,
            billboard: edo_city::materials::id("tree_01"),
        };
        let mut mesh = Mesh::new("lsystem".into());
        tree::mesh_tree(&sk, &spec, look, Lod::Full, origin(), frame(), &mut mesh);
        edo_city::output::write_model(path, &[mesh.finish()], "")?;
    }
    if !args.string {
        say!(
            "{} symbols after {generations} generations: {} segments, {} tips, {} dots, {} leaf polygons",
            word.modules.len(),
            sk.edges(),
            sk.tips().len(),
            sk.dots.len(),
            sk.polygons.len()
        );
    }
    Ok(())
}

/// The flags of `edo-city tree`.
#[derive(Args)]
pub struct TreeArgs {
    /// The species (a file of templates/trees/ or of `--templates`/trees/); without it, list
    /// the species.
    #[arg(long)]
    pub species: Option<String>,
    /// Seed of the tree's growth (the city uses the build's seed and the tree's id).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Level of detail written to `-o`: 0 full, 1 reduced, 2 crossed billboards.
    #[arg(long, default_value_t = 0)]
    pub lod: u8,
    /// Height, metres (default: the middle of the species' range).
    #[arg(long)]
    pub height: Option<f64>,
    /// Season of the leaves: spring, summer, autumn, winter.
    #[arg(long, default_value = "summer")]
    pub season: String,
    /// A template directory whose `trees/` holds more species.
    #[arg(long)]
    pub templates: Option<PathBuf>,
    /// Write the tree as OBJ + MTL + textures.
    #[arg(short = 'o', long)]
    pub output: Option<PathBuf>,
    /// Write its numbers as JSON: triangles, vertices, height, crown width, bytes per LOD.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Draw the chosen LOD seen from the south on a pale sky (PNG, 512 pixels tall); without
    /// `--species`, a contact sheet of every species.
    #[arg(long)]
    pub png: Option<PathBuf>,
}

fn frame() -> Frame {
    Frame { origin: [0.0, 0.0] }
}

fn origin() -> Placement {
    Placement {
        at: geo_types::Coord { x: 0.0, y: 0.0 },
        ground: 0.0,
        rotation: 0.0,
    }
}

/// `edo-city tree`.
pub fn tree_command(args: TreeArgs) -> Result<()> {
    let catalog = Catalog::load(args.templates.as_deref())?;
    let Some(name) = &args.species else {
        if let Some(path) = &args.png {
            return species_sheet(&catalog, &args, path);
        }
        for s in catalog.species.values() {
            say!(
                "{:<16} {:<4} {:<13} {:>4.1}-{:<4.1} m  {}",
                s.name,
                s.kanji,
                s.method,
                s.height[0],
                s.height[1],
                s.description
            );
        }
        return Ok(());
    };
    let species = catalog.species.get(name).with_context(|| {
        format!(
            "--species {name}: no such species (there are {})",
            catalog
                .species
                .keys()
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        )
    })?;
    if !SEASONS.contains(&args.season.as_str()) {
        bail!("--season must be one of {}", SEASONS.join(", "));
    }
    let lod = Lod::from_number(args.lod).context("--lod must be 0, 1 or 2")?;
    let height = args.height.unwrap_or(species.nominal_height());
    if !(height.is_finite() && height > 0.0 && height <= 100.0) {
        bail!("--height must be from 0 to 100 metres, got {height}");
    }
    let mut rng = edo_city::rng::feature_rng(args.seed, "tree", &species.name);
    let grown = species.grow(height, &mut rng).map_err(anyhow::Error::msg)?;
    let look = Look::of(species, height, &args.season);
    let meshes: Vec<Mesh> = [Lod::Full, Lod::Reduced, Lod::Billboard]
        .iter()
        .map(|&l| {
            let mut m = Mesh::new(format!("{}_lod{}", species.name, l.number()));
            tree::mesh_tree(
                &grown.skeleton,
                &species.mesh,
                look,
                l,
                origin(),
                frame(),
                &mut m,
            );
            m.finish()
        })
        .collect();
    let chosen = &meshes[lod.number() as usize];
    if let Some(path) = &args.output {
        edo_city::output::write_model(path, std::slice::from_ref(chosen), "")?;
    }
    if let Some(path) = &args.png {
        let (r, top) = tree::extent(&grown.skeleton, species.mesh.leaf_size);
        let img = side_view(chosen, r, top, 512);
        let png = edo_city::output::render::on_sky(&img);
        write_atomic(path, &png).with_context(|| format!("cannot write {}", path.display()))?;
    }
    let (radial, top) = tree::extent(&grown.skeleton, look.leaf.map_or(0.0, |_| look.leaf_size));
    let lods: Vec<serde_json::Value> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| {
            json!({
                "lod": k,
                "triangles": tree::triangles(m),
                "vertices": m.positions.len(),
                "bytes": edo_city::output::obj_bytes(std::slice::from_ref(m)),
            })
        })
        .collect();
    let mut report = json!({
        "species": species.name,
        "method": species.method,
        "seed": args.seed,
        "season": args.season,
        "height": top,
        "crown_width": 2.0 * radial,
        "nodes": grown.skeleton.nodes.len(),
        "tips": grown.skeleton.tips().len(),
        "lods": lods,
    });
    if let (Some(obj), Some(extra)) = (report.as_object_mut(), grown.report.as_object()) {
        for (k, v) in extra {
            obj.insert(k.clone(), v.clone());
        }
    }
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report)? + "\n";
        write_atomic(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    say!(
        "{} ({}) seed {}: {:.1} m tall, crown {:.1} m; LOD0 {} triangles, LOD1 {}, LOD2 {}",
        species.name,
        species.method,
        args.seed,
        top,
        2.0 * radial,
        tree::triangles(&meshes[0]),
        tree::triangles(&meshes[1]),
        tree::triangles(&meshes[2])
    );
    Ok(())
}

/// The side view of `lod` of one tree, framed square around it.
fn side_view(mesh: &Mesh, r: f64, top: f64, px: u32) -> image::RgbaImage {
    let half = r.max(top / 2.0) * 1.05;
    let window = [-half, half, -0.02 * top, 2.0 * half - 0.02 * top];
    edo_city::output::render::render(
        std::slice::from_ref(mesh),
        edo_city::output::render::View::South,
        window,
        (px, px),
        &edo_city::output::render::shipped_texture,
    )
}

/// `edo-city tree --png sheet.png`: every species at its nominal height, five to a row.
fn species_sheet(catalog: &Catalog, args: &TreeArgs, path: &std::path::Path) -> Result<()> {
    let lod = Lod::from_number(args.lod).context("--lod must be 0, 1 or 2")?;
    if !SEASONS.contains(&args.season.as_str()) {
        bail!("--season must be one of {}", SEASONS.join(", "));
    }
    let mut cells = Vec::new();
    for s in catalog.species.values() {
        let h = s.nominal_height();
        let mut rng = edo_city::rng::feature_rng(args.seed, "tree", &s.name);
        let grown = s.grow_in_city(h, &mut rng).map_err(anyhow::Error::msg)?;
        let look = Look::of(s, h, &args.season);
        let mut mesh = Mesh::new(s.name.clone());
        tree::mesh_tree(
            &grown.skeleton,
            &s.mesh,
            look,
            lod,
            origin(),
            frame(),
            &mut mesh,
        );
        let (r, top) = tree::extent(&grown.skeleton, s.mesh.leaf_size);
        cells.push((s.name.clone(), side_view(&mesh, r, top, 320)));
    }
    let png = edo_city::output::render::sheet(&cells, 5).context("cannot draw the sheet")?;
    write_atomic(path, &png).with_context(|| format!("cannot write {}", path.display()))?;
    say!("{} species drawn into {}", cells.len(), path.display());
    Ok(())
}
