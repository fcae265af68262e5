//! A tile's grown trees by instancing: each variant's model (a shared file,
//! [`super::models`], one primitive per material, without feature ids) and one node that
//! draws it at every tree of the variant (`EXT_mesh_gpu_instancing`: translation, rotation
//! about the vertical, scale), each instance with its own row of the metadata table
//! (`EXT_instance_features`, the instance attribute `_FEATURE_ID_0`), so a click on one tree
//! names its lot. The tile's bytes then grow with the trees, not their branches; three.js
//! draws a node as one `InstancedMesh` per primitive, CesiumJS as instanced draws.
//!
//! The OBJ draws the same trees as copies (`trees_grown`, made by `variant::place_copy` with the
//! same numbers), so both formats show the same branches; the GLB leaves that mesh out.

use serde_json::json;

use super::models::Model;
use super::Scene;
use crate::generate::planted::Instanced;

/// The mesh and the node of each variant, appended to the scene's (the node's mesh is its
/// index there). `models` are the variants' shared models, in the order of `groups`
/// (one per group with trees); `origin` is the dataset origin (map metres) and `shift` the
/// tile centre (output millimetres) the translations are taken around; `first_feature` is
/// the metadata row of the first tree.
pub(super) fn add(
    groups: &[Instanced],
    models: &[&Model],
    origin: [f64; 2],
    shift: [i64; 3],
    first_feature: usize,
    scene: &mut Scene,
) {
    let Scene {
        buf,
        used,
        meshes,
        nodes,
    } = scene;
    let mut feature = first_feature;
    let planted = groups.iter().filter(|g| !g.trees.is_empty());
    for (g, model) in planted.zip(models) {
        if model.is_empty() {
            // Its trees' rows are in the table all the same: the next variant's follow them.
            feature += g.trees.len();
            continue;
        }
        let primitives = super::models::graft(model, buf, used);
        let (mut t, mut r, mut s, mut ids) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for tree in &g.trees {
            let [x, y, z] = translation(tree.stance, origin, shift);
            t.extend_from_slice(&[x, y, z]);
            r.extend_from_slice(&rotation(tree.stance.place.rotation));
            // The model's positions are shorts of `step` metres around the foot.
            let (w, h) = (tree.stance.scale * tree.stance.squeeze, tree.stance.scale);
            let (w, h) = (w as f32 * model.step, h as f32 * model.step);
            s.extend_from_slice(&[w, h, w]);
            ids.push(feature as f32);
            feature += 1;
        }
        let attributes = json!({
            "TRANSLATION": buf.floats(&t, 3, false),
            "ROTATION": buf.floats(&r, 4, false),
            "SCALE": buf.floats(&s, 3, false),
            "_FEATURE_ID_0": buf.floats(&ids, 1, false),
        });
        nodes.push(json!({
            "name": format!("trees_{}", g.model.name),
            "mesh": meshes.len(),
            "extras": {"kind": "trees"},
            "extensions": {
                "EXT_mesh_gpu_instancing": {"attributes": attributes},
                "EXT_instance_features": {"featureIds": [{
                    "featureCount": g.trees.len(),
                    "attribute": 0,
                    "propertyTable": 0,
                }]},
            },
        }));
        meshes.push(json!({"name": g.model.name, "primitives": primitives}));
    }
}

/// The trunk's foot in the tile's frame: y-up, x east, z south, metres from the tile
/// centre (the model's foot is at its origin).
fn translation(
    st: crate::generate::variant::Stance,
    origin: [f64; 2],
    shift: [i64; 3],
) -> [f32; 3] {
    let p = [
        st.place.at.x - origin[0],
        st.place.ground,
        -(st.place.at.y - origin[1]),
    ];
    [0, 1, 2].map(|k| (p[k] - shift[k] as f64 / 1000.0) as f32)
}

/// A turn of `a` radians counter-clockwise seen from above (east toward north) as a unit
/// quaternion (x, y, z, w) in the y-up frame: about +y, which takes east (+x) toward north
/// (-z).
fn rotation(a: f64) -> [f32; 4] {
    let (s, c) = (a / 2.0).sin_cos();
    [0.0, s as f32, 0.0, c as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quarter_turn_takes_east_to_north() {
        // Rotate (1, 0, 0) by the quaternion: v' = v + 2w(q x v) + 2 q x (q x v).
        let [x, y, z, w] = rotation(std::f64::consts::FRAC_PI_2).map(f64::from);
        let q = [x, y, z];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let v = [1.0, 0.0, 0.0];
        let c1 = cross(q, v);
        let c2 = cross(q, c1);
        let out: Vec<f64> = (0..3)
            .map(|k| v[k] + 2.0 * w * c1[k] + 2.0 * c2[k])
            .collect();
        // North is -z in the y-up frame.
        assert!(
            out[0].abs() < 1e-6 && out[1].abs() < 1e-6 && (out[2] + 1.0).abs() < 1e-6,
            "{out:?}"
        );
    }
}
