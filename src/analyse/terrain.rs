//! Standing models on the terrain (section 2.2's elevation data): a house on the lowest
//! ground under its lot, so its flat base never floats on a slope; a fence segment on the
//! ground under each of its two ends.

use geo_types::Coord;

use crate::model::dem::Dem;
use crate::model::{PlannedFence, PlannedHouse};

/// Sets every house's ground from the DEM; returns how many sampled points were off it.
pub fn ground_houses(planned: &mut [&mut PlannedHouse], dem: &Dem) -> usize {
    let mut off = 0;
    for m in planned.iter_mut() {
        let f = &m.frontage;
        let mid = Coord {
            x: (f.a.x + f.b.x) / 2.0,
            y: (f.a.y + f.b.y) / 2.0,
        };
        let mut lowest = f64::INFINITY;
        let mut outside = false;
        for p in m.outline.exterior().0.iter().chain([&mid]) {
            let s = dem.sample(*p);
            lowest = lowest.min(s.z);
            outside |= s.outside;
        }
        off += outside as usize;
        if lowest.is_finite() {
            m.ground = lowest;
        }
    }
    off
}

/// Sets each segment's ground at its two ends; returns how many ends were off the DEM.
pub fn ground_fences(segments: &mut [PlannedFence], dem: &Dem) -> usize {
    let mut off = 0;
    for s in segments {
        let (a, b) = (dem.sample(s.a), dem.sample(s.b));
        off += a.outside as usize + b.outside as usize;
        s.ground = a.z;
        s.ground_end = b.z;
    }
    off
}
