//! Never a panic on user data: damaged files give an error with the file's name, and random
//! geometry goes through the whole pipeline with finite output inside its lot.

mod common;

use common::*;
use rand::{RngExt, SeedableRng};

/// A way to damage a file's bytes.
type Damage = Box<dyn Fn(&mut Vec<u8>) + Send + Sync>;

/// Runs a build on a copy of the fixture whose `file` was damaged by `damage`; the tool must
/// either build or exit with code 2 and a message, never crash (exit 101 is a Rust panic).
fn build_damaged(file: &str, damage: impl Fn(&mut Vec<u8>)) -> (i32, String) {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    let path = dir.path().join(file);
    let mut bytes = std::fs::read(&path).unwrap();
    damage(&mut bytes);
    std::fs::write(&path, &bytes).unwrap();
    let out = build_cmd(dir.path(), &dir.path().join("out"), &["--quiet"])
        .output()
        .unwrap();
    let code = out.status.code().unwrap_or(-1);
    (code, String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn truncated_and_scrambled_layers_never_panic() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut cases: Vec<(&str, usize, Damage)> = Vec::new();
    for file in [
        "lots.shp",
        "lots.shx",
        "lots.dbf",
        "streets.shp",
        "blocks.dbf",
    ] {
        let len = std::fs::metadata(fixture("kyoto-small").join(file))
            .unwrap()
            .len() as usize;
        let mut damages: Vec<Damage> = Vec::new();
        for cut in [0, 10, 50, 100, 101, len / 3, len / 2, len - 1] {
            damages.push(Box::new(move |b: &mut Vec<u8>| {
                b.truncate(cut.min(b.len()))
            }));
        }
        for _ in 0..12 {
            let (at, n, seed) = (
                rng.random_range(0..len),
                rng.random_range(1..64),
                rng.random::<u64>(),
            );
            damages.push(Box::new(move |b: &mut Vec<u8>| {
                let mut r = rand_pcg::Pcg64::seed_from_u64(seed);
                for i in at..(at + n).min(b.len()) {
                    b[i] = r.random();
                }
            }));
        }
        cases.extend(damages.into_iter().enumerate().map(|(k, d)| (file, k, d)));
    }
    // The damages are drawn above, in one order; the builds run two at a time (a build of
    // the small fixture leaves a core idle most of its time: 92 s one after the other).
    use rayon::prelude::*;
    let codes: Vec<i32> = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| {
            cases
                .par_iter()
                .map(|(file, k, damage)| {
                    let (code, stderr) = build_damaged(file, damage);
                    assert!(
                        code == 0 || code == 2,
                        "{file} case {k}: exit {code}\n{stderr}"
                    );
                    if code == 2 {
                        let layer = file.split('.').next().unwrap();
                        assert!(
                            stderr.contains("error:") && stderr.contains(layer),
                            "{file} case {k}: {stderr}"
                        );
                    }
                    code
                })
                .collect()
        });
    let refused = codes.iter().filter(|&&c| c == 2).count();
    let built = codes.len() - refused;
    // Both outcomes occur: damage that leaves a readable layer builds (with skips), the rest
    // is refused with the file named.
    assert!(
        built > 5 && refused > 10,
        "built {built}, refused {refused}"
    );
}

mod random_geometry {
    use edo_city::model::{Dataset, Lot, LotUse, Street};
    use edo_city::params::Params;
    use geo::{orient::Direction, Contains, Distance, Euclidean, Orient};
    use geo_types::{LineString, Point, Polygon};
    use proptest::prelude::*;

    /// A star-shaped polygon around (cx, cy): any radii, so concave, thin and tiny ones come up.
    fn star(cx: f64, cy: f64, radii: &[f64], twist: f64) -> Polygon<f64> {
        Polygon::new(LineString(super::star(cx, cy, radii, twist)), vec![])
            .orient(Direction::Default)
    }

    proptest! {
        #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(2008), ..ProptestConfig::with_cases(200) })]

        #[test]
        fn any_lot_is_built_inside_itself_or_skipped_with_a_reason(
            radii in prop::collection::vec(0.05f64..40.0, 3..12),
            twist in 0.0f64..6.3,
            far in prop::bool::ANY,
            street_y in -80.0f64..80.0,
            width in 0.5f64..30.0,
        ) {
            let (cx, cy) = if far { (-23_456.7, -110_123.4) } else { (0.0, 0.0) };
            let outline = star(cx, cy, &radii, twist);
            prop_assume!(geo::Area::unsigned_area(&outline) > 1e-3);
            let data = Dataset {
                lots: vec![Lot {
                    id: "1".into(),
                    record: 0,
                    outline: outline.clone(),
                    lot_use: LotUse::Machiya,
                    mtype: None,
                    district: None,
                    tile: None,
                    attrs: Default::default(),
                    ground: 0.0,
                }],
                streets: vec![Street {
                    id: "s".into(),
                    line: LineString::from(vec![(cx - 100.0, cy + street_y), (cx + 100.0, cy + street_y)]),
                    width,
                }],
                ..Default::default()
            };
            let params = Params::default();
            let catalog = edo_city::templates::Catalog::load(None).unwrap();
            let plan = edo_city::analyse::analyse(&data, &params, &catalog, "lots.shp", &|_| {});
            let files = edo_city::generate::LayerFiles::default();
            let variants = edo_city::generate::variant::Variants::of(&params);
            let mut houses = 0;
            for lots in plan.houses.values() {
                let tile = edo_city::generate::TilePlan { lots, ..Default::default() };
                let t = edo_city::generate::generate_tile(&tile, &catalog, &params, &variants, plan.origin, &files);
                for s in &t.stats.skipped {
                    prop_assert!(!s.reason.is_empty());
                }
                for mesh in &t.meshes {
                    // A kura (kura_<id>) stands wholly inside the lot, roof included.
                    let kura = mesh.name.starts_with("kura_");
                    houses += usize::from(!kura);
                    for p in &mesh.positions {
                        let (x, h, z) = (p[0] as f64 / 1000.0 + plan.origin[0], p[1] as f64 / 1000.0, -(p[2] as f64) / 1000.0 + plan.origin[1]);
                        prop_assert!(x.is_finite() && h.is_finite() && z.is_finite());
                        let q = Point::new(x, z);
                        let d = if outline.contains(&q) { 0.0 } else { Euclidean.distance(&q, outline.exterior()) };
                        if h <= 0.001 || kura {
                            prop_assert!(d <= 0.01, "{} vertex {:?} is {d} m outside", mesh.name, q);
                        } else {
                            prop_assert!(d <= 0.78, "vertex {:?} at {h} m is {d} m outside", q);
                        }
                    }
                }
            }
            let skipped = plan.skipped.len()
                + plan.houses.values().flatten().count() - houses;
            prop_assert_eq!(houses + skipped, 1, "the lot is either built or skipped");
        }
    }
}

/// A build killed at random moments leaves every tile either the complete old or the complete
/// new version, and the next run finishes the job.
#[test]
fn a_killed_build_loses_nothing() {
    let work = tempfile::tempdir().unwrap();
    let town = work.path().join("town");
    edo_city::synth::write_town(&town, 4000, 5, edo_city::synth::Profile::Grid, false).unwrap();
    // References: the complete old and new cities.
    let OldAndNew {
        old_params,
        new_params,
        old_files,
        new_files,
    } = old_and_new(&town, work.path());

    let out = work.path().join("out");
    build_ok(&town, &out, &["--quiet", "--params", &old_params]);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    for round in 0..6 {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("edo-city"))
            .args([
                "build",
                town.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .args([
                "--quiet",
                "--force",
                "--threads",
                "2",
                "--params",
                &new_params,
            ])
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(rng.random_range(5..400)));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        for (name, bytes) in all_files(&out) {
            if name.contains(".tmp-") || name == ".edo-city.lock" || name == ".edo-city.writing" {
                // A killed run's temporary (never read, swept by the next run), its lock
                // (a dead holder's, taken over by the next run) or its mark of a directory
                // being written (which makes a later --tiles check every file).
                continue;
            }
            let whole =
                old_files.get(&name) == Some(&bytes) || new_files.get(&name) == Some(&bytes);
            assert!(
                whole,
                "round {round}: {name} is neither the old nor the new version"
            );
        }
    }
    build_ok(
        &town,
        &out,
        &["--quiet", "--force", "--params", &new_params],
    );
    let done = all_files(&out);
    assert_eq!(
        done.keys().collect::<Vec<_>>(),
        new_files.keys().collect::<Vec<_>>(),
        "no leftovers"
    );
    assert!(done == new_files, "the next run finishes the job");
}

/// A disk that fills up mid-build (simulated: EDO_CITY_SIMULATE_DISK_BYTES) stops the build
/// with a message saying so; every file left is the complete old or the complete new
/// version, no temporary remains, and the same command finishes the job once there is room.
#[test]
fn a_full_disk_loses_nothing() {
    let work = tempfile::tempdir().unwrap();
    let town = fixture("kyoto-small");
    let OldAndNew {
        old_params,
        new_params,
        old_files,
        new_files,
    } = old_and_new(&town, work.path());
    let textures: usize = new_files
        .iter()
        .filter(|(k, _)| k.starts_with("tiles/textures/"))
        .map(|(_, v)| v.len())
        .sum();
    let tiles: usize = new_files
        .iter()
        .filter(|(k, _)| k.starts_with("tiles/") && !k.starts_with("tiles/textures/"))
        .map(|(_, v)| v.len())
        .sum();

    let out = work.path().join("out");
    build_ok(&town, &out, &["--quiet", "--params", &old_params]);
    // Room for the textures and the first tile (its OBJ and MTL), not for the second tile's
    // OBJ: on one thread the tiles are written in id order, so the disk fills in the second
    // tile, after one new tile and before the others.
    let size = |name: &str| new_files[name].len();
    let ids: Vec<&String> = new_files
        .keys()
        .filter(|k| k.starts_with("tiles/") && k.ends_with(".obj"))
        .collect();
    assert!(ids.len() >= 2, "two tiles at least");
    let first = ids[0].trim_end_matches(".obj");
    let room = textures + size(ids[0]) + size(&format!("{first}.mtl")) + size(ids[1]) / 2;
    assert!(room < textures + tiles);
    let o = std::process::Command::new(assert_cmd::cargo::cargo_bin("edo-city"))
        .args([
            "build",
            town.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(["--quiet", "--force", "-j", "1", "--params", &new_params])
        .env("EDO_CITY_SIMULATE_DISK_BYTES", room.to_string())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("No space left on device") && stderr.contains("run the same command"),
        "{stderr}"
    );
    assert_eq!(
        stderr.matches("No space left").count(),
        1,
        "said once: {stderr}"
    );
    let mut left = all_files(&out);
    assert!(
        left.remove(".edo-city.writing").is_some(),
        "the directory is marked as half-written, so --tiles checks it"
    );
    let (mut old_kept, mut new_written) = (0, 0);
    for (name, bytes) in &left {
        assert!(!name.contains(".tmp-"), "{name}: a temporary was left");
        let (is_old, is_new) = (
            old_files.get(name) == Some(bytes),
            new_files.get(name) == Some(bytes),
        );
        assert!(
            is_old || is_new,
            "{name} is neither the old nor the new version"
        );
        if name.starts_with("tiles/") && name.ends_with(".obj") && is_old != is_new {
            old_kept += is_old as usize;
            new_written += is_new as usize;
        }
    }
    assert!(
        new_written > 0 && old_kept > 0,
        "new {new_written}, old {old_kept}"
    );
    assert_eq!(
        left.get("manifest.json"),
        old_files.get("manifest.json"),
        "manifest is last"
    );
    build_ok(
        &town,
        &out,
        &["--quiet", "--force", "--params", &new_params],
    );
    assert!(all_files(&out) == new_files, "the rerun finishes the job");
}

/// A reader that goes away (`edo-city check dir | head -1`) closes stdout's pipe before the
/// tool has printed: the tool stops printing and exits 0, with no panic.
#[test]
fn a_closed_stdout_is_not_a_crash() {
    for args in [vec!["check"], vec!["tiles"]] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("edo-city"))
            .args(&args)
            .arg(fixture("kyoto-small"))
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Closed before the tool has read its input, let alone printed.
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(
            matches!(out.status.code(), Some(0) | Some(1)),
            "{args:?}: {:?} {stderr}",
            out.status
        );
    }
}
