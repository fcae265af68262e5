//! A tile's walkers as glTF 2.0 animation: one joint node per walker (its place, heading and
//! height), the figures (a picture's person at 1 m) of up to [`SKIN_JOINTS`] walkers as one
//! skinned mesh, so a tile's crowd is a draw call or two, and one clip, `crowd`, of every
//! walker's translation and rotation keys (LINEAR, the last key the first, so a player that
//! loops it shows no jump). three.js' GLTFLoader, Blender's importer and CesiumJS play it.
//!
//! Keys on a straight, even walk say nothing the keys either side do not: a key is kept only
//! where leaving it out would move the walker more than [`TOLERANCE`] metres or turn it more
//! than [`TURN_TOLERANCE`] from where interpolation puts it (each walker its own times).
//! Times, translations and rotations are floats, through meshopt's vertex codec when the GLB
//! is compressed. Core glTF allows normalized shorts for rotations, but CesiumJS 1.145 reads
//! them as raw integers: its walkers were drawn hundreds of metres tall.
//!
//! Each walker's node carries its person id and group in `extras` (three.js copies them into
//! the bone's `userData`), and its figure's vertices the feature id of the tile's people row
//! and its joint, so a click on a walker names it (the viewer finds the bone from the hit
//! vertex's joint) as a click on a standing person does.

use std::collections::BTreeMap;

use serde_json::{json, Value};

use super::{Primitive, Scene, Slot};
use crate::generate::crowd::Crowd;
use crate::model::WalkKey;

/// The largest distance (metres) between a walker and where its kept keys put it.
pub const TOLERANCE: f64 = 0.02;
/// The largest turn (radians) between a walker's heading and its kept keys'.
pub const TURN_TOLERANCE: f64 = 0.02;

/// The most keys one kept key may stand for (the check of a run grows with its square).
const MAX_RUN: usize = 64;

/// The clip's name.
pub const CLIP: &str = "crowd";

/// The most walkers one skin moves. A skinned mesh is one draw call whatever its joints;
/// CesiumJS gives each joint a 4-vector matrix uniform, and 32 of them (128 vectors) stay
/// within the 256 vertex uniform vectors of common mobile GPUs beside the rest of its shader
/// (three.js keeps bones in a texture and has no such bound).
pub const SKIN_JOINTS: usize = 32;

/// What a tile's crowd adds besides its meshes and nodes: the clip and the skins.
pub(super) struct Animated {
    pub clip: Value,
    pub skins: Vec<Value>,
}

/// Adds the walkers (appended to the scene's meshes and nodes) and returns the clip and skins.
/// Each walker is a joint node, `person_<id>`, under one `crowd` node; the figures of up to
/// [`SKIN_JOINTS`] walkers are one skinned mesh, each figure's vertices following its
/// walker's joint wholly (a node per walker drew each walker in a call of its own: +263
/// draw calls at the 30,052-lot town's central crossing). `feature` is the people row the
/// figures' vertices carry; `origin` and `shift` as for the tile's other nodes.
pub(super) fn add(
    crowd: &Crowd,
    atlas: Option<&crate::output::atlas::Atlas>,
    origin: [f64; 2],
    shift: [i64; 3],
    feature: u32,
    scene: &mut Scene,
) -> Option<Animated> {
    let Scene {
        buf,
        used,
        meshes,
        nodes,
    } = scene;
    let walkers: Vec<&crate::generate::crowd::Walker> = crowd
        .walkers
        .iter()
        .filter(|w| {
            crowd.figures[w.figure]
                .faces
                .iter()
                .any(|f| f.corners.len() > 2)
        })
        .collect();
    if walkers.is_empty() {
        return None;
    }
    let root = nodes.len();
    nodes.push(json!({"name": "crowd", "children": [], "extras": {"kind": "people"}}));
    let first_joint = nodes.len();
    let (mut skins, mut skinned) = (Vec::new(), Vec::new());
    for (k, group) in walkers.chunks(SKIN_JOINTS).enumerate() {
        let mut prims: BTreeMap<u16, Primitive> = BTreeMap::new();
        for (j, w) in group.iter().enumerate() {
            let f = &crowd.figures[w.figure];
            for face in &f.faces {
                let slot = Slot::of(atlas, face.material);
                let p = prims.entry(slot.key).or_default();
                p.joint = Some(j as u8);
                p.face(feature, f, &face.corners, [0, 0, 0], slot);
            }
        }
        let mut primitives = Vec::new();
        for (&material, p) in prims.iter_mut() {
            p.reorder();
            if !p.indices.is_empty() {
                primitives.push(super::primitive_json(p, material, true, None, buf, used));
            }
        }
        if primitives.is_empty() {
            continue; // faces of no area: nothing to draw, the joints still walk
        }
        let first = first_joint + k * SKIN_JOINTS;
        skins.push(json!({
            "name": format!("crowd_{k}"),
            "skeleton": root,
            "joints": (first..first + group.len()).collect::<Vec<_>>(),
        }));
        meshes.push(json!({"name": format!("crowd_{k}"), "primitives": primitives}));
        skinned.push((k, meshes.len() - 1));
    }
    // Every walker's keys in three views for the tile (times, translations, rotations),
    // each walker's accessors at its offset: a view and its JSON per walker and channel took
    // twice the bytes of the keys themselves.
    let (mut times, mut moves, mut turns) = (Vec::new(), Vec::new(), Vec::new());
    let mut animated: Vec<(usize, usize, usize)> = Vec::new(); // node, first key, keys
    for w in &walkers {
        let keys = &w.walk.keys;
        let place = |k: &WalkKey| {
            let p = [k.at[0] - origin[0], k.at[2], -(k.at[1] - origin[1])];
            [0, 1, 2].map(|i| (p[i] - shift[i] as f64 / 1000.0) as f32)
        };
        let h = w.height as f32;
        animated.push((nodes.len(), times.len(), 0));
        // The pose before the clip plays (a client that does not animate), in millimetres
        // and a rotation to 1e-5: a float's seventeen digits were a third of a node's JSON.
        let round = |v: f32, k: f32| f64::from((v * k).round()) / f64::from(k);
        let h = round(h, 1000.0);
        nodes.push(json!({
            "name": format!("person_{}", w.walk.id),
            "translation": place(&keys[0]).map(|v| round(v, 1000.0)),
            "rotation": rotation(keys[0].heading).map(|v| round(v, 1e5)),
            "scale": [h, h, h],
            "extras": {"kind": "people", "person": w.walk.id, "group": w.walk.group},
        }));
        let idx = kept(keys);
        let dt = w.walk.dt as f32;
        times.extend(idx.iter().map(|&k| k as f32 * dt));
        moves.extend(idx.iter().map(|&k| place(&keys[k])));
        let q = continuous(idx.iter().map(|&k| rotation(keys[k].heading)));
        turns.extend(q);
        if let Some(last) = animated.last_mut() {
            last.2 = idx.len();
        }
    }
    nodes[root]["children"] = json!((first_joint..nodes.len()).collect::<Vec<_>>());
    // The skinned meshes' nodes, at the scene's root with no transform of their own (glTF
    // ignores it: the joints place every vertex).
    for (skin, &(k, mesh)) in skinned.iter().enumerate() {
        nodes.push(json!({
            "name": format!("crowd_{k}"),
            "mesh": mesh,
            "skin": skin,
            "extras": {"kind": "people"},
        }));
    }
    let views = [
        buf.animation(&times, f32::to_le_bytes),
        buf.animation(&moves, flat12),
        buf.animation(&turns, |v: [f32; 4]| {
            let mut b = [0u8; 16];
            for (k, x) in v.iter().enumerate() {
                b[4 * k..4 * k + 4].copy_from_slice(&x.to_le_bytes());
            }
            b
        }),
    ];
    let (mut channels, mut samplers) = (Vec::new(), Vec::new());
    for (node, first, n) in animated {
        let t = &times[first..first + n];
        let input = buf.accessor(json!({
            "bufferView": views[0], "byteOffset": 4 * first, "componentType": 5126,
            "count": n, "type": "SCALAR", "min": [t[0]], "max": [t[n - 1]],
        }));
        let moved = buf.accessor(json!({
            "bufferView": views[1], "byteOffset": 12 * first, "componentType": 5126,
            "count": n, "type": "VEC3",
        }));
        let turned = buf.accessor(json!({
            "bufferView": views[2], "byteOffset": 16 * first, "componentType": 5126,
            "count": n, "type": "VEC4",
        }));
        for (path, output) in [("translation", moved), ("rotation", turned)] {
            channels
                .push(json!({"sampler": samplers.len(), "target": {"node": node, "path": path}}));
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        }
    }
    Some(Animated {
        clip: json!({"name": CLIP, "channels": channels, "samplers": samplers}),
        skins,
    })
}

/// The keys to keep (indices, the first and last always): from each kept key, the farthest
/// next key such that every key between lies within tolerance of the straight interpolation.
fn kept(keys: &[WalkKey]) -> Vec<usize> {
    let n = keys.len();
    if n <= 2 {
        return (0..n).collect();
    }
    let mut out = vec![0];
    let mut from = 0;
    while from < n - 1 {
        let mut to = from + 1;
        while to + 1 < n && to + 1 - from <= MAX_RUN && fits(keys, from, to + 1) {
            to += 1;
        }
        out.push(to);
        from = to;
    }
    out
}

/// Whether every key strictly between `a` and `b` lies within tolerance of the straight
/// interpolation between them, in place and in heading.
fn fits(keys: &[WalkKey], a: usize, b: usize) -> bool {
    let (ka, kb) = (&keys[a], &keys[b]);
    let span = (b - a) as f64;
    (a + 1..b).all(|k| {
        let t = (k - a) as f64 / span;
        let p = [0, 1, 2].map(|i| ka.at[i] + (kb.at[i] - ka.at[i]) * t);
        let d = [0, 1, 2].map(|i| p[i] - keys[k].at[i]);
        let h = ka.heading + wrap(kb.heading - ka.heading) * t;
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() <= TOLERANCE
            && wrap(h - keys[k].heading).abs() <= TURN_TOLERANCE
    })
}

/// An angle brought into (-pi, pi].
fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let r = a.rem_euclid(t);
    if r > std::f64::consts::PI {
        r - t
    } else {
        r
    }
}

/// A heading (radians counter-clockwise from east, seen from above) as a unit quaternion
/// (x, y, z, w) about +y of the y-up frame, as the instanced trees are turned.
fn rotation(a: f64) -> [f32; 4] {
    let (s, c) = (a / 2.0).sin_cos();
    [0.0, s as f32, 0.0, c as f32]
}

/// Quaternions with each one's sign chosen nearest the one before, so interpolation between
/// keys takes the short way round.
fn continuous(q: impl Iterator<Item = [f32; 4]>) -> Vec<[f32; 4]> {
    let mut out: Vec<[f32; 4]> = Vec::new();
    for r in q {
        let flip = out
            .last()
            .is_some_and(|p| p.iter().zip(&r).map(|(a, b)| a * b).sum::<f32>() < 0.0);
        out.push(if flip { r.map(|v| -v) } else { r });
    }
    out
}

fn flat12(v: [f32; 3]) -> [u8; 12] {
    let mut b = [0u8; 12];
    for (k, x) in v.iter().enumerate() {
        b[4 * k..4 * k + 4].copy_from_slice(&x.to_le_bytes());
    }
    b
}
