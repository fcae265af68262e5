//! Each object of a tile as a CityJSONFeature line: houses, kura, halls and landmarks as
//! `Building`s (an LoD1 block and the LoD2 model with semantic surfaces; the parts the
//! template calls installations as `BuildingInstallation` children), walls and gates as
//! `CityFurniture`, rock gardens as `PlantCover` with their stones as `CityFurniture`, trees
//! as `SolitaryVegetationObject`s, the ground as `LandUse`, the streets as `Road`, a DEM's
//! terrain as `TINRelief`. People are left out: a city model holds what stands.

use std::collections::BTreeMap;

use serde_json::{json, Map, Value};

use super::appearance::Appearance;
use super::geometry::{block, east_north_up, geometry, surfaces, Surface, Vertices};
use super::text;
use crate::generate::mesh::{open_edges_of, Mesh};
use crate::model::object::ObjectKind;
use crate::output::features::Feature;
use crate::output::palette::Palette;

/// What every feature of a tile shares.
pub struct Context<'a> {
    /// The tile's id (objects that span tiles are named per tile).
    pub tile: &'a str,
    /// The build's hypothesis: its parameters' fingerprint.
    pub hypothesis: &'a str,
    /// The materials' names, colours and textures.
    pub palette: Palette<'a>,
    /// Whether surfaces name their textures (`[output] cityjson_textures`).
    pub textures: bool,
}

/// Writes the CityJSONFeature line of one object into `out` (without its newline); false
/// for what a city model leaves out.
pub fn feature(out: &mut String, mesh: &Mesh, f: &Feature, cx: &Context) -> bool {
    if mesh.faces.is_empty() {
        return false;
    }
    match mesh.kind {
        k if k.is_building() => building(out, mesh, f, cx),
        ObjectKind::People | ObjectKind::Walkers | ObjectKind::Other => return false,
        kind => {
            let (ty, function) = match kind {
                ObjectKind::Fence => ("CityFurniture", Some("wall")),
                ObjectKind::Gate => ("CityFurniture", Some("gate")),
                ObjectKind::Stone => ("CityFurniture", Some("garden stone")),
                ObjectKind::Garden => ("PlantCover", Some("dry rock garden (karesansui)")),
                ObjectKind::Trees | ObjectKind::GrownTrees => ("SolitaryVegetationObject", None),
                ObjectKind::Ground => ("LandUse", None),
                ObjectKind::Streets => ("Road", None),
                _ => ("TINRelief", None),
            };
            other(out, mesh, f, cx, ty, function);
        }
    }
    true
}

/// A building: its body (the parts its template does not call installations) as LoD2, a
/// `Solid` when it is one closed part, else a `MultiSurface`; its LoD1 block; each
/// installation a child.
fn building(out: &mut String, mesh: &Mesh, f: &Feature, cx: &Context) {
    let facts = mesh.building.clone().unwrap_or_default();
    let ground = (facts.ground * 1000.0).round() as i64;
    let mut vertices = Vertices::default();
    let mut appearance = Appearance::new(cx.palette, cx.textures);
    let parts = part_ranges(mesh);
    let body: Vec<_> = parts.iter().filter(|p| !p.2).collect();
    let mut body_surfaces: Vec<Surface> = Vec::new();
    let mut points = Vec::new();
    for &&(start, end, _) in &body {
        let faces = &mesh.faces[start..end];
        points.extend(
            (faces.iter().flat_map(|fc| fc.corners.iter()))
                .map(|&(p, _)| east_north_up(mesh.positions[p as usize])),
        );
        body_surfaces.extend(surfaces(mesh, faces, ground, &mut vertices));
    }
    let closed = match body.as_slice() {
        [(start, end, _)] => open_edges_of(&mesh.faces[*start..*end]).is_empty(),
        _ => false,
    };
    let id = mesh.name.as_str();
    // The building's own object: its geometries first (they number the vertices).
    let mut geometries = String::from("[");
    if block(&mut geometries, &points, &mut vertices) && !body_surfaces.is_empty() {
        geometries.push(',');
    }
    if !body_surfaces.is_empty() {
        geometry(
            &mut geometries,
            mesh,
            &body_surfaces,
            "2",
            closed,
            &mut appearance,
            true,
        );
    }
    geometries.push(']');
    let top = points.iter().map(|p| p[2]).max().unwrap_or(ground);
    let mut attributes = base_attributes(f, cx);
    let mut put = |k: &str, v: Value| {
        attributes.insert(k.to_string(), v);
    };
    put("measuredHeight", json!((top - ground) as f64 / 1000.0));
    if let Some(n) = facts.storeys {
        put("storeysAboveGround", json!(n));
    }
    if let Some(r) = &facts.roof_type {
        put("roofType", json!(r));
    }
    if !facts.template.is_empty() {
        put("type", json!(facts.template));
    }
    if !f.street.is_empty() {
        put("street", json!(f.street));
    }
    // Its installations, each a child.
    let mut objects: BTreeMap<String, String> = BTreeMap::new();
    let mut children = Vec::new();
    for &(start, end, _) in parts.iter().filter(|p| p.2) {
        let name = part_name(mesh, start);
        let s = surfaces(mesh, &mesh.faces[start..end], ground, &mut vertices);
        if s.is_empty() {
            continue;
        }
        let child = format!("{id}-{name}");
        let mut o = String::from("{\"attributes\":");
        o.push_str(&json!({ "part": name }).to_string());
        o.push_str(",\"geometry\":[");
        geometry(&mut o, mesh, &s, "2", false, &mut appearance, true);
        o.push_str("],\"parents\":");
        o.push_str(&json!([id]).to_string());
        o.push_str(",\"type\":\"BuildingInstallation\"}");
        objects.insert(child.clone(), o);
        children.push(child);
    }
    let mut me = String::from("{\"attributes\":");
    me.push_str(&Value::Object(attributes).to_string());
    if !children.is_empty() {
        me.push_str(",\"children\":");
        me.push_str(&json!(children).to_string());
    }
    me.push_str(",\"geometry\":");
    me.push_str(&geometries);
    me.push_str(",\"type\":\"Building\"}");
    objects.insert(id.to_string(), me);
    wrap(out, id, &objects, &vertices, &appearance);
}

/// An object that is not a building: one geometry of all its faces, without semantics.
fn other(
    out: &mut String,
    mesh: &Mesh,
    f: &Feature,
    cx: &Context,
    ty: &str,
    function: Option<&str>,
) {
    let mut vertices = Vertices::default();
    let mut appearance = Appearance::new(cx.palette, cx.textures);
    let s = surfaces(mesh, &mesh.faces, 0, &mut vertices);
    let id = format!("{}-{}", mesh.name, cx.tile);
    let mut attributes = base_attributes(f, cx);
    if let Some(function) = function {
        attributes.insert("function".into(), json!(function));
    }
    let mut g = String::new();
    // A relief is a composite surface of its triangles.
    let relief = ty == "TINRelief";
    geometry(
        &mut g,
        mesh,
        &s,
        if relief { "1" } else { "2" },
        false,
        &mut appearance,
        false,
    );
    if relief {
        g = g.replace(
            "\"type\":\"MultiSurface\"}",
            "\"type\":\"CompositeSurface\"}",
        );
    }
    let mut o = String::from("{\"attributes\":");
    o.push_str(&Value::Object(attributes).to_string());
    o.push_str(",\"geometry\":[");
    o.push_str(&g);
    o.push_str("],\"type\":");
    text::string(&mut o, ty);
    o.push('}');
    let objects: BTreeMap<String, String> = [(id.clone(), o)].into_iter().collect();
    wrap(out, &id, &objects, &vertices, &appearance);
}

/// The attributes every object carries: its kind, lot and record, lot use, district, the
/// layer it came from, and the hypothesis.
fn base_attributes(f: &Feature, cx: &Context) -> Map<String, Value> {
    let mut a = Map::new();
    let mut text = |k: &str, v: &str| {
        if !v.is_empty() {
            a.insert(k.to_string(), json!(v));
        }
    };
    text("kind", &f.kind);
    text("lot", &f.lot);
    text("use", &f.lot_use);
    text("district", &f.district);
    text("source", &f.source);
    text("hypothesis", cx.hypothesis);
    if let Some(r) = f.record {
        a.insert("record".into(), json!(r));
    }
    if f.kura {
        a.insert("kura".into(), json!(true));
    }
    a
}

/// Writes a feature line: its city objects (each's JSON text, by id), its own vertices and
/// the appearance its geometries number. Keys in serde_json's order.
fn wrap(
    out: &mut String,
    id: &str,
    objects: &BTreeMap<String, String>,
    vertices: &Vertices,
    appearance: &Appearance,
) {
    out.push_str("{\"CityObjects\":{");
    for (i, (k, o)) in objects.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        text::string(out, k);
        out.push(':');
        out.push_str(o);
    }
    out.push('}');
    if !appearance.is_empty() {
        out.push_str(",\"appearance\":");
        appearance.write(out);
    }
    out.push_str(",\"id\":");
    text::string(out, id);
    out.push_str(",\"type\":\"CityJSONFeature\",\"vertices\":");
    vertices.write(out);
    out.push('}');
}

/// Each part's faces as (first, end, installation); a mesh without parts (a landmark's
/// model) is one body part.
fn part_ranges(mesh: &Mesh) -> Vec<(usize, usize, bool)> {
    if mesh.parts.is_empty() {
        return vec![(0, mesh.faces.len(), false)];
    }
    let n = mesh.faces.len();
    let mut out = Vec::new();
    for (i, p) in mesh.parts.iter().enumerate() {
        let start = (p.first_face as usize).min(n);
        let end = mesh
            .parts
            .get(i + 1)
            .map_or(n, |q| (q.first_face as usize).min(n));
        if end > start {
            out.push((start, end, p.installation));
        }
    }
    out
}

/// The name of the part whose faces start at `start`.
fn part_name(mesh: &Mesh, start: usize) -> &str {
    (mesh.parts.iter())
        .find(|p| p.first_face as usize == start)
        .map_or("part", |p| p.name.as_str())
}
