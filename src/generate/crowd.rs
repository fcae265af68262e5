//! A tile's walkers for formats that animate (GLB): a figure per picture, built once by the
//! people's template at 1 m tall, its foot at the origin, facing east; each walker is that
//! figure scaled to its height and moved along its clip. The OBJ, which cannot animate,
//! draws the same people where they stand at time 0 (the `people_walking` object).
//!
//! A figure is the template at one height scaled: exact for the shipped `person` template
//! (a quad whose size is its height times constants); a user's template that draws a person
//! otherwise at other heights is drawn as its 1 m figure scaled.

use std::collections::BTreeMap;

use super::mesh::{Frame, Mesh};
use crate::model::{PlannedBillboard, Walk};
use crate::params::Params;
use crate::templates::Catalog;

/// The walkers of a tile and the figures they are drawn with.
#[derive(Debug, Clone, Default)]
pub struct Crowd {
    /// One mesh per picture, named `figure_<texture>`.
    pub figures: Vec<Mesh>,
    /// The walkers, in the tile's order of people.
    pub walkers: Vec<Walker>,
}

/// One walker of a [`Crowd`].
#[derive(Debug, Clone)]
pub struct Walker {
    /// Its clip.
    pub walk: Walk,
    /// Its figure, an index into [`Crowd::figures`].
    pub figure: usize,
    /// Its height, metres: the figure's scale.
    pub height: f64,
}

impl Crowd {
    /// Every place its walkers reach (feet to head), in the meshes' frame (whole
    /// millimetres, x east, y up, z south, from `origin`): the tile's bounds must hold the
    /// whole clip, or a viewer culls walkers that have walked out of the tile's box.
    pub fn reach(&self, origin: [f64; 2]) -> Option<([i64; 3], [i64; 3])> {
        let mut out: Option<([i64; 3], [i64; 3])> = None;
        let mm = |v: f64| (v * 1000.0).round() as i64;
        for w in &self.walkers {
            for k in &w.walk.keys {
                let (x, z) = (mm(k.at[0] - origin[0]), mm(-(k.at[1] - origin[1])));
                let lo = [x, mm(k.at[2]), z];
                let hi = [x, mm(k.at[2] + w.height), z];
                out = Some(match out {
                    None => (lo, hi),
                    Some((a, b)) => (
                        [0, 1, 2].map(|i| a[i].min(lo[i])),
                        [0, 1, 2].map(|i| b[i].max(hi[i])),
                    ),
                });
            }
        }
        out
    }
}

/// The crowd of `people` (those of a tile with a clip in `walks`); `None` without walkers.
/// A walker whose figure cannot be built is left to the OBJ's copy (the reason is the
/// copy's skip).
pub fn build(
    people: &[&PlannedBillboard],
    walks: &[Walk],
    catalog: &Catalog,
    params: &Params,
) -> Option<Crowd> {
    let clips: BTreeMap<&str, &Walk> = walks.iter().map(|w| (w.id.as_str(), w)).collect();
    let mut crowd = Crowd::default();
    let mut figure_of: BTreeMap<&str, Option<usize>> = BTreeMap::new();
    for b in people {
        let Some(walk) = clips.get(b.id.as_str()) else {
            continue;
        };
        let figure = *figure_of.entry(&b.texture).or_insert_with(|| {
            let mut mesh = Mesh::new(format!("figure_{}", b.texture));
            let model = PlannedBillboard {
                at: geo_types::Coord { x: 0.0, y: 0.0 },
                facing: 0.0,
                ground: 0.0,
                height: 1.0,
                ..(*b).clone()
            };
            let frame = Frame { origin: [0.0, 0.0] };
            let template = &params.people.template;
            super::figure::build_one(
                &model,
                template,
                catalog,
                params.seed_for("people"),
                frame,
                &mut mesh,
            )
            .ok()
            .filter(|()| !mesh.faces.is_empty())
            .map(|()| {
                crowd.figures.push(mesh.finish());
                crowd.figures.len() - 1
            })
        });
        if let Some(figure) = figure {
            crowd.walkers.push(Walker {
                walk: (*walk).clone(),
                figure,
                height: b.height,
            });
        }
    }
    (!crowd.walkers.is_empty()).then_some(crowd)
}
