//! Terrain from a DEM: houses on the lowest ground under their lots, fences on the ground
//! under each end, clear messages for a DEM that is off the lots or in another CRS.

mod common;

use std::path::Path;

use common::{build_ok, copy_fixture, edo_city, fixture, load_tile, read_json, read_lots};

/// A plane rising 5 cm per metre east and 2 cm per metre north, as an ESRI ASCII grid of
/// `n` x `n` cells of 10 m from (x0, y0).
fn write_plane(path: &Path, x0: f64, y0: f64, n: usize) {
    let mut s = format!(
        "ncols {n}\nnrows {n}\nxllcorner {x0}\nyllcorner {y0}\ncellsize 10\nNODATA_value -9999\n"
    );
    for row in 0..n {
        let y = y0 + (n - row) as f64 * 10.0 - 5.0;
        let line: Vec<String> = (0..n)
            .map(|c| {
                let x = x0 + c as f64 * 10.0 + 5.0;
                format!("{:.4}", plane(x - x0, y - y0))
            })
            .collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

fn plane(dx: f64, dy: f64) -> f64 {
    0.05 * dx + 0.02 * dy
}

const X0: f64 = -23_100.0;
const Y0: f64 = -110_100.0;

#[test]
fn houses_and_fences_stand_on_the_dem() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    copy_fixture("kyoto-small", &input);
    write_plane(&input.join("dem.asc"), X0, Y0, 100);
    let out = dir.path().join("out");
    let r = build_ok(&input, &out, &["--quiet", "--no-plan"]);
    assert!(
        !r["warnings"].to_string().contains("outside the DEM"),
        "{}",
        r["warnings"]
    );
    let m = read_json(&out.join("manifest.json"));
    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
    ];
    let lots = read_lots(&fixture("kyoto-small").join("lots.shp"));
    let (mut houses, mut fences, mut halls) = (0, 0, 0);
    for t in m["tiles"].as_array().unwrap() {
        for o in load_tile(&out.join(t["obj"]["path"].as_str().unwrap()), origin) {
            if o.name == "people" || o.name == "trees" {
                continue; // billboards: tests/billboards.rs
            }
            if o.name == "ground" || o.name == "streets" {
                // Without `terrain` the ground stands on the lots' elevations, which the
                // DEM gave: every vertex within the plane's rise across a few lots.
                continue;
            }
            let (kind, id) = o.name.split_once('_').unwrap();
            let base = o
                .vertices
                .iter()
                .map(|v| v[2])
                .fold(f64::INFINITY, f64::min);
            match kind {
                "machiya" => {
                    // The flat base is the lowest ground under the lot: never floating.
                    let lot = &lots[id].2;
                    let lowest = lot
                        .exterior()
                        .0
                        .iter()
                        .map(|c| plane(c.x - X0, c.y - Y0))
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        (base - lowest).abs() < 0.002,
                        "{}: base {base}, lowest ground {lowest}",
                        o.name
                    );
                    houses += 1;
                }
                "fence" => {
                    // Every vertex on the lot's edge, at the foot of a wall, is on the ground
                    // under it; the inner foot of a thick wall follows the edge's slope, so
                    // it sits within the cross slope x thickness (5 cm/m x 0.6 m) of it.
                    for v in &o.vertices {
                        let g = plane(v[0] - X0, v[1] - Y0);
                        assert!(v[2] >= g - 0.031, "{}: {v:?} below ground {g}", o.name);
                    }
                    let on_ground = o
                        .vertices
                        .iter()
                        .filter(|v| (v[2] - plane(v[0] - X0, v[1] - Y0)).abs() < 0.002)
                        .count();
                    assert!(
                        on_ground >= 8,
                        "{}: {on_ground} vertices on the ground",
                        o.name
                    );
                    fences += 1;
                }
                "hall" => {
                    // A hall's flat base is the lowest ground under its plot's corners: at or
                    // below the ground under any of its own vertices (never floating), and
                    // less than a metre below it on this 5 cm/m slope.
                    let corners_low = o
                        .vertices
                        .iter()
                        .map(|v| plane(v[0] - X0, v[1] - Y0))
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        base <= corners_low + 0.002 && base > corners_low - 1.0,
                        "{}: base {base}, ground under it from {corners_low}",
                        o.name
                    );
                    halls += 1;
                }
                _ => {}
            }
        }
    }
    assert!(
        houses > 300 && fences == 2 && halls >= 3,
        "{houses} houses, {fences} fences, {halls} halls"
    );
}

#[test]
fn a_dem_off_the_lots_warns_and_one_in_another_crs_stops() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    copy_fixture("kyoto-small", &input);
    // Covers only the south-west corner of the town.
    write_plane(&input.join("dem.asc"), X0, Y0, 25);
    let r = build_ok(&input, &dir.path().join("out"), &["--quiet", "--no-plan"]);
    assert!(
        r["warnings"].to_string().contains("lie outside the DEM"),
        "{}",
        r["warnings"]
    );

    // A .prj in another zone: an error naming the file and what to do, nothing written.
    std::fs::write(
        input.join("dem.prj"),
        std::fs::read_to_string(input.join("lots.prj"))
            .unwrap()
            .replace("136", "139"),
    )
    .unwrap();
    let out = dir.path().join("out2");
    let run = edo_city()
        .arg("build")
        .arg(&input)
        .args(["--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("dem.asc") && err.contains("reproject the DEM"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn the_terrain_mesh_is_the_dem_clipped_to_each_tile() {
    // With `[ground]` the ground itself is draped on the DEM (object `ground`); without it,
    // the terrain is its own mesh `terrain_<tile>`.
    for (text, object) in [
        ("terrain = true\n", "ground"),
        ("terrain = true\n[ground]\nenabled = false\n", "terrain"),
    ] {
        terrain_clipped_to_each_tile(text, object);
    }
}

fn terrain_clipped_to_each_tile(params_text: &str, object: &str) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    copy_fixture("kyoto-small", &input);
    write_plane(&input.join("dem.asc"), X0, Y0, 100);
    let params = dir.path().join("p.toml");
    std::fs::write(&params, params_text).unwrap();
    let out = dir.path().join("out");
    build_ok(
        &input,
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let m = read_json(&out.join("manifest.json"));
    let origin = [
        m["origin"][0].as_f64().unwrap(),
        m["origin"][1].as_f64().unwrap(),
    ];
    let size = m["tile_size"].as_f64().unwrap();
    let grid = m["params"]["tile_origin"].as_array().unwrap();
    let (gx, gy) = (grid[0].as_f64().unwrap(), grid[1].as_f64().unwrap());
    let mut tiles = 0;
    for t in m["tiles"].as_array().unwrap() {
        let id = t["id"].as_str().unwrap();
        let (c, r) = id.split_once('_').unwrap();
        let (x0, y0) = (
            gx + c.parse::<f64>().unwrap() * size,
            gy + r.parse::<f64>().unwrap() * size,
        );
        let objects = load_tile(&out.join(t["obj"]["path"].as_str().unwrap()), origin);
        let name = match object {
            "terrain" => format!("terrain_{id}"),
            other => other.to_string(),
        };
        let ground: Vec<_> = objects.iter().filter(|o| o.name == name).collect();
        assert_eq!(ground.len(), 1, "{id}: one {name} object");
        assert!(
            !objects.iter().any(|o| o.name.starts_with("terrain_")) || object == "terrain",
            "{id}: the ground replaces the terrain mesh"
        );
        for v in &ground[0].vertices {
            assert!(
                v[0] >= x0 - 1e-3
                    && v[0] <= x0 + size + 1e-3
                    && v[1] >= y0 - 1e-3
                    && v[1] <= y0 + size + 1e-3,
                "{id}: {v:?} off the tile"
            );
            // Inside the DEM's cell centres the bilinear surface is the plane itself.
            if v[0] > X0 + 5.0 && v[1] > Y0 + 5.0 && v[0] < X0 + 995.0 && v[1] < Y0 + 995.0 {
                let g = plane(v[0] - X0, v[1] - Y0);
                assert!((v[2] - g).abs() < 0.002, "{id}: {v:?} vs {g}");
            }
        }
        assert!(ground[0].materials.contains(&"ground".to_string()));
        tiles += 1;
    }
    assert_eq!(tiles, 4);
}

#[test]
fn a_geotiff_gives_the_same_city_as_the_same_ascii_grid() {
    use tiff::encoder::{colortype, TiffEncoder};
    use tiff::tags::Tag;
    let n = 100;
    // Values exact in f32 and in decimal, so both files hold the very same numbers.
    let z = |col: usize, row: usize| (col as f32) * 0.5 + ((n - row) as f32) * 0.25;
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    copy_fixture("kyoto-small", &a);
    copy_fixture("kyoto-small", &b);
    let mut asc = format!("ncols {n}\nnrows {n}\nxllcorner {X0}\nyllcorner {Y0}\ncellsize 10\n");
    for row in 0..n {
        let line: Vec<String> = (0..n).map(|c| z(c, row).to_string()).collect();
        asc.push_str(&line.join(" "));
        asc.push('\n');
    }
    std::fs::write(a.join("dem.asc"), asc).unwrap();
    // The GeoTIFF, found by the default name's stem (dem.tif), placed by its tags.
    let mut enc = TiffEncoder::new(std::fs::File::create(b.join("dem.tif")).unwrap()).unwrap();
    let mut img = enc
        .new_image::<colortype::Gray32Float>(n as u32, n as u32)
        .unwrap();
    img.encoder()
        .write_tag(Tag::ModelPixelScaleTag, &[10.0f64, 10.0, 0.0][..])
        .unwrap();
    let top = Y0 + n as f64 * 10.0;
    img.encoder()
        .write_tag(Tag::ModelTiepointTag, &[0.0f64, 0.0, 0.0, X0, top, 0.0][..])
        .unwrap();
    let data: Vec<f32> = (0..n)
        .flat_map(|row| (0..n).map(move |c| z(c, row)))
        .collect();
    img.write_data(&data).unwrap();
    let (oa, ob) = (dir.path().join("oa"), dir.path().join("ob"));
    build_ok(&a, &oa, &["--quiet", "--no-plan"]);
    build_ok(&b, &ob, &["--quiet", "--no-plan"]);
    let tiles = |o: &Path| common::all_files(&o.join("tiles"));
    assert_eq!(tiles(&oa), tiles(&ob), "the same tiles, byte for byte");
    // And the DEM did move the houses: the same town without it differs.
    let flat = dir.path().join("flat");
    build_ok(&fixture("kyoto-small"), &flat, &["--quiet", "--no-plan"]);
    assert_ne!(tiles(&oa), tiles(&flat));
}
