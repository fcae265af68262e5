//! Vertex generalisation (section 2.2): redundant vertices go before analysis and are counted.

mod common;

use common::build_ok;
use edo_city::synth::{write_blocks, write_lots, SynthLot};

#[test]
fn collinear_vertices_are_removed_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    // A 6 x 25 m lot digitised with three extra points on its sides, 2-4 mm off the line.
    let lot = SynthLot {
        id: 1,
        ring: vec![
            [0.0, 0.0],
            [3.0, 0.003],
            [6.0, 0.0],
            [6.002, 12.0],
            [6.0, 25.0],
            [0.0, 25.0],
            [-0.004, 10.0],
        ],
        lot_use: "machiya",
        mtype: "平屋",
        district: "",
        gate: "",
    };
    write_lots(&dir.path().join("lots.shp"), &[lot]).unwrap();
    write_blocks(
        &dir.path().join("blocks.shp"),
        &[vec![[-20.0, 0.0], [40.0, 0.0], [40.0, 60.0], [-20.0, 60.0]]],
    )
    .unwrap();
    let r = build_ok(
        dir.path(),
        &dir.path().join("out"),
        &["--quiet", "--no-plan"],
    );
    let lots = r["layers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["role"] == "lots")
        .unwrap();
    assert_eq!(lots["vertices_before"], 7);
    assert_eq!(lots["vertices_after"], 4);
    assert_eq!(r["counts"]["machiya"], 1);

    // Tolerance 0 keeps them all.
    let p = dir.path().join("p.toml");
    std::fs::write(&p, "[simplify]\ntolerance = 0.0\n").unwrap();
    let r = build_ok(
        dir.path(),
        &dir.path().join("out0"),
        &["--quiet", "--no-plan", "--params", p.to_str().unwrap()],
    );
    let lots = r["layers"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["role"] == "lots")
        .unwrap();
    assert_eq!(
        lots["vertices_after"], 0,
        "not counted when nothing is generalised"
    );
    assert_eq!(r["counts"]["machiya"], 1);
}
