//! A compiled template: every expression resolved to slots, every material to its id, checked
//! once when the catalog loads (`compile.rs`) so that a build never starts with a broken
//! template; evaluated here for each feature.

use std::ops::Range;

use geo_types::Coord;

use super::expr::{Expr, Lot};
use super::file::{value_problem, Loc};

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
