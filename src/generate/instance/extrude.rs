//! Extruding planar pieces into a closed shell: top and bottom faces triangulated, walls on
//! the outline only, each face given its material and texture coordinates (roofs along the
//! slope, facades counted from the ground).

use geo_types::Coord;

use super::Local;
use crate::generate::clip::{area, is_convex, LocalPoly, LocalRing};
use crate::generate::mesh::{Frame, Mesh};

/// Texture base of walls, floors and faces without a base of their own: one repeat per 2 m.
const WORLD_TEXTURE_BASE: f64 = 2.0;
/// Texture base of roofs: one repeat per metre along the street and up the slope.
const ROOF_TEXTURE_BASE: f64 = 1.0;

/// How the walls of an extruded part are dressed.
pub(super) struct Dress {
    pub(super) top: u16,
    pub(super) bottom: u16,
    pub(super) wall: u16,
    /// Walls on the line `v = front_v` get this material with facade UVs.
    pub(super) facade: Option<Facade>,
}

pub(super) struct Facade {
    pub(super) material: u16,
    pub(super) front_v: f64,
    /// Width of one repeat along u.
    pub(super) base: f64,
    /// Height the texture spans once, bottom to top, from the ground.
    pub(super) height: f64,
}

pub(super) fn on_split(p: [f64; 2], q: [f64; 2], splits_v: &[f64], splits_u: &[f64]) -> bool {
    splits_v
        .iter()
        .any(|s| (p[1] - s).abs() < 1e-6 && (q[1] - s).abs() < 1e-6)
        || splits_u
            .iter()
            .any(|s| (p[0] - s).abs() < 1e-6 && (q[0] - s).abs() < 1e-6)
}

/// Extrudes planar pieces between a bottom and a top height, each a function of (u, v) that
/// is linear on every piece. Walls on `internal` edges are left out: there two pieces meet and
/// the shell continues. The result is closed when the pieces tile a closed region. `uv_top`
/// is piece k's own top, for the roof texture's slope.
#[allow(clippy::too_many_arguments)]
pub(super) fn extrude(
    mesh: &mut Mesh,
    frame: Frame,
    local: Local,
    parts: &[LocalPoly],
    bottom: &dyn Fn([f64; 2]) -> f64,
    top: &dyn Fn([f64; 2]) -> f64,
    uv_top: &dyn Fn(usize, [f64; 2]) -> f64,
    internal: &dyn Fn([f64; 2], [f64; 2]) -> bool,
    dress: &Dress,
    base: f64,
) {
    for (k, part) in parts.iter().enumerate() {
        let tris = triangles(part);
        // Roof texture follows the slope, so tiles keep their size on steep roofs.
        let stretch = |p: [f64; 2]| {
            let gu = uv_top(k, [p[0] + 0.5, p[1]]) - uv_top(k, [p[0] - 0.5, p[1]]);
            let gv = uv_top(k, [p[0], p[1] + 0.5]) - uv_top(k, [p[0], p[1] - 0.5]);
            ((1.0 + gu * gu).sqrt(), (1.0 + gv * gv).sqrt())
        };
        for tri in &tris {
            let corners = tri
                .iter()
                .map(|&p| {
                    let pos = mesh.vertex(frame, local.map(p), top(p));
                    // Tile courses run along the eaves: texture x across the slope.
                    let (su, sv) = stretch(p);
                    let (s, t) = if su > sv {
                        (p[1], p[0] * su)
                    } else {
                        (p[0], p[1] * sv)
                    };
                    let uv = mesh.uv(s / ROOF_TEXTURE_BASE, t / ROOF_TEXTURE_BASE);
                    (pos, uv)
                })
                .collect();
            mesh.face(dress.top, corners);
            let corners = tri
                .iter()
                .rev()
                .map(|&p| {
                    let pos = mesh.vertex(frame, local.map(p), bottom(p));
                    let uv = mesh.uv(p[0] / WORLD_TEXTURE_BASE, p[1] / WORLD_TEXTURE_BASE);
                    (pos, uv)
                })
                .collect();
            mesh.face(dress.bottom, corners);
        }
        // Walls, outward: the polygon's inside is on the left of every edge of every ring
        // (exterior counter-clockwise, holes clockwise), so outside is on the right.
        for (p, q) in part
            .rings()
            .flat_map(|r| (0..r.len()).map(move |i| (r[i], r[(i + 1) % r.len()])))
        {
            if internal(p, q) {
                continue;
            }
            let (hp0, hq0, hp1, hq1) = (bottom(p), bottom(q), top(p), top(q));
            let pm = local.map(p);
            let qm = local.map(q);
            let ids = [
                mesh.vertex(frame, pm, hp0),
                mesh.vertex(frame, qm, hq0),
                mesh.vertex(frame, qm, hq1),
                mesh.vertex(frame, pm, hp1),
            ];
            let facade = dress
                .facade
                .as_ref()
                .filter(|fa| (p[1] - fa.front_v).abs() < 0.01 && (q[1] - fa.front_v).abs() < 0.01);
            let (material, uvs) = match facade {
                Some(fa) => {
                    let (up, uq) = (p[0] / fa.base, q[0] / fa.base);
                    // Facade UVs count from the ground, so the texture's storeys line up with
                    // the house's whatever the ground elevation.
                    let h = fa.height;
                    (
                        fa.material,
                        [
                            mesh.uv(up, (hp0 - base) / h),
                            mesh.uv(uq, (hq0 - base) / h),
                            mesh.uv(uq, (hq1 - base) / h),
                            mesh.uv(up, (hp1 - base) / h),
                        ],
                    )
                }
                None => {
                    let len = (q[0] - p[0]).hypot(q[1] - p[1]) / WORLD_TEXTURE_BASE;
                    let b = WORLD_TEXTURE_BASE;
                    (
                        dress.wall,
                        [
                            mesh.uv(0.0, (hp0 - base) / b),
                            mesh.uv(len, (hq0 - base) / b),
                            mesh.uv(len, (hq1 - base) / b),
                            mesh.uv(0.0, (hp1 - base) / b),
                        ],
                    )
                }
            };
            mesh.face(material, ids.into_iter().zip(uvs).collect());
        }
    }
}

/// Triangles (counter-clockwise) covering a polygon: the polygon itself as one face when it
/// is convex without holes, else earcut (which keeps the holes open).
fn triangles(part: &LocalPoly) -> Vec<Vec<[f64; 2]>> {
    if part.holes.is_empty() && is_convex(&part.exterior) {
        return vec![part.exterior.clone()];
    }
    use geo::TriangulateEarcut;
    use geo_types::{LineString, Polygon};
    let ls = |r: &LocalRing| LineString(r.iter().map(|p| Coord { x: p[0], y: p[1] }).collect());
    let poly = Polygon::new(ls(&part.exterior), part.holes.iter().map(ls).collect());
    let raw = poly.earcut_triangles_raw();
    raw.triangle_indices
        .chunks_exact(3)
        .map(|t| {
            let mut tri: Vec<[f64; 2]> = t.iter().map(|&k| raw.vertices[k]).collect();
            if area(&tri) < 0.0 {
                tri.reverse();
            }
            tri
        })
        .filter(|tri| area(tri) > 1e-12)
        .collect()
}
