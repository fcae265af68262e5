//! A landmark's mesh: its model's triangles set on the map as analysis placed it, whole (a
//! landmark is never cut at a tile border), its materials the build's palette ids.

use geo_types::Coord;

use super::mesh::{Frame, Mesh};
use crate::model::PlannedLandmark;

/// The object `landmark_<id>`.
pub fn mesh(l: &PlannedLandmark, frame: Frame) -> Mesh {
    let model = &l.model;
    use crate::model::object::{ObjectKind, Owner, OwnerLayer};
    let owner = Owner::of(OwnerLayer::Landmarks, &l.id);
    let mut mesh = Mesh::object(l.object_name(), ObjectKind::Landmark, owner);
    // Each model vertex once, placed; the mesh welds what rounds to the same millimetre.
    let ids: Vec<u32> = model
        .positions
        .iter()
        .map(|&p| {
            let q = l.place(p);
            mesh.vertex(frame, Coord { x: q[0], y: q[1] }, q[2])
        })
        .collect();
    let uvs: Vec<u32> = model.uvs.iter().map(|t| mesh.uv(t[0], t[1])).collect();
    let none = (!model.triangles.iter().all(|t| t.uvs.is_some())).then(|| mesh.uv(0.0, 0.0));
    // Clockwise turns and mirroring keep the winding: only a negative scale would flip it,
    // and scales are above 0.
    for t in &model.triangles {
        let corners = (0..3)
            .map(|k| {
                let uv = t
                    .uvs
                    .map(|u| uvs[u[k] as usize])
                    .or(none)
                    .unwrap_or_default();
                (ids[t.positions[k] as usize], uv)
            })
            .collect();
        mesh.face(l.material_base + t.material as u16, corners);
    }
    mesh.finish()
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::model::landmark::{Model, ModelMaterial, ModelTriangle};

    fn planned(rotation_deg: f64, scale: f64) -> PlannedLandmark {
        // One triangle, y-up: (0,0,0), (2,0,0), (0,3,0) -> on the map x east, up 3 m.
        let model = Model {
            file: "t.obj".into(),
            stem: "t".into(),
            positions: vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]],
            uvs: vec![],
            triangles: vec![ModelTriangle {
                positions: [0, 1, 2],
                uvs: None,
                material: 0,
            }],
            materials: vec![ModelMaterial {
                name: "m".into(),
                kd: [1.0; 3],
                texture: None,
            }],
        };
        PlannedLandmark {
            id: "7".into(),
            record: 0,
            model: Arc::new(model),
            anchor: [0.0; 3],
            at: [100.0, 200.0, 5.0],
            rotation: rotation_deg.to_radians(),
            scale,
            z_up: false,
            material_base: 40,
            footprint: geo_types::Polygon::new(geo_types::LineString::new(vec![]), vec![]),
            bounds: [0.0; 6],
            tile: "0_0".into(),
        }
    }

    #[test]
    fn a_quarter_turn_clockwise_points_east_to_south() {
        let m = mesh(&planned(90.0, 2.0), Frame { origin: [0.0, 0.0] });
        // Output frame: x east, y up, z south (mm). The model's +x (4 m after scaling) now
        // points south: z grows by 4000.
        assert_eq!(m.positions[0], [100_000, 5_000, -200_000]);
        assert_eq!(m.positions[1], [100_000, 5_000, -196_000]);
        assert_eq!(m.positions[2], [100_000, 11_000, -200_000]);
        assert_eq!(m.faces[0].material, 40);
        assert_eq!(m.name, "landmark_7");
    }
}
