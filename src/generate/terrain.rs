//! The terrain mesh of one tile: the DEM's grid clipped to the tile, as a height field.
//!
//! Vertices stand at the DEM's cell centres inside the tile and on the tile's border, so two
//! neighbouring tiles share their border vertices exactly and the ground has no cracks. The
//! houses' flat bases are at the lowest ground under their lots, so they meet it or sink into
//! it, never float above it.

use geo_types::Coord;

use smallvec::smallvec;

use super::mesh::{Frame, Mesh};
use crate::materials;
use crate::model::dem::Dem;

/// Texture base of the ground: one repeat per this many metres.
const GROUND_TEXTURE_BASE: f64 = 4.0;

/// Coordinates along one axis: the tile's two borders and every cell centre between them.
fn stops(lo: f64, hi: f64, first_centre: f64, cell: f64) -> Vec<f64> {
    let mut v = vec![lo];
    let k0 = ((lo - first_centre) / cell).floor() as i64 + 1;
    let mut k = k0;
    loop {
        let c = first_centre + k as f64 * cell;
        if c >= hi - 1e-6 {
            break;
        }
        if c > lo + 1e-6 {
            v.push(c);
        }
        k += 1;
    }
    v.push(hi);
    v
}

/// The terrain of the tile `bounds` = [xmin, ymin, xmax, ymax], cut to the DEM's extent.
pub fn terrain_mesh(name: String, dem: &Dem, bounds: [f64; 4], frame: Frame) -> Option<Mesh> {
    let (dx0, dy0) = (dem.xll, dem.yll);
    let (dx1, dy1) = (
        dem.xll + dem.ncols as f64 * dem.cell,
        dem.yll + dem.nrows as f64 * dem.cell,
    );
    let (x0, y0) = (bounds[0].max(dx0), bounds[1].max(dy0));
    let (x1, y1) = (bounds[2].min(dx1), bounds[3].min(dy1));
    if x1 - x0 < 1e-6 || y1 - y0 < 1e-6 {
        return None;
    }
    let xs = stops(x0, x1, dx0 + dem.cell / 2.0, dem.cell);
    let ys = stops(y0, y1, dy0 + dem.cell / 2.0, dem.cell);
    let kind = crate::model::object::ObjectKind::Terrain;
    let mut mesh = Mesh::object(name, kind, Default::default());
    let material = materials::id("ground");
    let mut ids = vec![vec![(0u32, 0u32); xs.len()]; ys.len()];
    for (j, &y) in ys.iter().enumerate() {
        for (i, &x) in xs.iter().enumerate() {
            let p = Coord { x, y };
            let z = dem.sample(p).z;
            ids[j][i] = (
                mesh.vertex(frame, p, z),
                mesh.uv(x / GROUND_TEXTURE_BASE, y / GROUND_TEXTURE_BASE),
            );
        }
    }
    for j in 0..ys.len() - 1 {
        for i in 0..xs.len() - 1 {
            // Counter-clockwise seen from above: up is the outside of the ground.
            let (a, b, c, d) = (ids[j][i], ids[j][i + 1], ids[j + 1][i + 1], ids[j + 1][i]);
            mesh.face(material, smallvec![a, b, c]);
            mesh.face(material, smallvec![a, c, d]);
        }
    }
    Some(mesh.finish())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stops_include_both_borders_and_the_centres_between() {
        assert_eq!(
            stops(0.0, 30.0, 5.0, 10.0),
            vec![0.0, 5.0, 15.0, 25.0, 30.0]
        );
        assert_eq!(stops(5.0, 25.0, 5.0, 10.0), vec![5.0, 15.0, 25.0]);
    }
}
