//! The material and texture library: every material a template may name, with its texture.
//!
//! Textures are compiled into the binary and copied to `<out>/textures/`, so an output
//! directory is complete on its own and opens anywhere.

/// One material of the MTL files.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub name: &'static str,
    /// Diffuse colour, used by viewers that ignore textures.
    pub kd: [f32; 3],
    /// Texture file name in `textures/`, if the material is textured.
    pub texture: Option<&'static str>,
}

/// All materials, in the order MTL files list them.
pub const MATERIALS: &[Material] = &[
    Material {
        name: "facade_hiraya",
        kd: [0.45, 0.33, 0.22],
        texture: Some("facade_hiraya.png"),
    },
    Material {
        name: "facade_nakanikai",
        kd: [0.55, 0.45, 0.35],
        texture: Some("facade_nakanikai.png"),
    },
    Material {
        name: "facade_sounikai",
        kd: [0.45, 0.33, 0.22],
        texture: Some("facade_sounikai.png"),
    },
    Material {
        name: "facade_sangai",
        kd: [0.45, 0.33, 0.22],
        texture: Some("facade_sangai.png"),
    },
    Material {
        name: "facade_shimoutaya",
        kd: [0.40, 0.30, 0.20],
        texture: Some("facade_shimoutaya.png"),
    },
    Material {
        name: "facade_kanban",
        kd: [0.50, 0.45, 0.40],
        texture: Some("facade_kanban.png"),
    },
    Material {
        name: "shikkui_wall",
        kd: [0.90, 0.88, 0.82],
        texture: Some("shikkui.png"),
    },
    Material {
        name: "kawara_roof",
        kd: [0.30, 0.31, 0.33],
        texture: Some("kawara.png"),
    },
    Material {
        name: "wood",
        kd: [0.35, 0.25, 0.16],
        texture: Some("wood.png"),
    },
    Material {
        name: "tsuchikabe_wall",
        kd: [0.72, 0.60, 0.42],
        texture: Some("tsuchikabe.png"),
    },
    Material {
        name: "floor",
        kd: [0.35, 0.32, 0.28],
        texture: None,
    },
];

/// Texture files, compiled in: (file name, PNG bytes).
pub const TEXTURES: &[(&str, &[u8])] = &[
    (
        "facade_hiraya.png",
        include_bytes!("../../textures/facade_hiraya.png"),
    ),
    (
        "facade_nakanikai.png",
        include_bytes!("../../textures/facade_nakanikai.png"),
    ),
    (
        "facade_sounikai.png",
        include_bytes!("../../textures/facade_sounikai.png"),
    ),
    (
        "facade_sangai.png",
        include_bytes!("../../textures/facade_sangai.png"),
    ),
    (
        "facade_shimoutaya.png",
        include_bytes!("../../textures/facade_shimoutaya.png"),
    ),
    (
        "facade_kanban.png",
        include_bytes!("../../textures/facade_kanban.png"),
    ),
    ("shikkui.png", include_bytes!("../../textures/shikkui.png")),
    ("kawara.png", include_bytes!("../../textures/kawara.png")),
    ("wood.png", include_bytes!("../../textures/wood.png")),
    (
        "tsuchikabe.png",
        include_bytes!("../../textures/tsuchikabe.png"),
    ),
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
