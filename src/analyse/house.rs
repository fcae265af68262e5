//! The house on a planned lot, as the rules after the frontage see it: its frontage frame,
//! the lot in that frame, and how deep the house reaches. Kura, obstacles for people and
//! trees, and gardens all ask these.

use crate::geom::frame::Frame;
use crate::geom::ring;
use crate::model::PlannedHouse;
use crate::params::Params;
use crate::templates::Catalog;

/// A machiya's frontage frame: u along the street, v into the lot.
pub fn frame_of(m: &PlannedHouse) -> Frame {
    Frame::along(m.frontage.a, m.frontage.u_axis())
}

/// The exterior ring in the frame, not closed.
pub fn local_ring(m: &PlannedHouse, f: Frame) -> Vec<[f64; 2]> {
    ring::open(m.outline.exterior())
        .iter()
        .map(|c| f.local(*c))
        .collect()
}

/// Where the house ends behind the frontage: its type's `setback` + `depth` (else
/// `machiya.depth`), at most the lot; a footprint building is its whole outline.
pub fn house_end(m: &PlannedHouse, lot_depth: f64, catalog: &Catalog, params: &Params) -> f64 {
    match house_band(m, catalog, params) {
        Some((_, end)) => end.min(lot_depth),
        None => lot_depth,
    }
}

/// The band behind the frontage a machiya's body fills: from its type's `setback` to
/// `setback` + `depth` (else `machiya.depth`), metres along the frontage frame's v axis
/// (the lot may end sooner); `None` for a footprint building, which is its whole outline.
pub fn house_band(m: &PlannedHouse, catalog: &Catalog, params: &Params) -> Option<(f64, f64)> {
    if m.is_footprint() {
        return None;
    }
    let (mut setback, mut depth) = (0.0, 0.0);
    if let Some(t) = catalog.machiya(&m.mtype) {
        let overrides = catalog.overrides(&m.mtype, m.district.as_deref());
        setback = t.param(&overrides, "setback").unwrap_or(0.0);
        depth = t.param(&overrides, "depth").unwrap_or(0.0);
    }
    if depth <= 0.0 {
        depth = params.machiya.depth;
    }
    Some((setback, setback + depth))
}
