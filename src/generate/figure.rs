//! One billboard figure: its template built on a point, facing its direction, the
//! template's `picture` material slot given the billboard's texture. The people and trees of
//! a tile (`billboards.rs`) and the walkers' figures (`crowd.rs`) are made of it.

use geo_types::Coord;

use super::clip::LocalPoly;
use super::instance::{instantiate, Local, Site};
use super::mesh::{Frame, Mesh};
use crate::materials;
use crate::model::PlannedBillboard;
use crate::templates::expr::Lot;
use crate::templates::template::SiteInputs;
use crate::templates::Catalog;

/// One billboard into `mesh`: the template on a site whose v axis is the facing direction,
/// centred on the point, its picture slot given the billboard's texture.
pub fn build_one(
    b: &PlannedBillboard,
    template: &str,
    catalog: &Catalog,
    seed: u64,
    frame: Frame,
    mesh: &mut Mesh,
) -> Result<(), String> {
    let t = catalog
        .get(template)
        .ok_or_else(|| format!("billboard template `{template}` does not exist"))?;
    let picture = materials::find(&b.texture)
        .ok_or_else(|| format!("texture `{}` is not in the library", b.texture))?;
    let v = Coord {
        x: b.facing.cos(),
        y: b.facing.sin(),
    };
    let u = Coord { x: v.y, y: -v.x };
    let site = Site {
        lot: LocalPoly::simple(vec![[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]),
        local: Local { a: b.at, u, v },
        ground: b.ground,
        slope: 0.0,
    };
    let x = SiteInputs {
        width: 0.0,
        lot_depth: 0.0,
        a: b.at,
        b: b.at,
        centroid: b.at,
        ground: b.ground,
        id: &b.id,
        district: b.district.as_deref(),
        random: super::template_random(seed, b.kind.layer(), &b.id),
        billboard_height: b.height,
        ..SiteInputs::default()
    }
    .slots();
    let overrides = catalog.overrides(&t.name, b.district.as_deref());
    let slots = t.evaluate(&x, &overrides, &[], &site as &dyn Lot)?;
    let first = mesh.faces.len();
    if let Err(e) = instantiate(t, &slots, &site, frame, mesh) {
        mesh.faces.truncate(first);
        mesh.parts.retain(|p| (p.first_face as usize) < first);
        return Err(e);
    }
    if let Some(slot) = t.material_slot("picture") {
        for f in mesh.faces[first..]
            .iter_mut()
            .filter(|f| f.material == slot)
        {
            f.material = picture;
        }
    }
    Ok(())
}
