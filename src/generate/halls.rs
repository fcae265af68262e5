//! Hall meshes: a hall template built on the plot analysis found for it, its `v = 0` side
//! facing the lot's gate.

use super::clip::LocalPoly;
use super::instance::{instantiate, Local, Site};
use super::mesh::{Frame, Mesh};
use crate::model::PlannedHall;
use crate::params::MachiyaParams;
use crate::templates::expr::Lot;
use crate::templates::template::SiteInputs;
use crate::templates::Template;

/// Builds the hall `h` with its template `t`.
pub fn build(
    h: &PlannedHall,
    t: &Template,
    overrides: &[(usize, f64)],
    params: &MachiyaParams,
    random: f64,
    frame: Frame,
) -> Result<Mesh, String> {
    let [w, d] = h.size;
    let v = h.v();
    let site = Site {
        lot: LocalPoly::simple(vec![[0.0, 0.0], [w, 0.0], [w, d], [0.0, d]]),
        local: Local {
            a: h.corner,
            u: h.u,
            v,
        },
        ground: h.ground,
        slope: 0.0,
    };
    let at = |p: [f64; 2]| site.local.map(p);
    let x = SiteInputs {
        width: w,
        lot_depth: d,
        a: h.corner,
        b: at([w, 0.0]),
        centroid: at([w / 2.0, d / 2.0]),
        ground: h.ground,
        id: &h.lot,
        district: h.district.as_deref(),
        machiya_depth: params.depth,
        min_depth: params.min_depth,
        random,
        ..SiteInputs::default()
    }
    .slots();
    let slots = t.evaluate(&x, overrides, &[], &site as &dyn Lot)?;
    use crate::model::object::{ObjectKind, Owner, OwnerLayer};
    let owner = Owner::of(OwnerLayer::Lots, &h.lot);
    let mut mesh = Mesh::object(h.object_name(), ObjectKind::Hall, owner);
    instantiate(t, &slots, &site, frame, &mut mesh)?;
    mesh.building = Some(super::instance::building_facts(
        t,
        &slots,
        &site,
        &[],
        h.ground,
    ));
    Ok(mesh.finish())
}
