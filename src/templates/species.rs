//! Tree species (ki no shu 木の種), one TOML file each in `templates/trees/`: how a species
//! grows (an L-system with its turtle, or space colonization), how tall it stands, how its
//! skeleton is meshed (tube sides, what LOD1 prunes, leaves, bark) and its leaves by season.
//! Editable without code; errors carry `file:line:column` as the other templates do.
//!
//! A species knows nothing of lots: the city plants it (`analyse::trees`), the mesher builds
//! its levels of detail from the skeleton it grows (`generate::tree`).

use std::collections::BTreeMap;

use rand_pcg::Pcg64;
use serde::Deserialize;
use toml::Spanned;

use super::file::line_col;
use crate::growers::lsystem::{LSystem, LsError, Place, TurtleParams, DEFAULT_MAX_SYMBOLS};
use crate::growers::skeleton::Skeleton;
use crate::materials;

/// The seasons a build may show (`trees.season`).
pub const SEASONS: [&str; 4] = ["spring", "summer", "autumn", "winter"];

/// A grown tree: its skeleton and what its grower reports (the L-system's symbols; space
/// colonization's stop reason, iterations and groups).
#[derive(Debug, Clone)]
pub struct Grown {
    /// The skeleton, `height` metres tall, standing at the origin.
    pub skeleton: Skeleton,
    /// The grower's numbers, as JSON keys of `edo-city tree --report`.
    pub report: serde_json::Value,
}

/// How a species grows its skeleton.
#[derive(Debug, Clone)]
pub enum Grower {
    /// A bracketed L-system read by the 3D turtle (seed 003).
    LSystem {
        /// Axiom, rules, generations.
        system: LSystem,
        /// What the turtle's symbols mean in metres and degrees.
        turtle: TurtleParams,
    },
}

/// What a tip carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeafKind {
    /// Leaf cards around each tip, placed by the golden angle (phyllotaxis).
    Cluster,
    /// Narrow cards along the tip, as pine needles.
    Needles,
    /// No leaves.
    None,
}

/// How a skeleton is meshed.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshSpec {
    /// Sides of the LOD0 tubes.
    pub sides: u8,
    /// LOD1 prunes branches thinner than this share of the trunk's base radius into leaf
    /// cards.
    pub twig: f64,
    /// The bark material.
    pub bark: u16,
    /// Leaves.
    pub leaf: LeafKind,
    /// A leaf card's size, metres (at the species' nominal height).
    pub leaf_size: f64,
    /// Leaf cards per leafy node.
    pub per_tip: u32,
    /// How many nodes from each tip up carry leaves (1: the tip alone).
    pub leaf_nodes: u32,
}

/// A tree species.
#[derive(Debug, Clone)]
pub struct Species {
    /// Its name (romaji): `sakura`.
    pub name: String,
    /// Its kanji: 桜.
    pub kanji: String,
    /// What it is.
    pub description: String,
    /// The file it was read from.
    pub file: String,
    /// `lsystem` or `colonization`.
    pub method: &'static str,
    /// [low, high] metres: a planted tree's height is drawn between.
    pub height: [f64; 2],
    /// The library texture rendered from this species (its billboards and LOD2).
    pub billboard: u16,
    /// How it grows.
    pub grower: Grower,
    /// How it is meshed.
    pub mesh: MeshSpec,
    /// The leaf material of each season of [`SEASONS`]; `None` for bare branches.
    pub leaves: [Option<u16>; 4],
}

impl Species {
    /// Grows one skeleton with `rng` (the per-feature RNG of the tree), scaled so that it
    /// stands `height` metres tall.
    pub fn grow(&self, height: f64, rng: &mut Pcg64) -> Result<Grown, String> {
        let fail =
            |e: &dyn std::fmt::Display| format!("{}: species `{}`: {e}", self.file, self.name);
        let (mut sk, report) = match &self.grower {
            Grower::LSystem { system, turtle } => {
                let word = system.expand(rng).map_err(|e| fail(&e))?;
                let sk = crate::growers::lsystem::turtle::interpret(&word, turtle);
                (sk, serde_json::json!({ "symbols": word.modules.len() }))
            }
        };
        let (_, hi) = sk.bounds();
        if !(hi[2] > 0.0 && hi[2].is_finite()) {
            return Err(format!(
                "{}: species `{}` grows nothing above the ground",
                self.file, self.name
            ));
        }
        sk.scale(height / hi[2]);
        Ok(Grown {
            skeleton: sk,
            report,
        })
    }

    /// The leaf material shown in `season` (one of [`SEASONS`]).
    pub fn leaf_material(&self, season: &str) -> Option<u16> {
        let k = SEASONS.iter().position(|s| *s == season).unwrap_or(1);
        self.leaves[k]
    }

    /// The mean of the species' height range.
    pub fn nominal_height(&self) -> f64 {
        (self.height[0] + self.height[1]) / 2.0
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpecies {
    name: Spanned<String>,
    #[serde(default)]
    kanji: String,
    #[serde(default)]
    description: String,
    method: Spanned<String>,
    height: Spanned<[f64; 2]>,
    billboard: Spanned<String>,
    lsystem: Option<RawLSystem>,
    mesh: RawMesh,
    #[serde(default)]
    season: BTreeMap<String, Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLSystem {
    axiom: Spanned<String>,
    rules: Vec<Spanned<String>>,
    angle: f64,
    generations: Spanned<usize>,
    step: f64,
    width: f64,
    #[serde(default = "default_decay")]
    width_decay: f64,
    #[serde(default = "default_tropism")]
    tropism: [f64; 3],
    #[serde(default)]
    elasticity: f64,
    #[serde(default = "default_max")]
    max_symbols: usize,
}

fn default_decay() -> f64 {
    0.7
}
fn default_tropism() -> [f64; 3] {
    [0.0, 0.0, -1.0]
}
fn default_max() -> usize {
    DEFAULT_MAX_SYMBOLS
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMesh {
    #[serde(default = "default_sides")]
    sides: Spanned<u8>,
    #[serde(default = "default_twig")]
    twig: f64,
    #[serde(default = "default_bark")]
    bark: Spanned<String>,
    leaf: Spanned<String>,
    #[serde(default)]
    leaf_size: f64,
    #[serde(default)]
    per_tip: u32,
    #[serde(default = "default_leaf_nodes")]
    leaf_nodes: u32,
    /// The leaf material of every season not in `[season]`.
    #[serde(default)]
    leaf_material: Option<Spanned<String>>,
}

fn default_leaf_nodes() -> u32 {
    1
}
fn default_sides() -> Spanned<u8> {
    Spanned::new(0..0, 6)
}
fn default_twig() -> f64 {
    0.25
}
fn default_bark() -> Spanned<String> {
    Spanned::new(0..0, "bark".to_string())
}

/// Parses one species file.
pub fn parse(file: &str, text: &str) -> Result<Species, String> {
    let at = |span: std::ops::Range<usize>| {
        let (l, c) = line_col(text, span.start);
        format!("{file}:{l}:{c}")
    };
    let raw: RawSpecies = toml::from_str(text).map_err(|e| {
        let msg = e.message().trim_end().to_string();
        match e.span() {
            Some(s) => format!("{}: {msg}", at(s)),
            None => format!("{file}: {msg}"),
        }
    })?;
    let material = |s: &Spanned<String>, what: &str| -> Result<u16, String> {
        materials::find(s.get_ref()).ok_or_else(|| {
            format!(
                "{}: {what} `{}` is not a library material (see docs/templates.md)",
                at(s.span()),
                s.get_ref()
            )
        })
    };
    let name = raw.name.get_ref().clone();
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!(
            "{}: a species name is letters, digits and `_` (it names files), got `{name}`",
            at(raw.name.span())
        ));
    }
    let [lo, hi] = *raw.height.get_ref();
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi && hi <= 100.0) {
        return Err(format!(
            "{}: `height` must be [low, high] with 0 < low <= high <= 100",
            at(raw.height.span())
        ));
    }
    let billboard = material(&raw.billboard, "billboard")?;
    let m = &raw.mesh;
    let sides = *m.sides.get_ref();
    if !(3..=32).contains(&sides) {
        return Err(format!("{}: `sides` must be 3 to 32", at(m.sides.span())));
    }
    if !(m.twig.is_finite() && (0.0..1.0).contains(&m.twig)) {
        return Err(format!("{file}: `mesh.twig` must be in [0, 1)"));
    }
    let leaf = match m.leaf.get_ref().as_str() {
        "cluster" => LeafKind::Cluster,
        "needles" => LeafKind::Needles,
        "none" => LeafKind::None,
        other => {
            return Err(format!(
                "{}: `leaf` must be \"cluster\", \"needles\" or \"none\", got \"{other}\"",
                at(m.leaf.span())
            ))
        }
    };
    if leaf != LeafKind::None
        && !(m.leaf_size.is_finite() && m.leaf_size > 0.0 && m.leaf_size <= 10.0)
    {
        return Err(format!(
            "{file}: `mesh.leaf_size` must be from 0 to 10 metres for leaves `{}`",
            m.leaf.get_ref()
        ));
    }
    if m.per_tip > 64 || m.leaf_nodes > 64 {
        return Err(format!(
            "{file}: `mesh.per_tip` and `mesh.leaf_nodes` must be at most 64"
        ));
    }
    let base_leaf = match &m.leaf_material {
        Some(s) => Some(material(s, "leaf_material")?),
        None if leaf == LeafKind::None => None,
        None => return Err(format!("{file}: `mesh.leaf_material` is missing")),
    };
    let mut leaves = [base_leaf; 4];
    for (season, mat) in &raw.season {
        let Some(k) = SEASONS.iter().position(|s| s == season) else {
            return Err(format!(
                "{}: `{season}` is not a season ({})",
                at(mat.span()),
                SEASONS.join(", ")
            ));
        };
        leaves[k] = match mat.get_ref().as_str() {
            "none" => None,
            _ => Some(material(mat, "leaf material")?),
        };
    }
    let (method, grower) = match raw.method.get_ref().as_str() {
        "lsystem" => {
            let Some(l) = raw.lsystem else {
                return Err(format!(
                    "{}: method \"lsystem\" needs an [lsystem] table",
                    at(raw.method.span())
                ));
            };
            ("lsystem", lsystem(l, file, text)?)
        }
        other => {
            return Err(format!(
                "{}: `method` must be \"lsystem\", got \"{other}\"",
                at(raw.method.span())
            ))
        }
    };
    Ok(Species {
        name,
        kanji: raw.kanji,
        description: raw.description,
        file: file.to_string(),
        method,
        height: [lo, hi],
        billboard,
        grower,
        mesh: MeshSpec {
            sides,
            twig: m.twig,
            bark: material(&m.bark, "bark")?,
            leaf,
            leaf_size: m.leaf_size,
            per_tip: m.per_tip,
            leaf_nodes: m.leaf_nodes,
        },
        leaves,
    })
}

/// The `[lsystem]` table: the grammar parsed now, its errors pointing into the file.
fn lsystem(l: RawLSystem, file: &str, text: &str) -> Result<Grower, String> {
    let rules: Vec<String> = l.rules.iter().map(|r| r.get_ref().clone()).collect();
    let system = LSystem::parse(
        l.axiom.get_ref(),
        &rules,
        *l.generations.get_ref(),
        l.max_symbols,
    )
    .map_err(|e| {
        let (span, column) = match &e {
            LsError::Syntax { place, column, .. } => (
                match place {
                    Place::Axiom => l.axiom.span(),
                    Place::Rule(n) => l.rules[n - 1].span(),
                },
                *column,
            ),
            _ => (l.generations.span(), 0),
        };
        // The string's first character is one past its opening quote.
        let (line, col) = line_col(text, span.start);
        format!("{file}:{line}:{}: {e}", col + column)
    })?;
    for (key, v, lo, hi) in [
        ("angle", l.angle, -360.0, 360.0),
        ("step", l.step, 1e-6, 100.0),
        ("width", l.width, 0.0, 10.0),
        ("width_decay", l.width_decay, 0.0, 1.0),
        ("elasticity", l.elasticity, -1.0, 1.0),
    ] {
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err(format!(
                "{file}: `lsystem.{key}` must be from {lo} to {hi}, got {v}"
            ));
        }
    }
    if !l.tropism.iter().all(|t| t.is_finite()) {
        return Err(format!("{file}: `lsystem.tropism` must be three numbers"));
    }
    Ok(Grower::LSystem {
        system,
        turtle: TurtleParams {
            step: l.step,
            angle: l.angle,
            width: l.width,
            width_decay: l.width_decay,
            tropism: l.tropism,
            elasticity: l.elasticity,
        },
    })
}
