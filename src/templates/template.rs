//! A compiled template: every expression resolved to slots, every material to its id, checked
//! once when the catalog loads so that a build never starts with a broken template.

use std::collections::BTreeMap;
use std::ops::Range;

use geo_types::Coord;

use super::expr::{compile, Expr, Lot};
use super::file::{value_problem, Loc, OutlineSource, PartSource, Source, Src, Text};
use crate::materials;

/// What a template models; `type_mix` may name only machiya.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A townhouse on a town lot (or a footprint).
    Machiya,
    /// A storehouse behind a machiya.
    Kura,
    /// A wall segment.
    Fence,
    /// A gate in a wall.
    Gate,
    /// A tree billboard.
    Tree,
    /// A person billboard.
    Person,
    /// A hall of an estate or a temple (a temple's main hall, gate and pagoda, a samurai's
    /// main house, a court noble's residence), built on the open plot analysis finds for it
    /// behind the lot's gate: `u` across the plot, `v` away from the gate.
    Hall,
}

impl Kind {
    /// Every kind with the name template files use.
    pub const ALL: [(&'static str, Kind); 7] = [
        ("machiya", Kind::Machiya),
        ("kura", Kind::Kura),
        ("fence", Kind::Fence),
        ("gate", Kind::Gate),
        ("tree", Kind::Tree),
        ("person", Kind::Person),
        ("hall", Kind::Hall),
    ];
    /// The name template files use.
    pub fn name(self) -> &'static str {
        Kind::ALL.iter().find(|k| k.1 == self).map_or("", |k| k.0)
    }
}

/// The values every template gets, in slot order. `u` runs along the frontage from its first
/// vertex, `v` into the lot, `h` up from the ground; lengths are metres.
pub const INPUTS: &[(&str, &str)] = &[
    (
        "width",
        "frontage width: the frontage runs from u = 0 to u = width",
    ),
    (
        "lot_depth",
        "the lot's deepest point behind the frontage (largest v)",
    ),
    ("frontage_ax", "first frontage vertex, map x"),
    ("frontage_ay", "first frontage vertex, map y"),
    ("frontage_bx", "second frontage vertex, map x"),
    ("frontage_by", "second frontage vertex, map y"),
    ("centroid_x", "the lot's centroid, map x"),
    ("centroid_y", "the lot's centroid, map y"),
    ("ground", "ground elevation; h = 0 stands on it"),
    (
        "feature_id",
        "the feature's id when it is a number, else -1",
    ),
    ("district", "the district's id when it is a number, else -1"),
    (
        "building_height",
        "height of a footprint building from the data; 0 for a lot",
    ),
    ("machiya_depth", "machiya.depth of the parameter file"),
    ("min_depth", "machiya.min_depth of the parameter file"),
    (
        "random",
        "a number in [0, 1) fixed per feature by (seed, layer, feature id)",
    ),
    (
        "start_mitre",
        "fences: cot of half the interior angle at the segment's start (1 at a right angle, 0 at a free or straight end, < 0 at a reflex corner)",
    ),
    ("end_mitre", "fences: the same at the segment's end"),
    (
        "billboard_height",
        "people and trees: the height drawn from people.height / trees.height (or the point's height field); 0 for other models",
    ),
];

/// How many inputs there are (their slots come first).
pub const N_INPUTS: usize = INPUTS.len();

/// What a template is told about the site it is built on (the [`INPUTS`]); fields a kind of
/// model does not have stay at their default.
#[derive(Debug, Clone, Default)]
pub struct SiteInputs<'a> {
    /// Frontage width: the frontage runs from u = 0 to u = width.
    pub width: f64,
    /// The lot's deepest point behind the frontage (largest v).
    pub lot_depth: f64,
    /// The frontage's two vertices and the site's centroid, map coordinates.
    pub a: Coord<f64>,
    /// The second frontage vertex.
    pub b: Coord<f64>,
    /// The site's centroid.
    pub centroid: Coord<f64>,
    /// Ground elevation: h = 0 stands on it.
    pub ground: f64,
    /// The feature's id.
    pub id: &'a str,
    /// The feature's district.
    pub district: Option<&'a str>,
    /// A footprint building's height from the data; 0 for a lot.
    pub building_height: f64,
    /// `machiya.depth` of the parameter file.
    pub machiya_depth: f64,
    /// `machiya.min_depth` of the parameter file.
    pub min_depth: f64,
    /// A number in [0, 1) fixed per feature by (seed, layer, feature id).
    pub random: f64,
    /// Fences: cot of half the interior angle at the segment's start.
    pub start_mitre: f64,
    /// Fences: the same at its end.
    pub end_mitre: f64,
    /// People and trees: their drawn height.
    pub billboard_height: f64,
}

/// A number for an id-like text: the text itself when it is a number, else -1.
pub fn numeric_id(s: Option<&str>) -> f64 {
    s.and_then(|s| s.trim().parse::<f64>().ok())
        .filter(|x| x.is_finite())
        .unwrap_or(-1.0)
}

impl SiteInputs<'_> {
    /// The input slots, in [`INPUTS`] order.
    pub fn slots(&self) -> [f64; N_INPUTS] {
        let mut x = [0.0; N_INPUTS];
        for (name, value) in [
            ("width", self.width),
            ("lot_depth", self.lot_depth),
            ("frontage_ax", self.a.x),
            ("frontage_ay", self.a.y),
            ("frontage_bx", self.b.x),
            ("frontage_by", self.b.y),
            ("centroid_x", self.centroid.x),
            ("centroid_y", self.centroid.y),
            ("ground", self.ground),
            ("feature_id", numeric_id(Some(self.id))),
            ("district", numeric_id(self.district)),
            ("building_height", self.building_height),
            ("machiya_depth", self.machiya_depth),
            ("min_depth", self.min_depth),
            ("random", self.random),
            ("start_mitre", self.start_mitre),
            ("end_mitre", self.end_mitre),
            ("billboard_height", self.billboard_height),
        ] {
            x[input(name)] = value;
        }
        x
    }
}

/// Slot of an input by name (for callers that fill inputs).
pub fn input(name: &str) -> usize {
    INPUTS
        .iter()
        .position(|i| i.0 == name)
        .unwrap_or_else(|| panic!("no template input `{name}`"))
}

/// A compiled template: every name a slot, every expression compiled, every check and
/// material resolved; evaluated per feature without parsing.
#[derive(Debug, Clone)]
pub struct Template {
    /// Its name.
    pub name: String,
    /// Its name in kanji.
    pub kanji: String,
    /// Its kind.
    pub kind: Kind,
    /// What it models.
    pub description: String,
    /// Other spellings of a machiya type.
    pub aliases: Vec<String>,
    /// The file the template was read from.
    pub file: String,
    /// Whether it only serves to be extended.
    pub is_abstract: bool,
    /// Name of every slot: inputs, params, attributes, derived values, then `v`.
    pub names: Vec<String>,
    /// Default values of params and attributes (indexed by slot - N_INPUTS).
    pub defaults: Vec<f64>,
    /// The slots of its parameters.
    pub params: Range<usize>,
    /// The slots of its attributes.
    pub attributes: Range<usize>,
    /// Derived values in an order where each needs only earlier ones.
    pub derived: Vec<(usize, Expr, Loc)>,
    /// The slots of `u` and `v` (last two): the point a prism's `top` and `bottom` are
    /// evaluated at.
    pub v_slot: usize,
    /// Conditions every feature must meet, with the reason given when one fails.
    pub checks: Vec<(Expr, String)>,
    /// The height the model declares (checked by tests against the mesh).
    pub height: Option<(Expr, Loc)>,
    /// Its storeys above ground (`storeys`), for a city model.
    pub storeys: Option<Expr>,
    /// Its roof's form (`roof_type`), for a city model.
    pub roof_type: Option<String>,
    /// Its parts, in file order.
    pub parts: Vec<Part>,
    /// The `[materials]` slots and the library material each names: a billboard's drawn
    /// texture replaces its `picture` slot.
    pub material_slots: Vec<(String, u16)>,
}

impl Template {
    /// The library material a `[materials]` slot names.
    pub fn material_slot(&self, slot: &str) -> Option<u16> {
        self.material_slots
            .iter()
            .find(|(k, _)| k == slot)
            .map(|s| s.1)
    }
}

/// One compiled part.
#[derive(Debug, Clone)]
pub struct Part {
    /// Its name.
    pub name: String,
    /// Where it is written (for messages).
    pub loc: Loc,
    /// Built only where this is not 0.
    pub when: Option<Expr>,
    /// A prism or explicit faces.
    pub shape: Shape,
    /// Whether a city model holds it as an installation of the building.
    pub installation: bool,
}

/// What a part is made of.
#[derive(Debug, Clone)]
pub enum Shape {
    /// An outline extruded between two heights.
    Prism(Box<Prism>),
    /// Explicit vertices and faces.
    Faces(Faces),
}

/// An outline (the lot, or a polygon of (u, v) points) cut to `v0 <= v <= v1` and
/// `u0 <= u <= u1`, extruded from `bottom` to `top`, both functions of `v` that are linear
/// between the `split` depths.
#[derive(Debug, Clone)]
pub struct Prism {
    /// The part's own (u, v) outline; `None` = the lot.
    pub outline: Option<Vec<[Expr; 2]>>,
    /// The band: from depth `v0` ...
    pub v0: Option<Expr>,
    /// ... to `v1` ...
    pub v1: Option<Expr>,
    /// ... along the street from `u0` ...
    pub u0: Option<Expr>,
    /// ... to `u1`.
    pub u1: Option<Expr>,
    /// Height of the underside.
    pub bottom: Expr,
    /// Height of the top.
    pub top: Expr,
    /// Depths where the top bends.
    pub split: Vec<Expr>,
    /// Positions along the street where it bends.
    pub split_u: Vec<Expr>,
    /// A roof as the lower envelope of planes (`generate::envelope`): then `top` is unused.
    pub roof: Option<Roof>,
    /// Material of the top faces.
    pub top_material: u16,
    /// Material of the bottom faces.
    pub bottom_material: u16,
    /// Material of the side walls.
    pub side_material: u16,
    /// Walls on the front line `v = v0` with facade texture coordinates.
    pub front_material: Option<u16>,
    /// The facade texture's width, metres.
    pub front_base: Expr,
    /// The facade texture's height, metres.
    pub front_height: Expr,
    /// Whether the part must be a closed shell.
    pub closed: bool,
}

/// A roof surface: the lowest of its planes at every point (hip, irimoya, pyramidal, a
/// tier of a pagoda), cut into flat faces where the planes cross.
#[derive(Debug, Clone)]
pub struct Roof {
    /// Planes given by expressions linear in `u` and `v`.
    pub planes: Vec<Expr>,
    /// One plane per edge of the outline, from `(eave, pitch)`: a hip roof on any shape.
    pub hip: Option<(Expr, Expr)>,
    /// A slab: the bottom is the roof this much lower (else the part's `bottom`).
    pub thickness: Option<Expr>,
}

/// Explicit vertices (u, v, h) and faces over them.
#[derive(Debug, Clone)]
pub struct Faces {
    /// The vertices (u, v, h).
    pub vertices: Vec<[Expr; 3]>,
    /// The faces.
    pub faces: Vec<FaceSpec>,
    /// Whether the part must be a closed shell.
    pub closed: bool,
}

/// One explicit face.
#[derive(Debug, Clone)]
pub struct FaceSpec {
    /// 0-based vertex indices (written 1-based in the file, like OBJ and the paper).
    pub corners: Vec<usize>,
    /// Its material.
    pub material: u16,
    /// Texture coordinates per corner; `None` = projected onto the face, one repeat per `base`.
    pub uv: Option<Vec<[Expr; 2]>>,
    /// The texture repeat, metres, when coordinates are projected.
    pub base: Expr,
}

fn err(loc: &Loc, msg: impl std::fmt::Display) -> String {
    format!("{loc}: {msg}")
}

struct Names<'a> {
    names: &'a [String],
}

impl Names<'_> {
    fn compile(&self, t: &Text) -> Result<Expr, String> {
        compile(&t.value, &|n| self.names.iter().position(|m| m == n)).map_err(|e| err(&t.loc, e))
    }
    fn opt(&self, t: &Option<Text>) -> Result<Option<Expr>, String> {
        t.as_ref().map(|t| self.compile(t)).transpose()
    }
    fn or(&self, t: &Option<Text>, default: f64) -> Result<Expr, String> {
        Ok(self.opt(t)?.unwrap_or(Expr::constant(default)))
    }
    fn pair(&self, p: &[Text], loc: &Loc) -> Result<[Expr; 2], String> {
        match p {
            [a, b] => Ok([self.compile(a)?, self.compile(b)?]),
            _ => Err(err(loc, format!("a point needs 2 values, got {}", p.len()))),
        }
    }
}

/// Material slots of a template: slot name -> library material.
type Slots<'a> = &'a [(String, Src<String>)];

fn material(slots: Slots, m: &Option<Src<String>>, default: &str) -> Result<u16, String> {
    match m {
        None => Ok(materials::id(default)),
        Some(m) => material_of(slots, m),
    }
}

fn material_of(slots: Slots, m: &Src<String>) -> Result<u16, String> {
    let m = slots
        .iter()
        .find(|(k, _)| *k == m.value)
        .map_or(m, |(_, v)| v);
    materials::find(&m.value).ok_or_else(|| {
        err(
            &m.loc,
            format!(
                "material `{}` is not in the texture library ({})",
                m.value,
                materials::names().join(", ")
            ),
        )
    })
}

/// Compiles a template whose `extends` has been merged in.
pub fn compile_template(s: &Source) -> Result<Template, String> {
    let here = Loc(s.file.clone());
    let kind = kind_of(s)?;
    let ValueSlots {
        names,
        defaults,
        params,
        attributes,
        derived: d0,
        u,
    } = declare_slots(s)?;
    let scalar_names = Names { names: &names[..u] };
    let all = Names { names: &names };
    let derived = order_derived(s, &scalar_names, &names, d0)?;
    let height = match &s.height {
        Some(t) => Some((scalar_names.compile(t)?, t.loc.clone())),
        None => None,
    };
    let storeys = match &s.storeys {
        Some(t) => Some(scalar_names.compile(t)?),
        None => None,
    };
    let material_slots = material_slots(s, kind, &here)?;
    let checks = s
        .checks
        .iter()
        .map(|(t, reason)| Ok((scalar_names.compile(t)?, reason.clone())))
        .collect::<Result<Vec<_>, String>>()?;
    let mut parts = Vec::new();
    for p in &s.parts {
        if parts.iter().any(|q: &Part| q.name == p.name.value) {
            return Err(err(
                &p.name.loc,
                format!("a second part named `{}`", p.name.value),
            ));
        }
        parts.push(compile_part(p, &scalar_names, &all, &s.materials)?);
    }
    if parts.is_empty() && !s.is_abstract {
        return Err(err(&here, "the template has no `[[part]]`"));
    }
    Ok(Template {
        name: s.name.value.clone(),
        kanji: s.kanji.clone(),
        kind,
        description: s.description.clone(),
        aliases: s.aliases.clone(),
        file: s.file.clone(),
        is_abstract: s.is_abstract,
        defaults,
        params: params..attributes,
        attributes: attributes..d0,
        derived,
        v_slot: u + 1,
        checks,
        height,
        storeys,
        roof_type: s.roof_type.clone(),
        parts,
        names,
        material_slots,
    })
}

/// The template's `kind`, which decides where the city puts it.
fn kind_of(s: &Source) -> Result<Kind, String> {
    let Some(k) = &s.kind else {
        return Err(err(
            &s.name.loc,
            "`kind` is missing (machiya, kura, fence, gate, tree or person)",
        ));
    };
    Kind::ALL
        .iter()
        .find(|(n, _)| *n == k.value)
        .map(|x| x.1)
        .ok_or_else(|| {
            err(
                &k.loc,
                format!(
                    "unknown kind `{}` (machiya, kura, fence, gate, tree or person)",
                    k.value
                ),
            )
        })
}

/// The slots of a template's values, in order: inputs, parameters, attributes, derived
/// values, then `u` and `v`; with where each group starts.
struct ValueSlots {
    names: Vec<String>,
    /// Default values of the parameters and attributes, in slot order.
    defaults: Vec<f64>,
    params: usize,
    attributes: usize,
    derived: usize,
    /// The `u` slot (`v` follows it).
    u: usize,
}

/// Declares every name of the template once, refusing a name used twice or not a name.
fn declare_slots(s: &Source) -> Result<ValueSlots, String> {
    let mut names: Vec<String> = INPUTS.iter().map(|i| i.0.to_string()).collect();
    let mut defaults = Vec::new();
    let declare = |name: &str, loc: &Loc, names: &mut Vec<String>| -> Result<(), String> {
        if name == "u" || name == "v" || name == "pi" || names.iter().any(|n| n == name) {
            return Err(err(
                loc,
                format!(
                    "`{name}` is already a name (an input, parameter, attribute or derived value)"
                ),
            ));
        }
        if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(err(
                loc,
                format!("`{name}`: names are letters, digits and `_`"),
            ));
        }
        names.push(name.to_string());
        Ok(())
    };
    let params = names.len();
    for (k, v) in &s.params {
        declare(k, &v.loc, &mut names)?;
        defaults.push(v.value);
    }
    let attributes = names.len();
    for (k, v) in &s.attributes {
        declare(k, &v.loc, &mut names)?;
        defaults.push(v.value);
    }
    let derived = names.len();
    for (k, v) in &s.derived {
        declare(k, &v.loc, &mut names)?;
    }
    let u = names.len();
    names.push("u".into());
    names.push("v".into());
    Ok(ValueSlots {
        names,
        defaults,
        params,
        attributes,
        derived,
        u,
    })
}

/// The derived values compiled and ordered so that each needs only earlier ones; a cycle is
/// an error naming its members.
fn order_derived(
    s: &Source,
    scalar_names: &Names,
    names: &[String],
    d0: usize,
) -> Result<Vec<(usize, Expr, Loc)>, String> {
    let mut pending: BTreeMap<usize, (Expr, Loc, Vec<usize>)> = BTreeMap::new();
    for (i, (_, t)) in s.derived.iter().enumerate() {
        let e = scalar_names.compile(t)?;
        let mut deps = Vec::new();
        e.slots(&mut deps);
        deps.retain(|d| *d >= d0);
        pending.insert(d0 + i, (e, t.loc.clone(), deps));
    }
    let mut derived = Vec::new();
    let mut done = vec![false; names.len()];
    while !pending.is_empty() {
        let ready: Vec<usize> = pending
            .iter()
            .filter(|(_, (_, _, deps))| deps.iter().all(|d| done[*d]))
            .map(|(k, _)| *k)
            .collect();
        if ready.is_empty() {
            let cycle: Vec<&str> = pending.keys().map(|k| names[*k].as_str()).collect();
            let loc = &pending.values().next().expect("not empty").1;
            return Err(err(
                loc,
                format!(
                    "derived values depend on each other in a cycle: {}",
                    cycle.join(", ")
                ),
            ));
        }
        for k in ready {
            let (e, loc, _) = pending.remove(&k).expect("listed");
            done[k] = true;
            derived.push((k, e, loc));
        }
    }
    Ok(derived)
}

/// The `[materials]` slots with their library ids; a tree or person needs a `picture` slot
/// (the drawn texture replaces it).
fn material_slots(s: &Source, kind: Kind, here: &Loc) -> Result<Vec<(String, u16)>, String> {
    let mut slots = Vec::new();
    for (k, m) in &s.materials {
        let id = material_of(&[], m).map_err(|e| format!("{e} (material slot `{k}`)"))?;
        slots.push((k.clone(), id));
    }
    if matches!(kind, Kind::Tree | Kind::Person)
        && !s.is_abstract
        && !slots.iter().any(|(k, _)| k == "picture")
    {
        return Err(err(
            here,
            "a tree or person template needs a `picture` slot in `[materials]`: the texture \
             drawn for each billboard replaces it",
        ));
    }
    Ok(slots)
}

fn compile_part(p: &PartSource, scalar: &Names, all: &Names, slots: Slots) -> Result<Part, String> {
    let loc = p.name.loc.clone();
    let is_roof = !p.planes.is_empty() || p.hip_pitch.is_some() || p.hip_eave.is_some();
    let is_prism = p.top.is_some() || p.outline.is_some() || is_roof;
    let is_faces = !p.vertices.is_empty() || !p.faces.is_empty();
    let shape = match (is_prism, is_faces) {
        (true, true) => return Err(err(&loc, "a part is either a prism (`top`, `outline`) or explicit `vertices` and `faces`, not both")),
        (false, false) => return Err(err(&loc, "the part has neither `top` (a prism) nor `vertices` and `faces`")),
        (true, false) => {
            let roof = roof(p, scalar, all, &loc)?;
            let top = match (&p.top, &roof) {
                (Some(top), None) => all.compile(top)?,
                (None, Some(_)) => all.or(&None, 0.0)?,
                (None, None) => return Err(err(&loc, "a prism needs `top` (or a roof: `planes`, `hip_pitch`)")),
                (Some(_), Some(_)) => return Err(err(&loc, "a prism has either `top` or a roof (`planes`, `hip_pitch`), not both")),
            };
            let outline = match &p.outline {
                None => None,
                Some(Src { value: OutlineSource::Lot, .. }) => None,
                Some(Src { value: OutlineSource::Unknown(n), loc }) => {
                    return Err(err(loc, format!("outline `{n}`: give \"lot\" or a list of [u, v] points")))
                }
                Some(Src { value: OutlineSource::Points(pts), loc }) => {
                    if pts.len() < 3 {
                        return Err(err(loc, "an outline needs at least 3 points"));
                    }
                    Some(pts.iter().map(|pt| scalar.pair(pt, loc)).collect::<Result<_, _>>()?)
                }
            };
            if p.front_material.is_some() && p.front_height.is_none() {
                return Err(err(&loc, "`front_material` needs `front_height` (the height its texture spans)"));
            }
            Shape::Prism(Box::new(Prism {
                outline,
                v0: scalar.opt(&p.v0)?,
                v1: scalar.opt(&p.v1)?,
                u0: scalar.opt(&p.u0)?,
                u1: scalar.opt(&p.u1)?,
                bottom: all.or(&p.bottom, 0.0)?,
                top,
                roof,
                split: p.split.iter().map(|t| scalar.compile(t)).collect::<Result<_, _>>()?,
                split_u: p.split_u.iter().map(|t| scalar.compile(t)).collect::<Result<_, _>>()?,
                top_material: material(slots, &p.top_material, "kawara_roof")?,
                bottom_material: material(slots, &p.bottom_material, "floor")?,
                side_material: material(slots, &p.side_material, "shikkui_wall")?,
                front_material: p.front_material.as_ref().map(|m| material_of(slots, m)).transpose()?,
                front_base: scalar.or(&p.front_base, 1.818)?,
                front_height: scalar.or(&p.front_height, 1.0)?,
                closed: p.closed.unwrap_or(true),
            }))
        }
        (false, true) => {
            let vertices = p
                .vertices
                .iter()
                .map(|v| match v.value.as_slice() {
                    [a, b, c] => Ok([scalar.compile(a)?, scalar.compile(b)?, scalar.compile(c)?]),
                    other => Err(err(&v.loc, format!("a vertex is [u, v, h], got {} values", other.len()))),
                })
                .collect::<Result<Vec<_>, _>>()?;
            let mut faces = Vec::new();
            for f in &p.faces {
                if f.corners.value.len() < 3 {
                    return Err(err(&f.corners.loc, "a face needs at least 3 corners"));
                }
                let mut corners = Vec::new();
                for c in &f.corners.value {
                    if c.value < 1 || c.value as usize > vertices.len() {
                        return Err(err(&c.loc, format!("face corner {} is out of range: the part has vertices 1 to {}", c.value, vertices.len())));
                    }
                    corners.push(c.value as usize - 1);
                }
                let uv = match &f.uv {
                    None => None,
                    Some(uv) => {
                        if uv.value.len() != corners.len() {
                            return Err(err(&uv.loc, format!("{} texture coordinates for {} corners", uv.value.len(), corners.len())));
                        }
                        Some(uv.value.iter().map(|pt| scalar.pair(pt, &uv.loc)).collect::<Result<_, _>>()?)
                    }
                };
                faces.push(FaceSpec {
                    corners,
                    material: material_of(slots, &f.material)?,
                    uv,
                    base: scalar.or(&f.base, 2.0)?,
                });
            }
            Shape::Faces(Faces {
                vertices,
                faces,
                closed: p.closed.unwrap_or(true),
            })
        }
    };
    Ok(Part {
        name: p.name.value.clone(),
        loc,
        when: scalar.opt(&p.when)?,
        shape,
        installation: p.installation,
    })
}

/// A prism's roof keys, checked: `planes` and `hip_pitch` with `hip_eave`, optionally
/// `thickness`; never with `split` (the planes say where the roof bends).
fn roof(p: &PartSource, scalar: &Names, all: &Names, loc: &Loc) -> Result<Option<Roof>, String> {
    if p.planes.is_empty() && p.hip_pitch.is_none() && p.hip_eave.is_none() {
        if p.thickness.is_some() {
            return Err(err(
                loc,
                "`thickness` belongs to a roof (`planes`, `hip_pitch`); give `bottom` instead",
            ));
        }
        return Ok(None);
    }
    if !p.split.is_empty() || !p.split_u.is_empty() {
        return Err(err(
            loc,
            "a roof of `planes` bends where its planes cross: leave out `split` and `split_u`",
        ));
    }
    let hip = match (&p.hip_eave, &p.hip_pitch) {
        (Some(e), Some(pi)) => Some((scalar.compile(e)?, scalar.compile(pi)?)),
        (None, None) => None,
        _ => return Err(err(
            loc,
            "a hip roof needs both `hip_eave` (its eave height) and `hip_pitch` (rise per metre)",
        )),
    };
    if p.thickness.is_some() && p.bottom.is_some() {
        return Err(err(
            loc,
            "a roof slab has `thickness` or `bottom`, not both",
        ));
    }
    Ok(Some(Roof {
        planes: p
            .planes
            .iter()
            .map(|t| all.compile(t))
            .collect::<Result<_, _>>()?,
        hip,
        thickness: scalar.opt(&p.thickness)?,
    }))
}

/// The largest size of a derived value (areas and products of metres stay well below it).
pub const MAX_DERIVED: f64 = 1e6;

impl Template {
    /// Every scalar slot for one feature: the inputs, the params (defaults, then `overrides`),
    /// the attributes (defaults, then the feature's own, each within [`super::file::MAX_VALUE`]), then
    /// the derived values. A derived value that is not a finite number, or is larger than
    /// [`MAX_DERIVED`], is an error naming it.
    pub fn evaluate(
        &self,
        inputs: &[f64; N_INPUTS],
        overrides: &[(usize, f64)],
        attributes: &[(String, f64)],
        lot: &dyn Lot,
    ) -> Result<Vec<f64>, String> {
        let mut slots = vec![0.0; self.names.len()];
        slots[..N_INPUTS].copy_from_slice(inputs);
        slots[N_INPUTS..N_INPUTS + self.defaults.len()].copy_from_slice(&self.defaults);
        for (k, v) in overrides {
            slots[*k] = *v;
        }
        for (name, v) in attributes {
            if let Some(k) = self
                .attributes
                .clone()
                .find(|k| self.names[*k].eq_ignore_ascii_case(name))
            {
                if let Some(why) = value_problem(*v) {
                    return Err(format!(
                        "template {}: the feature's attribute `{name}` = {v} {why}",
                        self.name
                    ));
                }
                slots[k] = *v;
            }
        }
        for (k, e, loc) in &self.derived {
            let x = e.eval(&slots, lot);
            if !x.is_finite() || x.abs() > MAX_DERIVED {
                return Err(format!(
                    "template {}: `{}` ({loc}) is {x} for this feature (at most {MAX_DERIVED:e} \
                     in size)",
                    self.name, self.names[*k]
                ));
            }
            slots[*k] = x;
        }
        for (e, reason) in &self.checks {
            if e.eval(&slots, lot) == 0.0 {
                return Err(self.fill(reason, &slots));
            }
        }
        Ok(slots)
    }

    /// `reason` with every `{name}` replaced by that slot's value (2 decimals).
    fn fill(&self, reason: &str, slots: &[f64]) -> String {
        let mut out = String::new();
        let mut rest = reason;
        while let Some(i) = rest.find('{') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            match after.find('}') {
                Some(j) if self.slot(&after[..j]).is_some() => {
                    let k = self.slot(&after[..j]).expect("checked");
                    out.push_str(&format!("{:.2}", slots[k]));
                    rest = &after[j + 1..];
                }
                _ => {
                    out.push('{');
                    rest = after;
                }
            }
        }
        out.push_str(rest);
        out
    }

    /// A param's value with the parameter file's `overrides` (the last one wins).
    pub fn param(&self, overrides: &[(usize, f64)], name: &str) -> Option<f64> {
        let slot = self.params.clone().find(|s| self.names[*s] == name)?;
        Some(
            overrides
                .iter()
                .rev()
                .find(|(k, _)| *k == slot)
                .map_or(self.defaults[slot - N_INPUTS], |(_, v)| *v),
        )
    }

    /// The slot of a param or attribute name.
    pub fn slot(&self, name: &str) -> Option<usize> {
        self.names[..self.v_slot - 1].iter().position(|n| n == name)
    }

    /// Names of the params (what `[template.<name>]` may set), sorted.
    pub fn param_names(&self) -> Vec<&str> {
        let mut v: Vec<&str> = self.names[self.params.clone()]
            .iter()
            .map(String::as_str)
            .collect();
        v.sort_unstable();
        v
    }

    /// Names of the attributes a feature may give.
    pub fn attribute_names(&self) -> impl Iterator<Item = &str> {
        self.names[self.attributes.clone()]
            .iter()
            .map(String::as_str)
    }
}
