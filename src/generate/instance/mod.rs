//! Instantiating a template on one site: evaluating its parts into a mesh.
//!
//! A site is a lot (or any outline) in its frontage frame: u along the street, v into the
//! lot, h up from the ground. Prism parts are cut from their outline and extruded, so a house
//! fits whatever lot it is given; explicit parts place the template's own vertices. Every
//! closed part is checked to be watertight, and every value to be a finite number, before
//! anything is kept: a template that fails on one lot skips that lot with the reason.

use std::cell::RefCell;

use geo_types::Coord;

use super::clip::{area, clip_band, clip_band_u, dedup, extent_at, LocalPoly, LocalRing};
use super::mesh::{open_edges_of, Frame, Mesh};
use crate::templates::expr::{Expr, Lot};
use crate::templates::template::{FaceSpec, Faces, Prism, Shape};
use crate::templates::Template;

mod extrude;
mod roof;

use extrude::{extrude, on_split, Dress, Facade};
use roof::roof_prism;

/// The frontage frame: u along the street, v into the lot, in map metres.
pub use crate::geom::frame::Frame as Local;

/// Where a template is built.
#[derive(Debug, Clone)]
pub struct Site {
    /// The lot in the frontage frame (exterior counter-clockwise, holes clockwise).
    pub lot: LocalPoly,
    /// The frontage frame the lot is given in.
    pub local: Local,
    /// Ground elevation, metres: h = 0 of the template at u = 0 ...
    pub ground: f64,
    /// ... rising this much per metre of u (a fence on a slope); 0 for houses, whose flat
    /// base stands on the lowest ground under them.
    pub slope: f64,
}

impl Lot for Site {
    fn extent_at(&self, v: f64) -> (f64, f64) {
        extent_at(&self.lot.exterior, v)
    }
}

impl Site {
    /// A rectangle `width` x `depth` at the origin, facing a street along the x axis.
    pub fn rectangle(width: f64, depth: f64) -> Site {
        Site {
            lot: LocalPoly::simple(vec![[0.0, 0.0], [width, 0.0], [width, depth], [0.0, depth]]),
            local: Local {
                a: Coord { x: 0.0, y: 0.0 },
                u: Coord { x: 1.0, y: 0.0 },
                v: Coord { x: 0.0, y: 1.0 },
            },
            ground: 0.0,
            slope: 0.0,
        }
    }

    /// The lot's depth: its largest v.
    pub fn depth(&self) -> f64 {
        self.lot.exterior.iter().map(|p| p[1]).fold(0.0, f64::max)
    }
}

/// What a city model says of a building built from `t` with `slots` on `site`: its storeys
/// (the feature's own `storeys` attribute when it has one, else the template's expression),
/// its roof type, and the ground it stands on.
pub fn building_facts(
    t: &Template,
    slots: &[f64],
    site: &Site,
    attrs: &[(String, f64)],
    ground: f64,
) -> super::mesh::BuildingFacts {
    let given = attrs
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case("storeys"))
        .map(|(_, v)| *v);
    let storeys = given
        .or_else(|| t.storeys.as_ref().map(|e| e.eval(slots, site)))
        .filter(|s| s.is_finite() && *s >= 1.0 && *s <= 200.0)
        .map(|s| s.round() as u32);
    super::mesh::BuildingFacts {
        storeys,
        roof_type: t.roof_type.clone(),
        ground,
        template: t.name.clone(),
    }
}

/// Builds every part of `t` whose `when` holds into `mesh`. `slots` come from
/// [`Template::evaluate`] for this site.
pub fn instantiate(
    t: &Template,
    slots: &[f64],
    site: &Site,
    frame: Frame,
    mesh: &mut Mesh,
) -> Result<(), String> {
    let cell = RefCell::new(slots.to_vec());
    let scalar = |e: &Expr, what: &str, part: &str| -> Result<f64, String> {
        let x = e.eval(&cell.borrow(), site);
        if x.is_finite() {
            Ok(x)
        } else {
            Err(format!("template {}: part `{part}`: {what} is {x}", t.name))
        }
    };
    for part in &t.parts {
        if let Some(w) = &part.when {
            if scalar(w, "`when`", &part.name)? == 0.0 {
                continue;
            }
        }
        // Parts share the mesh's vertices; each part's own faces must close on themselves.
        let first_face = mesh.faces.len();
        mesh.parts.push(super::mesh::MeshPart {
            name: part.name.clone(),
            first_face: first_face as u32,
            installation: part.installation,
        });
        let closed = match &part.shape {
            Shape::Prism(p) => {
                let cx = PartCx {
                    t,
                    name: &part.name,
                    loc: &part.loc,
                    site,
                    cell: &cell,
                    scalar: &scalar,
                };
                prism(&cx, p, frame, mesh)?;
                p.closed
            }
            Shape::Faces(f) => {
                faces(f, &part.name, site, frame, &scalar, mesh)?;
                f.closed
            }
        };
        if closed && !open_edges_of(&mesh.faces[first_face..]).is_empty() {
            return Err(format!(
                "template {}: part `{}` ({}) is not a closed shell on this lot",
                t.name, part.name, part.loc
            ));
        }
    }
    Ok(())
}

type Scalar<'a> = dyn Fn(&Expr, &str, &str) -> Result<f64, String> + 'a;

/// What every part of one template built on one site shares.
struct PartCx<'a> {
    t: &'a Template,
    name: &'a str,
    /// Where the part is written, for errors only a site can reveal.
    loc: &'a crate::templates::file::Loc,
    site: &'a Site,
    /// The template's slots, with the `u` and `v` slots set per point by [`PartCx::at`].
    cell: &'a RefCell<Vec<f64>>,
    scalar: &'a Scalar<'a>,
}

impl PartCx<'_> {
    /// A scalar expression of the part (finite, or an error naming `what`).
    fn scalar(&self, e: &Expr, what: &str) -> Result<f64, String> {
        (self.scalar)(e, what, self.name)
    }

    /// An expression of the part evaluated at the local point `q` (`u`, `v` set).
    fn at(&self, e: &Expr, q: [f64; 2]) -> f64 {
        let (us, vs) = (self.t.v_slot - 1, self.t.v_slot);
        let mut s = self.cell.borrow_mut();
        s[us] = q[0];
        s[vs] = q[1];
        e.eval(&s, self.site)
    }
}

/// A prism part: its outline (the lot, or its own points) cut to its bands, split where its
/// roof line bends, checked, and extruded between its bottom and top.
fn prism(cx: &PartCx, p: &Prism, frame: Frame, mesh: &mut Mesh) -> Result<(), String> {
    let bound = |e: &Option<Expr>, what: &str, inf: f64| -> Result<f64, String> {
        e.as_ref().map_or(Ok(inf), |e| cx.scalar(e, what))
    };
    let (v0, v1) = (
        bound(&p.v0, "v0", f64::NEG_INFINITY)?,
        bound(&p.v1, "v1", f64::INFINITY)?,
    );
    let (u0, u1) = (
        bound(&p.u0, "u0", f64::NEG_INFINITY)?,
        bound(&p.u1, "u1", f64::INFINITY)?,
    );
    let outline = prism_outline(cx, p)?;
    let mut pieces = Vec::new();
    for b in clip_band(&outline, v0, v1) {
        pieces.extend(clip_band_u(&b, u0, u1));
    }
    if let Some(roof) = &p.roof {
        return roof_prism(cx, p, roof, &pieces, v0, frame, mesh);
    }
    // Where the roof line bends: split there so that every top face is planar.
    let splits = |exprs: &[Expr], what: &str| -> Result<Vec<f64>, String> {
        exprs.iter().map(|e| cx.scalar(e, what)).collect()
    };
    let (splits_v, splits_u) = (
        splits(&p.split, "a split")?,
        splits(&p.split_u, "a split_u")?,
    );
    for &s in &splits_v {
        pieces = split_at(pieces, 1, s);
    }
    for &s in &splits_u {
        pieces = split_at(pieces, 0, s);
    }
    if pieces.is_empty() {
        // Nothing of the outline lies in the band: the part is absent on this lot.
        return Ok(());
    }
    check_heights(cx, p, &pieces)?;
    let front_v = front_line(p, v0, &pieces);
    let dress = dress_of(cx, p, front_v)?;
    let (g, slope) = (cx.site.ground, cx.site.slope);
    let top = |q: [f64; 2]| g + slope * q[0] + cx.at(&p.top, q);
    extrude(
        mesh,
        frame,
        cx.site.local,
        &pieces,
        &|q| g + slope * q[0] + cx.at(&p.bottom, q),
        &top,
        &|_, q| top(q),
        &|a, b| on_split(a, b, &splits_v, &splits_u),
        &dress,
        g,
    );
    Ok(())
}

/// The part's front line: its `v0`, else the front of its pieces.
fn front_line(p: &Prism, v0: f64, pieces: &[LocalPoly]) -> f64 {
    if p.v0.is_some() {
        return v0;
    }
    pieces
        .iter()
        .flat_map(|x| &x.exterior)
        .map(|q| q[1])
        .fold(f64::INFINITY, f64::min)
}

/// How a part's walls and faces are dressed: its materials, and the facade on its front line
/// `front_v` when it has one.
fn dress_of(cx: &PartCx, p: &Prism, front_v: f64) -> Result<Dress, String> {
    let facade = match p.front_material {
        Some(material) => Some(Facade {
            material,
            front_v,
            base: cx.scalar(&p.front_base, "front_base")?,
            height: cx.scalar(&p.front_height, "front_height")?,
        }),
        None => None,
    };
    Ok(Dress {
        top: p.top_material,
        bottom: p.bottom_material,
        wall: p.side_material,
        facade,
    })
}

/// The outline a prism is cut from: the lot, or the part's own points (counter-clockwise,
/// with an area).
fn prism_outline(cx: &PartCx, p: &Prism) -> Result<LocalPoly, String> {
    let Some(points) = &p.outline else {
        return Ok(cx.site.lot.clone());
    };
    let mut ring: LocalRing = points
        .iter()
        .map(|[u, v]| Ok([cx.scalar(u, "an outline u")?, cx.scalar(v, "an outline v")?]))
        .collect::<Result<_, String>>()?;
    if area(&ring) < 0.0 {
        ring.reverse();
    }
    let ring = dedup(ring);
    if ring.len() < 3 || area(&ring) <= 1e-9 {
        return Err(format!(
            "template {}: part `{}`: the outline has no area",
            cx.t.name, cx.name
        ));
    }
    Ok(LocalPoly::simple(ring))
}

/// The pieces split along the line `axis = s` (0: u, 1: v). A vertex within a millimetre of
/// the line is first moved onto it: otherwise the two sides share a sliver that rounds to
/// nothing and leaves the shell open.
fn split_at(mut pieces: Vec<LocalPoly>, axis: usize, s: f64) -> Vec<LocalPoly> {
    for q in pieces.iter_mut() {
        for r in std::iter::once(&mut q.exterior).chain(q.holes.iter_mut()) {
            for p in r.iter_mut() {
                if (p[axis] - s).abs() < 1e-3 {
                    p[axis] = s;
                }
            }
        }
    }
    let clip = if axis == 1 { clip_band } else { clip_band_u };
    pieces
        .iter()
        .flat_map(|q| {
            let mut both = clip(q, f64::NEG_INFINITY, s);
            both.extend(clip(q, s, f64::INFINITY));
            both
        })
        .collect()
}

/// Every corner once: top and bottom finite, and the top not below the bottom.
fn check_heights(cx: &PartCx, p: &Prism, pieces: &[LocalPoly]) -> Result<(), String> {
    for q in pieces.iter().flat_map(|x| x.rings().flatten()) {
        let (b, h) = (cx.at(&p.bottom, *q), cx.at(&p.top, *q));
        if !(b.is_finite() && h.is_finite()) {
            return Err(format!(
                "template {}: part `{}`: top or bottom is not a number at u={:.2}, v={:.2}",
                cx.t.name, cx.name, q[0], q[1]
            ));
        }
        if h < b - 1e-6 {
            return Err(format!(
                "template {}: part `{}`: top {h:.2} m is below bottom {b:.2} m (a negative \
                 height) at u={:.2}, v={:.2}",
                cx.t.name, cx.name, q[0], q[1]
            ));
        }
    }
    Ok(())
}

fn faces(
    f: &Faces,
    name: &str,
    site: &Site,
    frame: Frame,
    scalar: &Scalar,
    mesh: &mut Mesh,
) -> Result<(), String> {
    let pts: Vec<[f64; 3]> = f
        .vertices
        .iter()
        .enumerate()
        .map(|(i, [u, v, h])| {
            let what = format!("vertex {}", i + 1);
            Ok([
                scalar(u, &what, name)?,
                scalar(v, &what, name)?,
                scalar(h, &what, name)?,
            ])
        })
        .collect::<Result<_, String>>()?;
    for (k, face) in f.faces.iter().enumerate() {
        let uvs = face_uvs(face, &pts, scalar, name, k)?;
        let corners = face
            .corners
            .iter()
            .zip(uvs)
            .map(|(&i, [s, t])| {
                let p = pts[i];
                let h = site.ground + site.slope * p[0] + p[2];
                let pos = mesh.vertex(frame, site.local.map([p[0], p[1]]), h);
                (pos, mesh.uv(s, t))
            })
            .collect();
        mesh.face(face.material, corners);
    }
    Ok(())
}

/// A face's texture coordinates: as written, or projected onto the face with one repeat per
/// `base` metres (walls: along the wall and up from the ground; flat faces: u and v).
fn face_uvs(
    face: &FaceSpec,
    pts: &[[f64; 3]],
    scalar: &Scalar,
    name: &str,
    k: usize,
) -> Result<Vec<[f64; 2]>, String> {
    if let Some(uv) = &face.uv {
        let what = format!("a uv of face {}", k + 1);
        return uv
            .iter()
            .map(|[s, t]| Ok([scalar(s, &what, name)?, scalar(t, &what, name)?]))
            .collect();
    }
    let base = scalar(&face.base, "base", name)?;
    if base <= 0.0 {
        return Err(format!(
            "part `{name}`: face {} has base {base} (must be > 0)",
            k + 1
        ));
    }
    let c: Vec<[f64; 3]> = face.corners.iter().map(|&i| pts[i]).collect();
    // Newell's normal.
    let mut n = [0.0; 3];
    for i in 0..c.len() {
        let (p, q) = (c[i], c[(i + 1) % c.len()]);
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && (n[2] / len).abs() < 0.7 {
        // A wall: across along its horizontal direction, up with h.
        let (hx, hy) = (-n[1], n[0]);
        let hl = hx.hypot(hy);
        Ok(c.iter()
            .map(|p| [(p[0] * hx + p[1] * hy) / hl / base, p[2] / base])
            .collect())
    } else {
        Ok(c.iter().map(|p| [p[0] / base, p[1] / base]).collect())
    }
}
