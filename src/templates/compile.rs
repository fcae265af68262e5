//! A template's source compiled: its names made slots, its expressions compiled against
//! them, its materials made library ids, its derived values put in an order where each needs
//! only earlier ones, each part's shape and roof checked. Everything a template can get wrong
//! is found here, when the catalog loads, with the file and line.

use std::collections::BTreeMap;

use super::expr::{compile, Expr};
use super::file::{Loc, OutlineSource, PartSource, Source, Src, Text};
use super::template::{FaceSpec, Faces, Kind, Part, Prism, Roof, Shape, Template, INPUTS};
use crate::materials;

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
