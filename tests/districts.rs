//! Districts with their own type mix and template values.

mod common;

use common::{build_ok, edo_city, synth};

#[test]
fn two_districts_draw_from_their_own_type_mixes() {
    let dir = tempfile::tempdir().unwrap();
    let town = dir.path().join("town");
    synth(&town, 3000, 3);
    let params = dir.path().join("p.toml");
    std::fs::write(
        &params,
        "[district.\"上京\".type_mix]\nsangai = 1.0\n\n\
         [district.\"下京\".type_mix]\nhiraya = 3.0\nsou-nikai = 1.0\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let r = build_ok(
        &town,
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let drawn = &r["counts"]["drawn_by_district"];
    let n = |d: &str, t: &str| drawn[d][t].as_u64().unwrap_or(0) as f64;
    let total = |d: &str| -> f64 {
        drawn[d]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap() as f64)
            .sum()
    };
    // 上京: every drawn type is sangai.
    assert!(total("上京") > 100.0, "{drawn}");
    assert_eq!(n("上京", "sangai"), total("上京"), "{drawn}");
    // 下京: hiraya with probability 3/4, within 4 standard deviations.
    let (k, m) = (n("下京", "hiraya"), total("下京"));
    assert_eq!(k + n("下京", "sou-nikai"), m, "{drawn}");
    let sd = (m * 0.75 * 0.25).sqrt();
    assert!((k - 0.75 * m).abs() < 4.0 * sd, "{k} of {m}");
    // 中京 keeps the global mix (Table 1): no sangai drawn there.
    assert!(total("中京") > 100.0);
    assert_eq!(n("中京", "sangai"), 0.0);
    assert!(n("中京", "hiraya") > 0.0 && n("中京", "naka-nikai-large") > 0.0);

    // An unknown type in a district's mix is an error naming the key.
    std::fs::write(&params, "[district.\"上京\".type_mix]\ncastle = 1.0\n").unwrap();
    let run = edo_city()
        .arg("build")
        .arg(&town)
        .args([
            "--out",
            dir.path().join("x").to_str().unwrap(),
            "--params",
            params.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("district.上京.type_mix names `castle`"));
}
