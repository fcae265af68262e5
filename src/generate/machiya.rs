//! Machiya (町家) townhouses, section 4.1 of the paper.
//!
//! A machiya is built to the full width of its frontage, side walls against its neighbours,
//! facing the street with no gap (the paper: "建物は間口いっぱいに建てられて"). The house is the
//! part of the lot between `setback` and `setback + depth` behind the frontage, so it can never
//! leave its lot whatever the lot's shape; a gable roof with its ridge parallel to the street
//! (hirairi 平入) sits on it, and a pent roof (hisashi 庇) reaches over the street.

use geo_types::Coord;

use super::clip::{area, clip_band, dedup, is_convex, LocalPoly, LocalRing};
use super::materials;
use super::mesh::{Frame, Mesh};
use crate::model::PlannedMachiya;
use crate::params::MachiyaParams;
use crate::templates::MachiyaType;

/// Pitch of the street-side pent roof (rise per metre).
const HISASHI_PITCH: f64 = 0.3;
/// Thickness of the pent roof slab.
const HISASHI_THICKNESS: f64 = 0.12;
/// The pent roof reaches this far into the house so that its back face is hidden inside.
const HISASHI_TUCK: f64 = 0.05;
/// Thickness of the wall of a heitsuki and of a kanban-gatera board.
const WALL_THICKNESS: f64 = 0.25;
/// The kanban board stands this far in front of the facade ...
const BOARD_OFFSET: f64 = 0.02;
/// ... and reaches this far below the eave, behind the wall's top.
const BOARD_OVERLAP: f64 = 0.3;
/// Texture base of plaster, wood and floor: one repeat per this many metres.
const WORLD_TEXTURE_BASE: f64 = 2.0;
/// Texture base of roof tiles: one repeat per metre along the street and up the slope.
const ROOF_TEXTURE_BASE: f64 = 1.0;

/// The frontage frame: u along the street, v into the lot, in map metres.
#[derive(Debug, Clone, Copy)]
struct Local {
    a: Coord<f64>,
    u: Coord<f64>,
    v: Coord<f64>,
}

impl Local {
    fn to_map(self, p: [f64; 2]) -> Coord<f64> {
        Coord {
            x: self.a.x + p[0] * self.u.x + p[1] * self.v.x,
            y: self.a.y + p[0] * self.u.y + p[1] * self.v.y,
        }
    }
    fn to_local(self, c: Coord<f64>) -> [f64; 2] {
        let (dx, dy) = (c.x - self.a.x, c.y - self.a.y);
        [dx * self.u.x + dy * self.u.y, dx * self.v.x + dy * self.v.y]
    }
}

/// How the walls of an extruded part are dressed.
struct Dress {
    top: u16,
    bottom: u16,
    wall: u16,
    /// Walls on the line `v = front_v` get this material with facade UVs.
    facade: Option<Facade>,
}

struct Facade {
    material: u16,
    front_v: f64,
    /// Texture repeats per metre along u (a whole number of repeats across the frontage).
    u_scale: f64,
    /// Height the texture spans once, bottom to top.
    height: f64,
}

/// Builds the mesh of one machiya, or says why it cannot be built.
pub fn build(
    m: &PlannedMachiya,
    t: &MachiyaType,
    params: &MachiyaParams,
    frame: Frame,
) -> Result<Mesh, String> {
    let f = &m.frontage;
    let local = Local {
        a: f.a,
        u: f.u_axis(),
        v: f.v_axis(),
    };
    let to_ring = |ls: &geo_types::LineString<f64>| -> LocalRing {
        dedup(
            ls.0[..ls.0.len().saturating_sub(1)]
                .iter()
                .map(|c| local.to_local(*c))
                .collect(),
        )
    };
    // Courtyards (holes) stay open: the house is built around them.
    let lot = LocalPoly {
        exterior: to_ring(m.outline.exterior()),
        holes: m
            .outline
            .interiors()
            .iter()
            .map(|h| {
                let mut r = to_ring(h);
                if area(&r) > 0.0 {
                    r.reverse();
                }
                r
            })
            .filter(|r| r.len() >= 3)
            .collect(),
    };
    let ring = &lot.exterior;
    if ring.len() < 3 || area(ring) <= 0.0 {
        return Err("the outline is degenerate in the frontage frame".into());
    }
    let lot_depth = ring.iter().map(|p| p[1]).fold(0.0, f64::max);
    let footprint = m.height.is_some();
    // A footprint is the building itself: no setback, its whole depth.
    let setback = if footprint { 0.0 } else { t.setback };
    let wanted = if footprint {
        lot_depth
    } else if t.depth > 0.0 {
        t.depth
    } else {
        params.depth
    };
    let depth = wanted.min(lot_depth - setback);
    if depth < params.min_depth {
        return Err(format!(
            "type {} needs {:.2} m behind the frontage (setback {setback} m + machiya.min_depth \
             {} m) but the lot is {lot_depth:.2} m deep",
            t.name,
            setback + params.min_depth,
            params.min_depth
        ));
    }
    let body = clip_band(&lot, setback, setback + depth);
    if body.is_empty() {
        return Err("no part of the lot lies in the house's band behind the frontage".into());
    }

    let mut mesh = Mesh::new(m.object_name());
    let width = f.width();
    let (eave, pitch) = match m.height {
        None => (t.eave_height, t.roof_pitch),
        // Fit the type's roof under the building's own height: the rise never takes more
        // than a third of it, so tall buildings keep walls and low ones keep a roof.
        Some(h) => {
            let rise = (t.roof_pitch * depth / 2.0).min(h / 3.0);
            (h - rise, rise / (depth / 2.0))
        }
    };
    let ridge_v = setback + depth / 2.0;
    let base = m.ground;
    let gable = move |v: f64| eave + pitch * (depth / 2.0 - (v - ridge_v).abs());
    let facade_material = materials::find(&t.facade_material).unwrap_or(0);
    let repeats = (width / t.facade_base).ceil().max(1.0);
    let dress = Dress {
        top: materials::find(&t.roof_material).unwrap_or(0),
        bottom: materials::id("floor"),
        wall: materials::find(&t.wall_material).unwrap_or(0),
        facade: Some(Facade {
            material: facade_material,
            front_v: setback,
            u_scale: repeats / width,
            height: t.eave_height + t.parapet_height,
        }),
    };
    // The two roof halves meet at the ridge: split the body there so every face is planar.
    let mut halves = Vec::new();
    for part in &body {
        halves.extend(clip_band(part, f64::NEG_INFINITY, ridge_v));
        halves.extend(clip_band(part, ridge_v, f64::INFINITY));
    }
    let roof = move |v: f64| base + gable(v);
    extrude(
        &mut mesh,
        frame,
        local,
        &halves,
        &|_| base,
        &roof,
        Some(ridge_v),
        &dress,
        base,
    );

    if t.hisashi_height > 0.0 && t.hisashi_height < eave - 0.3 {
        hisashi(&mut mesh, frame, local, &body, t, setback, base);
    }
    if !footprint && t.front_wall_height > 0.0 && setback > WALL_THICKNESS {
        let wall = clip_band(&lot, 0.0, WALL_THICKNESS);
        let h = t.front_wall_height;
        let dress = Dress {
            top: materials::id("wood"),
            bottom: materials::id("floor"),
            wall: materials::id("tsuchikabe_wall"),
            facade: None,
        };
        extrude(
            &mut mesh,
            frame,
            local,
            &wall,
            &|_| base,
            &|_| base + h,
            None,
            &dress,
            base,
        );
    }
    if t.parapet_height > 0.0 {
        // The board stands 2 cm proud of the facade and reaches down behind its top, so it
        // is a closed shell of its own and never coplanar with the wall (no z-fighting).
        if let Some((u0, u1)) = front_extent(&body, setback) {
            let v0 = setback - BOARD_OFFSET;
            let board = LocalPoly::simple(vec![
                [u0, v0],
                [u1, v0],
                [u1, setback + WALL_THICKNESS],
                [u0, setback + WALL_THICKNESS],
            ]);
            let top = eave + t.parapet_height;
            let bottom = eave - BOARD_OVERLAP;
            let dress = Dress {
                top: materials::id("wood"),
                bottom: materials::id("wood"),
                wall: materials::id("wood"),
                facade: Some(Facade {
                    material: facade_material,
                    front_v: v0,
                    u_scale: repeats / width,
                    height: t.eave_height + t.parapet_height,
                }),
            };
            extrude(
                &mut mesh,
                frame,
                local,
                &[board],
                &|_| base + bottom,
                &|_| base + top,
                None,
                &dress,
                base,
            );
        }
    }
    Ok(mesh.finish())
}

/// The street-side pent roof: a thin sloping slab along the facade, reaching over the street.
fn hisashi(
    mesh: &mut Mesh,
    frame: Frame,
    local: Local,
    body: &[LocalPoly],
    t: &MachiyaType,
    front_v: f64,
    base: f64,
) {
    let Some((u0, u1)) = front_extent(body, front_v) else {
        return;
    };
    let (v0, v1) = (front_v - t.hisashi_depth, front_v + HISASHI_TUCK);
    let slab = LocalPoly::simple(vec![[u0, v0], [u1, v0], [u1, v1], [u0, v1]]);
    let hh = t.hisashi_height;
    let top = move |v: f64| base + hh + (v - front_v) * HISASHI_PITCH;
    let bottom = move |v: f64| top(v) - HISASHI_THICKNESS;
    let dress = Dress {
        top: materials::id("kawara_roof"),
        bottom: materials::id("wood"),
        wall: materials::id("wood"),
        facade: None,
    };
    extrude(
        mesh,
        frame,
        local,
        &[slab],
        &bottom,
        &top,
        None,
        &dress,
        base,
    );
}

/// The span along the street of the house's front wall (points of the body on `v = front_v`).
fn front_extent(body: &[LocalPoly], front_v: f64) -> Option<(f64, f64)> {
    let (mut u0, mut u1) = (f64::MAX, f64::MIN);
    for p in body
        .iter()
        .flat_map(|b| &b.exterior)
        .filter(|p| (p[1] - front_v).abs() < 0.01)
    {
        u0 = u0.min(p[0]);
        u1 = u1.max(p[0]);
    }
    (u1 - u0 >= 0.1).then_some((u0, u1))
}

/// Extrudes planar parts between a bottom and a top height, each a function of v that is
/// linear on every part. Walls on the line `v = ridge` are left out: there two parts meet
/// and the shell continues. The result is closed when the parts tile a closed region.
#[allow(clippy::too_many_arguments)]
fn extrude(
    mesh: &mut Mesh,
    frame: Frame,
    local: Local,
    parts: &[LocalPoly],
    bottom: &dyn Fn(f64) -> f64,
    top: &dyn Fn(f64) -> f64,
    ridge: Option<f64>,
    dress: &Dress,
    base: f64,
) {
    for part in parts {
        // Top (counter-clockwise seen from above) and bottom (reversed).
        let tris = triangles(part);
        let slope = |p: [f64; 2]| {
            let dh = top(p[1] + 0.5) - top(p[1] - 0.5);
            (1.0 + dh * dh).sqrt()
        };
        for tri in &tris {
            let corners = tri
                .iter()
                .map(|&p| {
                    let pos = mesh.vertex(frame, local.to_map(p), top(p[1]));
                    let uv = mesh.uv(
                        p[0] / ROOF_TEXTURE_BASE,
                        p[1] * slope(p) / ROOF_TEXTURE_BASE,
                    );
                    (pos, uv)
                })
                .collect();
            mesh.face(dress.top, corners);
            let corners = tri
                .iter()
                .rev()
                .map(|&p| {
                    let pos = mesh.vertex(frame, local.to_map(p), bottom(p[1]));
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
            if let Some(r) = ridge {
                if (p[1] - r).abs() < 1e-6 && (q[1] - r).abs() < 1e-6 {
                    continue;
                }
            }
            let (hp0, hq0, hp1, hq1) = (bottom(p[1]), bottom(q[1]), top(p[1]), top(q[1]));
            let pm = local.to_map(p);
            let qm = local.to_map(q);
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
                    let (up, uq) = (p[0] * fa.u_scale, q[0] * fa.u_scale);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::mesh::open_edges;
    use crate::model::Frontage;
    use crate::params::Params;
    use crate::templates::Catalog;
    use geo_types::{LineString, Polygon};
    use proptest::prelude::*;

    fn planned(ring: &[[f64; 2]]) -> PlannedMachiya {
        let mut pts: Vec<Coord<f64>> = ring.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
        pts.push(pts[0]);
        PlannedMachiya {
            id: "1".into(),
            record: 0,
            outline: Polygon::new(LineString(pts), vec![]),
            frontage: Frontage {
                a: Coord {
                    x: ring[0][0],
                    y: ring[0][1],
                },
                b: Coord {
                    x: ring[1][0],
                    y: ring[1][1],
                },
                fallback: false,
            },
            mtype: String::new(),
            type_given: false,
            district: None,
            tile: "0_0".into(),
            ground: 0.0,
            height: None,
        }
    }

    /// Ground vertices of a mesh, back in map metres.
    fn ground(mesh: &Mesh) -> Vec<[f64; 2]> {
        mesh.positions
            .iter()
            .filter(|p| p[1] == 0)
            .map(|p| [p[0] as f64 / 1000.0, -(p[2] as f64) / 1000.0])
            .collect()
    }

    fn inside_or_on(ring: &[[f64; 2]], p: [f64; 2], tol: f64) -> bool {
        use geo::{Contains, Distance, Euclidean};
        let poly = planned(ring).outline;
        let pt = geo_types::Point::new(p[0], p[1]);
        poly.contains(&pt) || Euclidean.distance(&pt, poly.exterior()) <= tol
    }

    #[test]
    fn every_shipped_type_is_a_closed_shell_on_a_town_lot() {
        let cat = Catalog::load(None).unwrap();
        let params = Params::default().machiya;
        let lot = [[0.0, 0.0], [5.4, 0.0], [5.5, 30.0], [0.1, 30.0]];
        for t in cat.types.values() {
            let mesh = build(&planned(&lot), t, &params, Frame { origin: [0.0, 0.0] })
                .unwrap_or_else(|e| panic!("{}: {e}", t.name));
            assert!(open_edges(&mesh).is_empty(), "{}: open edges", t.name);
            let top = mesh.positions.iter().map(|p| p[1]).max().unwrap();
            assert!(
                top as f64 / 1000.0 > t.eave_height,
                "{}: roof above the eaves",
                t.name
            );
            for p in ground(&mesh) {
                assert!(inside_or_on(&lot, p, 0.001), "{}: {p:?} outside", t.name);
            }
        }
    }

    #[test]
    fn a_courtyard_stays_open_and_the_house_stays_closed() {
        let cat = Catalog::load(None).unwrap();
        let params = Params::default().machiya;
        let mut m = planned(&[[0.0, 0.0], [10.0, 0.0], [10.0, 30.0], [0.0, 30.0]]);
        // A courtyard (tsuboniwa 坪庭) 4 m x 4 m inside the house's 12 m band.
        let hole = LineString::from(vec![
            (3.0, 4.0),
            (7.0, 4.0),
            (7.0, 8.0),
            (3.0, 8.0),
            (3.0, 4.0),
        ]);
        m.outline = Polygon::new(m.outline.exterior().clone(), vec![hole]);
        let mesh = build(
            &m,
            cat.get("hiraya").unwrap(),
            &params,
            Frame { origin: [0.0, 0.0] },
        )
        .unwrap();
        assert!(open_edges(&mesh).is_empty(), "closed around the courtyard");
        for p in ground(&mesh) {
            let strictly_inside = p[0] > 3.001 && p[0] < 6.999 && p[1] > 4.001 && p[1] < 7.999;
            assert!(!strictly_inside, "{p:?} is inside the courtyard");
        }
        // Walls stand on the courtyard's four sides, up to the roof.
        let courtyard_corners = mesh
            .positions
            .iter()
            .filter(|p| [3000, 7000].contains(&p[0]) && [-4000, -8000].contains(&p[2]))
            .count();
        assert_eq!(
            courtyard_corners, 8,
            "4 corners at the ground and 4 under the roof"
        );
    }

    #[test]
    fn a_lot_too_shallow_is_refused_with_a_reason() {
        let cat = Catalog::load(None).unwrap();
        let params = Params::default().machiya;
        let lot = [[0.0, 0.0], [5.0, 0.0], [5.0, 1.0], [0.0, 1.0]];
        let err = build(
            &planned(&lot),
            cat.get("hiraya").unwrap(),
            &params,
            Frame { origin: [0.0, 0.0] },
        )
        .unwrap_err();
        assert!(err.contains("1.00 m deep"), "{err}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Any strip lot, any type: the house is closed, stands inside its lot, and only
        /// the pent roof reaches over the street.
        #[test]
        fn houses_are_closed_and_stay_in_their_lots(
            width in 2.7f64..12.0,
            d1 in 3.0f64..60.0,
            d2 in 3.0f64..60.0,
            s1 in -0.3f64..0.3,
            s2 in -0.3f64..0.3,
            type_index in 0usize..8,
            ox in -50_000.0f64..50_000.0,
        ) {
            let cat = Catalog::load(None).unwrap();
            let t = cat.types.values().nth(type_index % cat.types.len()).unwrap();
            let params = Params::default().machiya;
            let lot = [[ox, 0.0], [ox + width, 0.0], [ox + width + s1 * d1, d1], [ox + s2 * d2, d2]];
            let local: Vec<[f64; 2]> = lot.iter().map(|p| [p[0] - ox, p[1]]).collect();
            prop_assume!(is_convex(&local));
            match build(&planned(&lot), t, &params, Frame { origin: [0.0, 0.0] }) {
                Ok(mesh) => {
                    prop_assert!(open_edges(&mesh).is_empty(), "open edges on {:?}", lot);
                    for p in ground(&mesh) {
                        prop_assert!(inside_or_on(&lot, p, 0.002), "{:?} outside {:?}", p, lot);
                    }
                    for p in &mesh.positions {
                        let q = [p[0] as f64 / 1000.0, -(p[2] as f64) / 1000.0];
                        let over_street = !inside_or_on(&lot, q, 0.002);
                        prop_assert!(!over_street || (q[1] >= -t.hisashi_depth - 0.002 && p[1] > 2000),
                            "{:?} leaves the lot other than as eaves", q);
                    }
                }
                Err(reason) => prop_assert!(reason.contains("deep"), "{}", reason),
            }
        }
    }
}
