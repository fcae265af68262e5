//! The geometry of one CityJSON feature: its own vertex list (CityJSONSeq's features are
//! self-contained), surfaces as rings of indices into it, the semantic surface a face is
//! (by its normal and height), and the LoD1 block of a building.
//!
//! Vertices are the meshes' own integers: millimetres relative to the build's origin, turned
//! from the output frame (x east, y up, z south) to east, north, up. The header's
//! `transform` (scale 0.001, translate the origin) makes them map metres again, exactly.

use geo::ConvexHull;

use super::appearance::Appearance;
use super::text;

use crate::generate::mesh::{Face, Mesh};

/// The vertices of one feature, each once (hashed with foldhash: the std map's SipHash was
/// a twentieth of a model's time).
#[derive(Default)]
pub struct Vertices {
    list: Vec<[i64; 3]>,
    index: std::collections::HashMap<[i64; 3], u32, foldhash::fast::FixedState>,
}

impl Vertices {
    /// The index of map point `p` (east, north, up millimetres from the origin).
    pub fn add(&mut self, p: [i64; 3]) -> u32 {
        let next = self.list.len() as u32;
        *self.index.entry(p).or_insert_with(|| {
            self.list.push(p);
            next
        })
    }

    /// Writes the list, as CityJSON has it: `[[x,y,z],...]`.
    pub fn write(&self, out: &mut String) {
        text::array(out, &self.list, |out, v| text::vertex(out, *v));
    }
}

/// A mesh position (x east, y up, z south) as east, north, up.
pub fn east_north_up(p: [i64; 3]) -> [i64; 3] {
    [p[0], -p[2], p[1]]
}

/// What a surface of a building is (CityJSON's semantic surfaces).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Semantic {
    /// Facing up and sloped, or the top of its part.
    Roof,
    /// Upright.
    Wall,
    /// Facing down at the ground.
    Ground,
    /// Facing down above the ground (an eave's underside, an overhang).
    OuterCeiling,
    /// Facing up and flat, below the top of its part (a veranda, a base's top).
    OuterFloor,
}

impl Semantic {
    /// CityJSON's name of it.
    pub fn name(self) -> &'static str {
        match self {
            Semantic::Roof => "RoofSurface",
            Semantic::Wall => "WallSurface",
            Semantic::Ground => "GroundSurface",
            Semantic::OuterCeiling => "OuterCeilingSurface",
            Semantic::OuterFloor => "OuterFloorSurface",
        }
    }
}

/// One polygon of a feature: its ring (indices into the feature's vertices), its semantic
/// surface and its material (the library id, or none).
pub struct Surface {
    /// The exterior ring, counter-clockwise seen from outside.
    pub ring: Vec<u32>,
    /// The texture coordinate of each corner of the ring (indices into the mesh's).
    pub uvs: Vec<u32>,
    /// What it is, for a building.
    pub semantic: Semantic,
    /// Its material.
    pub material: u16,
}

/// The faces `range` of `mesh` as surfaces, classified against the building's ground `z0`
/// and its part's top `top` (both millimetres); faces that degenerate to fewer than three
/// vertices are left out.
pub fn surfaces(mesh: &Mesh, faces: &[Face], ground: i64, vertices: &mut Vertices) -> Vec<Surface> {
    let top = faces
        .iter()
        .flat_map(|f| f.corners.iter())
        .map(|&(p, _)| mesh.positions[p as usize][1])
        .max()
        .unwrap_or(0);
    let mut out = Vec::with_capacity(faces.len());
    for f in faces {
        let points: Vec<[i64; 3]> = (f.corners.iter())
            .map(|&(p, _)| east_north_up(mesh.positions[p as usize]))
            .collect();
        let mut corners: Vec<(u32, u32)> = (points.iter().zip(&f.corners))
            .map(|(&p, &(_, t))| (vertices.add(p), t))
            .collect();
        corners.dedup_by_key(|c| c.0);
        if corners.len() > 1 && corners.first().map(|c| c.0) == corners.last().map(|c| c.0) {
            corners.pop();
        }
        let (ring, uvs): (Vec<u32>, Vec<u32>) = corners.into_iter().unzip();
        let mut distinct = ring.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 3 {
            continue;
        }
        out.push(Surface {
            ring,
            uvs,
            semantic: classify(&points, ground, top),
            material: f.material,
        });
    }
    out
}

/// A face's semantic surface, by its normal (Newell's) and its height: sloped or upward at
/// the top is roof, upright is wall, downward at the ground is ground, downward above it is
/// an outer ceiling, upward and flat below the top is an outer floor.
pub fn classify(points: &[[i64; 3]], ground: i64, top: i64) -> Semantic {
    let mut n = [0.0f64; 3];
    for (i, a) in points.iter().enumerate() {
        let b = points[(i + 1) % points.len()];
        let (a, b) = (a.map(|v| v as f64), b.map(|v| v as f64));
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let up = if len > 0.0 { n[2] / len } else { 0.0 };
    let zmin = points.iter().map(|p| p[2]).min().unwrap_or(0);
    let zmax = points.iter().map(|p| p[2]).max().unwrap_or(0);
    // 5 cm: a floor a hand's breadth above the ground is no ground.
    const NEAR: i64 = 50;
    match up {
        u if u > 0.999 && zmax < top - NEAR => Semantic::OuterFloor,
        u if u > 0.1 => Semantic::Roof,
        u if u < -0.1 && zmin <= ground + NEAR => Semantic::Ground,
        u if u < -0.1 => Semantic::OuterCeiling,
        _ => Semantic::Wall,
    }
}

/// Writes a geometry object of `lod` from `surfaces` of `mesh`: a `Solid` of one shell when
/// `solid`, else a `MultiSurface`; with its semantics (when `with_semantics`), its materials
/// and, when the appearance has them, its textures (`appearance` numbers both locally).
pub fn geometry(
    out: &mut String,
    mesh: &Mesh,
    surfaces: &[Surface],
    lod: &str,
    solid: bool,
    appearance: &mut Appearance,
    with_semantics: bool,
) {
    let mut kinds: Vec<Semantic> = surfaces.iter().map(|s| s.semantic).collect();
    kinds.sort_unstable();
    kinds.dedup();
    let sem: Vec<usize> = (surfaces.iter())
        .map(|s| kinds.binary_search(&s.semantic).unwrap_or(0))
        .collect();
    let mat: Vec<usize> = (surfaces.iter())
        .map(|s| appearance.material(s.material))
        .collect();
    // A solid's arrays are one level deeper: its one shell.
    let (open, close) = if solid { ("[", "]") } else { ("", "") };
    out.push('{');
    text::key(out, "boundaries");
    out.push_str(open);
    text::array(out, surfaces, |out, s| {
        text::array(out, [&s.ring], |out, r| text::ints(out, r))
    });
    out.push_str(close);
    out.push(',');
    text::key(out, "lod");
    text::string(out, lod);
    out.push(',');
    text::key(out, "material");
    out.push_str("{\"visual\":{\"values\":");
    out.push_str(open);
    text::ints(out, &mat);
    out.push_str(close);
    out.push_str("}}");
    if with_semantics {
        out.push(',');
        text::key(out, "semantics");
        out.push('{');
        text::key(out, "surfaces");
        text::array(out, &kinds, |out, k| {
            out.push_str("{\"type\":\"");
            out.push_str(k.name());
            out.push_str("\"}");
        });
        out.push(',');
        text::key(out, "values");
        out.push_str(open);
        text::ints(out, &sem);
        out.push_str(close);
        out.push('}');
    }
    if appearance.has_textures() {
        out.push(',');
        text::key(out, "texture");
        out.push_str("{\"visual\":{\"values\":");
        out.push_str(open);
        text::array(out, surfaces, |out, s| {
            appearance.write_texture_ring(out, s.material, &mesh.uvs, &s.uvs)
        });
        out.push_str(close);
        out.push_str("}}");
    }
    out.push(',');
    text::key(out, "type");
    text::string(out, if solid { "Solid" } else { "MultiSurface" });
    out.push('}');
}

/// Writes the LoD1 block of a building: the convex hull of its vertices seen from above,
/// from its lowest to its highest point, as a Solid (walls, roof, ground with their
/// semantics); false when there is none (a flat or empty building).
pub fn block(out: &mut String, points: &[[i64; 3]], vertices: &mut Vertices) -> bool {
    let (Some(z0), Some(z1)) = (
        points.iter().map(|p| p[2]).min(),
        points.iter().map(|p| p[2]).max(),
    ) else {
        return false;
    };
    if z1 <= z0 {
        return false;
    }
    let cloud: geo_types::MultiPoint<f64> = points
        .iter()
        .map(|p| geo_types::Point::new(p[0] as f64, p[1] as f64))
        .collect();
    let hull = cloud.convex_hull();
    // The hull's exterior, counter-clockwise, without its closing point; its points are
    // the input's own integers.
    let mut ring: Vec<[i64; 2]> = hull
        .exterior()
        .0
        .iter()
        .map(|c| [c.x.round() as i64, c.y.round() as i64])
        .collect();
    ring.pop();
    ring.dedup();
    if ring.len() < 3 {
        return false;
    }
    let low: Vec<u32> = ring
        .iter()
        .map(|p| vertices.add([p[0], p[1], z0]))
        .collect();
    let high: Vec<u32> = ring
        .iter()
        .map(|p| vertices.add([p[0], p[1], z1]))
        .collect();
    // The ground faces down: its ring clockwise seen from above.
    let ground: Vec<u32> = low.iter().rev().copied().collect();
    let mut shell = vec![ground, high.clone()];
    let mut sem = vec![2u8, 0];
    for i in 0..ring.len() {
        let j = (i + 1) % ring.len();
        shell.push(vec![low[i], low[j], high[j], high[i]]);
        sem.push(1);
    }
    out.push_str("{\"boundaries\":[");
    text::array(out, &shell, |out, r| {
        text::array(out, [r], |out, r| text::ints(out, r))
    });
    out.push_str(
        "],\"lod\":\"1\",\"semantics\":{\"surfaces\":[{\"type\":\"RoofSurface\"},\
                  {\"type\":\"WallSurface\"},{\"type\":\"GroundSurface\"}],\"values\":[",
    );
    text::ints(out, &sem);
    out.push_str("]},\"type\":\"Solid\"}");
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_roof_wall_ground_ceiling_or_floor_by_normal_and_height() {
        // Counter-clockwise seen from outside.
        let up = [
            [0, 0, 3000],
            [1000, 0, 3000],
            [1000, 1000, 3000],
            [0, 1000, 3000],
        ];
        let down: Vec<[i64; 3]> = up.iter().rev().map(|p| [p[0], p[1], 0]).collect();
        let wall = [[0, 0, 0], [1000, 0, 0], [1000, 0, 3000], [0, 0, 3000]];
        let slope = [
            [0, 0, 3000],
            [1000, 0, 3000],
            [1000, 1000, 4000],
            [0, 1000, 4000],
        ];
        assert_eq!(classify(&up, 0, 3000), Semantic::Roof);
        assert_eq!(classify(&up, 0, 6000), Semantic::OuterFloor);
        assert_eq!(classify(&down, 0, 3000), Semantic::Ground);
        let eave: Vec<[i64; 3]> = down.iter().map(|p| [p[0], p[1], 2500]).collect();
        assert_eq!(classify(&eave, 0, 3000), Semantic::OuterCeiling);
        assert_eq!(classify(&wall, 0, 3000), Semantic::Wall);
        assert_eq!(classify(&slope, 0, 4000), Semantic::Roof);
    }

    #[test]
    fn a_block_is_a_closed_solid_of_the_hull() {
        let pts = [
            [0, 0, 0],
            [4000, 0, 0],
            [4000, 3000, 5000],
            [0, 3000, 6000],
            [2000, 1000, 1000],
        ];
        let mut v = Vertices::default();
        let mut text = String::new();
        assert!(block(&mut text, &pts, &mut v));
        let g: serde_json::Value = serde_json::from_str(&text).unwrap();
        let shell = g["boundaries"][0].as_array().unwrap();
        assert_eq!(shell.len(), 2 + 4, "ground, roof and four walls");
        assert_eq!(v.list.len(), 8);
        // Every edge is used once each way: a closed shell.
        let mut edges = std::collections::BTreeMap::new();
        for s in shell {
            let r: Vec<u64> = s[0]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap())
                .collect();
            for i in 0..r.len() {
                *edges.entry((r[i], r[(i + 1) % r.len()])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!((n, edges.get(&(b, a))), (1, Some(&1)), "edge {a}-{b}");
        }
    }
}
