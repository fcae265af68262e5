//! The ground of a city (`[ground]`) and its halls: every tile has a `ground` object and a
//! `streets` object where it holds a street; the tiles of a town put together are one
//! continuous ground, without gaps or overlaps, across tile borders; streets lie on their
//! centrelines, water where the water layer draws it; halls stand inside their lots, clear
//! of the walls, and each is reported.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{build_objects, build_ok, fixture, read_json, read_lots, ObjObject};
use geo::Contains;

/// Triangles (map x, y) of the named objects, bucketed on a 10 m grid for lookups.
struct Cover {
    tris: Vec<[[f64; 2]; 3]>,
    grid: HashMap<(i64, i64), Vec<usize>>,
}

const CELL: f64 = 10.0;

impl Cover {
    fn of<'a>(objects: impl Iterator<Item = &'a ObjObject>) -> Cover {
        let mut tris = Vec::new();
        for o in objects {
            for t in o.vertices.chunks_exact(3) {
                tris.push([[t[0][0], t[0][1]], [t[1][0], t[1][1]], [t[2][0], t[2][1]]]);
            }
        }
        let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        for (i, t) in tris.iter().enumerate() {
            let lo = |k: usize| t.iter().map(|p| p[k]).fold(f64::MAX, f64::min);
            let hi = |k: usize| t.iter().map(|p| p[k]).fold(f64::MIN, f64::max);
            let c = |v: f64| (v / CELL).floor() as i64;
            for x in c(lo(0))..=c(hi(0)) {
                for y in c(lo(1))..=c(hi(1)) {
                    grid.entry((x, y)).or_default().push(i);
                }
            }
        }
        Cover { tris, grid }
    }

    /// How many triangles hold `p` (a point on a shared edge counts once: half-open test).
    fn count(&self, p: [f64; 2]) -> usize {
        let key = ((p[0] / CELL).floor() as i64, (p[1] / CELL).floor() as i64);
        self.grid.get(&key).map_or(0, |ids| {
            ids.iter().filter(|&&i| inside(&self.tris[i], p)).count()
        })
    }
}

/// Whether `p` is strictly inside the triangle (a point exactly on an edge, to 0.1 µm, is in
/// neither: samples are placed off the tiles' borders).
fn inside(t: &[[f64; 2]; 3], p: [f64; 2]) -> bool {
    let area2 = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let total = area2(t[0], t[1], t[2]);
    if total.abs() < 1e-12 {
        return false;
    }
    (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        area2(a, b, p) * total.signum() / len > 1e-7
    })
}

/// The squares of the tiles a build wrote.
fn squares(out: &Path) -> Vec<[f64; 4]> {
    let m = read_json(&out.join("manifest.json"));
    let p = &m["params"];
    let size = p["tile_size"].as_f64().unwrap();
    let origin = [
        p["tile_origin"][0].as_f64().unwrap(),
        p["tile_origin"][1].as_f64().unwrap(),
    ];
    m["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| {
            let id = t["id"].as_str().unwrap();
            let (c, r) = id.split_once('_').unwrap();
            let (c, r): (f64, f64) = (c.parse().unwrap(), r.parse().unwrap());
            let (x, y) = (origin[0] + c * size, origin[1] + r * size);
            [x, y, x + size, y + size]
        })
        .collect()
}

#[test]
fn the_tiles_of_a_town_are_one_ground_without_gaps_or_overlaps() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    common::synth(&town, 1500, 5);
    let out = dir.path().join("out");
    let params = dir.path().join("p.toml");
    // Small tiles: many borders to cross.
    std::fs::write(
        &params,
        "tile_size = 120.0\n[output]\nformats = [\"obj\"]\n",
    )
    .unwrap();
    build_ok(&town, &out, &["--params", params.to_str().unwrap()]);
    let objects = build_objects(&out);
    let report = read_json(&out.join("report.json"));
    let tiles = report["tiles"].as_array().unwrap();
    assert!(tiles.len() >= 6, "{} tiles", tiles.len());
    // Every tile has its ground, and the ground's bytes are reported.
    let m = read_json(&out.join("manifest.json"));
    for t in m["tiles"].as_array().unwrap() {
        let text = std::fs::read_to_string(out.join(t["obj"]["path"].as_str().unwrap())).unwrap();
        assert!(text.contains("\no ground\n"), "{}", t["id"]);
    }
    assert!(tiles
        .iter()
        .all(|t| t["ground_bytes"].as_u64().unwrap() > 0));
    let ground = Cover::of(
        objects
            .iter()
            .filter(|o| o.name == "ground" || o.name == "streets"),
    );
    // A 1.3 m grid over every tile, and rows 5 mm either side of every tile border: each
    // point lies in exactly one triangle (0: a gap; 2: an overlap).
    let mut samples = 0;
    let mut check = |p: [f64; 2]| {
        let n = ground.count(p);
        assert_eq!(n, 1, "({:.3}, {:.3}) is covered {n} times", p[0], p[1]);
        samples += 1;
    };
    for sq in squares(&out) {
        let mut x = sq[0] + 0.37;
        while x < sq[2] {
            let mut y = sq[1] + 0.41;
            while y < sq[3] {
                check([x, y]);
                y += 1.3;
            }
            x += 1.3;
        }
        let mut t = sq[0] + 0.29;
        while t < sq[2] {
            for y in [sq[1] + 0.005, sq[3] - 0.005] {
                check([t, y]);
            }
            t += 0.7;
        }
        let mut t = sq[1] + 0.31;
        while t < sq[3] {
            for x in [sq[0] + 0.005, sq[2] - 0.005] {
                check([x, t]);
            }
            t += 0.7;
        }
    }
    assert!(samples > 50_000, "{samples}");
    // Every lot's inside lies in a tile written (the ground covers it).
    let lots = read_lots(&town.join("lots.shp"));
    let sq = squares(&out);
    for (id, (_, _, poly)) in lots.iter().take(300) {
        let c = geo::Centroid::centroid(poly).unwrap();
        assert!(
            sq.iter()
                .any(|s| c.x() >= s[0] && c.x() < s[2] && c.y() >= s[1] && c.y() < s[3]),
            "lot {id}"
        );
        assert_eq!(ground.count([c.x(), c.y()]), 1, "lot {id}");
    }
}

#[test]
fn streets_lie_on_their_centrelines_and_water_where_the_layer_draws_it() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    common::copy_fixture("kyoto-small", &town);
    // A pond in the middle of the town's first tile, on lots and a street alike.
    let probe = read_json(&{
        let probe = dir.path().join("probe");
        build_ok(&town, &probe, &["--no-plan", "--format", "obj"]);
        probe.join("manifest.json")
    });
    // Tile bounds are relative to the output origin.
    let (b, o) = (&probe["tiles"][0]["bounds"], &probe["origin"]);
    let e0 = b[0].as_f64().unwrap() + o[0].as_f64().unwrap();
    let n0 = b[1].as_f64().unwrap() + o[1].as_f64().unwrap();
    let pond = vec![
        [e0 + 40.0, n0 + 40.0],
        [e0 + 70.0, n0 + 40.0],
        [e0 + 70.0, n0 + 60.0],
        [e0 + 40.0, n0 + 60.0],
    ];
    edo_city::synth::write_blocks(&town.join("water.shp"), std::slice::from_ref(&pond)).unwrap();
    let out = dir.path().join("out");
    build_ok(&town, &out, &["--no-plan", "--format", "obj"]);
    let objects = build_objects(&out);
    // The pond's middle is water, in the ground object.
    let mtl = std::fs::read_to_string(
        std::fs::read_dir(out.join("tiles"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "mtl"))
            .unwrap(),
    )
    .unwrap();
    assert!(mtl.contains("newmtl water"));
    let ledger = read_json(&out.join("report.json"))["accounting"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["role"] == "water")
        .cloned()
        .expect("the water layer has its ledger");
    assert_eq!(ledger["read"], 1);
    assert_eq!(ledger["unaccounted"], 0);
    let water: Vec<&ObjObject> = objects.iter().filter(|o| o.name == "ground").collect();
    let wet = water.iter().any(|o| {
        o.materials.iter().any(|m| m == "water")
            && o.vertices.iter().any(|v| (v[0] - (e0 + 40.0)).abs() < 0.01)
    });
    assert!(
        wet,
        "the pond's edge is a vertex of the water: {:?}",
        water.iter().map(|o| &o.materials).collect::<Vec<_>>()
    );
    // Street centrelines: points along them lie on the `streets` surface, outside the pond.
    let streets = Cover::of(objects.iter().filter(|o| o.name == "streets"));
    let lines =
        shapefile::read_shapes_as::<_, shapefile::Polyline>(town.join("streets.shp")).unwrap();
    let sq = squares(&out);
    let mut on = 0;
    for l in &lines {
        for part in l.parts() {
            for w in part.windows(2) {
                for k in 0..60 {
                    let t = (k as f64 + 0.5) / 60.0;
                    let p = [
                        w[0].x + t * (w[1].x - w[0].x),
                        w[0].y + t * (w[1].y - w[0].y),
                    ];
                    let in_tile = sq.iter().any(|s| {
                        p[0] > s[0] + 0.1
                            && p[0] < s[2] - 0.1
                            && p[1] > s[1] + 0.1
                            && p[1] < s[3] - 0.1
                    });
                    if in_tile {
                        assert_eq!(streets.count(p), 1, "({:.2}, {:.2})", p[0], p[1]);
                        on += 1;
                    }
                }
            }
        }
    }
    assert!(on > 100, "{on} centreline points checked");
}

#[test]
fn halls_stand_inside_their_lots_facing_away_from_the_street_and_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--no-plan", "--format", "obj"],
    );
    let report = read_json(&out.join("report.json"));
    let halls = report["halls"].as_array().unwrap();
    let placed: Vec<&serde_json::Value> = halls.iter().filter(|h| h["placed"] == true).collect();
    assert!(placed.len() >= 3, "{halls:?}");
    for h in halls {
        assert!(h["placed"] == true || !h["reason"].as_str().unwrap().is_empty());
    }
    let lots = read_lots(&fixture("kyoto-small").join("lots.shp"));
    let objects = build_objects(&out);
    let mut seen = 0;
    for h in &placed {
        let (lot, template) = (h["lot"].as_str().unwrap(), h["template"].as_str().unwrap());
        let name = format!("hall_{lot}_{template}");
        let o = objects
            .iter()
            .find(|o| o.name == name)
            .unwrap_or_else(|| panic!("{name} is in a tile"));
        let poly = &lots[lot].2;
        for v in &o.vertices {
            // Inside the lot, and clear of its edge (where the walls stand) by a metre.
            assert!(
                poly.contains(&geo::Point::new(v[0], v[1])),
                "{name}: ({}, {}) outside lot {lot}",
                v[0],
                v[1]
            );
            let edge = poly
                .exterior()
                .lines()
                .map(|l| geo::Distance::distance(&geo::Euclidean, &l, &geo::Point::new(v[0], v[1])))
                .fold(f64::MAX, f64::min);
            assert!(edge > 1.0, "{name}: {edge} m from the lot's edge");
        }
        seen += 1;
    }
    assert_eq!(seen, placed.len());
    // No tree or person stands in a hall's plot.
    let people_and_trees: Vec<&ObjObject> = objects
        .iter()
        .filter(|o| o.name == "trees" || o.name == "people")
        .collect();
    let hall_cover = Cover::of(objects.iter().filter(|o| o.name.starts_with("hall_")));
    for o in people_and_trees {
        for q in o.vertices.chunks_exact(6) {
            // A billboard's foot: the lowest two corners' middle.
            let mut by_height = q.to_vec();
            by_height.sort_by(|a, b| a[2].total_cmp(&b[2]));
            let foot = [
                (by_height[0][0] + by_height[1][0]) / 2.0,
                (by_height[0][1] + by_height[1][1]) / 2.0,
            ];
            assert_eq!(hall_cover.count(foot), 0, "{} at {foot:?}", o.name);
        }
    }
}

#[test]
fn a_lot_too_small_for_its_halls_is_reported_with_why_and_a_use_without_halls_stays_open() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(
        &params,
        "[halls.uses]\njisha = [\"shinden\"]\nbuke = []\n[template.shinden]\nplot_width = 400.0\nplot_depth = 300.0\nmin_scale = 0.9\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = common::build_cmd(
        &fixture("kyoto-small"),
        &out,
        &[
            "--no-plan",
            "--format",
            "obj",
            "--params",
            params.to_str().unwrap(),
        ],
    )
    .output()
    .unwrap();
    assert!(run.status.success());
    // The summary counts the halls and those without room.
    let said = String::from_utf8_lossy(&run.stdout);
    assert!(
        said.contains("; 1 without room, see report.json halls"),
        "{said}"
    );
    let report = read_json(&out.join("report.json"));
    let halls = report["halls"].as_array().unwrap();
    assert_eq!(halls.len(), 1, "only the temple asks for a hall: {halls:?}");
    assert_eq!(halls[0]["placed"], false);
    assert!(halls[0]["reason"]
        .as_str()
        .unwrap()
        .contains("no open plot of 360.0 x 270.0 m"));
    let objects = build_objects(&out);
    assert!(!objects.iter().any(|o| o.name.starts_with("hall_")));
}

#[test]
fn a_hall_use_naming_no_hall_template_stops_the_build() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[halls.uses]\njisha = [\"kura\"]\n").unwrap();
    let out = dir.path().join("out");
    let run = common::build_cmd(
        &fixture("kyoto-small"),
        &out,
        &["--params", params.to_str().unwrap()],
    )
    .output()
    .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("halls.uses.jisha names `kura`"), "{err}");
    assert!(err.contains("hondo"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_temples_garden_faces_its_main_hall_and_keeps_clear_of_every_hall() {
    let dir = tempfile::tempdir().unwrap();
    common::synth(dir.path(), 3000, 4);
    let params = edo_city::params::Params::default();
    let data = edo_city::input::read_dataset(dir.path(), &params).expect("reads");
    let catalog = edo_city::templates::Catalog::load(None).unwrap();
    let plan = edo_city::analyse::analyse(&data, &params, &catalog, "lots.shp", &|_| {});
    let halls: Vec<_> = plan.halls.values().flatten().collect();
    let mut faced = 0;
    for g in plan.gardens.values().flatten() {
        let ring = g.outline();
        // No corner or side midpoint of the garden lies in a hall's plot.
        for h in &halls {
            let plot = geo_types::Polygon::new(
                h.outline().into_iter().chain([h.outline()[0]]).collect(),
                vec![],
            );
            for k in 0..4 {
                let (a, b) = (ring[k], ring[(k + 1) % 4]);
                for p in [
                    a,
                    geo_types::Coord {
                        x: (a.x + b.x) / 2.0,
                        y: (a.y + b.y) / 2.0,
                    },
                ] {
                    assert!(
                        !plot.contains(&geo::Point(p)),
                        "garden {} in hall {}",
                        g.lot,
                        h.template
                    );
                }
            }
        }
        let Some(hondo) = halls
            .iter()
            .find(|h| h.lot == g.lot && h.template == "hondo")
        else {
            continue;
        };
        // The viewing side (ring[0] -> ring[1]) is nearer the hall than the far side.
        let c = hondo.centre();
        let mid = |a: geo_types::Coord<f64>, b: geo_types::Coord<f64>| {
            ((a.x + b.x) / 2.0 - c.x).hypot((a.y + b.y) / 2.0 - c.y)
        };
        assert!(
            mid(ring[0], ring[1]) < mid(ring[2], ring[3]),
            "garden {}",
            g.lot
        );
        faced += 1;
    }
    assert!(faced > 0, "some temple has both a hondo and a garden");
}
