//! Kura (蔵) meshes: the kura template built on the rectangle analysis chose for it.
//!
//! The kura's site is its own rectangle, in the machiya's frame: its `v = 0` side faces the
//! house (the door is there), its `u` runs along the street like the house's.

use geo_types::Coord;

use super::clip::LocalPoly;
use super::instance::{instantiate, Local, Site};
use super::mesh::{Frame, Mesh};
use crate::model::PlannedHouse;
use crate::params::MachiyaParams;
use crate::templates::expr::Lot;
use crate::templates::template::SiteInputs;
use crate::templates::Template;

/// Builds the kura of `m` on `rect` (`[u0, v0, u1, v1]` in the machiya's frame).
#[allow(clippy::too_many_arguments)]
pub fn build(
    m: &PlannedHouse,
    rect: [f64; 4],
    t: &Template,
    overrides: &[(usize, f64)],
    params: &MachiyaParams,
    random: f64,
    frame: Frame,
) -> Result<Mesh, String> {
    let f = &m.frontage;
    let (u, v) = (f.u_axis(), f.v_axis());
    let at = |p: [f64; 2]| Coord {
        x: f.a.x + p[0] * u.x + p[1] * v.x,
        y: f.a.y + p[0] * u.y + p[1] * v.y,
    };
    let (w, d) = (rect[2] - rect[0], rect[3] - rect[1]);
    let site = Site {
        lot: LocalPoly::simple(vec![[0.0, 0.0], [w, 0.0], [w, d], [0.0, d]]),
        local: Local {
            a: at([rect[0], rect[1]]),
            u,
            v,
        },
        ground: m.ground,
        slope: 0.0,
    };
    let (a, b, c) = (
        at([rect[0], rect[1]]),
        at([rect[2], rect[1]]),
        at([(rect[0] + rect[2]) / 2.0, (rect[1] + rect[3]) / 2.0]),
    );
    let x = SiteInputs {
        width: w,
        lot_depth: d,
        a,
        b,
        centroid: c,
        ground: m.ground,
        id: &m.id,
        district: m.district.as_deref(),
        machiya_depth: params.depth,
        min_depth: params.min_depth,
        random,
        ..SiteInputs::default()
    }
    .slots();
    let slots = t.evaluate(&x, overrides, &[], &site as &dyn Lot)?;
    let kind = crate::model::object::ObjectKind::Kura;
    let mut mesh = Mesh::object(format!("kura_{}", m.id), kind, m.owner());
    instantiate(t, &slots, &site, frame, &mut mesh)?;
    mesh.building = Some(super::instance::building_facts(
        t,
        &slots,
        &site,
        &[],
        m.ground,
    ));
    Ok(mesh.finish())
}
