//! The cut-out atlas (`tiles/textures/cutouts.png`): the GLB tiles draw every cut-out
//! (billboard trees, people, walkers, grown trees' leaves) from one texture, a kind's
//! cut-outs in one primitive, each card inside its texture's cell; the OBJ keeps the
//! separate textures.

mod common;

use common::{build_ok, fixture};

/// Texels of slack at a cell's border: texture coordinates are stored in steps of 1/4096.
const SLACK: f64 = 1.0;

#[test]
fn every_cut_out_is_drawn_from_its_cell_of_the_atlas_one_primitive_a_kind() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(
        &params,
        "[trees]\nstyle = \"lsystem\"\n[people]\nmotion = \"boids\"\n\
         [output]\nglb_compression = \"none\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    let atlas = image::open(out.join("tiles/textures/cutouts.png")).unwrap();
    let manifest = common::read_json(&out.join("manifest.json"));
    assert!(
        manifest["textures"]
            .as_array()
            .unwrap()
            .iter()
            .any(|t| t["path"] == "tiles/textures/cutouts.png"),
        "the atlas is listed"
    );
    let (mut cards, mut kinds_with_cutouts) = (0usize, 0usize);
    let mut cells_seen = std::collections::BTreeSet::new();
    for t in manifest["tiles"].as_array().unwrap() {
        let Some(glb) = t["glb"]["path"].as_str() else {
            continue;
        };
        let path = out.join(glb);
        let bytes = std::fs::read(&path).unwrap();
        let glb = gltf::Gltf::from_slice_without_validation(&bytes).unwrap();
        let data = common::glb::buffers(&path, &glb);
        for node in glb.nodes() {
            let Some(mesh) = node.mesh() else { continue };
            let mut masked = 0;
            for prim in mesh.primitives() {
                let m = prim.material();
                if m.alpha_mode() != gltf::material::AlphaMode::Mask {
                    continue;
                }
                masked += 1;
                assert_eq!(m.name(), Some("cutouts"), "{}", path.display());
                let tex = m.pbr_metallic_roughness().base_color_texture().unwrap();
                match tex.texture().source().source() {
                    gltf::image::Source::Uri { uri, .. } => {
                        assert_eq!(uri, "textures/cutouts.png")
                    }
                    _ => panic!("the atlas is an external file"),
                }
                let extras: serde_json::Value =
                    serde_json::from_str(m.extras().as_ref().unwrap().get()).unwrap();
                let size = &extras["atlas"]["size"];
                let (w, h) = (size[0].as_f64().unwrap(), size[1].as_f64().unwrap());
                assert_eq!([w as u32, h as u32], [atlas.width(), atlas.height()]);
                let cells: Vec<(String, [f64; 4])> = extras["atlas"]["cells"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|c| {
                        let r = &c["rect"];
                        let r = [0, 1, 2, 3].map(|k| r[k].as_f64().unwrap());
                        (c["texture"].as_str().unwrap().to_string(), r)
                    })
                    .collect();
                let reader = prim.reader(|b| data.get(b.index()).map(|d| &d[..]));
                let uvs: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
                let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
                for tri in idx.chunks(3) {
                    let px: Vec<[f64; 2]> = tri
                        .iter()
                        .map(|&i| {
                            let [u, v] = uvs[i as usize];
                            [u as f64 * w, v as f64 * h]
                        })
                        .collect();
                    let inside = |r: &[f64; 4], p: &[f64; 2]| {
                        p[0] >= r[0] - SLACK
                            && p[0] <= r[0] + r[2] + SLACK
                            && p[1] >= r[1] - SLACK
                            && p[1] <= r[1] + r[3] + SLACK
                    };
                    let cell = cells
                        .iter()
                        .find(|(_, r)| px.iter().all(|p| inside(r, p)))
                        .unwrap_or_else(|| {
                            panic!("{}: a card across cells: {px:?}", path.display())
                        });
                    cells_seen.insert(cell.0.clone());
                    cards += 1;
                }
            }
            assert!(
                masked <= 1,
                "{}: node {:?} has {masked} cut-out primitives",
                path.display(),
                node.name()
            );
            kinds_with_cutouts += masked;
        }
    }
    assert!(cards > 1000, "{cards} cut-out triangles");
    assert!(kinds_with_cutouts > 10);
    // Trees, people and leaves all came from the atlas.
    for family in ["tree_", "person_", "leaf_"] {
        assert!(
            cells_seen.iter().any(|c| c.starts_with(family)),
            "{family}: {cells_seen:?}"
        );
    }
    // The OBJ keeps a material (and texture) per cut-out.
    let mtl = std::fs::read_to_string(out.join("tiles/1108_760.mtl")).unwrap();
    assert!(mtl.contains("newmtl person_01") && mtl.contains("textures/person_01.png"));
    assert!(!mtl.contains("cutouts"));
}

#[test]
fn an_obj_only_build_writes_no_atlas() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    build_ok(
        &fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--format", "obj"],
    );
    assert!(out.join("tiles/textures/person_01.png").exists());
    assert!(!out.join("tiles/textures/cutouts.png").exists());
}
