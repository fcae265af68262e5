//! `edo-city template`: one template built alone on a rectangular site, for authoring.
//!
//! A historian editing a template wants to see it without building a city: this builds it
//! on a `width` x `depth` lot facing a street along x, and writes an OBJ with its MTL and
//! textures beside it, ready for Blender or a web viewer.

use std::path::Path;

use crate::generate::instance::{instantiate, Site};
use crate::generate::mesh::{open_edges, Frame, Mesh};

use crate::output::ModelError;
use crate::params::Params;
use crate::templates::template::{SiteInputs, N_INPUTS};
use crate::templates::{Catalog, Template};

/// Why a template cannot be built alone.
#[derive(Debug, thiserror::Error)]
pub enum AuthorError {
    /// The site's width and depth, metres.
    #[error("the site must be positive, got {0} x {1} m")]
    Site(f64, f64),
    /// `--set` names a parameter the template does not have.
    #[error("--set {key}: {template} has no parameter `{key}` (its parameters: {known})")]
    NoParameter {
        /// The name given.
        key: String,
        /// The template.
        template: String,
        /// Its parameters, comma-separated.
        known: String,
    },
    /// `--set` gives a value no template may take.
    #[error("--set {key}={value}: {why}")]
    Value {
        /// The parameter.
        key: String,
        /// The value.
        value: f64,
        /// What is wrong with it.
        why: String,
    },
    /// The template's expressions or parts fail on this site (their own message).
    #[error("{0}")]
    Template(String),
}

/// A template built alone.
#[derive(Debug)]
pub struct Alone {
    /// The template's mesh, built on the rectangle.
    pub mesh: Mesh,
    /// The height the template declares, metres (None when it declares none).
    pub declared_height: Option<f64>,
    /// The highest point of the mesh, metres.
    pub top: f64,
    /// Names of the parts whose `when` held.
    pub parts: Vec<String>,
}

/// The inputs of a rectangle `width` x `depth` at the origin, frontage along x.
pub fn rectangle_inputs(width: f64, depth: f64, params: &Params) -> [f64; N_INPUTS] {
    SiteInputs {
        width,
        lot_depth: depth,
        b: geo_types::Coord { x: width, y: 0.0 },
        centroid: geo_types::Coord {
            x: width / 2.0,
            y: depth / 2.0,
        },
        id: "",
        machiya_depth: params.machiya.depth,
        min_depth: params.machiya.min_depth,
        random: 0.5,
        ..SiteInputs::default()
    }
    .slots()
}

/// Builds template `t` on a `width` x `depth` rectangle with the parameter file's values for
/// it, then `sets` (param name, value) on top.
pub fn build_alone(
    catalog: &Catalog,
    t: &Template,
    width: f64,
    depth: f64,
    params: &Params,
    sets: &[(String, f64)],
) -> Result<Alone, AuthorError> {
    if !(width > 0.0 && depth > 0.0 && width.is_finite() && depth.is_finite()) {
        return Err(AuthorError::Site(width, depth));
    }
    let mut overrides = catalog.overrides(&t.name, None);
    for (k, v) in sets {
        let slot = t
            .params
            .clone()
            .find(|s| t.names[*s] == *k)
            .ok_or_else(|| AuthorError::NoParameter {
                key: k.clone(),
                template: t.name.clone(),
                known: t.param_names().join(", "),
            })?;
        if let Some(why) = crate::templates::file::value_problem(*v) {
            let (key, value) = (k.clone(), *v);
            return Err(AuthorError::Value { key, value, why });
        }
        overrides.push((slot, *v));
    }
    let site = Site::rectangle(width, depth);
    let slots = t
        .evaluate(
            &rectangle_inputs(width, depth, params),
            &overrides,
            &[],
            &site,
        )
        .map_err(AuthorError::Template)?;
    let mut mesh = Mesh::new(t.name.clone());
    instantiate(t, &slots, &site, Frame { origin: [0.0, 0.0] }, &mut mesh)
        .map_err(AuthorError::Template)?;
    let parts = t
        .parts
        .iter()
        .filter(|p| p.when.as_ref().is_none_or(|w| w.eval(&slots, &site) != 0.0))
        .map(|p| p.name.clone())
        .collect();
    let top = mesh.positions.iter().map(|p| p[1]).max().unwrap_or(0) as f64 / 1000.0;
    Ok(Alone {
        declared_height: t.height.as_ref().map(|(e, _)| e.eval(&slots, &site)),
        mesh: mesh.finish(),
        top,
        parts,
    })
}

/// Writes `<stem>.obj`, `<stem>.mtl` and `textures/` into the OBJ's directory.
pub fn write(alone: &Alone, obj_path: &Path, texture_set: &str) -> Result<usize, ModelError> {
    crate::output::write_model(obj_path, std::slice::from_ref(&alone.mesh), texture_set)
}

/// True when every edge of the mesh is shared by two faces (for the summary line).
pub fn is_closed(mesh: &Mesh) -> bool {
    open_edges(mesh).is_empty()
}
