//! The text of a template file: a TOML schema whose every expression remembers where it was
//! written, so that errors found after parsing still point at `file:line:column`.

use std::collections::BTreeMap;

use serde::Deserialize;
use toml::Spanned;

/// A number or an expression, as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum NumOrText {
    Int(i64),
    Float(f64),
    Text(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTemplate {
    name: Spanned<String>,
    #[serde(default)]
    kanji: String,
    kind: Option<Spanned<String>>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    aliases: Vec<String>,
    extends: Option<Spanned<String>>,
    #[serde(default, rename = "abstract")]
    is_abstract: bool,
    height: Option<Spanned<NumOrText>>,
    storeys: Option<Spanned<NumOrText>>,
    roof_type: Option<String>,
    #[serde(default)]
    params: BTreeMap<String, Spanned<f64>>,
    #[serde(default)]
    attributes: BTreeMap<String, Spanned<f64>>,
    #[serde(default)]
    derived: BTreeMap<String, Spanned<NumOrText>>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<String>>,
    #[serde(default)]
    check: Vec<RawCheck>,
    #[serde(default)]
    part: Vec<RawPart>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCheck {
    expr: Spanned<NumOrText>,
    reason: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPart {
    name: Spanned<String>,
    when: Option<Spanned<NumOrText>>,
    // A prism: an outline cut to a band and extruded.
    outline: Option<Spanned<RawOutline>>,
    v0: Option<Spanned<NumOrText>>,
    v1: Option<Spanned<NumOrText>>,
    u0: Option<Spanned<NumOrText>>,
    u1: Option<Spanned<NumOrText>>,
    bottom: Option<Spanned<NumOrText>>,
    top: Option<Spanned<NumOrText>>,
    #[serde(default)]
    split: Vec<Spanned<NumOrText>>,
    #[serde(default)]
    split_u: Vec<Spanned<NumOrText>>,
    #[serde(default)]
    planes: Vec<Spanned<NumOrText>>,
    hip_eave: Option<Spanned<NumOrText>>,
    hip_pitch: Option<Spanned<NumOrText>>,
    thickness: Option<Spanned<NumOrText>>,
    top_material: Option<Spanned<String>>,
    bottom_material: Option<Spanned<String>>,
    side_material: Option<Spanned<String>>,
    front_material: Option<Spanned<String>>,
    front_base: Option<Spanned<NumOrText>>,
    front_height: Option<Spanned<NumOrText>>,
    #[serde(default)]
    installation: bool,
    // Explicit vertices and faces.
    #[serde(default)]
    vertices: Vec<Spanned<Vec<Spanned<NumOrText>>>>,
    #[serde(default)]
    faces: Vec<RawFace>,
    closed: Option<bool>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum RawOutline {
    Named(String),
    // Spans do not survive an untagged enum: points are located at the outline.
    Points(Vec<Vec<NumOrText>>),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFace {
    corners: Spanned<Vec<Spanned<i64>>>,
    material: Spanned<String>,
    uv: Option<Spanned<Vec<Vec<Spanned<NumOrText>>>>>,
    base: Option<Spanned<NumOrText>>,
}

/// Where something was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Loc(pub String);

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// A value as written, with its place.
#[derive(Debug, Clone)]
pub struct Src<T> {
    /// The value.
    pub value: T,
    /// Where it was written.
    pub loc: Loc,
}

/// An expression's text (numbers become their decimal text).
pub type Text = Src<String>;

/// A template file, read but not yet compiled or merged with the template it extends.
#[derive(Debug, Clone)]
pub struct Source {
    /// The file it was read from.
    pub file: String,
    /// The template's name (`name`, else the file's stem).
    pub name: Src<String>,
    /// Its name in kanji.
    pub kanji: String,
    /// Its kind (machiya, kura, fence, gate, tree, person).
    pub kind: Option<Src<String>>,
    /// What it models, for `edo-city template`.
    pub description: String,
    /// Other spellings of a machiya type's name in the data.
    pub aliases: Vec<String>,
    /// The template it extends.
    pub extends: Option<Src<String>>,
    /// Whether it only serves to be extended (never built itself).
    pub is_abstract: bool,
    /// The height the model declares (tests hold the mesh to it).
    pub height: Option<Text>,
    /// Its storeys above ground, for a city model (`storeys`).
    pub storeys: Option<Text>,
    /// Its roof's form, for a city model (`roof_type`: gable, hip, hip-and-gable, ...).
    pub roof_type: Option<String>,
    /// Parameters with their defaults (a parameter file may set them).
    pub params: Vec<(String, Src<f64>)>,
    /// Attributes with their defaults (a lot's field of the same name sets them).
    pub attributes: Vec<(String, Src<f64>)>,
    /// Derived values, as expressions.
    pub derived: Vec<(String, Text)>,
    /// Material slots: a part's material may name a slot, which names a library material.
    pub materials: Vec<(String, Src<String>)>,
    /// Conditions every feature must meet, with the reason given when one fails.
    pub checks: Vec<(Text, String)>,
    /// The parts, in file order.
    pub parts: Vec<PartSource>,
}

/// One `[[part]]` as written.
#[derive(Debug, Clone)]
pub struct PartSource {
    /// Its name, unique in the template.
    pub name: Src<String>,
    /// Built only where this is not 0.
    pub when: Option<Text>,
    /// `lot` or a list of (u, v) points.
    pub outline: Option<Src<OutlineSource>>,
    /// The band it is cut to: from depth `v0` ...
    pub v0: Option<Text>,
    /// ... to `v1` ...
    pub v1: Option<Text>,
    /// ... and along the street from `u0` ...
    pub u0: Option<Text>,
    /// ... to `u1`.
    pub u1: Option<Text>,
    /// Height of its underside, a function of u and v.
    pub bottom: Option<Text>,
    /// Height of its top.
    pub top: Option<Text>,
    /// Depths where the top bends (a ridge).
    pub split: Vec<Text>,
    /// Positions along the street where it bends.
    pub split_u: Vec<Text>,
    /// A roof as the lower envelope of planes, each linear in u and v.
    pub planes: Vec<Text>,
    /// A hip roof on the outline: one plane per edge from this eave height ...
    pub hip_eave: Option<Text>,
    /// ... rising at this pitch.
    pub hip_pitch: Option<Text>,
    /// A roof slab: the bottom is the top this much lower.
    pub thickness: Option<Text>,
    /// Material of the top faces.
    pub top_material: Option<Src<String>>,
    /// Material of the bottom faces.
    pub bottom_material: Option<Src<String>>,
    /// Material of the side walls.
    pub side_material: Option<Src<String>>,
    /// Material of the front wall, textured as a facade.
    pub front_material: Option<Src<String>>,
    /// The facade texture's width, metres (one repeat).
    pub front_base: Option<Text>,
    /// The facade texture's height, metres.
    pub front_height: Option<Text>,
    /// Explicit vertices (u, v, h).
    pub vertices: Vec<Src<Vec<Text>>>,
    /// Explicit faces over them.
    pub faces: Vec<FaceSource>,
    /// Whether the part must be a closed shell.
    pub closed: Option<bool>,
    /// Whether a city model holds it as an installation of the building (a pent roof, a
    /// board facade, a gate, a porch), not as the building's own body.
    pub installation: bool,
}

/// A prism's outline as written.
#[derive(Debug, Clone)]
pub enum OutlineSource {
    /// The lot itself.
    Lot,
    /// A name other than `lot` (reported when compiled).
    Unknown(String),
    /// (u, v) points.
    Points(Vec<Vec<Text>>),
}

/// One explicit face as written.
#[derive(Debug, Clone)]
pub struct FaceSource {
    /// Its vertices, 1-based.
    pub corners: Src<Vec<Src<i64>>>,
    /// Its material (a slot or a library name).
    pub material: Src<String>,
    /// Texture coordinates per corner.
    pub uv: Option<Src<Vec<Vec<Text>>>>,
    /// The texture repeat, metres, when the coordinates are projected.
    pub base: Option<Text>,
}

pub use crate::model::source::line_col;

fn as_text(x: NumOrText) -> String {
    match x {
        NumOrText::Int(i) => i.to_string(),
        // `{:?}` keeps a decimal point, so the expression reads as a float.
        NumOrText::Float(f) => format!("{f:?}"),
        NumOrText::Text(t) => t,
    }
}

struct Ctx<'a> {
    file: &'a str,
    text: &'a str,
}

impl Ctx<'_> {
    fn loc(&self, span: std::ops::Range<usize>) -> Loc {
        let (l, c) = line_col(self.text, span.start);
        Loc(format!("{}:{l}:{c}", self.file))
    }
    fn src<T>(&self, s: Spanned<T>) -> Src<T> {
        let loc = self.loc(s.span());
        Src {
            value: s.into_inner(),
            loc,
        }
    }
    fn text(&self, s: Spanned<NumOrText>) -> Text {
        let loc = self.loc(s.span());
        Src {
            value: as_text(s.into_inner()),
            loc,
        }
    }
    fn plain(&self, x: NumOrText, loc: &Loc) -> Text {
        Src {
            value: as_text(x),
            loc: loc.clone(),
        }
    }
    fn opt(&self, s: Option<Spanned<NumOrText>>) -> Option<Text> {
        s.map(|s| self.text(s))
    }
    fn list(&self, v: Vec<Spanned<NumOrText>>) -> Vec<Text> {
        v.into_iter().map(|s| self.text(s)).collect()
    }
}

/// Parses one template file. The error is `file:line:column: message`.
pub fn parse(file: &str, text: &str) -> Result<Source, String> {
    let raw: RawTemplate =
        toml::from_str(text).map_err(|e| crate::model::source::toml_error(file, text, &e))?;
    let cx = Ctx { file, text };
    // A template's own numbers are bounded as a parameter file's are.
    let nums = |m: BTreeMap<String, Spanned<f64>>| -> Result<Vec<(String, Src<f64>)>, String> {
        m.into_iter()
            .map(|(k, v)| {
                let s = cx.src(v);
                match value_problem(s.value) {
                    Some(why) => Err(format!("{}: `{k}` = {} {why}", s.loc, s.value)),
                    None => Ok((k, s)),
                }
            })
            .collect()
    };
    let parts = raw
        .part
        .into_iter()
        .map(|p| PartSource {
            name: cx.src(p.name),
            when: cx.opt(p.when),
            outline: p.outline.map(|o| {
                let loc = cx.loc(o.span());
                let value = match o.into_inner() {
                    RawOutline::Named(n) if n == "lot" => OutlineSource::Lot,
                    RawOutline::Named(n) => OutlineSource::Unknown(n),
                    RawOutline::Points(pts) => OutlineSource::Points(
                        pts.into_iter()
                            .map(|p| p.into_iter().map(|x| cx.plain(x, &loc)).collect())
                            .collect(),
                    ),
                };
                Src { value, loc }
            }),
            v0: cx.opt(p.v0),
            v1: cx.opt(p.v1),
            u0: cx.opt(p.u0),
            u1: cx.opt(p.u1),
            bottom: cx.opt(p.bottom),
            top: cx.opt(p.top),
            split: cx.list(p.split),
            split_u: cx.list(p.split_u),
            planes: cx.list(p.planes),
            hip_eave: cx.opt(p.hip_eave),
            hip_pitch: cx.opt(p.hip_pitch),
            thickness: cx.opt(p.thickness),
            top_material: p.top_material.map(|s| cx.src(s)),
            bottom_material: p.bottom_material.map(|s| cx.src(s)),
            side_material: p.side_material.map(|s| cx.src(s)),
            front_material: p.front_material.map(|s| cx.src(s)),
            front_base: cx.opt(p.front_base),
            front_height: cx.opt(p.front_height),
            vertices: p
                .vertices
                .into_iter()
                .map(|v| {
                    let loc = cx.loc(v.span());
                    Src {
                        value: cx.list(v.into_inner()),
                        loc,
                    }
                })
                .collect(),
            faces: p
                .faces
                .into_iter()
                .map(|f| FaceSource {
                    corners: {
                        let loc = cx.loc(f.corners.span());
                        Src {
                            value: f
                                .corners
                                .into_inner()
                                .into_iter()
                                .map(|c| cx.src(c))
                                .collect(),
                            loc,
                        }
                    },
                    material: cx.src(f.material),
                    uv: f.uv.map(|uv| {
                        let loc = cx.loc(uv.span());
                        Src {
                            value: uv.into_inner().into_iter().map(|p| cx.list(p)).collect(),
                            loc,
                        }
                    }),
                    base: cx.opt(f.base),
                })
                .collect(),
            closed: p.closed,
            installation: p.installation,
        })
        .collect();
    Ok(Source {
        file: file.to_string(),
        name: cx.src(raw.name),
        kanji: raw.kanji,
        kind: raw.kind.map(|k| cx.src(k)),
        description: raw.description,
        aliases: raw.aliases,
        extends: raw.extends.map(|e| cx.src(e)),
        is_abstract: raw.is_abstract,
        height: cx.opt(raw.height),
        storeys: cx.opt(raw.storeys),
        roof_type: raw.roof_type,
        params: nums(raw.params)?,
        attributes: nums(raw.attributes)?,
        derived: raw
            .derived
            .into_iter()
            .map(|(k, v)| (k, cx.text(v)))
            .collect(),
        materials: raw
            .materials
            .into_iter()
            .map(|(k, v)| (k, cx.src(v)))
            .collect(),
        checks: raw
            .check
            .into_iter()
            .map(|c| (cx.text(c.expr), c.reason))
            .collect(),
        parts,
    })
}

/// `child` on top of the template it extends: its params, attributes and derived values
/// replace those of the same name, its parts replace parts of the same name and are added
/// after the others, and whatever it leaves out comes from `base`.
pub fn merge(base: &Source, child: &Source) -> Source {
    fn over<T: Clone>(base: &[(String, T)], child: &[(String, T)]) -> Vec<(String, T)> {
        let mut out: Vec<(String, T)> = base
            .iter()
            .filter(|(k, _)| !child.iter().any(|(c, _)| c == k))
            .cloned()
            .collect();
        out.extend(child.iter().cloned());
        out
    }
    let mut parts: Vec<PartSource> = base
        .parts
        .iter()
        .map(|p| {
            child
                .parts
                .iter()
                .find(|c| c.name.value == p.name.value)
                .unwrap_or(p)
                .clone()
        })
        .collect();
    parts.extend(
        child
            .parts
            .iter()
            .filter(|c| !base.parts.iter().any(|p| p.name.value == c.name.value))
            .cloned(),
    );
    Source {
        file: child.file.clone(),
        name: child.name.clone(),
        kanji: child.kanji.clone(),
        kind: child.kind.clone().or_else(|| base.kind.clone()),
        description: child.description.clone(),
        aliases: child.aliases.clone(),
        extends: None,
        is_abstract: child.is_abstract,
        height: child.height.clone().or_else(|| base.height.clone()),
        storeys: child.storeys.clone().or_else(|| base.storeys.clone()),
        roof_type: child.roof_type.clone().or_else(|| base.roof_type.clone()),
        params: over(&base.params, &child.params),
        attributes: over(&base.attributes, &child.attributes),
        derived: over(&base.derived, &child.derived),
        materials: over(&base.materials, &child.materials),
        checks: base.checks.iter().chain(&child.checks).cloned().collect(),
        parts,
    }
}

/// The largest size of a number a user gives a template (a parameter's default or the
/// parameter file's value, `--set`, a feature's attribute): metres, degrees and counts of a
/// building are far below it; 1e7 made a house 10,000 km tall.
pub const MAX_VALUE: f64 = 1000.0;
/// Why `v` cannot be a value a user gives a template, or `None`.
pub fn value_problem(v: f64) -> Option<String> {
    if !v.is_finite() {
        Some("is not a number".into())
    } else if v.abs() > MAX_VALUE {
        Some(format!(
            "is larger than a building's numbers may be (at most {MAX_VALUE} in size): give \
             it in metres, degrees or a count"
        ))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locations_are_line_and_column() {
        let text = "name = \"x\"\n[params]\nwidth2 = 3\n[derived]\nd = \"width2 * 2\"\n";
        let s = parse("t.toml", text).unwrap();
        assert_eq!(s.derived[0].1.loc.0, "t.toml:5:5");
        assert_eq!(s.derived[0].1.value, "width2 * 2");
        assert_eq!(s.params[0].1.value, 3.0);
    }

    #[test]
    fn numbers_become_float_text() {
        let s = parse("t.toml", "name = \"x\"\nheight = 7\n[derived]\na = 2.5\n").unwrap();
        assert_eq!(s.height.unwrap().value, "7");
        assert_eq!(s.derived[0].1.value, "2.5");
    }

    #[test]
    fn toml_errors_point_at_the_line() {
        let e = parse("t.toml", "name = \"x\"\nbogus = 1\n").unwrap_err();
        assert!(e.starts_with("t.toml:2:1:"), "{e}");
        let e = parse("t.toml", "name = \"x\"\n[[part]]\nname = \"p\"\ntop = [\n").unwrap_err();
        assert!(e.starts_with("t.toml:4:"), "{e}");
    }
}
