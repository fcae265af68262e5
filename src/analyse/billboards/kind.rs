//! The settings of one kind of billboard (people or trees) read from the parameter file, and
//! how a drawn point is dressed: height, texture, facing and thinning key.

use geo_types::Coord;
use rand::RngExt;

use super::Candidate;
use crate::model::{BillboardKind, PlannedBillboard};
use crate::params::Params;

/// The settings of one kind of billboard.
pub(super) struct Kind<'a> {
    pub(super) kind: BillboardKind,
    pub(super) enabled: bool,
    pub(super) layer: &'static str,
    pub(super) file: &'a str,
    pub(super) height: [f64; 2],
    pub(super) textures: &'a [String],
    pub(super) min_spacing: f64,
    pub(super) clearance: f64,
    pub(super) max_per_tile: usize,
    pub(super) max_turn: f64,
    /// The parameter that sets the density, for messages.
    pub(super) density_key: &'static str,
}

impl<'a> Kind<'a> {
    pub(super) fn of(kind: BillboardKind, p: &'a Params) -> Kind<'a> {
        match kind {
            BillboardKind::Person => Kind {
                kind,
                enabled: p.people.enabled,
                layer: "people",
                file: &p.layers.people.file,
                height: p.people.height,
                textures: &p.people.textures,
                min_spacing: p.people.min_spacing,
                clearance: p.people.clearance,
                max_per_tile: p.people.max_points_per_tile,
                max_turn: p.people.max_turn_deg.to_radians(),
                density_key: "people.per_100m",
            },
            BillboardKind::Tree => Kind {
                kind,
                enabled: p.trees.enabled,
                layer: "trees",
                file: &p.layers.trees.file,
                height: p.trees.height,
                textures: &p.trees.textures,
                min_spacing: p.trees.min_spacing,
                clearance: p.trees.clearance,
                max_per_tile: p.trees.max_points_per_tile,
                max_turn: std::f64::consts::PI,
                density_key: "trees.per_ha / trees.per_ha_machiya",
            },
        }
    }

    /// Height, texture, facing and key of a point, drawn from `rng` (or taken from the point).
    pub(super) fn dress(
        &self,
        rng: &mut impl rand::Rng,
        id: String,
        at: Coord<f64>,
        along: f64,
        (district, ground): (Option<String>, f64),
        tile_of: impl Fn(Coord<f64>) -> String,
    ) -> Candidate {
        let [lo, hi] = self.height;
        let height = lo + rng.random::<f64>() * (hi - lo);
        let texture = self.textures[rng.random_range(0..self.textures.len())].clone();
        // A person walks either way along the street, turned by at most max_turn; a tree
        // turns freely (its two quads repeat every quarter turn).
        let facing = match self.kind {
            BillboardKind::Person => {
                let back = if rng.random_bool(0.5) {
                    std::f64::consts::PI
                } else {
                    0.0
                };
                along + back + (2.0 * rng.random::<f64>() - 1.0) * self.max_turn
            }
            BillboardKind::Tree => rng.random::<f64>() * std::f64::consts::FRAC_PI_2,
        };
        Candidate {
            key: rng.random::<u64>(),
            b: PlannedBillboard {
                kind: self.kind,
                id,
                at,
                facing,
                height,
                texture,
                ground,
                district,
                tile: tile_of(at),
                tree: None,
            },
        }
    }
}
