//! `edo-city boids`: the seed's demo (Oyama et al., seed 004) end to end: the CSV of the
//! order parameters, the plot of both systems, the snapshot, determinism and bad flags.

mod common;

use common::edo_city;

fn run(dir: &std::path::Path, name: &str, extra: &[&str]) -> String {
    let csv = dir.join(name);
    let o = edo_city()
        .args(["boids", "--steps", "400", "--csv"])
        .arg(&csv)
        .args(extra)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_to_string(csv).unwrap()
}

#[test]
fn the_csv_has_the_header_a_row_per_step_and_the_same_bytes_for_the_same_seed() {
    let dir = tempfile::tempdir().unwrap();
    let a = run(dir.path(), "a.csv", &["--seed", "3"]);
    let b = run(dir.path(), "b.csv", &["--seed", "3"]);
    let c = run(dir.path(), "c.csv", &["--seed", "4"]);
    let r = run(dir.path(), "r.csv", &["--seed", "3", "--no-rules"]);
    assert!(a.starts_with("step,lambda1,lambda2,lambda3\n"), "{a}");
    assert_eq!(a.lines().count(), 402, "the header, step 0 and 400 steps");
    assert_eq!(a, b, "same seed, same bytes");
    assert_ne!(a, c);
    assert_ne!(a, r, "--no-rules is the random system");
    // Every value is a number in [-1, 1].
    for line in a.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!(v.len(), 4);
        assert!(v[1..].iter().all(|x| (-1.0..=1.0).contains(x)), "{line}");
    }
}

#[test]
fn the_plot_and_the_snapshot_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let (png, svg) = (dir.path().join("l.png"), dir.path().join("s.svg"));
    run(
        dir.path(),
        "a.csv",
        &[
            "--plot",
            png.to_str().unwrap(),
            "--svg",
            svg.to_str().unwrap(),
        ],
    );
    let img = image::load_from_memory(&std::fs::read(&png).unwrap()).unwrap();
    assert_eq!((img.width(), img.height()), (960, 480));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    assert_eq!(text.matches("<line ").count(), 10, "one heading per agent");
}

#[test]
fn bad_flags_are_refused_naming_them() {
    for (args, says) in [
        (vec!["--r0", "90"], "r0 <= r1"),
        (vec!["--agents", "100001"], "--agents must be at most"),
        (vec!["--width", "nan"], "--width and --height"),
        (vec!["--steps", "1000001"], "--steps at most"),
    ] {
        let o = edo_city().arg("boids").args(&args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(says), "{args:?}: {e}");
    }
}
