//! Fences and gates along walled lots (section 4.3): every edge walled, gates split the wall
//! as Fig.11, textures repeat instead of stretching, and sharp corners close.

mod common;

use std::path::Path;

use common::{build_ok, read_json};
use edo_city::synth::{write_blocks, write_lots, SynthLot};
use geo_types::{Coord, LineString, Polygon};

fn walled(id: u64, lot_use: &'static str, ring: Vec<[f64; 2]>) -> SynthLot {
    SynthLot {
        id,
        ring,
        lot_use,
        mtype: "",
        district: "",
        gate: "",
    }
}

/// A ten-pointed star (temple, earthen wall), a rectangle (samurai, board fence 2.5 m high)
/// and a small noble lot whose street edge is shorter than a gate; each has its gate on the
/// edge facing the street.
fn town(dir: &Path) -> Vec<SynthLot> {
    let star: Vec<[f64; 2]> = (0..10)
        .map(|k| {
            let a = std::f64::consts::PI * 2.0 * k as f64 / 10.0 - std::f64::consts::FRAC_PI_2;
            let r = if k % 2 == 0 { 25.0 } else { 12.0 };
            [60.0 + r * a.cos(), 30.0 + r * a.sin()]
        })
        .collect();
    let lots = vec![
        walled(1, "jisha", star),
        walled(
            2,
            "buke",
            vec![[100.0, 0.0], [140.0, 0.0], [140.0, 30.0], [100.0, 30.0]],
        ),
        walled(
            3,
            "kuge",
            vec![[160.0, 0.0], [162.5, 0.0], [170.0, 20.0], [160.0, 20.0]],
        ),
    ];
    write_lots(&dir.join("lots.shp"), &lots).unwrap();
    write_blocks(
        &dir.join("blocks.shp"),
        &[vec![[0.0, 0.0], [200.0, 0.0], [200.0, 80.0], [0.0, 80.0]]],
    )
    .unwrap();
    std::fs::write(
        dir.join("lots.csv"),
        "id,gate,height\n1,1,\n2,street,2.5\n3,1,\n",
    )
    .unwrap();
    lots
}

/// A triangle's corners (map x, y, h) and their texture coordinates.
type Tri = ([[f64; 3]; 3], [[f64; 2]; 3]);

struct Object {
    name: String,
    /// Triangles: map (x, y, h) corners and their texture coordinates.
    tris: Vec<Tri>,
}

fn objects(out: &Path) -> Vec<Object> {
    let m = read_json(&out.join("manifest.json"));
    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
    ];
    let mut all = Vec::new();
    for t in m["tiles"].as_array().unwrap() {
        let opts = tobj::LoadOptions {
            triangulate: true,
            ..Default::default()
        };
        let (models, _) =
            tobj::load_obj(out.join(t["obj"]["path"].as_str().unwrap()), &opts).unwrap();
        for model in models {
            let mesh = &model.mesh;
            let p = |i: u32| {
                let i = i as usize;
                [
                    mesh.positions[3 * i] + origin[0],
                    -mesh.positions[3 * i + 2] + origin[1],
                    mesh.positions[3 * i + 1],
                ]
            };
            let uv = |i: u32| {
                let i = i as usize;
                [mesh.texcoords[2 * i], mesh.texcoords[2 * i + 1]]
            };
            let tris = (0..mesh.indices.len() / 3)
                .map(|k| {
                    let (a, b) = (
                        &mesh.indices[3 * k..3 * k + 3],
                        &mesh.texcoord_indices[3 * k..3 * k + 3],
                    );
                    ([p(a[0]), p(a[1]), p(a[2])], [uv(b[0]), uv(b[1]), uv(b[2])])
                })
                .collect();
            all.push(Object {
                name: model.name.clone(),
                tris,
            });
        }
    }
    all
}

fn polygon(ring: &[[f64; 2]]) -> Polygon<f64> {
    let mut pts: Vec<Coord<f64>> = ring.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
    pts.push(pts[0]);
    Polygon::new(LineString(pts), vec![])
}

fn in_triangle(p: [f64; 2], t: &[[f64; 3]; 3]) -> bool {
    let s =
        |a: [f64; 3], b: [f64; 3]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let (d0, d1, d2) = (s(t[0], t[1]), s(t[1], t[2]), s(t[2], t[0]));
    (d0 >= -1e-9 && d1 >= -1e-9 && d2 >= -1e-9) || (d0 <= 1e-9 && d1 <= 1e-9 && d2 <= 1e-9)
}

#[test]
fn walls_gates_and_corners() {
    let dir = tempfile::tempdir().unwrap();
    let lots = town(dir.path());
    let out = dir.path().join("out");
    let r = build_ok(dir.path(), &out, &["--quiet", "--no-plan"]);
    let c = &r["counts"];
    // Star: 9 whole edges + the gate edge's two side parts; rectangle 3 + 2; lot 3: 3 edges
    // beside the edge its gate fills.
    assert_eq!(c["gates"], 3, "{c}");
    assert_eq!(c["fence_segments"], 11 + 5 + 3, "{c}");
    assert!(
        r["warnings"]
            .to_string()
            .contains("is 2.50 m, shorter than the gate (3.03 m): the gate fills the edge"),
        "{}",
        r["warnings"]
    );
    let wall = c["wall_metres"]["tsuiji"].as_f64().unwrap();
    assert!(wall > 100.0, "star and noble lot walls: {wall} m");
    assert!((c["wall_metres"]["fence"].as_f64().unwrap() - (140.0 - 3.03)).abs() < 0.01);

    let objs = objects(&out);
    // tobj splits an object per material: gather the parts of each name.
    let get = |name: &str| {
        let parts: Vec<&Object> = objs.iter().filter(|o| o.name.starts_with(name)).collect();
        assert!(!parts.is_empty(), "no {name}");
        assert!(
            parts.iter().all(|o| o.name == parts[0].name),
            "one object: {name}"
        );
        Object {
            name: parts[0].name.clone(),
            tris: parts.iter().flat_map(|o| o.tris.iter().cloned()).collect(),
        }
    };
    let mut names: Vec<&str> = objs.iter().map(|o| o.name.as_str()).collect();
    names.dedup();
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(
        names.len(),
        unique.len(),
        "each object once, in one run: {names:?}"
    );

    // The star's wall stands on its lot: no spike leaves it at the sharp points.
    let star = polygon(&lots[0].ring);
    use geo::{Contains, Distance, Euclidean};
    for (tri, _) in &get("fence_1").tris {
        for p in tri.iter().filter(|p| p[2] < 0.001) {
            let q = geo_types::Point::new(p[0], p[1]);
            let d = if star.contains(&q) {
                0.0
            } else {
                Euclidean.distance(&q, star.exterior())
            };
            assert!(d < 0.002, "ground vertex {p:?} {d} m outside the star");
        }
    }
    // No gaps: a point 0.3 m inside every edge (the wall is 0.6 m thick), near its ends as
    // well as in its middle, lies under the wall, except in the gate's opening.
    let fence1 = get("fence_1");
    let ground: Vec<&[[f64; 3]; 3]> = fence1
        .tris
        .iter()
        .map(|t| &t.0)
        .filter(|t| t.iter().all(|p| p[2].abs() < 0.001))
        .collect();
    let gate = get("gate_1_");
    let gate_edge: usize = gate.name.rsplit('_').next().unwrap().parse().unwrap();
    let gate_ground: Vec<&[[f64; 3]; 3]> = gate
        .tris
        .iter()
        .map(|t| &t.0)
        .filter(|t| t.iter().all(|p| p[2].abs() < 0.001))
        .collect();
    let ring = &lots[0].ring;
    for i in 0..ring.len() {
        let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let (ux, uy) = ((b[0] - a[0]) / len, (b[1] - a[1]) / len);
        for t in [0.15, 0.5, len / 2.0, len - 0.5, len - 0.15] {
            let p = [a[0] + ux * t - uy * 0.3, a[1] + uy * t + ux * 0.3];
            // Near a sharp point the sample can fall outside the lot: nothing to cover there.
            let in_gate_opening = !star.contains(&geo_types::Point::new(p[0], p[1]));
            let _ = gate_edge;
            let covered = ground.iter().any(|tri| in_triangle(p, tri))
                || gate_ground.iter().any(|tri| in_triangle(p, tri));
            assert!(
                covered || in_gate_opening,
                "edge {}: {p:?} ({t:.2} m along) is in a gap",
                i + 1
            );
        }
    }

    // The board fence: 2.5 m high from the lot's `height`; its texture repeats, one repeat
    // per 1.818 m rounded up, on every panel; the gate is taller than the wall.
    let fence = get("fence_2");
    let top = fence
        .tris
        .iter()
        .flat_map(|t| t.0)
        .map(|p| p[2])
        .fold(0.0, f64::max);
    assert!((top - 2.5).abs() < 0.001, "{top}");
    let lens = [(40.0 - 3.03) / 2.0, (40.0 - 3.03) / 2.0, 30.0, 40.0, 30.0];
    let mut wanted: Vec<f64> = lens.iter().map(|l| (l / 1.818f64).ceil()).collect();
    wanted.sort_by(f64::total_cmp);
    wanted.dedup();
    let mut spans: Vec<f64> = fence
        .tris
        .iter()
        .map(|t| t.1.iter().map(|uv| uv[0]).fold(0.0, f64::max))
        .collect();
    spans.sort_by(f64::total_cmp);
    spans.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    assert_eq!(spans, wanted, "UV spans of the panels");
    let gate2 = get("gate_2_");
    let gate_top = gate2
        .tris
        .iter()
        .flat_map(|t| t.0)
        .map(|p| p[2])
        .fold(0.0, f64::max);
    assert!(gate_top > 3.0, "{gate_top}");
    // The gate is 1 jo wide, centred on the street edge (y = 0, x from 100 to 140), standing
    // on it and reaching into the lot.
    let ground: Vec<[f64; 3]> = gate2
        .tris
        .iter()
        .flat_map(|t| t.0)
        .filter(|p| p[2] < 0.001)
        .collect();
    let (lo, hi) = ground
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[0]), b.max(p[0])));
    assert!(
        (lo - (120.0 - 1.515)).abs() < 0.002 && (hi - (120.0 + 1.515)).abs() < 0.002,
        "{lo} {hi}"
    );
    assert!(ground.iter().all(|p| (0.0..=1.0).contains(&p[1])));
}

/// One line of `fences.shp`: id, points, fence type, gate, height.
type FenceRow<'a> = (u32, Vec<[f64; 2]>, &'a str, &'a str, f64);

fn write_fence_lines(path: &Path, lines: &[FenceRow]) {
    use dbase::{FieldName, FieldValue, Record, TableWriterBuilder};
    let name = |s: &str| FieldName::try_from(s).unwrap();
    let table = TableWriterBuilder::new()
        .add_numeric_field(name("id"), 10, 0)
        .add_character_field(name("fence"), 20)
        .add_character_field(name("gate"), 10)
        .add_numeric_field(name("height"), 8, 2);
    let mut w = shapefile::Writer::from_path(path, table).unwrap();
    for (id, pts, fence, gate, height) in lines {
        let mut rec = Record::default();
        rec.insert("id".into(), FieldValue::Numeric(Some(*id as f64)));
        rec.insert(
            "fence".into(),
            FieldValue::Character(Some(fence.to_string())),
        );
        rec.insert("gate".into(), FieldValue::Character(Some(gate.to_string())));
        rec.insert("height".into(), FieldValue::Numeric(Some(*height)));
        let pts: Vec<shapefile::Point> = pts
            .iter()
            .map(|p| shapefile::Point::new(p[0], p[1]))
            .collect();
        w.write_shape_and_record(&shapefile::Polyline::new(pts), &rec)
            .unwrap();
    }
}

#[test]
fn free_standing_fence_lines_from_a_line_layer() {
    let dir = tempfile::tempdir().unwrap();
    // One town lot, so there is something on the street; the fences stand on open ground.
    write_lots(
        &dir.path().join("lots.shp"),
        &[SynthLot {
            id: 1,
            ring: vec![[0.0, 0.0], [6.0, 0.0], [6.0, 20.0], [0.0, 20.0]],
            lot_use: "machiya",
            mtype: "平屋",
            district: "",
            gate: "",
        }],
    )
    .unwrap();
    write_blocks(
        &dir.path().join("blocks.shp"),
        &[vec![[0.0, 0.0], [100.0, 0.0], [100.0, 60.0], [0.0, 60.0]]],
    )
    .unwrap();
    write_fence_lines(
        &dir.path().join("fences.shp"),
        &[
            // A closed square drawn clockwise: still walled on its inside.
            (
                7,
                vec![
                    [20.0, 10.0],
                    [20.0, 30.0],
                    [40.0, 30.0],
                    [40.0, 10.0],
                    [20.0, 10.0],
                ],
                "tsuiji",
                "0",
                3.0,
            ),
            // An open line of two segments, gate on the second, wall on its left.
            (
                8,
                vec![[50.0, 10.0], [70.0, 10.0], [70.0, 30.0]],
                "fence",
                "e2",
                0.0,
            ),
        ],
    );
    // Small numbers without a .prj would read as degrees: give the lots' CRS.
    std::fs::copy(dir.path().join("lots.prj"), dir.path().join("fences.prj")).unwrap();
    let out = dir.path().join("out");
    let r = build_ok(dir.path(), &out, &["--quiet", "--no-plan"]);
    let c = &r["counts"];
    assert_eq!(c["gates"], 1, "{c}");
    assert_eq!(c["fence_segments"], 4 + 1 + 2, "{c}");
    assert!(
        (c["wall_metres"]["tsuiji"].as_f64().unwrap() - 80.0).abs() < 0.01,
        "{c}"
    );
    assert!((c["wall_metres"]["fence"].as_f64().unwrap() - (40.0 - 3.03)).abs() < 0.01);
    let layers = r["layers"].as_array().unwrap();
    assert!(layers
        .iter()
        .any(|l| l["role"] == "fences" && l["features"] == 2));

    let objs = objects(&out);
    let square: Vec<[f64; 3]> = objs
        .iter()
        .filter(|o| o.name == "fenceline_7")
        .flat_map(|o| o.tris.iter().flat_map(|t| t.0))
        .collect();
    assert!(!square.is_empty());
    // The tsuiji of the square stands inside it (its coping reaches out above 3 m), 3 m high.
    for p in square.iter().filter(|p| p[2] < 2.0) {
        assert!(
            (20.0 - 1e-3..=40.0 + 1e-3).contains(&p[0])
                && (10.0 - 1e-3..=30.0 + 1e-3).contains(&p[1]),
            "{p:?} outside the square"
        );
    }
    // Its earthen wall reaches the `height` of the line (3 m), under the coping.
    assert!(square.iter().any(|p| (p[2] - 3.0).abs() < 1e-3));
    assert!(!square.iter().any(|p| p[2] > 1.0 && p[2] < 2.9));
    // The open line's wall is on its left: north of its first segment, west of its second.
    let open: Vec<[f64; 3]> = objs
        .iter()
        .filter(|o| o.name == "fenceline_8")
        .flat_map(|o| o.tris.iter().flat_map(|t| t.0))
        .collect();
    assert!(!open.is_empty());
    assert!(objs.iter().any(|o| o.name == "gateline_8_2"));
    let gate: Vec<[f64; 3]> = objs
        .iter()
        .filter(|o| o.name == "gateline_8_2")
        .flat_map(|o| o.tris.iter().flat_map(|t| t.0))
        .filter(|p| p[2] < 0.001)
        .collect();
    assert!(
        gate.iter().all(|p| p[0] <= 70.0 + 1e-3 && p[0] >= 69.0),
        "west of x = 70: {gate:?}"
    );
}
