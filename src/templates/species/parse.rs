//! A species file read: its TOML into raw tables (with their spans, so each error names its
//! `file:line:column`), then checked and made a [`Species`]: the L-system parsed, the
//! colonization's groups, fields and envelopes (an OBJ hull within its bounds), the mesh and
//! the leaves by season.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

use super::{Grower, LeafKind, MeshSpec, Species, SEASONS};
use crate::growers::colonization::{self, Attach, Envelope, Field};
use crate::growers::lsystem::{LSystem, LsError, Place, TurtleParams, DEFAULT_MAX_SYMBOLS};
use crate::materials;
use crate::templates::file::line_col;

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
            let obj = crate::templates::dir::read_beside(std::path::Path::new(file), name, MAX_HULL_BYTES)
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
