//! Every size and number a user gives is checked before anything is allocated: random
//! user-sized numbers (0, negative, tiny, huge, NaN, infinite, 2^64-1) for parameter keys,
//! shard counts and thread counts go to the real binary under a memory limit; it builds or
//! refuses with exit code 2, and never panics, aborts or runs out of memory (issue 17).

mod common;

use std::process::Command;

use proptest::prelude::*;

/// Numbers people type by mistake, and the edges of the types that hold them.
const NUMBERS: &[&str] = &[
    "0",
    "1",
    "-1",
    "-5",
    "0.5",
    "1e-300",
    "3",
    "40",
    "1e6",
    "1e9",
    "1e12",
    "1e300",
    "-1e300",
    "nan",
    "inf",
    "-inf",
    "18446744073709551615",
    "9223372036854775807",
    "2.5e8",
];

/// Parameter keys that take a number (`table.key`), and whether the key is a point `[x, y]`.
const KEYS: &[(&str, bool)] = &[
    ("tile_size", false),
    ("origin", true),
    ("tile_origin", true),
    ("people.per_100m", false),
    ("people.max_points_per_tile", false),
    ("people.min_spacing", false),
    ("trees.per_ha", false),
    ("trees.per_ha_machiya", false),
    ("trees.max_points_per_tile", false),
    ("fence.gate_width", false),
    ("machiya.depth", false),
    ("machiya.min_depth", false),
    ("kura.width", false),
    ("kura.gap", false),
    ("simplify.tolerance", false),
    ("simplify.max_vertices", false),
    ("layers.streets.default_width", false),
    ("type_mix.hiraya", false),
    ("frontage.max_angle_deg", false),
];

/// The TOML of one key set to one number.
fn toml_of(key: &str, point: bool, value: &str) -> String {
    let v = if point {
        format!("[{value}, {value}]")
    } else {
        value.to_string()
    };
    match key.rsplit_once('.') {
        Some((table, k)) => format!("[{table}]\n{k} = {v}\n"),
        None => format!("{key} = {v}\n"),
    }
}

/// Runs `edo-city <args>` under an address-space limit (8 GiB: a build of the example town
/// needs under 200 MB); returns the exit code (None when killed by a signal) and stderr.
fn run_limited(args: &[String]) -> (Option<i32>, String) {
    let bin = assert_cmd::cargo::cargo_bin("edo-city");
    let mut line = format!("ulimit -v 8388608; exec '{}'", bin.display());
    for a in args {
        line.push_str(&format!(" '{}'", a.replace('\'', "'\\''")));
    }
    let o = Command::new("sh").arg("-c").arg(&line).output().unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn no_panic(code: Option<i32>, stderr: &str, what: &str) {
    assert!(
        matches!(code, Some(0) | Some(2)),
        "{what}: exit {code:?} (a signal or an abort): {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    assert!(!stderr.contains("memory allocation"), "{what}: {stderr}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, rng_seed: proptest::test_runner::RngSeed::Fixed(2008), ..ProptestConfig::default() })]

    #[test]
    fn any_number_for_a_parameter_builds_or_is_refused_naming_the_key(
        k in 0..KEYS.len(),
        n in 0..NUMBERS.len(),
    ) {
        let (key, point) = KEYS[k];
        let value = NUMBERS[n];
        let dir = tempfile::tempdir().unwrap();
        let params = dir.path().join("p.toml");
        std::fs::write(&params, toml_of(key, point, value)).unwrap();
        let out = dir.path().join("out");
        let args: Vec<String> = [
            "build",
            common::fixture("kyoto-small").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
            "--no-plan",
            "--params",
            params.to_str().unwrap(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let (code, stderr) = run_limited(&args);
        let what = format!("{key} = {value}");
        no_panic(code, &stderr, &what);
        if code == Some(2) {
            let last = key.rsplit('.').next().unwrap();
            prop_assert!(
                stderr.contains(last) || stderr.contains("p.toml"),
                "{}: the error names neither the key nor the file: {}", what, stderr
            );
        }
    }

    #[test]
    fn any_shard_or_thread_count_builds_or_is_refused(
        i in 0..NUMBERS.len(),
        n in 0..NUMBERS.len(),
        j in 0..NUMBERS.len(),
    ) {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let input = common::fixture("kyoto-small");
        let base = |extra: &[String]| {
            let mut a: Vec<String> = vec![
                "build".into(),
                input.display().to_string(),
                "--out".into(),
                out.display().to_string(),
                "--quiet".into(),
                "--no-plan".into(),
            ];
            a.extend_from_slice(extra);
            a
        };
        let shard = format!("{}/{}", NUMBERS[i], NUMBERS[n]);
        let (code, stderr) = run_limited(&base(&["--shard".into(), shard.clone()]));
        no_panic(code, &stderr, &format!("--shard {shard}"));
        let (code, stderr) = run_limited(&base(&["-j".into(), NUMBERS[j].into()]));
        no_panic(code, &stderr, &format!("-j {}", NUMBERS[j]));
    }
}

/// The cases found by hand, each once: they must be refused naming what to change.
#[test]
fn the_numbers_that_once_panicked_aborted_or_ran_for_minutes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::fixture("kyoto-small").display().to_string();
    let out = dir.path().join("out").display().to_string();
    let build = |extra: &[&str]| {
        let mut a: Vec<String> = ["build", &input, "--out", &out, "--quiet", "--no-plan"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let params = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (build(&["--shard", "1/18446744073709551615"]), "N <= 10000"),
        (build(&["--shard", "1/1000000000"]), "N <= 10000"),
        (build(&["-j", "100000"]), "at most 1024 worker threads"),
        (
            build(&["--params", &params("a.toml", "origin = [nan, 0.0]\n")]),
            "`origin` must be two finite numbers",
        ),
        (
            build(&["--params", &params("b.toml", "tile_size = 1e-300\n")]),
            "`tile_size`",
        ),
        (
            build(&[
                "--params",
                &params("c.toml", "tile_origin = [1e300, 0.0]\n"),
            ]),
            "`tile_origin` must be two finite numbers",
        ),
        (
            build(&[
                "--params",
                &params(
                    "d.toml",
                    "[people]\nper_100m = 1e9\nmax_points_per_tile = 100000000\n",
                ),
            ]),
            "`people.per_100m` must be from 0 to 1000",
        ),
        (
            build(&[
                "--params",
                &params("e.toml", "[type_mix]\nhiraya = 1e308\nsou-nikai = 1e308\n"),
            ]),
            "must be a weight from 0 to 1e9",
        ),
        (
            vec![
                "synth".into(),
                dir.path().join("huge").display().to_string(),
                "--lots".into(),
                "18446744073709551615".into(),
            ],
            "--lots must be from 1 to 10000000",
        ),
        // Issue 57: a garden of 5 mm panicked in the repair's clamp.
        (
            vec![
                "garden".into(),
                "--width".into(),
                "0.005".into(),
                "--depth".into(),
                "0.005".into(),
                "-o".into(),
                dir.path().join("g.obj").display().to_string(),
            ],
            "width and depth must be from 1 to 10,000 metres",
        ),
        // Issue 57: 1 m tiles over a town of 2,000 lots are half a million tiles.
        (
            {
                let town = dir.path().join("town");
                common::edo_city()
                    .args([
                        "synth",
                        town.to_str().unwrap(),
                        "--lots",
                        "2000",
                        "--seed",
                        "3",
                    ])
                    .output()
                    .unwrap();
                vec![
                    "tiles".into(),
                    town.display().to_string(),
                    "--params".into(),
                    params("g.toml", "tile_size = 1.0\n"),
                ]
            },
            "`tile_size` = 1 m cuts this city into more than 200000 tiles",
        ),
    ];
    for (args, says) in cases {
        let (code, stderr) = run_limited(&args);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: `{says}` not in {stderr}");
    }
    // Allowed, and once an integer overflow in the spacing grid (found by the proptest).
    let tiny = build(&[
        "--params",
        &params("f.toml", "[people]\nmin_spacing = 1e-300\n"),
    ]);
    let (code, stderr) = run_limited(&tiny);
    assert_eq!(code, Some(0), "{tiny:?}: {stderr}");
}

/// The numbers of templates, species and `[crowd]`, and nesting in their expressions
/// (issue 39): each refused with exit 2 naming the key or the place, never a panic, an
/// abort or a stack overflow.
#[test]
fn template_species_and_crowd_numbers_and_nesting_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::fixture("kyoto-small").display().to_string();
    let out = dir.path().join("out").display().to_string();
    let params = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let build = |p: String| -> Vec<String> {
        [
            "build",
            &input,
            "--out",
            &out,
            "--quiet",
            "--no-plan",
            "--params",
            &p,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    // A species that asks for 1e15 symbols, one with a rule nested 20,000 deep, and a
    // template whose derived value is nested 20,000 deep.
    // Each species in a directory of its own (a tree command reads every species of its
    // directory), from the shipped cherry with its rules replaced.
    let sakura = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("templates/trees/sakura.toml"),
    )
    .unwrap();
    let species = |name: &str, rules: &str, extra: &str| {
        let d = dir.path().join(name);
        std::fs::create_dir_all(d.join("trees")).unwrap();
        let start = sakura.find("rules = [").unwrap();
        let end = start + sakura[start..].find("\n]").unwrap() + 2;
        let text = format!(
            "{}rules = [{rules}]\ngenerations = 60\n{extra}{}",
            &sakura[..start],
            &sakura[end..].replace("generations = 6\n", "")
        )
        .replace("name = \"sakura\"", &format!("name = \"{name}\""));
        std::fs::write(d.join(format!("trees/{name}.toml")), text).unwrap();
        d.display().to_string()
    };
    let huge = species("huge", "\"A=AA\"", "max_symbols = 1000000000000000\n");
    let deep = format!("\"A=F({}1{})\"", "(".repeat(20_000), ")".repeat(20_000));
    let deep = species("deep", &deep, "");
    let nested = dir.path().join("nested");
    std::fs::create_dir_all(&nested).unwrap();
    std::fs::write(
        nested.join("nested.toml"),
        format!(
            "name = \"nested\"\nextends = \"hiraya\"\n[derived]\nd = \"{}1{}\"\n",
            "(".repeat(20_000),
            ")".repeat(20_000)
        ),
    )
    .unwrap();
    let tree = |species: &str, t: &str| -> Vec<String> {
        ["tree", "--species", species, "--templates", t]
            .iter()
            .map(|s| s.to_string())
            .collect()
    };
    let cases: Vec<(Vec<String>, &[&str])> = vec![
        (
            build(params(
                "t1.toml",
                "[template.hiraya]\neave_height = 1e300\n",
            )),
            &["eave_height", "at most 1000"],
        ),
        (
            build(params(
                "t2.toml",
                "[template.hiraya]\nhisashi_depth = 1e6\n",
            )),
            &["hisashi_depth", "at most 1000"],
        ),
        (
            build(params(
                "t3.toml",
                "[people]\nmotion = \"boids\"\n[crowd]\nweights = [1e308, 1e308, 1e308]\n",
            )),
            &["[crowd]", "at most 1000"],
        ),
        (tree("huge", &huge), &["max_symbols", "give 1 to 50000000"]),
        (tree("deep", &deep), &["deep.toml", "nested more than"]),
        (
            [
                "template",
                "nested",
                "--templates",
                &nested.display().to_string(),
                "-o",
                &dir.path().join("n.obj").display().to_string(),
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            &["nested.toml:4:5", "more than 4000"],
        ),
        (
            [
                "template",
                "hiraya",
                "--set",
                "eave_height=1e7",
                "-o",
                &dir.path().join("h.obj").display().to_string(),
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            &["eave_height", "at most 1000"],
        ),
        (
            [
                "lsystem",
                "--axiom",
                "A",
                "--rule",
                "A=AA",
                "--generations",
                "60",
                "--max-symbols",
                "1000000000000000",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            &["max_symbols", "give 1 to 50000000"],
        ),
    ];
    for (args, says) in cases {
        let (code, stderr) = run_limited(&args);
        assert_eq!(code, Some(2), "{:?}: {stderr}", &args[..2]);
        for s in says {
            assert!(
                stderr.contains(s),
                "{:?}: `{s}` not in {stderr}",
                &args[..2]
            );
        }
        assert!(stderr.len() < 2000, "{} bytes: {stderr}", stderr.len());
    }
}
