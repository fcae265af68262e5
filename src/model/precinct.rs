//! What analysis plans inside the precincts of temples and estates: halls on their plots,
//! the ground under a build, and rock gardens (seed 000) with their report entries.

use std::collections::BTreeMap;

use geo_types::{Coord, Polygon};
use serde::{Deserialize, Serialize};

use super::tile::TileId;

/// A hall (a template of kind `hall`: a temple's main hall, gate or pagoda, a samurai's main
/// house, a court noble's residence) on the plot analysis found for it in an estate or
/// temple lot, facing the lot's gate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedHall {
    /// The lot's id.
    pub lot: String,
    /// The lot's record in its layer.
    pub record: usize,
    /// The hall template.
    pub template: String,
    /// Map point of the plot's (0, 0): the left end of its side facing the gate.
    pub corner: Coord<f64>,
    /// Unit vector of the plot's u axis (along the side facing the gate); v is it turned a
    /// quarter to the left, away from the gate.
    pub u: Coord<f64>,
    /// Width (u) and depth (v) of the plot, metres.
    pub size: [f64; 2],
    /// Ground elevation.
    pub ground: f64,
    /// The lot's district.
    pub district: Option<String>,
    /// The tile it is written to.
    pub tile: TileId,
}

impl PlannedHall {
    /// Its object name: `hall_<lot>_<template>`.
    pub fn object_name(&self) -> String {
        format!("hall_{}_{}", self.lot, self.template)
    }

    /// The plot's unit v axis: u turned a quarter to the left.
    pub fn v(&self) -> Coord<f64> {
        Coord {
            x: -self.u.y,
            y: self.u.x,
        }
    }

    /// The middle of the plot on the map.
    pub fn centre(&self) -> Coord<f64> {
        let v = self.v();
        let [w, d] = self.size;
        Coord {
            x: self.corner.x + (w * self.u.x + d * v.x) / 2.0,
            y: self.corner.y + (w * self.u.y + d * v.y) / 2.0,
        }
    }

    /// The plot on the map, counter-clockwise.
    pub fn outline(&self) -> Vec<Coord<f64>> {
        let v = self.v();
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(a, b)| Coord {
                x: self.corner.x + a * self.size[0] * self.u.x + b * self.size[1] * v.x,
                y: self.corner.y + a * self.size[0] * self.u.y + b * self.size[1] * v.y,
            })
            .collect()
    }
}

/// One hall a lot's use asked for, in the report: placed (with its plot) or not (why).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HallStat {
    /// The lot's id.
    pub lot: String,
    /// The lot's use.
    #[serde(rename = "use")]
    pub lot_use: String,
    /// The hall template.
    pub template: String,
    /// Whether it was placed.
    pub placed: bool,
    /// Why not, when it was not.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub reason: String,
    /// Width and depth of its plot, metres (placed halls).
    #[serde(default)]
    pub size: [f64; 2],
}

/// What a tile's ground is cut from: the surfaces near the tile, unclipped, and how high the
/// ground stands. Generation clips them to `bounds` (see `generate::ground`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PlannedGround {
    /// The tile's square, `[xmin, ymin, xmax, ymax]`.
    pub bounds: [f64; 4],
    /// Street surfaces (buffered centrelines) touching the tile.
    pub streets: Vec<Polygon<f64>>,
    /// When the streets are the ground between city blocks: the blocks touching the tile.
    pub blocks: Option<Vec<Polygon<f64>>>,
    /// Water (rivers, ponds) touching the tile.
    pub water: Vec<Polygon<f64>>,
    /// Lots touching the tile, with their use's ground material.
    pub lots: Vec<(Polygon<f64>, String)>,
    /// How high the ground stands where there is no DEM.
    pub height: GroundHeight,
}

/// The ground's height without a DEM: flat where every lot stands at one elevation, else
/// interpolated from the lots' own elevations (inverse distance, the nearest few).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum GroundHeight {
    /// One elevation everywhere.
    Flat(f64),
    /// Lot centres and their elevations near the tile.
    Points(Vec<([f64; 2], f64)>),
}

impl Default for GroundHeight {
    fn default() -> Self {
        GroundHeight::Flat(0.0)
    }
}

/// A dry rock garden (karesansui 枯山水) planned in a lot (seed 000).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannedGarden {
    /// Its name in object names and its RNG key: the lot's id, or `area-<id>` for a polygon
    /// of the gardens layer.
    pub lot: String,
    /// Map point of garden (0, 0): the left end of its viewing side.
    pub corner: Coord<f64>,
    /// Direction of the viewing side, radians counter-clockwise from east.
    pub angle: f64,
    /// Width along the viewing side and depth away from it, metres.
    pub size: [f64; 2],
    /// Ground elevation.
    pub ground: f64,
    /// The stones: (x, y, size, group from 0) in garden coordinates, each group largest first.
    pub stones: Vec<[f64; 4]>,
    /// The tile it is written to.
    pub tile: TileId,
}

impl PlannedGarden {
    /// Whose it is: its lot's, or (`area-<id>`) the gardens layer's polygon's.
    pub fn owner(&self) -> super::object::Owner {
        use super::object::{Owner, OwnerLayer};
        match self.lot.starts_with("area-") {
            true => Owner::of(OwnerLayer::Gardens, &self.lot),
            false => Owner::of(OwnerLayer::Lots, &self.lot),
        }
    }

    /// Its outline on the map, counter-clockwise.
    pub fn outline(&self) -> Vec<Coord<f64>> {
        let (s, c) = self.angle.sin_cos();
        [
            (0.0, 0.0),
            (self.size[0], 0.0),
            (self.size[0], self.size[1]),
            (0.0, self.size[1]),
        ]
        .iter()
        .map(|&(x, y)| Coord {
            x: self.corner.x + x * c - y * s,
            y: self.corner.y + x * s + y * c,
        })
        .collect()
    }
}

/// One lot's garden in the report: placed (with its size and fitness) or skipped (why).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GardenStat {
    /// The lot's id (for a garden of the gardens layer: the lot holding its centre, or
    /// empty when none does).
    pub lot: String,
    /// The id of its polygon in the gardens layer, when it has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub area: Option<String>,
    /// Whether a garden was placed.
    pub placed: bool,
    /// Why not, when it was not.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub reason: String,
    /// Width and depth, metres.
    #[serde(default)]
    pub size: [f64; 2],
    /// The best layout's fitness (seed 000's eq. 1).
    #[serde(default)]
    pub fitness: f64,
    /// Its stones.
    #[serde(default)]
    pub stones: usize,
    /// The best layout's degree of violation of each of seed 000's five rules, by rule name
    /// (0: the rule is kept).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub scores: BTreeMap<String, f64>,
    /// The garden's key (its lot id, or `area-<id>`): what a design in `garden.designs` is
    /// for, and what `edo-city serve` designs it by.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub key: String,
    /// Map point of garden (0, 0), the left end of its viewing side (placed gardens).
    #[serde(default, skip_serializing_if = "is_origin")]
    pub corner: [f64; 2],
    /// Direction of the viewing side, radians counter-clockwise from east.
    #[serde(default, skip_serializing_if = "is_zero_f64")]
    pub angle: f64,
    /// Ground elevation.
    #[serde(default, skip_serializing_if = "is_zero_f64")]
    pub ground: f64,
    /// Its stones: (x, y, size, group) in garden coordinates, as placed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub layout: Vec<[f64; 4]>,
    /// Whether the stones are a design kept in `garden.designs` (else the GA's).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub kept: bool,
}

fn is_origin(p: &[f64; 2]) -> bool {
    p[0] == 0.0 && p[1] == 0.0
}

fn is_zero_f64(v: &f64) -> bool {
    *v == 0.0
}
