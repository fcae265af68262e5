use super::*;

#[test]
fn a_designs_file_is_found_beside_the_parameter_file_that_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(sub.join("base.toml"), "[garden]\ndesigns = \"kept.json\"\n").unwrap();
    std::fs::write(dir.path().join("p.toml"), "extends = \"sub/base.toml\"\n").unwrap();
    let p = Params::from_path(&dir.path().join("p.toml")).unwrap();
    assert_eq!(Path::new(&p.garden.designs), sub.join("kept.json"));
    let abs = dir.path().join("elsewhere.json");
    let text = format!("[garden]\ndesigns = {:?}\n", abs.display().to_string());
    std::fs::write(dir.path().join("q.toml"), text).unwrap();
    let q = Params::from_path(&dir.path().join("q.toml")).unwrap();
    assert_eq!(Path::new(&q.garden.designs), abs);
    assert_eq!(Params::default().garden.designs, "");
}

#[test]
fn shipped_defaults_parse_and_follow_the_paper() {
    let p = Params::default();
    assert_eq!(p.tile_size, 250.0);
    assert_eq!(p.frontage.max_angle_deg, 120.0);
    assert_eq!(p.frontage.min_length, 1.2);
    assert_eq!(p.type_mix.get("hiraya"), Some(&86.0));
    assert_eq!(p.type_mix.get("naka-nikai-small"), Some(&66.0));
    assert_eq!(p.type_mix.get("naka-nikai-large"), Some(&84.0));
}

#[test]
fn a_partial_file_overrides_only_its_keys() {
    let p = Params::from_toml_str("seed = 9\n[machiya]\ndepth = 8.0\n", "t.toml").unwrap();
    assert_eq!(p.seed, 9);
    assert_eq!(p.machiya.depth, 8.0);
    assert_eq!(p.tile_size, 250.0);
}

#[test]
fn unknown_key_names_key_and_line() {
    let err = Params::from_toml_str("seed = 1\n\n[frontage]\nmax_angel_deg = 100\n", "t.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("max_angel_deg"), "{err}");
    assert!(err.contains("line 4"), "{err}");
}

#[test]
fn wrong_type_names_key_and_line() {
    let err = Params::from_toml_str("seed = 1\ntile_size = \"big\"\n", "t.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 2"), "{err}");
    assert!(err.contains("tile_size") || err.contains("f64"), "{err}");
}

#[test]
fn negative_tile_size_is_rejected() {
    let err = Params::from_toml_str("tile_size = -5.0\n", "t.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("tile_size"), "{err}");
}

#[test]
fn extends_overlays_a_chain_and_catches_loops() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("base.toml"),
        "extends = \"default.toml\"\nseed = 5\n[machiya]\ndepth = 10.0\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("h.toml"),
        "extends = \"base.toml\"\n[machiya]\nmin_depth = 3.0\n",
    )
    .unwrap();
    let p = Params::from_path(&dir.path().join("h.toml")).unwrap();
    assert_eq!(
        (p.seed, p.machiya.depth, p.machiya.min_depth),
        (5, 10.0, 3.0)
    );
    assert_eq!(p.tile_size, 250.0);
    std::fs::write(dir.path().join("a.toml"), "extends = \"b.toml\"\n").unwrap();
    std::fs::write(dir.path().join("b.toml"), "extends = \"a.toml\"\n").unwrap();
    let err = Params::from_path(&dir.path().join("a.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("loops"), "{err}");
    std::fs::write(
        dir.path().join("c.toml"),
        "extends = \"b.toml\"\nseeed = 1\n",
    )
    .unwrap();
    let err = Params::from_path(&dir.path().join("c.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("c.toml") && err.contains("seeed"), "{err}");
}

#[test]
fn a_species_row_is_replaced_whole_and_the_other_rows_stay() {
    let p = Params::from_toml_str("[trees.species]\nmachiya = { kusu = 1.0 }\n", "t.toml").unwrap();
    assert_eq!(p.trees.species["machiya"].len(), 1);
    assert!(p.trees.species["jisha"].contains_key("sugi"));
}

#[test]
fn type_mix_is_replaced_whole() {
    let p = Params::from_toml_str("[type_mix]\nsangai = 1.0\n", "t.toml").unwrap();
    assert_eq!(p.type_mix.len(), 1);
}
