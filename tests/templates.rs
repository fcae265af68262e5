//! Templates: every shipped template alone (closed, inside its site, of its declared height),
//! `edo-city template`, broken template files, and numbers changed without recompiling.

mod common;

use std::path::Path;

use common::{build_ok, copy_fixture, edo_city, fixture, load_tile, read_json};
use edo_city::author::build_alone;
use edo_city::generate::mesh::open_edges;
use edo_city::params::Params;
use edo_city::templates::{Catalog, Kind};

/// The site each template is built on in these tests: (width, depth); a hall on the plot
/// it asks for.
fn site(t: &edo_city::templates::Template) -> (f64, f64) {
    let plot = |k: &str| t.param(&[], k).expect("a hall names its plot");
    match t.kind {
        Kind::Hall => (plot("plot_width"), plot("plot_depth")),
        Kind::Machiya => (5.454, 20.0),
        Kind::Kura => (4.5, 6.5),
        Kind::Fence => (5.454, 1.0),
        Kind::Gate => (3.03, 1.0),
        Kind::Tree | Kind::Person => (1.0, 1.0),
    }
}

/// Signed volume enclosed by the mesh, cubic metres: positive when faces point outward.
fn volume(mesh: &edo_city::generate::mesh::Mesh) -> f64 {
    let p = |i: u32| {
        let q = mesh.positions[i as usize];
        [
            q[0] as f64 / 1000.0,
            q[1] as f64 / 1000.0,
            q[2] as f64 / 1000.0,
        ]
    };
    let mut v = 0.0;
    for f in &mesh.faces {
        let a = p(f.corners[0].0);
        for k in 1..f.corners.len() - 1 {
            let (b, c) = (p(f.corners[k].0), p(f.corners[k + 1].0));
            v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
        }
    }
    v / 6.0
}

#[test]
fn every_template_is_closed_inside_its_site_and_as_tall_as_it_declares() {
    let cat = Catalog::load(None).unwrap();
    let params = Params::default();
    let mut built = 0;
    for t in cat.templates.values().filter(|t| !t.is_abstract) {
        let (w, d) = site(t);
        let alone =
            build_alone(&cat, t, w, d, &params, &[]).unwrap_or_else(|e| panic!("{}: {e}", t.name));
        let mesh = &alone.mesh;
        assert!(!mesh.faces.is_empty(), "{}", t.name);
        // Every edge is shared by two faces: volumes are closed shells, billboards and the
        // board fence two-sided surfaces (each quad and its back) of no volume.
        assert!(open_edges(mesh).is_empty(), "{}: open edges", t.name);
        let surface = matches!(t.kind, Kind::Tree | Kind::Person) || t.name == "fence";
        let vol = volume(mesh);
        if surface {
            assert!(vol.abs() < 1e-6, "{}: a surface of volume {vol}", t.name);
        } else {
            assert!(
                vol > 0.05,
                "{}: a closed shell of volume {vol} m3 (outward faces)",
                t.name
            );
        }
        let declared = alone
            .declared_height
            .expect("every shipped template declares its height");
        assert!(
            (alone.top - declared).abs() < 0.0015,
            "{}: top {} m, declared {declared} m",
            t.name,
            alone.top
        );
        // Everything stands on the ground.
        let bottom = mesh.positions.iter().map(|p| p[1]).min().unwrap();
        assert_eq!(bottom, 0, "{}: lowest point {bottom} mm", t.name);
        // Inside the site: every point below 2 m lies on the lot; only roofs, eaves and
        // copings above 2 m may reach out (over the street or the neighbour's wall top).
        if !matches!(t.kind, Kind::Tree | Kind::Person) {
            for p in &mesh.positions {
                let (u, v) = (p[0] as f64 / 1000.0, -(p[2] as f64) / 1000.0);
                let inside = (-0.001..=w + 0.001).contains(&u) && (-0.001..=d + 0.001).contains(&v);
                // A hall's plot is what analysis found clear of walls: nothing leaves it.
                assert!(
                    inside || (p[1] > 2000 && t.kind != Kind::Hall),
                    "{}: ({u}, {v}) at {} mm is outside the {w} x {d} m site",
                    t.name,
                    p[1]
                );
            }
        }
        built += 1;
    }
    assert_eq!(
        built, 19,
        "8 machiya types, kura, fence, tsuiji, gate, tree, person, 5 halls"
    );
}

#[test]
fn template_command_writes_an_obj_that_tobj_reads_with_its_alpha_maps() {
    let dir = tempfile::tempdir().unwrap();
    for (name, extra) in [
        ("kura", vec!["--width", "4.5", "--depth", "6.5"]),
        ("tree", vec![]),
    ] {
        let obj = dir.path().join(format!("{name}.obj"));
        let out = edo_city()
            .args(["template", name, "-o", obj.to_str().unwrap()])
            .args(&extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("declared"), "{text}");
        let objects = load_tile(&obj, [0.0, 0.0]);
        assert_eq!(objects.len(), 1);
        assert_eq!(objects[0].name, name);
        let (_, mats) = tobj::load_obj(&obj, &tobj::LoadOptions::default()).unwrap();
        let mats = mats.unwrap();
        let used = &objects[0].materials;
        let textured = mats
            .iter()
            .filter(|m| used.contains(&m.name) && m.diffuse_texture.is_some());
        assert!(textured.clone().count() > 0);
        for m in textured {
            let tex = m.diffuse_texture.as_ref().expect("filtered");
            assert!(dir.path().join(tex).exists(), "{tex}");
            if name == "tree" {
                assert_eq!(
                    m.dissolve_texture.as_ref(),
                    Some(&tex.replace(".png", "_mask.png")),
                    "alpha map of {}",
                    m.name
                );
            }
        }
    }
    // Unknown templates and parameters are named.
    let out = edo_city().args(["template", "castle"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no template `castle`"));
    let out = edo_city()
        .args(["template", "kura", "--set", "roof_colour=3", "-o"])
        .arg(dir.path().join("k.obj"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no parameter `roof_colour`"));
}

#[test]
fn a_broken_template_stops_the_build_with_file_line_and_column() {
    let out_dir = tempfile::tempdir().unwrap();
    let out = out_dir.path().join("city");
    let run = edo_city()
        .arg("build")
        .arg(fixture("kyoto-small"))
        .arg("--out")
        .arg(&out)
        .arg("--templates")
        .arg(fixture("templates-broken"))
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("tall-house.toml:10:9"), "{err}");
    assert!(err.contains("lacks an operand"), "{err}");
    assert!(!out.exists(), "nothing written");
}

/// Heights of the houses in a build: object name -> highest point, metres.
fn heights(out: &Path) -> std::collections::BTreeMap<String, f64> {
    let manifest = read_json(&out.join("manifest.json"));
    let mut h = std::collections::BTreeMap::new();
    for tile in manifest["tiles"].as_array().unwrap() {
        for o in load_tile(&out.join(tile["obj"]["path"].as_str().unwrap()), [0.0, 0.0]) {
            let top = o.vertices.iter().map(|v| v[2]).fold(f64::MIN, f64::max);
            h.insert(o.name, top);
        }
    }
    h
}

#[test]
fn numbers_in_templates_and_parameter_files_change_the_city_without_recompiling() {
    let work = tempfile::tempdir().unwrap();
    let input = work.path().join("in");
    copy_fixture("kyoto-small", &input);
    // Lots 7 and 8 are hiraya, lot 7 with three storeys in the table.
    std::fs::write(
        input.join("lots.csv"),
        "id,mtype,storeys\n7,hiraya,3\n8,hiraya,\n",
    )
    .unwrap();
    let base = work.path().join("base");
    build_ok(&input, &base, &["--quiet", "--no-plan"]);
    let h0 = heights(&base);

    // 1. The parameter file raises every hiraya's eaves, and only the hiraya's.
    let params = work.path().join("p.toml");
    std::fs::write(&params, "[template.hiraya]\neave_height = 4.4\n").unwrap();
    let p_out = work.path().join("p");
    build_ok(
        &input,
        &p_out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let h1 = heights(&p_out);
    let r = read_json(&base.join("report.json"));
    let hiraya_count = r["counts"]["by_type"]["hiraya"].as_u64().unwrap();
    let raised = h0
        .iter()
        .filter(|(k, v)| (h1[*k] - **v - 1.0).abs() < 0.002)
        .count();
    assert_eq!(raised as u64, hiraya_count, "every hiraya 1 m taller");
    let same = h0.iter().filter(|(k, v)| h1[*k] == **v).count();
    assert_eq!(same + raised, h0.len(), "nothing else moved");

    // 2. A district of its own: only the hiraya of 中京 change.
    std::fs::write(
        &params,
        "[district.\"中京\".template.hiraya]\neave_height = 4.4\n",
    )
    .unwrap();
    let d_out = work.path().join("d");
    build_ok(
        &input,
        &d_out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let h2 = heights(&d_out);
    let raised_in_district = h0.iter().filter(|(k, v)| h2[*k] > **v + 0.5).count();
    assert!(raised_in_district > 0 && (raised_in_district as u64) < hiraya_count);

    // 3. A template file of the same name replaces the shipped one, and a lot attribute
    //    drives it: eaves at storeys x 3 m.
    let templates = work.path().join("templates");
    std::fs::create_dir(&templates).unwrap();
    std::fs::write(
        templates.join("hiraya.toml"),
        "name = \"hiraya\"\nkanji = \"平屋\"\nextends = \"machiya\"\n\
         [attributes]\nstoreys = 1\n[derived]\neave = \"storeys * 3\"\n\
         [params]\nhisashi_height = 2.5\n",
    )
    .unwrap();
    let t_out = work.path().join("t");
    build_ok(
        &input,
        &t_out,
        &[
            "--quiet",
            "--no-plan",
            "--templates",
            templates.to_str().unwrap(),
        ],
    );
    let h3 = heights(&t_out);
    assert!(
        (h3["machiya_7"] - h3["machiya_8"] - 6.0).abs() < 0.002,
        "3 storeys vs the default 1: {} vs {}",
        h3["machiya_7"],
        h3["machiya_8"]
    );
}

#[test]
fn the_fixture_uses_every_machiya_type() {
    let out = tempfile::tempdir().unwrap();
    let r = build_ok(
        &fixture("kyoto-small"),
        out.path(),
        &["--quiet", "--no-plan"],
    );
    let cat = Catalog::load(None).unwrap();
    for name in cat.names_of(Kind::Machiya) {
        assert!(
            r["counts"]["by_type"][name].as_u64().unwrap_or(0) > 0,
            "{name} not built: {}",
            r["counts"]["by_type"]
        );
    }
}

#[test]
fn a_texture_set_replaces_textures_by_name() {
    let work = tempfile::tempdir().unwrap();
    let set = work.path().join("set");
    std::fs::create_dir(&set).unwrap();
    let scan = image::RgbaImage::from_pixel(4, 4, image::Rgba([200, 20, 20, 255]));
    scan.save(set.join("kawara.png")).unwrap();
    // A person cut out of a scan: drawn in the middle, black and transparent around it.
    let mut person = image::RgbaImage::new(8, 8);
    for (x, y) in [(3, 3), (4, 3), (3, 4), (4, 4)] {
        person.put_pixel(x, y, image::Rgba([30, 60, 150, 255]));
    }
    person.save(set.join("person_01.png")).unwrap();
    let params = work.path().join("p.toml");
    std::fs::write(
        &params,
        format!("textures = {:?}\n", set.display().to_string()),
    )
    .unwrap();
    let out = work.path().join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    assert_eq!(
        std::fs::read(out.join("tiles/textures/kawara.png")).unwrap(),
        std::fs::read(set.join("kawara.png")).unwrap()
    );
    // The cut-out's transparent texels take the drawn colour (no black card where a
    // converter drops the alpha); its alpha is the scan's.
    let written = image::open(out.join("tiles/textures/person_01.png"))
        .unwrap()
        .to_rgba8();
    for (x, y, p) in written.enumerate_pixels() {
        assert_eq!(p[3], person.get_pixel(x, y)[3]);
        assert_eq!(&p.0[..3], &[30, 60, 150], "texel ({x}, {y})");
    }
    // A file that replaces nothing, or is not a PNG, stops the build before it writes.
    std::fs::write(set.join("kawara.png"), b"not a png").unwrap();
    let out2 = work.path().join("out2");
    let run = edo_city()
        .arg("build")
        .arg(fixture("kyoto-small"))
        .args([
            "--out",
            out2.to_str().unwrap(),
            "--params",
            params.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("not a readable PNG"));
    assert!(!out2.exists());
}

#[test]
fn the_worked_example_of_docs_templates_md_builds() {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/templates.md"))
            .unwrap();
    let at = doc
        .find("Save as `mydir/udatsu-ya.toml`")
        .expect("the example is in the doc");
    let start = doc[at..].find("```toml\n").unwrap() + at + "```toml\n".len();
    let end = doc[start..].find("```").unwrap() + start;
    let dir = tempfile::tempdir().unwrap();
    let mydir = dir.path().join("mydir");
    std::fs::create_dir(&mydir).unwrap();
    std::fs::write(mydir.join("udatsu-ya.toml"), &doc[start..end]).unwrap();
    let obj = dir.path().join("udatsu.obj");
    let out = edo_city()
        .args(["template", "udatsu-ya", "--templates"])
        .arg(&mydir)
        .arg("-o")
        .arg(&obj)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("udatsu_left, udatsu_right") && text.contains("closed shell"),
        "{text}"
    );
    assert!(text.contains("height 8.900 m (declared 8.900 m)"), "{text}");
    // And in a city: the parameter file names it in the mix.
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[type_mix]\nudatsu-ya = 1.0\n").unwrap();
    let city = dir.path().join("city");
    let r = build_ok(
        &fixture("kyoto-small"),
        &city,
        &[
            "--quiet",
            "--no-plan",
            "--templates",
            mydir.to_str().unwrap(),
            "--params",
            params.to_str().unwrap(),
        ],
    );
    assert!(
        r["counts"]["by_type"]["udatsu-ya"].as_u64().unwrap() > 200,
        "{}",
        r["counts"]["by_type"]
    );
    // `plan` draws that city from its manifest, with the same templates.
    let png = dir.path().join("again.png");
    edo_city()
        .args([
            "plan",
            city.to_str().unwrap(),
            "--input",
            fixture("kyoto-small").to_str().unwrap(),
            "--templates",
            mydir.to_str().unwrap(),
            "--output",
            png.to_str().unwrap(),
        ])
        .assert()
        .success();
    assert!(image::open(&png).unwrap().width() > 100);
}

#[test]
fn a_template_that_fails_on_a_lot_skips_that_lot_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let (_, r) = common::build_with_failing_template(dir.path());
    let skipped = r["skipped"].as_array().unwrap();
    let nan = skipped
        .iter()
        .filter(|s| {
            s["reason"].as_str().unwrap().contains("`odd_w` (")
                && s["reason"].as_str().unwrap().contains("is NaN")
        })
        .count();
    let upside = skipped
        .iter()
        .filter(|s| {
            s["reason"]
                .as_str()
                .unwrap()
                .contains("part `upside_down`: top 2.00 m is below bottom 3.00 m")
        })
        .count();
    assert!(
        nan > 0 && upside > 0,
        "{nan} NaN, {upside} upside down: {}",
        r["skipped_by_reason"]
    );
    let odd_built = r["counts"]["by_type"]["odd"].as_u64().unwrap_or(0);
    assert!(odd_built > 0, "lots of 5-6 m frontage are built");
    assert_eq!(
        r["counts"]["lots"].as_u64().unwrap(),
        r["counts"]["machiya"].as_u64().unwrap() + skipped.len() as u64 + 2,
        "every lot is built or skipped (the 2 are the buke and jisha lots)"
    );
    for s in skipped {
        assert_eq!(s["layer"], "lots");
        assert!(s["file"].as_str().unwrap().ends_with("lots.shp"));
    }
}
