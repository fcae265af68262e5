//! The material and texture library: every material a template may name, with its texture.
//!
//! Textures are compiled into the binary and copied to `<out>/textures/`, so an output
//! directory is complete on its own and opens anywhere.

/// One material of the MTL files.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// The name templates and MTL files use.
    pub name: &'static str,
    /// Diffuse colour, used by viewers that ignore textures.
    pub kd: [f32; 3],
    /// Texture file name in `textures/`, if the material is textured.
    pub texture: Option<&'static str>,
    /// The texture's alpha cuts the face out (billboards): the MTL adds `map_d`.
    pub alpha: bool,
    /// For a cut-out, the mask texture the MTL's `map_d` names: RGBA = a,a,a,a of the
    /// texture, derived when the library is written (three.js reads an alpha map from its
    /// green channel, Blender from its alpha: a grey mask means the same to both).
    pub mask: Option<&'static str>,
}

/// All materials, in the order MTL files list them.
pub const MATERIALS: &[Material] = &[
    Material {
        name: "facade_hiraya",
        kd: [0.45, 0.33, 0.22],
        alpha: false,
        mask: None,
        texture: Some("facade_hiraya.png"),
    },
    Material {
        name: "facade_nakanikai",
        kd: [0.55, 0.45, 0.35],
        alpha: false,
        mask: None,
        texture: Some("facade_nakanikai.png"),
    },
    Material {
        name: "facade_sounikai",
        kd: [0.45, 0.33, 0.22],
        alpha: false,
        mask: None,
        texture: Some("facade_sounikai.png"),
    },
    Material {
        name: "facade_sangai",
        kd: [0.45, 0.33, 0.22],
        alpha: false,
        mask: None,
        texture: Some("facade_sangai.png"),
    },
    Material {
        name: "facade_shimoutaya",
        kd: [0.40, 0.30, 0.20],
        alpha: false,
        mask: None,
        texture: Some("facade_shimoutaya.png"),
    },
    Material {
        name: "facade_kanban",
        kd: [0.50, 0.45, 0.40],
        alpha: false,
        mask: None,
        texture: Some("facade_kanban.png"),
    },
    Material {
        name: "shikkui_wall",
        kd: [0.90, 0.88, 0.82],
        alpha: false,
        mask: None,
        texture: Some("shikkui.png"),
    },
    Material {
        name: "kawara_roof",
        kd: [0.30, 0.31, 0.33],
        alpha: false,
        mask: None,
        texture: Some("kawara.png"),
    },
    Material {
        name: "wood",
        kd: [0.35, 0.25, 0.16],
        alpha: false,
        mask: None,
        texture: Some("wood.png"),
    },
    Material {
        name: "tsuchikabe_wall",
        kd: [0.72, 0.60, 0.42],
        alpha: false,
        mask: None,
        texture: Some("tsuchikabe.png"),
    },
    Material {
        name: "floor",
        kd: [0.35, 0.32, 0.28],
        alpha: false,
        mask: None,
        texture: None,
    },
    Material {
        name: "koshi",
        kd: [0.40, 0.27, 0.17],
        alpha: false,
        mask: None,
        texture: Some("koshi.png"),
    },
    Material {
        name: "gate",
        kd: [0.38, 0.25, 0.15],
        alpha: false,
        mask: None,
        texture: Some("gate.png"),
    },
    Material {
        name: "namako",
        kd: [0.35, 0.36, 0.38],
        alpha: false,
        mask: None,
        texture: Some("namako.png"),
    },
    Material {
        name: "tree_01",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_01_mask.png"),
        texture: Some("tree_01.png"),
    },
    Material {
        name: "tree_02",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_02_mask.png"),
        texture: Some("tree_02.png"),
    },
    Material {
        name: "tree_03",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_03_mask.png"),
        texture: Some("tree_03.png"),
    },
    Material {
        name: "tree_04",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_04_mask.png"),
        texture: Some("tree_04.png"),
    },
    Material {
        name: "tree_05",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_05_mask.png"),
        texture: Some("tree_05.png"),
    },
    Material {
        name: "tree_06",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_06_mask.png"),
        texture: Some("tree_06.png"),
    },
    Material {
        name: "tree_07",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_07_mask.png"),
        texture: Some("tree_07.png"),
    },
    Material {
        name: "tree_08",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_08_mask.png"),
        texture: Some("tree_08.png"),
    },
    Material {
        name: "tree_09",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_09_mask.png"),
        texture: Some("tree_09.png"),
    },
    Material {
        name: "tree_10",
        kd: [0.25, 0.40, 0.22],
        alpha: true,
        mask: Some("tree_10_mask.png"),
        texture: Some("tree_10.png"),
    },
    Material {
        name: "person_01",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_01_mask.png"),
        texture: Some("person_01.png"),
    },
    Material {
        name: "person_02",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_02_mask.png"),
        texture: Some("person_02.png"),
    },
    Material {
        name: "person_03",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_03_mask.png"),
        texture: Some("person_03.png"),
    },
    Material {
        name: "person_04",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_04_mask.png"),
        texture: Some("person_04.png"),
    },
    Material {
        name: "person_05",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_05_mask.png"),
        texture: Some("person_05.png"),
    },
    Material {
        name: "person_06",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_06_mask.png"),
        texture: Some("person_06.png"),
    },
    Material {
        name: "person_07",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_07_mask.png"),
        texture: Some("person_07.png"),
    },
    Material {
        name: "person_08",
        kd: [0.25, 0.25, 0.35],
        alpha: true,
        mask: Some("person_08_mask.png"),
        texture: Some("person_08.png"),
    },
    Material {
        name: "ground",
        kd: [0.55, 0.48, 0.38],
        alpha: false,
        mask: None,
        texture: Some("ground.png"),
    },
    Material {
        name: "bark",
        kd: [0.30, 0.24, 0.18],
        alpha: false,
        mask: None,
        texture: Some("bark.png"),
    },
    Material {
        name: "leaf_broad",
        kd: [0.22, 0.38, 0.18],
        alpha: true,
        mask: Some("leaf_broad_mask.png"),
        texture: Some("leaf_broad.png"),
    },
    Material {
        name: "leaf_needle",
        kd: [0.16, 0.30, 0.16],
        alpha: true,
        mask: Some("leaf_needle_mask.png"),
        texture: Some("leaf_needle.png"),
    },
    Material {
        name: "leaf_blossom",
        kd: [0.93, 0.76, 0.80],
        alpha: true,
        mask: Some("leaf_blossom_mask.png"),
        texture: Some("leaf_blossom.png"),
    },
    Material {
        name: "leaf_red",
        kd: [0.70, 0.20, 0.12],
        alpha: true,
        mask: Some("leaf_red_mask.png"),
        texture: Some("leaf_red.png"),
    },
    Material {
        name: "leaf_yellow",
        kd: [0.78, 0.62, 0.20],
        alpha: true,
        mask: Some("leaf_yellow_mask.png"),
        texture: Some("leaf_yellow.png"),
    },
    Material {
        name: "leaf_willow",
        kd: [0.45, 0.58, 0.28],
        alpha: true,
        mask: Some("leaf_willow_mask.png"),
        texture: Some("leaf_willow.png"),
    },
    Material {
        name: "leaf_bamboo",
        kd: [0.36, 0.52, 0.24],
        alpha: true,
        mask: Some("leaf_bamboo_mask.png"),
        texture: Some("leaf_bamboo.png"),
    },
    Material {
        name: "bamboo_culm",
        kd: [0.42, 0.55, 0.28],
        alpha: false,
        mask: None,
        texture: Some("bamboo_culm.png"),
    },
    Material {
        name: "gravel_raked",
        kd: [0.82, 0.80, 0.76],
        alpha: false,
        mask: None,
        texture: Some("gravel_raked.png"),
    },
    Material {
        name: "moss",
        kd: [0.30, 0.42, 0.20],
        alpha: false,
        mask: None,
        texture: Some("moss.png"),
    },
    Material {
        name: "stone",
        kd: [0.45, 0.44, 0.42],
        alpha: false,
        mask: None,
        texture: Some("stone.png"),
    },
    Material {
        name: "rake_line",
        kd: [0.62, 0.60, 0.56],
        alpha: false,
        mask: None,
        texture: None,
    },
    // The ground of a tile (`generate::ground`): street surfaces, the white gravel of
    // temple and court grounds, water.
    Material {
        name: "street",
        kd: [0.47, 0.42, 0.36],
        alpha: false,
        mask: None,
        texture: Some("street.png"),
    },
    Material {
        name: "gravel",
        kd: [0.70, 0.68, 0.63],
        alpha: false,
        mask: None,
        texture: Some("gravel.png"),
    },
    Material {
        name: "water",
        kd: [0.26, 0.40, 0.48],
        alpha: false,
        mask: None,
        texture: Some("water.png"),
    },
];

/// Texture files, compiled in: (file name, PNG bytes).
pub const TEXTURES: &[(&str, &[u8])] = &[
    (
        "facade_hiraya.png",
        include_bytes!("../textures/facade_hiraya.png"),
    ),
    (
        "facade_nakanikai.png",
        include_bytes!("../textures/facade_nakanikai.png"),
    ),
    (
        "facade_sounikai.png",
        include_bytes!("../textures/facade_sounikai.png"),
    ),
    (
        "facade_sangai.png",
        include_bytes!("../textures/facade_sangai.png"),
    ),
    (
        "facade_shimoutaya.png",
        include_bytes!("../textures/facade_shimoutaya.png"),
    ),
    (
        "facade_kanban.png",
        include_bytes!("../textures/facade_kanban.png"),
    ),
    ("shikkui.png", include_bytes!("../textures/shikkui.png")),
    ("kawara.png", include_bytes!("../textures/kawara.png")),
    ("wood.png", include_bytes!("../textures/wood.png")),
    (
        "tsuchikabe.png",
        include_bytes!("../textures/tsuchikabe.png"),
    ),
    ("koshi.png", include_bytes!("../textures/koshi.png")),
    ("gate.png", include_bytes!("../textures/gate.png")),
    ("namako.png", include_bytes!("../textures/namako.png")),
    ("tree_01.png", include_bytes!("../textures/tree_01.png")),
    ("tree_02.png", include_bytes!("../textures/tree_02.png")),
    ("tree_03.png", include_bytes!("../textures/tree_03.png")),
    ("tree_04.png", include_bytes!("../textures/tree_04.png")),
    ("tree_05.png", include_bytes!("../textures/tree_05.png")),
    ("tree_06.png", include_bytes!("../textures/tree_06.png")),
    ("tree_07.png", include_bytes!("../textures/tree_07.png")),
    ("tree_08.png", include_bytes!("../textures/tree_08.png")),
    ("tree_09.png", include_bytes!("../textures/tree_09.png")),
    ("tree_10.png", include_bytes!("../textures/tree_10.png")),
    ("person_01.png", include_bytes!("../textures/person_01.png")),
    ("person_02.png", include_bytes!("../textures/person_02.png")),
    ("person_03.png", include_bytes!("../textures/person_03.png")),
    ("person_04.png", include_bytes!("../textures/person_04.png")),
    ("person_05.png", include_bytes!("../textures/person_05.png")),
    ("person_06.png", include_bytes!("../textures/person_06.png")),
    ("person_07.png", include_bytes!("../textures/person_07.png")),
    ("person_08.png", include_bytes!("../textures/person_08.png")),
    ("ground.png", include_bytes!("../textures/ground.png")),
    ("bark.png", include_bytes!("../textures/bark.png")),
    (
        "leaf_broad.png",
        include_bytes!("../textures/leaf_broad.png"),
    ),
    (
        "leaf_needle.png",
        include_bytes!("../textures/leaf_needle.png"),
    ),
    (
        "leaf_blossom.png",
        include_bytes!("../textures/leaf_blossom.png"),
    ),
    ("leaf_red.png", include_bytes!("../textures/leaf_red.png")),
    (
        "leaf_yellow.png",
        include_bytes!("../textures/leaf_yellow.png"),
    ),
    (
        "leaf_willow.png",
        include_bytes!("../textures/leaf_willow.png"),
    ),
    (
        "gravel_raked.png",
        include_bytes!("../textures/gravel_raked.png"),
    ),
    ("moss.png", include_bytes!("../textures/moss.png")),
    ("stone.png", include_bytes!("../textures/stone.png")),
    (
        "bamboo_culm.png",
        include_bytes!("../textures/bamboo_culm.png"),
    ),
    (
        "leaf_bamboo.png",
        include_bytes!("../textures/leaf_bamboo.png"),
    ),
    ("street.png", include_bytes!("../textures/street.png")),
    ("gravel.png", include_bytes!("../textures/gravel.png")),
    ("water.png", include_bytes!("../textures/water.png")),
];

/// Index of a material by name.
pub fn find(name: &str) -> Option<u16> {
    MATERIALS
        .iter()
        .position(|m| m.name == name)
        .map(|i| i as u16)
}

/// Index of a material that is known to exist (names used by the generators themselves).
pub fn id(name: &str) -> u16 {
    find(name).unwrap_or_else(|| panic!("built-in material `{name}` missing from MATERIALS"))
}

/// Whether a library file is a cut-out material's colour texture (bled when replaced,
/// packed into the GLB tiles' atlas).
pub fn is_cut_out_texture(file: &str) -> bool {
    MATERIALS.iter().any(|m| m.alpha && m.texture == Some(file))
}

/// Every material's name, for messages that list them.
pub fn names() -> Vec<&'static str> {
    MATERIALS.iter().map(|m| m.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_textured_material_has_its_png() {
        for m in MATERIALS {
            if let Some(t) = m.texture {
                let bytes = TEXTURES.iter().find(|(n, _)| *n == t).map(|(_, b)| *b);
                let bytes = bytes.unwrap_or_else(|| panic!("{t} not compiled in"));
                assert_eq!(&bytes[1..4], b"PNG", "{t}");
            }
        }
    }
}
