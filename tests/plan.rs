//! The plan image: every house's lot shows its type's colour where the plan says it is.

mod common;

use common::*;
use geo::Centroid;

#[test]
fn lots_are_painted_in_their_types_colours() {
    let out = tempfile::tempdir().unwrap();
    build_ok(&fixture("kyoto-small"), out.path(), &["--quiet"]);
    let png = image::open(out.path().join("plan.png"))
        .expect("every build draws plan.png")
        .to_rgba8();

    // The same plan, through the library, to know where each lot is and what it became.
    let params = edo_city::params::Params::default();
    let catalog = edo_city::build::load_catalog(&params, None).unwrap();
    let (data, plan, _, _) = edo_city::build::read_and_analyse(
        &fixture("kyoto-small"),
        &params,
        &catalog,
        &edo_city::build::NoProgress,
    )
    .unwrap();
    let view = edo_city::output::plan::View::fit(&data, None).unwrap();
    let colours = edo_city::output::plan::type_colours(&plan);
    assert_eq!((png.width(), png.height()), (2400, 2400));

    let (mut checked, mut types) = (0, std::collections::BTreeSet::new());
    for m in plan.houses.values().flatten() {
        let c = m.outline.centroid().unwrap();
        let (x, y) = view.pixel(&c.0);
        // Leave out what the legend (top right) and the scale bar (bottom left) cover.
        let under_legend = x > 2400.0 - 480.0 && y < 480.0;
        let under_scale = x < 400.0 && y > 2400.0 - 80.0;
        // ... and what a tree's crown (a quarter of its height) or a person's dot covers.
        let under_billboard = plan.billboards.values().flatten().any(|b| {
            let (bx, by) = view.pixel(&b.at);
            let r = (b.height * 0.25 * view.scale).max(2.5) as f32 + 2.0;
            (bx - x).hypot(by - y) <= r
        });
        if under_legend || under_scale || under_billboard {
            continue;
        }
        let p = png.get_pixel(x as u32, y as u32);
        let want = colours[&m.mtype];
        assert_eq!(
            [p[0], p[1], p[2]],
            want,
            "lot {} ({}) at pixel ({x:.0}, {y:.0})",
            m.id,
            m.mtype
        );
        checked += 1;
        types.insert(m.mtype.clone());
    }
    assert!(checked > 350, "{checked} lots checked");
    assert!(types.len() >= 6, "{types:?}");
}

#[test]
fn one_tile_at_full_resolution() {
    let out = tempfile::tempdir().unwrap();
    build_ok(
        &fixture("kyoto-small"),
        &out.path().join("out"),
        &["--quiet"],
    );
    let png = out.path().join("tile.png");
    edo_city()
        .arg("plan")
        .arg(out.path().join("out"))
        .arg("--input")
        .arg(fixture("kyoto-small"))
        .arg("-o")
        .arg(&png)
        .arg("--tile")
        .arg("1108_760")
        .assert()
        .success();
    // The published manifest does not say where the input is: without --input, or with
    // another directory, `plan` says what to give.
    for extra in [
        vec![],
        vec![
            "--input".to_string(),
            fixture("landmark-models").display().to_string(),
        ],
    ] {
        let o = edo_city()
            .arg("plan")
            .arg(out.path().join("out"))
            .args(&extra)
            .arg("-o")
            .arg(&png)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2));
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains("kyoto-small") && e.contains("give"), "{e}");
    }
    let img = image::open(&png).unwrap();
    assert_eq!(
        (img.width(), img.height()),
        (2400, 2400),
        "one 250 m tile on 2400 px"
    );
}

/// A parameter naming a place outside the input by its path is published as a name and a
/// fingerprint; `--tiles` still knows the build's parameters, and `plan` asks for the file.
#[test]
fn paths_outside_the_input_are_not_published_and_plan_asks_for_the_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let secret = dir.path().join("alice-private");
    std::fs::create_dir_all(secret.join("models")).unwrap();
    let params = dir.path().join("p.toml");
    let models = secret.join("models");
    std::fs::write(
        &params,
        format!("[landmarks]\nmodels_dir = \"{}\"\n", models.display()),
    )
    .unwrap();
    let out = dir.path().join("out");
    let p = params.to_str().unwrap();
    build_ok(&fixture("kyoto-small"), &out, &["--quiet", "--params", p]);
    for file in ["manifest.json", "report.json"] {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        assert!(!text.contains("alice-private"), "{file} publishes the path");
    }
    let m = read_json(&out.join("manifest.json"));
    let published = m["params"]["landmarks"]["models_dir"].as_str().unwrap();
    assert!(
        published.starts_with("(not published) models#"),
        "{published}"
    );
    let tile = m["tiles"][0]["id"].as_str().unwrap().to_string();
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--params", p, "--tiles", &tile],
    );

    let png = dir.path().join("plan.png");
    let plan = |extra: &[&str]| {
        edo_city()
            .arg("plan")
            .arg(&out)
            .arg("--input")
            .arg(fixture("kyoto-small"))
            .arg("-o")
            .arg(&png)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = plan(&[]);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("landmarks.models_dir") && e.contains("--params"),
        "{e}"
    );
    let other = dir.path().join("other.toml");
    std::fs::write(&other, "[landmarks]\nmodels_dir = \"/elsewhere/models\"\n").unwrap();
    let o = plan(&["--params", other.to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("`landmarks.models_dir` differs"), "{e}");
    let o = plan(&["--params", p]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(png.exists());
}
