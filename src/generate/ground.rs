//! The ground of one tile: a `streets` surface and a `ground` object (water, estate ground by
//! use, and the lot and open ground), each clipped to the tile's square so that the tiles of a
//! town put together are one continuous ground, without gaps or overlaps.
//!
//! The surfaces are cut with geo's boolean operations (i_overlay): streets first (the union
//! of the buffered centrelines, or the square less the city blocks), then water, then each
//! estate material's lots, each less everything before it; the rest of the square is the
//! default ground. Heights come from the DEM (the pieces split along its grid, so the ground
//! follows it), else from the lots' elevations (flat when they agree).

use std::collections::BTreeMap;

use geo::{BooleanOps, TriangulateEarcut};
use geo_types::{Coord, LineString, MultiPolygon, Polygon, Rect};

use crate::geom::union::cascaded;
use crate::model::object::ObjectKind;

use super::clip::{clip_band, clip_band_u, LocalPoly, LocalRing};
use super::mesh::{Frame, Mesh};
use crate::materials;
use crate::model::dem::Dem;
use crate::model::{GroundHeight, PlannedGround};
use crate::params::GroundParams;

/// Lot centres the ground's height is interpolated from, at each point.
const NEAREST: usize = 6;

/// The tile's `ground` object and, when it holds any street, its `streets` object.
pub fn tile_ground(
    g: &PlannedGround,
    p: &GroundParams,
    dem: Option<&Dem>,
    frame: Frame,
) -> (Mesh, Option<Mesh>) {
    let [x0, y0, x1, y1] = g.bounds;
    let square = MultiPolygon(vec![Rect::new(
        Coord { x: x0, y: y0 },
        Coord { x: x1, y: y1 },
    )
    .to_polygon()]);
    let streets = match &g.blocks {
        Some(blocks) => square.difference(&cascaded(blocks)),
        None => cascaded(&g.streets).intersection(&square),
    };
    let mut taken = streets.clone();
    let mut layers: Vec<(u16, MultiPolygon<f64>)> = Vec::new();
    if !g.water.is_empty() {
        let water = cascaded(&g.water).intersection(&square).difference(&taken);
        taken = taken.union(&water);
        layers.push((materials::id("water"), water));
    }
    let default = p
        .materials
        .get("default")
        .and_then(|m| materials::find(m))
        .unwrap_or_else(|| materials::id("ground"));
    // Lots by their ground material, in the materials' order; the default needs no cut.
    let mut by_material: BTreeMap<u16, Vec<&Polygon<f64>>> = BTreeMap::new();
    for (poly, use_name) in &g.lots {
        let m = p
            .materials
            .get(use_name)
            .and_then(|m| materials::find(m))
            .unwrap_or(default);
        if m != default {
            by_material.entry(m).or_default().push(poly);
        }
    }
    for (m, polys) in by_material {
        let lots = cascaded(polys).intersection(&square).difference(&taken);
        taken = taken.union(&lots);
        layers.push((m, lots));
    }
    layers.push((default, square.difference(&taken)));
    let height = Height::new(&g.height, dem);
    let mut ground = Mesh::object("ground".into(), ObjectKind::Ground, Default::default());
    for (m, area) in &layers {
        lay(
            &mut ground,
            *m,
            area,
            &height,
            dem,
            g.bounds,
            p.texture_size,
            frame,
        );
    }
    let street_mesh = (!streets.0.is_empty()).then(|| {
        let mut mesh = Mesh::object("streets".into(), ObjectKind::Streets, Default::default());
        let m = materials::id("street");
        lay(
            &mut mesh,
            m,
            &streets,
            &height,
            dem,
            g.bounds,
            p.texture_size,
            frame,
        );
        mesh.finish()
    });
    (ground.finish(), street_mesh.filter(|m| !m.faces.is_empty()))
}

/// The ground's height at a point.
struct Height<'a> {
    dem: Option<&'a Dem>,
    given: &'a GroundHeight,
}

impl<'a> Height<'a> {
    fn new(given: &'a GroundHeight, dem: Option<&'a Dem>) -> Height<'a> {
        Height { dem, given }
    }

    fn at(&self, p: Coord<f64>) -> f64 {
        if let Some(dem) = self.dem {
            return dem.sample(p).z;
        }
        match self.given {
            GroundHeight::Flat(z) => *z,
            GroundHeight::Points(pts) => idw(pts, p),
        }
    }
}

/// Inverse-distance weighting (power 2) of the nearest lot centres: continuous, so two
/// tiles meeting at a border give their shared points one height.
fn idw(pts: &[([f64; 2], f64)], p: Coord<f64>) -> f64 {
    let mut near: Vec<(f64, f64)> = pts
        .iter()
        .map(|(c, z)| ((c[0] - p.x).powi(2) + (c[1] - p.y).powi(2), *z))
        .collect();
    if near.is_empty() {
        return 0.0;
    }
    let k = NEAREST.min(near.len());
    near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let near = &near[..k];
    if let Some(hit) = near.iter().find(|(d2, _)| *d2 < 1e-12) {
        return hit.1;
    }
    let (num, den) = near
        .iter()
        .fold((0.0, 0.0), |(n, d), (d2, z)| (n + z / d2, d + 1.0 / d2));
    num / den
}

/// Adds `area` to `mesh` as upward triangles of material `m`, split along the DEM's grid
/// when there is one.
#[allow(clippy::too_many_arguments)]
fn lay(
    mesh: &mut Mesh,
    m: u16,
    area: &MultiPolygon<f64>,
    height: &Height,
    dem: Option<&Dem>,
    bounds: [f64; 4],
    texture: f64,
    frame: Frame,
) {
    // Work relative to the tile's corner: small numbers, exact grid lines.
    let (ox, oy) = (bounds[0], bounds[1]);
    for poly in &area.0 {
        let local = to_local(poly, ox, oy);
        let pieces = match dem {
            Some(dem) => split_on_grid(local, dem, bounds),
            None => vec![local],
        };
        for piece in pieces {
            for tri in triangles(&piece) {
                let corners = tri
                    .iter()
                    .map(|q| {
                        let p = Coord {
                            x: q[0] + ox,
                            y: q[1] + oy,
                        };
                        let pos = mesh.vertex(frame, p, height.at(p));
                        // World-anchored texture: neighbouring tiles continue it.
                        let uv = mesh.uv(
                            (p.x - frame.origin[0]) / texture,
                            (p.y - frame.origin[1]) / texture,
                        );
                        (pos, uv)
                    })
                    .collect();
                mesh.face(m, corners);
            }
        }
    }
}

fn to_local(poly: &Polygon<f64>, ox: f64, oy: f64) -> LocalPoly {
    let ring = |ls: &LineString<f64>| -> LocalRing {
        crate::geom::ring::open(ls)
            .iter()
            .map(|c| [c.x - ox, c.y - oy])
            .collect()
    };
    let mut exterior = ring(poly.exterior());
    if super::clip::area(&exterior) < 0.0 {
        exterior.reverse();
    }
    let holes = poly
        .interiors()
        .iter()
        .map(|h| {
            let mut r = ring(h);
            if super::clip::area(&r) > 0.0 {
                r.reverse();
            }
            r
        })
        .collect();
    LocalPoly { exterior, holes }
}

/// The piece cut along the DEM's cell-centre lines (where its bilinear surface bends), so
/// each part lies within one cell of the height field.
fn split_on_grid(piece: LocalPoly, dem: &Dem, bounds: [f64; 4]) -> Vec<LocalPoly> {
    let lines = |lo: f64, hi: f64, first: f64| -> Vec<f64> {
        let k0 = ((lo - first) / dem.cell).ceil() as i64;
        let k1 = ((hi - first) / dem.cell).floor() as i64;
        (k0..=k1.min(k0 + 100_000))
            .map(|k| first + k as f64 * dem.cell)
            .filter(|c| *c > lo + 1e-6 && *c < hi - 1e-6)
            .collect()
    };
    let xs = lines(bounds[0], bounds[2], dem.xll + dem.cell / 2.0);
    let ys = lines(bounds[1], bounds[3], dem.yll + dem.cell / 2.0);
    let cut = |pieces: Vec<LocalPoly>, at: &[f64], off: f64, along_u: bool| -> Vec<LocalPoly> {
        let mut out = Vec::new();
        for p in pieces {
            let mut edges: Vec<f64> = vec![f64::NEG_INFINITY];
            edges.extend(at.iter().map(|c| c - off));
            edges.push(f64::INFINITY);
            for w in edges.windows(2) {
                out.extend(if along_u {
                    clip_band_u(&p, w[0], w[1])
                } else {
                    clip_band(&p, w[0], w[1])
                });
            }
        }
        out
    };
    let cols = cut(vec![piece], &xs, bounds[0], true);
    cut(cols, &ys, bounds[1], false)
}

/// Counter-clockwise triangles covering a piece (earcut keeps its holes open).
fn triangles(piece: &LocalPoly) -> Vec<[[f64; 2]; 3]> {
    let ls = |r: &LocalRing| LineString(r.iter().map(|p| Coord { x: p[0], y: p[1] }).collect());
    let poly = Polygon::new(ls(&piece.exterior), piece.holes.iter().map(ls).collect());
    let raw = poly.earcut_triangles_raw();
    raw.triangle_indices
        .chunks_exact(3)
        .filter_map(|t| {
            let mut tri = [raw.vertices[t[0]], raw.vertices[t[1]], raw.vertices[t[2]]];
            let a = super::clip::area(&tri);
            if a.abs() < 1e-9 {
                return None;
            }
            if a < 0.0 {
                tri.swap(1, 2);
            }
            Some(tri)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon<f64> {
        Rect::new(Coord { x: x0, y: y0 }, Coord { x: x1, y: y1 }).to_polygon()
    }

    fn covered(mesh: &Mesh) -> f64 {
        mesh.faces
            .iter()
            .map(|f| {
                let p = |k: usize| {
                    let q = mesh.positions[f.corners[k].0 as usize];
                    [q[0] as f64 / 1000.0, -(q[2] as f64) / 1000.0]
                };
                crate::generate::clip::area(&[p(0), p(1), p(2)])
            })
            .sum()
    }

    #[test]
    fn streets_water_and_ground_tile_the_square_exactly() {
        let g = PlannedGround {
            bounds: [0.0, 0.0, 100.0, 100.0],
            streets: vec![square(-10.0, 40.0, 110.0, 50.0)],
            blocks: None,
            water: vec![square(20.0, 45.0, 30.0, 90.0)],
            lots: vec![
                (square(0.0, 0.0, 40.0, 38.0), "jisha".into()),
                (square(60.0, 60.0, 80.0, 80.0), "machiya".into()),
            ],
            height: GroundHeight::Flat(0.0),
        };
        let p = crate::params::Params::default().ground;
        let (ground, streets) = tile_ground(&g, &p, None, Frame { origin: [0.0, 0.0] });
        let streets = streets.expect("a street crosses the tile");
        assert!(
            (covered(&streets) - 1000.0).abs() < 0.01,
            "{}",
            covered(&streets)
        );
        assert!(
            (covered(&ground) - 9000.0).abs() < 0.01,
            "{}",
            covered(&ground)
        );
        let water = materials::id("water");
        let wet: f64 = ground.faces.iter().filter(|f| f.material == water).count() as f64;
        assert!(wet > 0.0);
        // Every face looks up.
        for f in &ground.faces {
            let p = |k: usize| {
                let q = ground.positions[f.corners[k].0 as usize];
                [q[0] as f64, -(q[2] as f64)]
            };
            assert!(crate::generate::clip::area(&[p(0), p(1), p(2)]) > 0.0);
        }
    }

    #[test]
    fn blocks_leave_the_streets_between_them() {
        let g = PlannedGround {
            bounds: [0.0, 0.0, 50.0, 50.0],
            blocks: Some(vec![
                square(0.0, 0.0, 20.0, 50.0),
                square(26.0, 0.0, 50.0, 50.0),
            ]),
            height: GroundHeight::Flat(3.0),
            ..PlannedGround::default()
        };
        let p = crate::params::Params::default().ground;
        let (ground, streets) = tile_ground(&g, &p, None, Frame { origin: [0.0, 0.0] });
        assert!((covered(&streets.unwrap()) - 300.0).abs() < 0.01);
        assert!((covered(&ground) - 2200.0).abs() < 0.01);
        assert!(ground.positions.iter().all(|q| q[1] == 3000));
    }

    #[test]
    fn heights_between_lots_are_weighted_by_inverse_distance() {
        let pts = vec![([0.0, 0.0], 10.0), ([10.0, 0.0], 20.0)];
        assert!((idw(&pts, Coord { x: 5.0, y: 0.0 }) - 15.0).abs() < 1e-12);
        assert_eq!(idw(&pts, Coord { x: 10.0, y: 0.0 }), 20.0);
        assert!(idw(&pts, Coord { x: 1.0, y: 0.0 }) < 11.0);
    }
}
