//! People and trees (section 4.4): where the generated points stand, which way people face,
//! alpha-textured materials, densities per district, the per-tile cap, and points given by
//! point layers.

mod common;

use std::path::Path;

use common::{build_objects, build_ok, copy_fixture, fixture, read_json, synth};
use edo_city::geom::segment::segment_distance_2;
use edo_city::model::{BillboardKind, LotUse, Plan, PlannedBillboard};
use edo_city::params::Params;
use geo::{BoundingRect, Contains, ConvexHull};
use geo_types::{MultiPoint, Point, Polygon};

fn plan_of(dir: &Path, params: &Params) -> (edo_city::model::Dataset, Plan) {
    let data = edo_city::input::read_dataset(dir, params).expect("reads");
    let catalog = edo_city::templates::Catalog::load(None).unwrap();
    let plan = edo_city::analyse::analyse(&data, params, &catalog, "lots.shp", &|_| {});
    (data, plan)
}

fn billboards(plan: &Plan, kind: BillboardKind) -> Vec<&PlannedBillboard> {
    plan.billboards
        .values()
        .flatten()
        .filter(|b| b.kind == kind)
        .collect()
}

/// Ground outlines of every building object (machiya_, footprint_, kura_) of a build: the
/// convex hull of its vertices at its lowest height (synth lots are convex).
fn building_bases(out: &Path) -> Vec<(String, Polygon<f64>)> {
    let mut bases = Vec::new();
    for o in build_objects(out) {
        let building = ["machiya_", "footprint_", "kura_"]
            .iter()
            .any(|p| o.name.starts_with(p));
        if !building {
            continue;
        }
        let low = o
            .vertices
            .iter()
            .map(|v| v[2])
            .fold(f64::INFINITY, f64::min);
        let base: MultiPoint<f64> = o
            .vertices
            .iter()
            .filter(|v| v[2] < low + 0.01)
            .map(|v| Point::new(v[0], v[1]))
            .collect();
        bases.push((o.name.clone(), base.convex_hull()));
    }
    bases
}

#[test]
fn people_stand_in_the_streets_facing_along_them_and_no_billboard_stands_in_a_building() {
    let dir = tempfile::tempdir().unwrap();
    synth(dir.path(), 1500, 5);
    let params = Params::default();
    let (data, plan) = plan_of(dir.path(), &params);
    let people = billboards(&plan, BillboardKind::Person);
    let trees = billboards(&plan, BillboardKind::Tree);
    assert!(people.len() > 200, "{} people", people.len());
    assert!(trees.len() > 50, "{} trees", trees.len());

    let turn = params.people.max_turn_deg.to_radians();
    for p in &people {
        // In the street: within its width (less the margin) of a centreline ...
        let (dist, angle) = data
            .streets
            .iter()
            .flat_map(|s| s.line.lines().map(move |l| (s, l)))
            .map(|(s, l)| {
                let d = segment_distance_2(p.at.into(), l.start.into(), l.end.into()).sqrt()
                    - s.width / 2.0;
                (d, (l.end.y - l.start.y).atan2(l.end.x - l.start.x))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap();
        assert!(dist <= -params.people.edge_margin + 1e-6, "{} {dist}", p.id);
        // ... facing along its street, either way, turned by at most max_turn_deg. At a
        // crossing the nearest centreline may be the other street: allow the right angle.
        let off = (p.facing - angle).rem_euclid(std::f64::consts::PI);
        let off = off.min(std::f64::consts::PI - off);
        let crossing = (off - std::f64::consts::FRAC_PI_2).abs() <= turn + 1e-9;
        assert!(off <= turn + 1e-9 || crossing, "{} turned {off}", p.id);
        assert!(
            (params.people.height[0]..=params.people.height[1]).contains(&p.height),
            "{}",
            p.id
        );
        // ... and in no lot (synth streets run between the blocks).
        assert!(
            !data.lots.iter().any(|l| l.outline.contains(&p.at)),
            "{} stands in a lot",
            p.id
        );
    }
    for t in &trees {
        let lot = data
            .lots
            .iter()
            .find(|l| l.outline.contains(&t.at))
            .unwrap_or_else(|| panic!("tree {} stands in no lot", t.id));
        assert!(
            matches!(lot.lot_use, LotUse::Machiya | LotUse::Buke | LotUse::Jisha),
            "{}",
            t.id
        );
        assert!(t.texture.starts_with("tree_"), "{}", t.texture);
    }
    // Minimum spacing among the generated points.
    for (kind, list, spacing) in [
        ("people", &people, params.people.min_spacing),
        ("trees", &trees, params.trees.min_spacing),
    ] {
        let mut sorted: Vec<_> = list.iter().map(|b| b.at).collect();
        sorted.sort_by(|a, b| a.x.total_cmp(&b.x));
        for (i, a) in sorted.iter().enumerate() {
            for b in sorted[i + 1..].iter().take_while(|b| b.x - a.x < spacing) {
                assert!(
                    (a.x - b.x).hypot(a.y - b.y) >= spacing,
                    "two {kind} closer than {spacing} m"
                );
            }
        }
    }

    // The built city: no person or tree stands inside a house or kura as written.
    let out = dir.path().join("out");
    let report = build_ok(dir.path(), &out, &["--no-plan"]);
    assert_eq!(report["counts"]["people"], people.len());
    assert_eq!(report["counts"]["trees"], trees.len());
    let bases = building_bases(&out);
    assert!(bases.len() > 1500);
    for b in people.iter().chain(&trees) {
        let p = Point(b.at);
        for (name, base) in &bases {
            let inside = base.bounding_rect().is_some_and(|r| r.contains(&p)) && base.contains(&p);
            assert!(!inside, "{} {} stands inside {name}", b.kind.layer(), b.id);
        }
    }
}

#[test]
fn billboards_are_one_object_per_kind_with_cut_out_alpha_textures() {
    let out = tempfile::tempdir().unwrap();
    let report = build_ok(&fixture("kyoto-small"), out.path(), &["--no-plan"]);
    let people = report["counts"]["people"].as_u64().unwrap();
    let trees = report["counts"]["trees"].as_u64().unwrap();
    assert!(people > 0 && trees > 0, "{people} people, {trees} trees");
    let textures = report["counts"]["billboard_textures"].as_object().unwrap();
    assert_eq!(
        textures.values().map(|v| v.as_u64().unwrap()).sum::<u64>(),
        people + trees
    );
    assert!(
        textures.keys().filter(|k| k.starts_with("tree_")).count() >= 8,
        "{textures:?}"
    );

    let m = read_json(&out.path().join("manifest.json"));
    let (mut quads_people, mut quads_trees) = (0, 0);
    for t in m["tiles"].as_array().unwrap() {
        let obj = out.path().join(t["obj"]["path"].as_str().unwrap());
        let opts = tobj::LoadOptions {
            triangulate: true,
            ..Default::default()
        };
        let (models, materials) = tobj::load_obj(&obj, &opts).unwrap();
        let materials = materials.unwrap();
        for model in &models {
            let triangles = model.mesh.indices.len() / 3;
            let material = &materials[model.mesh.material_id.unwrap()];
            match model.name.as_str() {
                "people" => quads_people += triangles / 2,
                "trees" => quads_trees += triangles / 2,
                _ => continue,
            }
            // map_d names the RGBA picture's mask (a,a,a,a): Blender and three.js cut the
            // figure out of it alike.
            let kd = material.diffuse_texture.as_ref().expect("map_Kd");
            let d = material.dissolve_texture.as_ref().expect("map_d");
            assert_eq!(d, &kd.replace(".png", "_mask.png"), "{}", material.name);
            let dir = obj.parent().unwrap();
            let (rgba, mask) = (
                image::open(dir.join(kd)).unwrap().to_rgba8(),
                image::open(dir.join(d)).unwrap().to_rgba8(),
            );
            for (c, m) in rgba.pixels().zip(mask.pixels()) {
                assert_eq!(m.0, [c[3]; 4], "{d}: the mask is the texture's alpha");
            }
            let png = image::open(obj.parent().unwrap().join(kd)).unwrap();
            assert!(png.color().has_alpha(), "{kd}");
            let alpha: Vec<u8> = png.to_rgba8().pixels().map(|p| p.0[3]).collect();
            assert!(
                alpha.contains(&0) && alpha.contains(&255),
                "{kd} cuts nothing out"
            );
        }
    }
    // A person is one quad seen from both sides; a tree two crossed quads, both sides.
    assert_eq!(quads_people as u64, 2 * people);
    assert_eq!(quads_trees as u64, 4 * trees);
}

fn params_file(dir: &Path, text: &str) -> String {
    let p = dir.join("params.toml");
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn density_zero_yields_none_and_a_district_can_have_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let none = params_file(
        dir.path(),
        "[people]\nper_100m = 0.0\n[trees]\nper_ha = 0.0\nper_ha_machiya = 0.0\n",
    );
    let out = dir.path().join("none");
    let r = build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--params", &none, "--no-plan"],
    );
    assert_eq!(r["counts"]["people"], 0);
    assert_eq!(r["counts"]["trees"], 0);
    for e in std::fs::read_dir(out.join("tiles")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "obj") {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        assert!(!text.contains("\no people") && !text.contains("\no trees"));
    }

    let quiet = params_file(
        dir.path(),
        "[district.\"中京\"]\npeople_per_100m = 0.0\ntrees_per_ha_machiya = 0.0\n",
    );
    let out = dir.path().join("quiet");
    let r = build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--params", &quiet, "--no-plan"],
    );
    let people = r["counts"]["people_by_district"].as_object().unwrap();
    assert!(!people.contains_key("中京"), "{people:?}");
    assert!(people.get("下京").is_some_and(|n| n.as_u64().unwrap() > 0));
    let trees = r["counts"]["trees_by_district"].as_object().unwrap();
    assert!(!trees.contains_key("中京"), "{trees:?}");
}

#[test]
fn a_density_beyond_the_tile_cap_is_capped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let crowd = params_file(
        dir.path(),
        "[people]\nper_100m = 1000.0\nmin_spacing = 0.0\nmax_points_per_tile = 40\n",
    );
    let out = dir.path().join("out");
    let r = build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--params", &crowd, "--no-plan"],
    );
    let warnings: Vec<&str> = r["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["class"] == "billboards" && w["key"] == "people.max_points_per_tile")
        .map(|w| w["message"].as_str().unwrap())
        .collect();
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("max_points_per_tile = 40") && w.contains("people")),
        "{warnings:?}"
    );
    let m = read_json(&out.join("manifest.json"));
    for t in m["tiles"].as_array().unwrap() {
        let n: u64 = t["stats"]["people_by_district"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert!(n <= 40, "tile {} has {n} people", t["id"]);
    }
    assert!(r["counts"]["people"].as_u64().unwrap() >= 40);
}

/// Writes a point layer with id, height and texture fields, in the fixture's CRS.
fn write_points(path: &Path, points: &[(&str, [f64; 2], Option<f64>, &str)]) {
    let name = |n: &str| dbase::FieldName::try_from(n).unwrap();
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(name("id"), 10)
        .add_numeric_field(name("height"), 8, 2)
        .add_character_field(name("texture"), 12);
    let mut w = shapefile::Writer::from_path(path, table).unwrap();
    for (id, at, height, texture) in points {
        let mut rec = dbase::Record::default();
        rec.insert(
            "id".into(),
            dbase::FieldValue::Character(Some(id.to_string())),
        );
        rec.insert("height".into(), dbase::FieldValue::Numeric(*height));
        rec.insert(
            "texture".into(),
            dbase::FieldValue::Character(Some(texture.to_string())),
        );
        w.write_shape_and_record(&shapefile::Point::new(at[0], at[1]), &rec)
            .unwrap();
    }
    drop(w);
    std::fs::copy(
        fixture("kyoto-small").join("lots.prj"),
        path.with_extension("prj"),
    )
    .unwrap();
}

#[test]
fn point_layers_replace_the_generated_billboards() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    copy_fixture("kyoto-small", &input);
    let params = Params::default();
    let (data, plan) = plan_of(&input, &params);
    // A point in a street, one inside a house (just behind its frontage), one in an estate.
    let street = &data.streets[0].line.0;
    let on_street = [
        (street[0].x + street[1].x) / 2.0,
        (street[0].y + street[1].y) / 2.0,
    ];
    let house = plan.houses.values().flatten().next().unwrap();
    let f = house.frontage;
    let v = f.v_axis();
    let in_house = [
        (f.a.x + f.b.x) / 2.0 + 1.0 * v.x,
        (f.a.y + f.b.y) / 2.0 + 1.0 * v.y,
    ];
    let estate = data
        .lots
        .iter()
        .find(|l| l.lot_use == LotUse::Buke)
        .unwrap();
    let c = geo::Centroid::centroid(&estate.outline).unwrap();
    write_points(
        &input.join("people.shp"),
        &[
            ("p1", on_street, Some(1.25), ""),
            ("p2", in_house, None, ""),
        ],
    );
    write_points(
        &input.join("trees.shp"),
        &[("t1", [c.x(), c.y()], Some(9.5), "3")],
    );

    let out = dir.path().join("out");
    let r = build_ok(&input, &out, &["--no-plan"]);
    assert_eq!(r["counts"]["people"], 1);
    assert_eq!(r["counts"]["trees"], 1);
    assert_eq!(r["counts"]["billboard_textures"]["tree_03"], 1);
    let skipped = r["skipped"].as_array().unwrap();
    assert!(
        skipped.iter().any(|s| s["layer"] == "people"
            && s["id"] == "p2"
            && s["file"].as_str().unwrap().ends_with("people.shp")
            && s["reason"].as_str().unwrap().contains("inside a building")),
        "{skipped:?}"
    );
    // The given heights: the tree's picture is 9.5 m tall, the person 1.25 m.
    let mut heights = Vec::new();
    for o in build_objects(&out) {
        if o.name == "people" || o.name == "trees" {
            let lo = o
                .vertices
                .iter()
                .map(|v| v[2])
                .fold(f64::INFINITY, f64::min);
            let hi = o
                .vertices
                .iter()
                .map(|v| v[2])
                .fold(f64::NEG_INFINITY, f64::max);
            heights.push((o.name.clone(), ((hi - lo) * 1000.0).round() / 1000.0));
        }
    }
    heights.sort_by(|a, b| a.0.cmp(&b.0));
    assert_eq!(
        heights,
        vec![("people".to_string(), 1.25), ("trees".to_string(), 9.5)]
    );
}

#[test]
fn a_billboard_template_of_the_wrong_kind_or_an_unknown_texture_stops_the_build() {
    let dir = tempfile::tempdir().unwrap();
    for (text, expect) in [
        (
            "[people]\ntemplate = \"kura\"\n",
            "people.template names `kura`",
        ),
        (
            "[trees]\ntextures = [\"tree_01\", \"oak\"]\n",
            "trees.textures names `oak`",
        ),
        (
            "[people]\nheight = [1.8, 1.2]\n",
            "`people.height` must be [low, high]",
        ),
    ] {
        let p = params_file(dir.path(), text);
        let out = dir.path().join("out");
        let o = common::build_cmd(&fixture("kyoto-small"), &out, &["--params", &p])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{text}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(expect), "{text}: {err}");
        assert!(!out.join("manifest.json").exists());
    }
}
