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
use crate::growers::colonization::{self, Attach, Envelope, Field, GroupReport};
use crate::growers::lsystem::{LSystem, LsError, Place, TurtleParams, DEFAULT_MAX_SYMBOLS};
use crate::growers::skeleton::Skeleton;
use crate::materials;

/// The seed of each species' sample tree: its crown shape is measured on it, its billboard
/// texture rendered from it, and `<out>/species/` holds its LOD0.
pub const SAMPLE_SEED: u64 = 1;

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
    /// Space colonization with vector-field control, in groups (seed 001).
    Colonization {
        /// Step, influence, kill, field.
        params: colonization::Params,
        /// Trunk, branches, roots.
        groups: Vec<colonization::Group>,
        /// Radius of a branch tip, metres (at the species' nominal height).
        tip_radius: f64,
        /// The pipe model's exponent, 2 to 3.
        pipe_exponent: f64,
        /// Roots within this many metres of the trunk are shown above ground in the city
        /// (`[roots] exposed`).
        roots_exposed: f64,
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
            Grower::Colonization {
                params,
                groups,
                tip_radius,
                pipe_exponent,
                ..
            } => {
                let (mut sk, reports) =
                    colonization::grow(params, groups, rng).map_err(|e| fail(&e))?;
                sk.pipe_radii(*tip_radius, *pipe_exponent);
                let report = colonization_report(params, &reports, &sk);
                (sk, report)
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

    /// [`Species::grow`], then the roots as the city shows them: those within
    /// `roots_exposed` of the trunk along the ground, the rest (hidden below it) dropped.
    pub fn grow_in_city(&self, height: f64, rng: &mut Pcg64) -> Result<Grown, String> {
        let mut g = self.grow(height, rng)?;
        g.skeleton
            .expose_roots(self.roots_exposed() * height / self.nominal_height());
        Ok(g)
    }

    /// How far from the trunk roots show above ground (0 for none or an L-system).
    pub fn roots_exposed(&self) -> f64 {
        match &self.grower {
            Grower::Colonization { roots_exposed, .. } => *roots_exposed,
            Grower::LSystem { .. } => 0.0,
        }
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
    colonization: Option<RawColonization>,
    mesh: RawMesh,
    #[serde(default)]
    season: BTreeMap<String, Spanned<String>>,
    /// `[roots] exposed = metres`: how far from the trunk roots show above ground.
    #[serde(default)]
    roots: Option<RawRoots>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRoots {
    exposed: f64,
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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawColonization {
    step: f64,
    influence: Option<f64>,
    kill: Option<f64>,
    #[serde(default = "default_iter")]
    max_iter: usize,
    #[serde(default)]
    field: Option<RawField>,
    #[serde(default)]
    weight: f64,
    #[serde(default)]
    twist: f64,
    tip_radius: f64,
    #[serde(default = "default_pipe")]
    pipe_exponent: f64,
    group: Vec<Spanned<RawGroup>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawField {
    kind: String,
    #[serde(default)]
    vector: Option<[f64; 3]>,
    #[serde(default)]
    strength: f64,
    #[serde(default)]
    rise: f64,
    #[serde(default)]
    at: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGroup {
    name: String,
    points: usize,
    envelope: RawEnvelope,
    /// "base", or [low, high] shares of the first group's height.
    #[serde(default)]
    attach: Option<toml::Value>,
    weight: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEnvelope {
    shape: String,
    center: Option<[f64; 3]>,
    radii: Option<[f64; 3]>,
    base: Option<f64>,
    top: Option<f64>,
    radius: Option<f64>,
    file: Option<String>,
}

fn default_iter() -> usize {
    1000
}
fn default_pipe() -> f64 {
    2.5
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
    let raw: RawSpecies =
        toml::from_str(text).map_err(|e| crate::model::source::toml_error(file, text, &e))?;
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
        "colonization" => {
            let Some(c) = raw.colonization else {
                return Err(format!(
                    "{}: method \"colonization\" needs a [colonization] table",
                    at(raw.method.span())
                ));
            };
            let exposed = raw.roots.as_ref().map_or(0.0, |r| r.exposed);
            ("colonization", colonization_grower(c, exposed, file, text)?)
        }
        other => {
            return Err(format!(
                "{}: `method` must be \"lsystem\" or \"colonization\", got \"{other}\"",
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

/// The `[colonization]` table: parameters checked, envelopes built (a hull read from its OBJ,
/// relative to the species file).
fn colonization_grower(
    c: RawColonization,
    roots_exposed: f64,
    file: &str,
    text: &str,
) -> Result<Grower, String> {
    let at = |span: std::ops::Range<usize>| {
        let (l, col) = line_col(text, span.start);
        format!("{file}:{l}:{col}")
    };
    let field =
        match &c.field {
            None => Field::None,
            Some(f) => match f.kind.as_str() {
                "none" => Field::None,
                "constant" => Field::Constant(f.vector.ok_or_else(|| {
                    format!("{file}: a constant field needs `vector = [x, y, z]`")
                })?),
                "vortex" => Field::Vortex {
                    strength: f.strength,
                    rise: f.rise,
                },
                "point" => Field::Toward(
                    f.at.ok_or_else(|| format!("{file}: a point field needs `at = [x, y, z]`"))?,
                ),
                other => {
                    return Err(format!(
                    "{file}: `colonization.field.kind` must be none, constant, vortex or point, \
                     got \"{other}\""
                ))
                }
            },
        };
    let params = colonization::Params {
        step: c.step,
        influence: c.influence.unwrap_or(10.0 * c.step),
        kill: c.kill.unwrap_or(2.0 * c.step),
        max_iter: c.max_iter,
        field,
        weight: c.weight,
        twist: c.twist.to_radians(),
    };
    if let Some(p) = params.problem() {
        return Err(format!("{file}: [colonization]: {p}"));
    }
    if !(c.tip_radius.is_finite() && c.tip_radius > 0.0 && c.tip_radius < 1.0) {
        return Err(format!(
            "{file}: `colonization.tip_radius` must be from 0 to 1 metre"
        ));
    }
    if !(2.0..=3.0).contains(&c.pipe_exponent) {
        return Err(format!(
            "{file}: `colonization.pipe_exponent` must be from 2 to 3"
        ));
    }
    if !(roots_exposed.is_finite() && (0.0..=50.0).contains(&roots_exposed)) {
        return Err(format!(
            "{file}: `roots.exposed` must be from 0 to 50 metres"
        ));
    }
    if c.group.is_empty() {
        return Err(format!(
            "{file}: [colonization] needs at least one [[colonization.group]]"
        ));
    }
    let mut groups = Vec::new();
    for g in &c.group {
        let here = at(g.span());
        let g = g.get_ref();
        if g.points == 0 || g.points > colonization::MAX_POINTS {
            return Err(format!(
                "{here}: group `{}`: `points` must be from 1 to {}",
                g.name,
                colonization::MAX_POINTS
            ));
        }
        let attach = match &g.attach {
            None => Attach::Base,
            Some(toml::Value::String(s)) if s == "base" => Attach::Base,
            Some(toml::Value::Array(a)) if a.len() == 2 => {
                let num = |v: &toml::Value| v.as_float().or(v.as_integer().map(|i| i as f64));
                match (num(&a[0]), num(&a[1])) {
                    (Some(lo), Some(hi)) if (0.0..=1.0).contains(&lo) && lo <= hi && hi <= 1.0 => {
                        Attach::Stem(lo, hi)
                    }
                    _ => {
                        return Err(format!(
                            "{here}: group `{}`: `attach` = [low, high] with 0 <= low <= high <= 1",
                            g.name
                        ))
                    }
                }
            }
            Some(_) => {
                return Err(format!(
                    "{here}: group `{}`: `attach` is \"base\" or [low, high]",
                    g.name
                ))
            }
        };
        groups.push(colonization::Group {
            name: g.name.clone(),
            envelope: envelope(&g.envelope, file)
                .map_err(|e| format!("{here}: group `{}`: {e}", g.name))?,
            points: g.points,
            attach,
            weight: g.weight,
        });
    }
    Ok(Grower::Colonization {
        params,
        groups,
        tip_radius: c.tip_radius,
        pipe_exponent: c.pipe_exponent,
        roots_exposed,
    })
}

fn envelope(e: &RawEnvelope, file: &str) -> Result<Envelope, String> {
    let pos = |v: f64| v.is_finite() && v > 0.0;
    let need = |v: Option<f64>, key: &str| {
        v.filter(|v| v.is_finite())
            .ok_or_else(|| format!("envelope `{}` needs `{key}`", e.shape))
    };
    let radii = || {
        e.radii
            .filter(|r| r.iter().all(|&v| pos(v)))
            .ok_or_else(|| format!("envelope `{}` needs positive `radii = [x, y, z]`", e.shape))
    };
    Ok(match e.shape.as_str() {
        "ellipsoid" => Envelope::Ellipsoid {
            center: e.center.unwrap_or([0.0; 3]),
            radii: radii()?,
        },
        "below_ground" => Envelope::BelowGround { radii: radii()? },
        "cone" | "cylinder" => {
            let (base, top, radius) = (need(e.base, "base")?, need(e.top, "top")?, need(e.radius, "radius")?);
            if !(top > base && radius > 0.0) {
                return Err("needs top > base and a positive radius".into());
            }
            if e.shape == "cone" {
                Envelope::Cone { base, top, radius }
            } else {
                Envelope::Cylinder { base, top, radius }
            }
        }
        "hull" => {
            let name = e.file.as_deref().ok_or("envelope `hull` needs `file` (an OBJ)")?;
            let obj = super::dir::read_beside(std::path::Path::new(file), name, MAX_HULL_BYTES)
                .map_err(|err| format!("hull: {err}"))?;
            let triangles = obj_triangles(&obj).map_err(|err| format!("hull {name}: {err}"))?;
            Envelope::hull(triangles).map_err(|err| format!("hull {name}: {err}"))?
        }
        other => {
            return Err(format!(
                "envelope shape must be ellipsoid, below_ground, cone, cylinder or hull, got \"{other}\""
            ))
        }
    })
}

/// Bytes of a hull's OBJ (a 100,000-triangle hull is about 6 MB).
const MAX_HULL_BYTES: u64 = 16 << 20;

/// The triangles of an OBJ's faces (fans), in the growers' axes: OBJ is y-up, so (x, y, z)
/// of the file is (x, -z, y) here; at most [`colonization::MAX_HULL_TRIANGLES`].
fn obj_triangles(text: &str) -> Result<Vec<[[f64; 3]; 3]>, String> {
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => {
                let c: Vec<f64> = w.take(3).filter_map(|t| t.parse().ok()).collect();
                if c.len() != 3 || !c.iter().all(|x| x.is_finite()) {
                    return Err(format!("line {}: a vertex needs three numbers", n + 1));
                }
                v.push([c[0], -c[2], c[1]]);
            }
            Some("f") => {
                let idx: Vec<usize> = w
                    .map(|t| {
                        let i: i64 = t.split('/').next().unwrap_or("").parse().unwrap_or(0);
                        if i < 0 {
                            (v.len() as i64 + i) as usize
                        } else {
                            (i - 1).max(0) as usize
                        }
                    })
                    .collect();
                if idx.len() < 3 || idx.iter().any(|&i| i >= v.len()) {
                    return Err(format!("line {}: a face names a missing vertex", n + 1));
                }
                for k in 1..idx.len() - 1 {
                    out.push([v[idx[0]], v[idx[k]], v[idx[k + 1]]]);
                }
                if out.len() > colonization::MAX_HULL_TRIANGLES {
                    return Err(format!(
                        "line {}: more than {} triangles: simplify the hull",
                        n + 1,
                        colonization::MAX_HULL_TRIANGLES
                    ));
                }
            }
            _ => {}
        }
    }
    if out.len() < 4 {
        return Err("fewer than four triangles: not a closed hull".into());
    }
    Ok(out)
}

/// The report keys of a colonized tree: each group's, and their sums (the first group that
/// did not use up its points gives the stop reason, else `all_killed`). The tree's `edges`
/// are the skeleton's, not the groups' sum: a group that starts on the stem counts the
/// stem's edges it starts from as its own (kusu, seed 1, summed 1,876 edges over 1,873
/// nodes).
fn colonization_report(
    p: &colonization::Params,
    reports: &[GroupReport],
    sk: &Skeleton,
) -> serde_json::Value {
    let group = |r: &GroupReport| {
        serde_json::json!({
            "name": r.name,
            "stop": r.stop.as_str(),
            "iterations": r.iterations,
            "nodes": r.nodes,
            "edges": r.edges,
            "points_left": r.points_left,
            "oscillations": r.oscillations,
            "step": p.step,
            "influence": p.influence,
            "kill": p.kill,
        })
    };
    let stop = reports
        .iter()
        .map(|r| r.stop)
        .find(|s| *s != colonization::Stop::AllKilled)
        .unwrap_or(colonization::Stop::AllKilled);
    serde_json::json!({
        "stop": stop.as_str(),
        "iterations": reports.iter().map(|r| r.iterations).sum::<usize>(),
        "edges": sk.nodes.iter().filter(|n| n.parent.is_some()).count(),
        "points_left": reports.iter().map(|r| r.points_left).sum::<usize>(),
        "step": p.step,
        "influence": p.influence,
        "kill": p.kill,
        "groups": reports.iter().map(group).collect::<Vec<_>>(),
    })
}
