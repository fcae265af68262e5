//! A tile's walkers as glTF 2.0 animation: each figure (a picture's person at 1 m) once as a
//! mesh, one node per walker drawing its figure at its scale, and one clip, `crowd`, of every
//! walker's translation and rotation keys (LINEAR, the last key the first, so a player that
//! loops it shows no jump). three.js' GLTFLoader, Blender's importer and CesiumJS play it.
//!
//! Keys on a straight, even walk say nothing the keys either side do not: a key is kept only
//! where leaving it out would move the walker more than [`TOLERANCE`] metres or turn it more
//! than [`TURN_TOLERANCE`] from where interpolation puts it (each walker its own times).
//! Rotations are normalized shorts (core glTF allows them for rotation outputs), times and
//! translations floats; all through meshopt's vertex codec when the GLB is compressed.
//!
//! Each walker's node carries its person id and group in `extras` (three.js copies them into
//! `userData`), and its figure's vertices the feature id of the tile's people row, so a click
//! on a walker names it as a click on a standing person does.

use std::collections::BTreeMap;

use serde_json::{json, Value};

use super::buffer::Buffer;
use super::{Primitive, Slot};
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

/// Adds the figures as meshes and a node per walker (appended to `meshes` and `nodes`) and
/// returns the clip. `feature` is the people row the figures' vertices carry; `origin` and
/// `shift` as for the tile's other nodes.
#[allow(clippy::too_many_arguments)]
pub(super) fn add(
    crowd: &Crowd,
    atlas: Option<&crate::output::atlas::Atlas>,
    origin: [f64; 2],
    shift: [i64; 3],
    feature: u32,
    buf: &mut Buffer,
    used: &mut Vec<u16>,
    meshes: &mut Vec<Value>,
    nodes: &mut Vec<Value>,
) -> Option<Value> {
    let mut figure_mesh: Vec<Option<usize>> = Vec::new();
    for f in &crowd.figures {
        let mut prims: BTreeMap<u16, Primitive> = BTreeMap::new();
        for face in &f.faces {
            let slot = Slot::of(atlas, face.material);
            prims
                .entry(slot.key)
                .or_default()
                .face(feature, f, &face.corners, [0, 0, 0], slot);
        }
        let mut primitives = Vec::new();
        for (&material, p) in prims.iter_mut() {
            p.reorder();
            if !p.indices.is_empty() {
                primitives.push(super::primitive_json(p, material, true, buf, used));
            }
        }
        figure_mesh.push((!primitives.is_empty()).then(|| {
            meshes.push(json!({"name": f.name, "primitives": primitives}));
            meshes.len() - 1
        }));
    }
    // Every walker's keys in three views for the tile (times, translations, rotations),
    // each walker's accessors at its offset: a view and its JSON per walker and channel took
    // twice the bytes of the keys themselves.
    let (mut times, mut moves, mut turns) = (Vec::new(), Vec::new(), Vec::new());
    let mut animated: Vec<(usize, usize, usize)> = Vec::new(); // node, first key, keys
    for w in &crowd.walkers {
        let Some(mesh) = figure_mesh[w.figure] else {
            continue;
        };
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
            "mesh": mesh,
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
        turns.extend(q.iter().map(|r| r.map(short)));
        if let Some(last) = animated.last_mut() {
            last.2 = idx.len();
        }
    }
    if animated.is_empty() {
        return None;
    }
    let views = [
        buf.animation(&times, f32::to_le_bytes),
        buf.animation(&moves, flat12),
        buf.animation(&turns, |v: [i16; 4]| {
            let mut b = [0u8; 8];
            for (k, x) in v.iter().enumerate() {
                b[2 * k..2 * k + 2].copy_from_slice(&x.to_le_bytes());
            }
            b
        }),
    ];
    let (mut channels, mut samplers) = (Vec::new(), Vec::new());
    for (node, first, n) in animated {
        let t = &times[first..first + n];
        let input = push(
            buf,
            json!({
                "bufferView": views[0], "byteOffset": 4 * first, "componentType": 5126,
                "count": n, "type": "SCALAR", "min": [t[0]], "max": [t[n - 1]],
            }),
        );
        let moved = push(
            buf,
            json!({
                "bufferView": views[1], "byteOffset": 12 * first, "componentType": 5126,
                "count": n, "type": "VEC3",
            }),
        );
        let turned = push(
            buf,
            json!({
                "bufferView": views[2], "byteOffset": 8 * first, "componentType": 5122,
                "normalized": true, "count": n, "type": "VEC4",
            }),
        );
        for (path, output) in [("translation", moved), ("rotation", turned)] {
            channels
                .push(json!({"sampler": samplers.len(), "target": {"node": node, "path": path}}));
            samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        }
    }
    Some(json!({"name": CLIP, "channels": channels, "samplers": samplers}))
}

/// Adds an accessor; returns its index.
fn push(buf: &mut Buffer, accessor: Value) -> usize {
    buf.accessors.push(accessor);
    buf.accessors.len() - 1
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

/// A unit component as a normalized short.
fn short(v: f32) -> i16 {
    (v.clamp(-1.0, 1.0) * 32767.0).round() as i16
}

fn flat12(v: [f32; 3]) -> [u8; 12] {
    let mut b = [0u8; 12];
    for (k, x) in v.iter().enumerate() {
        b[4 * k..4 * k + 4].copy_from_slice(&x.to_le_bytes());
    }
    b
}
