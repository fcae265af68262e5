//! Roofs of planes (the lower envelope of sloped planes): hip, irimoya, pyramidal and stacked
//! roofs are closed shells with their ridges where the planes put them, on rectangles of any
//! proportion and on lots that are not rectangles; roof keys written wrong stop with
//! file:line:column.

mod common;

use common::edo_city;
use edo_city::author::build_alone;
use edo_city::generate::instance::{instantiate, Local, Site};
use edo_city::generate::mesh::{open_edges, Frame, Mesh};
use edo_city::params::Params;
use edo_city::templates::template::{SiteInputs, N_INPUTS};
use edo_city::templates::Catalog;

/// A template file written to its own directory, loaded as a user catalog.
fn user_catalog(name: &str, text: &str) -> (tempfile::TempDir, Result<Catalog, String>) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(format!("{name}.toml")), text).unwrap();
    let cat = Catalog::load(Some(dir.path())).map_err(|e| e.to_string());
    (dir, cat)
}

/// Positions of a mesh in metres as (u, v, h) of the site (the output frame is x east, y up,
/// z south).
fn points(mesh: &Mesh) -> Vec<[f64; 3]> {
    mesh.positions
        .iter()
        .map(|p| {
            [
                p[0] as f64 / 1000.0,
                -(p[2] as f64) / 1000.0,
                p[1] as f64 / 1000.0,
            ]
        })
        .collect()
}

/// The vertices at the mesh's greatest height: the ridge (or apex).
fn ridge(mesh: &Mesh) -> (f64, Vec<[f64; 3]>) {
    let pts = points(mesh);
    let top = pts.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
    let at: Vec<[f64; 3]> = pts
        .into_iter()
        .filter(|p| (p[2] - top).abs() < 0.0015)
        .collect();
    (top, at)
}

const HIP: &str = r#"
name = "hip-test"
kind = "hall"
height = "eave + pitch * min(width, lot_depth) / 2"
[params]
eave = 3.0
pitch = 0.5
[[part]]
name = "roof"
hip_eave = "eave"
hip_pitch = "pitch"
bottom = "0"
"#;

#[test]
fn a_hip_roof_is_closed_and_its_ridge_runs_the_long_way_for_the_difference_of_the_sides() {
    let (_d, cat) = user_catalog("hip-test", HIP);
    let cat = cat.unwrap();
    let t = cat.get("hip-test").unwrap();
    for (w, d) in [(12.0, 8.0), (8.0, 12.0), (20.0, 5.5), (7.3, 7.3)] {
        let alone = build_alone(&cat, t, w, d, &Params::default(), &[]).unwrap();
        assert!(open_edges(&alone.mesh).is_empty(), "{w} x {d}: cracks");
        let (top, at) = ridge(&alone.mesh);
        let expected = 3.0 + 0.5 * f64::min(w, d) / 2.0;
        assert!((top - expected).abs() < 0.0015, "{w} x {d}: ridge {top}");
        let span = |k: usize| {
            let lo = at.iter().map(|p| p[k]).fold(f64::MAX, f64::min);
            let hi = at.iter().map(|p| p[k]).fold(f64::MIN, f64::max);
            hi - lo
        };
        // A hip roof's ridge is as long as the long side less the short one, and lies along
        // the long side; a square gives an apex.
        let (long, short) = if w >= d { (0, 1) } else { (1, 0) };
        assert!((span(long) - (w - d).abs()).abs() < 0.002, "{w} x {d}");
        assert!(span(short) < 0.002, "{w} x {d}");
        // Every face of the roof is flat: a triangle or a quad of one plane.
        let pts = points(&alone.mesh);
        for f in &alone.mesh.faces {
            let c: Vec<[f64; 3]> = f.corners.iter().map(|k| pts[k.0 as usize]).collect();
            if c.len() > 3 {
                let n = normal(c[0], c[1], c[2]);
                for p in &c[3..] {
                    let dist = (0..3).map(|i| (p[i] - c[0][i]) * n[i]).sum::<f64>();
                    assert!(
                        dist.abs() < 0.003,
                        "{w} x {d}: a face off its plane by {dist}"
                    );
                }
            }
        }
    }
}

fn normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let (u, v) = (
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
        [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
    );
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    [n[0] / l, n[1] / l, n[2] / l]
}

/// Builds `t` on a lot given by its (u, v) outline, as the city does.
fn on_lot(cat: &Catalog, name: &str, ring: Vec<[f64; 2]>) -> Result<Mesh, String> {
    let t = cat.get(name).unwrap();
    let site = Site {
        lot: edo_city::generate::clip::LocalPoly::simple(ring.clone()),
        local: Local {
            a: geo_types::Coord { x: 0.0, y: 0.0 },
            u: geo_types::Coord { x: 1.0, y: 0.0 },
            v: geo_types::Coord { x: 0.0, y: 1.0 },
        },
        ground: 0.0,
        slope: 0.0,
    };
    let width = ring.iter().map(|p| p[0]).fold(f64::MIN, f64::max);
    let depth = ring.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
    let inputs: [f64; N_INPUTS] = SiteInputs {
        width,
        lot_depth: depth,
        a: geo_types::Coord { x: 0.0, y: 0.0 },
        b: geo_types::Coord { x: width, y: 0.0 },
        centroid: geo_types::Coord {
            x: width / 2.0,
            y: depth / 2.0,
        },
        ground: 0.0,
        id: "1",
        district: None,
        building_height: 0.0,
        machiya_depth: 12.0,
        min_depth: 4.0,
        random: 0.5,
        ..SiteInputs::default()
    }
    .slots();
    let slots = t.evaluate(&inputs, &[], &[], &site)?;
    let mut mesh = Mesh::new("x".into());
    instantiate(t, &slots, &site, Frame { origin: [0.0; 2] }, &mut mesh)?;
    Ok(mesh)
}

#[test]
fn a_hip_roof_fits_lots_that_are_not_rectangles() {
    let (_d, cat) = user_catalog("hip-test", HIP);
    let cat = cat.unwrap();
    let lots = [
        // A trapezoid, a slanted parallelogram, a pentagon and an L (non-convex: booleans).
        vec![[0.0, 0.0], [14.0, 0.0], [11.0, 9.0], [2.0, 9.0]],
        vec![[0.0, 0.0], [10.0, 0.0], [13.0, 8.0], [3.0, 8.0]],
        vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [12.0, 6.0],
            [5.0, 10.0],
            [-2.0, 6.0],
        ],
        vec![
            [0.0, 0.0],
            [12.0, 0.0],
            [12.0, 5.0],
            [5.0, 5.0],
            [5.0, 12.0],
            [0.0, 12.0],
        ],
    ];
    for ring in lots {
        let mesh = on_lot(&cat, "hip-test", ring.clone()).unwrap();
        assert!(open_edges(&mesh).is_empty(), "{ring:?}: cracks");
        // The eaves lie on the lot's outline at the eave height (on a lot with a reflex
        // corner, its hull's edges), and nothing leaves the lot.
        let pts = points(&mesh);
        let eaves = pts.iter().filter(|p| (p[2] - 3.0).abs() < 0.0015).count();
        let convex = edo_city::generate::clip::is_convex(&ring);
        assert!(
            eaves >= if convex { ring.len() } else { 4 },
            "{ring:?}: {eaves} eave vertices"
        );
        let lowest = pts
            .iter()
            .map(|p| p[2])
            .filter(|h| *h > 0.0)
            .fold(9.0, f64::min);
        assert!(
            lowest >= 3.0 - 0.0015,
            "{ring:?}: the roof dips to {lowest}"
        );
        let lot = geo_types::Polygon::new(
            ring.iter()
                .chain(&ring[..1])
                .map(|p| geo_types::Coord { x: p[0], y: p[1] })
                .collect(),
            vec![],
        );
        for p in &pts {
            let d =
                geo::Distance::distance(&geo::Euclidean, &lot, &geo_types::Point::new(p[0], p[1]));
            assert!(d < 0.002, "{ring:?}: ({}, {}) leaves the lot", p[0], p[1]);
        }
    }
}

#[test]
fn the_shipped_irimoya_has_its_gable_where_the_hip_skirt_is_cut() {
    let cat = Catalog::load(None).unwrap();
    let t = cat.get("hondo").unwrap();
    for (w, d) in [(24.0, 18.0), (16.0, 12.0), (30.0, 14.0)] {
        let alone = build_alone(&cat, t, w, d, &Params::default(), &[]).unwrap();
        assert!(open_edges(&alone.mesh).is_empty(), "{w} x {d}: cracks");
        let (top, at) = ridge(&alone.mesh);
        // The ridge: over the middle of the depth, from one gable to the other.
        let p = |k| t.param(&[], k).unwrap();
        let s = p("margin") + p("overhang") + p("gable_inset");
        let expected = p("eave_height") + p("pitch") * (d / 2.0 - p("margin"));
        assert!((top - expected).abs() < 0.0015, "{w} x {d}: ridge {top}");
        let us: Vec<f64> = at.iter().map(|q| q[0]).collect();
        let lo = us.iter().cloned().fold(f64::MAX, f64::min);
        let hi = us.iter().cloned().fold(f64::MIN, f64::max);
        assert!(
            (lo - s).abs() < 0.002 && (hi - (w - s)).abs() < 0.002,
            "{lo}..{hi}"
        );
        assert!(at.iter().all(|q| (q[1] - d / 2.0).abs() < 0.002));
    }
}

#[test]
fn the_pagoda_stacks_five_roofs_each_narrower_than_the_one_below() {
    let cat = Catalog::load(None).unwrap();
    let t = cat.get("goju-no-to").unwrap();
    let alone = build_alone(&cat, t, 13.0, 13.0, &Params::default(), &[]).unwrap();
    assert!(open_edges(&alone.mesh).is_empty());
    let roofs: Vec<&String> = alone
        .parts
        .iter()
        .filter(|p| p.starts_with("roof"))
        .collect();
    assert_eq!(roofs.len(), 5);
    // The eaves of every tier: corners of the roofs at their eave heights, each tier's
    // half-width `shrink` less than the one below.
    let p = |k| t.param(&[], k).unwrap();
    let pts = points(&alone.mesh);
    let mut eave_heights: Vec<f64> = Vec::new();
    for k in 0..5 {
        let half = p("base_half") - k as f64 * p("shrink") + p("overhang");
        let corner = pts
            .iter()
            .filter(|q| {
                (q[0] - (6.5 - half)).abs() < 0.002
                    && (q[1] - (6.5 - half)).abs() < 0.002
                    && q[2] > 1.0
            })
            .map(|q| q[2])
            .fold(f64::MAX, f64::min);
        assert!(corner < f64::MAX, "tier {} has its eave corner", k + 1);
        eave_heights.push(corner);
    }
    assert!(
        eave_heights.windows(2).all(|w| w[1] > w[0] + 2.0),
        "{eave_heights:?}"
    );
}

#[test]
fn roof_keys_written_wrong_stop_with_the_file_line_and_column() {
    let cases = [
        (
            "top = \"3\"\nplanes = [\"3 + v\"]",
            "either `top` or a roof",
        ),
        ("hip_eave = \"3\"", "needs both `hip_eave`"),
        ("planes = [\"3 + v\"]\nsplit = [\"2\"]", "leave out `split`"),
        (
            "top = \"3\"\nthickness = \"0.3\"",
            "`thickness` belongs to a roof",
        ),
    ];
    for (keys, says) in cases {
        let text =
            format!("name = \"bad-roof\"\nkind = \"hall\"\n[[part]]\nname = \"roof\"\n{keys}\n");
        let (_d, cat) = user_catalog("bad-roof", &text);
        let err = cat.expect_err(keys);
        assert!(err.contains("bad-roof.toml:4:"), "{keys}: {err}");
        assert!(err.contains(says), "{keys}: {err}");
    }
}

#[test]
fn a_plane_that_bends_is_refused_on_the_site_naming_the_part() {
    let text = "name = \"bent\"\nkind = \"hall\"\n[[part]]\nname = \"roof\"\nplanes = [\"3 + abs(v - 4)\"]\n";
    let (_d, cat) = user_catalog("bent", text);
    let cat = cat.unwrap();
    let err = build_alone(
        &cat,
        cat.get("bent").unwrap(),
        8.0,
        8.0,
        &Params::default(),
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("plane 1 is not flat"), "{err}");
    assert!(err.contains("bent.toml:4:"), "{err}");
}

#[test]
fn the_template_command_renders_a_hall_on_its_own_plot() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("pagoda.obj");
    let out = edo_city()
        .args(["template", "goju-no-to", "-o"])
        .arg(&obj)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("on a 13 x 13 m lot"), "{said}");
    assert!(said.contains("closed shell"), "{said}");
    let (models, _) = tobj::load_obj(&obj, &tobj::GPU_LOAD_OPTIONS).unwrap();
    assert!(!models.is_empty());
}
