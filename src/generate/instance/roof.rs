//! Parts under a roof of planes: the roof's planes read off the template on this site, and the
//! part cut into the regions where each plane is the lowest, so a hipped or gabled roof fits any
//! lot's outline.

use super::extrude::extrude;
use super::{dress_of, front_line, PartCx};
use crate::generate::clip::LocalPoly;
use crate::generate::envelope;
use crate::generate::mesh::{Frame, Mesh};
use crate::templates::template::{Prism, Roof};

/// A prism under a roof of planes: the pieces cut into the regions where each plane is the
/// lowest (`envelope::regions`), each region's top on its plane, walls only on the outline.
#[allow(clippy::too_many_arguments)]
pub(super) fn roof_prism(
    cx: &PartCx,
    p: &Prism,
    roof: &Roof,
    pieces: &[LocalPoly],
    v0: f64,
    frame: Frame,
    mesh: &mut Mesh,
) -> Result<(), String> {
    if pieces.is_empty() {
        return Ok(());
    }
    let planes = roof_planes(cx, roof, pieces)?;
    if planes.is_empty() {
        return Err(format!(
            "template {}: part `{}`: the roof has no plane",
            cx.t.name, cx.name
        ));
    }
    let regions = envelope::regions(pieces, &planes);
    let thickness = match &roof.thickness {
        Some(e) => Some(cx.scalar(e, "thickness")?),
        None => None,
    };
    let (g, slope) = (cx.site.ground, cx.site.slope);
    let top = |q: [f64; 2]| g + slope * q[0] + envelope::lowest(&planes, q);
    let bottom = |q: [f64; 2]| match thickness {
        Some(t) => top(q) - t,
        None => g + slope * q[0] + cx.at(&p.bottom, q),
    };
    for q in regions.iter().flat_map(|(r, _)| r.rings().flatten()) {
        let (b, h) = (bottom(*q), top(*q));
        if !(b.is_finite() && h.is_finite()) || h < b - 1e-6 {
            return Err(format!(
                "template {}: part `{}`: the roof at u={:.2}, v={:.2} is {h:.2} m, below its \
                 bottom {b:.2} m (or not a number)",
                cx.t.name, cx.name, q[0], q[1]
            ));
        }
    }
    let front_v = front_line(p, v0, pieces);
    let dress = dress_of(cx, p, front_v)?;
    // An edge two regions share (run both ways) is inside the roof: no wall there.
    let key = |q: [f64; 2]| ((q[0] * 1e4).round() as i64, (q[1] * 1e4).round() as i64);
    let mut edges = std::collections::HashSet::new();
    for (r, _) in &regions {
        for ring in r.rings() {
            for k in 0..ring.len() {
                edges.insert((key(ring[k]), key(ring[(k + 1) % ring.len()])));
            }
        }
    }
    let polys: Vec<LocalPoly> = regions.iter().map(|(r, _)| r.clone()).collect();
    let owner: Vec<usize> = regions.iter().map(|(_, i)| *i).collect();
    extrude(
        mesh,
        frame,
        cx.site.local,
        &polys,
        &bottom,
        &top,
        &|k, q| envelope::height(&planes[owner[k]], q),
        &|a, b| edges.contains(&(key(b), key(a))),
        &dress,
        g,
    );
    Ok(())
}

/// The roof's planes on this site: each `planes` expression read off at three points (and
/// checked flat at a fourth), then one plane per outline edge for a hip roof.
fn roof_planes(
    cx: &PartCx,
    roof: &Roof,
    pieces: &[LocalPoly],
) -> Result<Vec<envelope::Plane>, String> {
    let o = pieces[0].exterior[0];
    // Probes: every corner of the pieces and the middle of their box, so that a plane bent
    // anywhere over the part (an abs or a min inside it) is caught.
    let corners: Vec<[f64; 2]> = pieces
        .iter()
        .flat_map(|x| x.rings().flatten())
        .copied()
        .collect();
    let (lo, hi) = corners
        .iter()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), q| {
            (
                [l[0].min(q[0]), l[1].min(q[1])],
                [h[0].max(q[0]), h[1].max(q[1])],
            )
        });
    let middle = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
    let mut planes = Vec::new();
    for (k, e) in roof.planes.iter().enumerate() {
        let h0 = cx.at(e, o);
        let hu = cx.at(e, [o[0] + 1.0, o[1]]) - h0;
        let hv = cx.at(e, [o[0], o[1] + 1.0]) - h0;
        let plane = [h0 - hu * o[0] - hv * o[1], hu, hv];
        let bent = corners.iter().chain([&middle]).any(|q| {
            let off = cx.at(e, *q) - envelope::height(&plane, *q);
            off.is_nan() || off.abs() > 1e-6 * (1.0 + plane[0].abs())
        });
        if !plane.iter().all(|x| x.is_finite()) || bent {
            return Err(format!(
                "template {}: part `{}` ({}): plane {} is not flat (a roof plane is linear in u \
                 and v: no abs, min or max inside one plane; give each slope as its own plane)",
                cx.t.name,
                cx.name,
                cx.loc,
                k + 1
            ));
        }
        planes.push(plane);
    }
    if let Some((eave, pitch)) = &roof.hip {
        let (eave, pitch) = (cx.scalar(eave, "hip_eave")?, cx.scalar(pitch, "hip_pitch")?);
        // The planes rise from the edges of the pieces' hull: on a lot with a reflex corner
        // the plane of an inner edge would cut through the other wing, so the inner sides
        // rise as gables instead.
        let r = envelope::hull(&corners);
        for k in 0..r.len() {
            planes.extend(envelope::from_eave(r[k], r[(k + 1) % r.len()], eave, pitch));
        }
    }
    Ok(planes)
}
