//! Fence and gate meshes (section 4.3): each planned segment is its template built on the
//! segment, the walls of one lot in one object `fence_<id>`, each gate an object
//! `gate_<id>_<edge>`.

use geo_types::Coord;

use super::clip::LocalPoly;
use super::instance::{instantiate, Local, Site};
use super::mesh::{Frame, Mesh};
use crate::model::{FenceKind, PlannedFence};
use crate::params::Params;
use crate::templates::expr::Lot;
use crate::templates::template::SiteInputs;
use crate::templates::Catalog;

/// The site of a segment: u from `a` to `b`, the enclosed side (v > 0) on the left.
fn site(f: &PlannedFence) -> Option<(Site, f64)> {
    let (dx, dy) = (f.b.x - f.a.x, f.b.y - f.a.y);
    let len = dx.hypot(dy);
    if len.is_nan() || len <= 1e-6 {
        return None;
    }
    let u = Coord {
        x: dx / len,
        y: dy / len,
    };
    let site = Site {
        lot: LocalPoly::simple(vec![[0.0, 0.0], [len, 0.0], [len, 1.0], [0.0, 1.0]]),
        local: Local {
            a: f.a,
            u,
            v: Coord { x: -u.y, y: u.x },
        },
        ground: f.ground,
        slope: (f.ground_end - f.ground) / len,
    };
    Some((site, len))
}

/// Builds one segment into `mesh`; returns its length.
pub fn build_segment(
    f: &PlannedFence,
    catalog: &Catalog,
    params: &Params,
    random: f64,
    frame: Frame,
    mesh: &mut Mesh,
) -> Result<f64, String> {
    let t = catalog
        .get(&f.template)
        .ok_or_else(|| format!("fence template `{}` does not exist", f.template))?;
    let (site, len) = site(f).ok_or("the segment has no length")?;
    let mid = Coord {
        x: (f.a.x + f.b.x) / 2.0,
        y: (f.a.y + f.b.y) / 2.0,
    };
    let x = SiteInputs {
        width: len,
        lot_depth: f.room,
        a: f.a,
        b: f.b,
        centroid: mid,
        ground: f.ground,
        id: &f.id,
        district: f.district.as_deref(),
        machiya_depth: params.machiya.depth,
        min_depth: params.machiya.min_depth,
        random,
        start_mitre: f.start_mitre,
        end_mitre: f.end_mitre,
        ..SiteInputs::default()
    }
    .slots();
    let overrides = catalog.overrides(&t.name, f.district.as_deref());
    let slots = t.evaluate(&x, &overrides, &f.attrs, &site as &dyn Lot)?;
    instantiate(t, &slots, &site, frame, mesh)?;
    Ok(len)
}

/// What a segment's object is: a lot's or a line's walls, or a gate.
pub fn object_kind(f: &PlannedFence) -> crate::model::object::ObjectKind {
    match f.kind {
        FenceKind::Wall => crate::model::object::ObjectKind::Fence,
        FenceKind::Gate => crate::model::object::ObjectKind::Gate,
    }
}

/// Whose a segment is: its walled lot's, or its fence line's.
pub fn owner(f: &PlannedFence) -> crate::model::object::Owner {
    use crate::model::object::{Owner, OwnerLayer};
    match f.layer == "fences" {
        true => Owner::of(OwnerLayer::Fences, &f.id),
        false => Owner::of(OwnerLayer::Lots, &f.id),
    }
}

/// The object a segment goes into.
/// `fence_<lot>` / `gate_<lot>_<edge>` for a walled lot, `fenceline_<id>` /
/// `gateline_<id>_<edge>` for a line of the fences layer (ids of two layers may coincide).
pub fn object_name(f: &PlannedFence) -> String {
    let line = if f.layer == "fences" { "line" } else { "" };
    match f.kind {
        FenceKind::Wall => format!("fence{line}_{}", f.id),
        FenceKind::Gate => format!("gate{line}_{}_{}", f.id, f.edge + 1),
    }
}
