//! Each object of a tile as a CityJSONFeature: houses, kura, halls and landmarks as
//! `Building`s (an LoD1 block and the LoD2 model with semantic surfaces; the parts the
//! template calls installations as `BuildingInstallation` children), walls and gates as
//! `CityFurniture`, rock gardens as `PlantCover` with their stones as `CityFurniture`, trees
//! as `SolitaryVegetationObject`s, the ground as `LandUse`, the streets as `Road`, a DEM's
//! terrain as `TINRelief`. People are left out: a city model holds what stands.

use serde_json::{json, Map, Value};

use super::geometry::{block, geometry, surfaces, Surface, Vertices};
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
    /// The materials' names and colours.
    pub palette: Palette<'a>,
}

/// The CityJSONFeature of one object, or `None` for what a city model leaves out.
pub fn feature(mesh: &Mesh, f: &Feature, cx: &Context) -> Option<Value> {
    if mesh.faces.is_empty() {
        return None;
    }
    match mesh.kind {
        k if k.is_building() => Some(building(mesh, f, cx)),
        ObjectKind::People | ObjectKind::Walkers | ObjectKind::Other => None,
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
            Some(other(mesh, f, cx, ty, function))
        }
    }
}

/// A building: its body (the parts its template does not call installations) as LoD2, a
/// `Solid` when it is one closed part, else a `MultiSurface`; its LoD1 block; each
/// installation a child.
fn building(mesh: &Mesh, f: &Feature, cx: &Context) -> Value {
    let facts = mesh.building.clone().unwrap_or_default();
    let ground = (facts.ground * 1000.0).round() as i64;
    let mut vertices = Vertices::default();
    let mut materials = Vec::new();
    let parts = part_ranges(mesh);
    let body: Vec<_> = parts.iter().filter(|p| !p.2).collect();
    let mut body_surfaces: Vec<Surface> = Vec::new();
    let mut points = Vec::new();
    for &&(start, end, _) in &body {
        let faces = &mesh.faces[start..end];
        points.extend(
            (faces.iter().flat_map(|fc| fc.corners.iter()))
                .map(|&(p, _)| super::geometry::east_north_up(mesh.positions[p as usize])),
        );
        body_surfaces.extend(surfaces(mesh, faces, ground, &mut vertices));
    }
    let closed = match body.as_slice() {
        [(start, end, _)] => open_edges_of(&mesh.faces[*start..*end]).is_empty(),
        _ => false,
    };
    let id = mesh.name.clone();
    let mut geometries = Vec::new();
    if let Some(lod1) = block(&points, &mut vertices) {
        geometries.push(lod1);
    }
    if !body_surfaces.is_empty() {
        geometries.push(geometry(&body_surfaces, "2", closed, &mut materials, true));
    }
    let top = points.iter().map(|p| p[2]).max().unwrap_or(ground);
    let mut attributes = base_attributes(f, cx);
    let mut put = |k: &str, v: Value| {
        attributes.insert(k.to_string(), v);
    };
    put("measuredHeight", json!(round_mm(top - ground)));
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
    let mut objects = Map::new();
    let mut children = Vec::new();
    for &(start, end, _) in parts.iter().filter(|p| p.2) {
        let name = part_name(mesh, start);
        let s = surfaces(mesh, &mesh.faces[start..end], ground, &mut vertices);
        if s.is_empty() {
            continue;
        }
        let child = format!("{id}-{name}");
        objects.insert(
            child.clone(),
            json!({
                "type": "BuildingInstallation",
                "parents": [id],
                "attributes": {"part": name},
                "geometry": [geometry(&s, "2", false, &mut materials, true)],
            }),
        );
        children.push(child);
    }
    let mut me = json!({
        "type": "Building",
        "attributes": attributes,
        "geometry": geometries,
    });
    if !children.is_empty() {
        me["children"] = json!(children);
    }
    objects.insert(id.clone(), me);
    wrap(id, objects, &vertices, &materials, cx)
}

/// An object that is not a building: one geometry of all its faces, without semantics.
fn other(mesh: &Mesh, f: &Feature, cx: &Context, ty: &str, function: Option<&str>) -> Value {
    let mut vertices = Vertices::default();
    let mut materials = Vec::new();
    let s = surfaces(mesh, &mesh.faces, 0, &mut vertices);
    let id = format!("{}-{}", mesh.name, cx.tile);
    let mut attributes = base_attributes(f, cx);
    if let Some(function) = function {
        attributes.insert("function".into(), json!(function));
    }
    let g = match ty {
        // A relief is a composite surface of its triangles.
        "TINRelief" => {
            let mut g = geometry(&s, "1", false, &mut materials, false);
            g["type"] = json!("CompositeSurface");
            g
        }
        _ => geometry(&s, "2", false, &mut materials, false),
    };
    let mut objects = Map::new();
    objects.insert(
        id.clone(),
        json!({"type": ty, "attributes": attributes, "geometry": [g]}),
    );
    wrap(id, objects, &vertices, &materials, cx)
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

/// A feature line's object: its city objects, its own vertices and the materials its
/// geometries number (their names and colours).
pub fn wrap(
    id: String,
    objects: Map<String, Value>,
    vertices: &Vertices,
    materials: &[u16],
    cx: &Context,
) -> Value {
    let mut v = json!({
        "type": "CityJSONFeature",
        "id": id,
        "CityObjects": objects,
        "vertices": vertices.json(),
    });
    if !materials.is_empty() {
        let list: Vec<Value> = (materials.iter())
            .map(|&m| {
                let e = cx.palette.get(m);
                json!({
                    "name": e.name,
                    "diffuseColor": e.kd.map(|c| round_colour(c as f64)),
                })
            })
            .collect();
        v["appearance"] = json!({"materials": list});
    }
    v
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

/// Millimetres as metres, to the millimetre.
fn round_mm(mm: i64) -> f64 {
    mm as f64 / 1000.0
}

/// A colour channel to three decimals (the library's colours are given so).
fn round_colour(c: f64) -> f64 {
    (c.clamp(0.0, 1.0) * 1000.0).round() / 1000.0
}
