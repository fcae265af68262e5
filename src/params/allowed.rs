//! What a parameter may be, said once: the ranges and the choices that `Params::validate`
//! checks and that the workbench's `GET /api/params` lists as `allowed` (issue 61), so the
//! panel offers what the build accepts and nothing else.
//!
//! The checks that tie several keys together (a kura's minimum within its size, the crowd's
//! radii in order) stay in their sections' `validate`; a key without an entry here is
//! described by its comment in `params/default.toml`.

/// The densest crowd a parameter may ask for: a person every 10 cm of street.
pub const MAX_PER_100M: f64 = 1000.0;
/// The densest wood: a tree per square metre.
pub const MAX_PER_HA: f64 = 10_000.0;
/// The tree styles.
pub const TREE_STYLES: [&str; 3] = ["billboard", "lsystem", "colonization"];
/// The formats a build can write, as `--format` and `output.formats` spell them: two of
/// tiles, `gpkg`, the build's decisions as GIS layers (`plan.gpkg`), and `cityjson`, the
/// city as a CityJSON 2.0 model (`city.city.jsonl`).
pub const FORMATS: &[&str] = &["obj", "glb", "gpkg", "cityjson"];
/// The values of `output.glb_compression`.
pub const GLB_COMPRESSIONS: &[&str] = &["meshopt", "none"];

/// What one parameter may be.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Allowed {
    /// A number from `low` to `high`; `low` itself only when `closed` (0 switches a thing
    /// off; a size of 0 is no size).
    Range {
        /// The least value (see `closed`).
        low: f64,
        /// The greatest value, itself allowed.
        high: f64,
        /// Whether `low` itself is allowed.
        closed: bool,
    },
    /// One of these words.
    OneOf(&'static [&'static str]),
    /// A list of these words.
    ListOf(&'static [&'static str]),
}

const fn size(high: f64) -> Allowed {
    Allowed::Range {
        low: 0.0,
        high,
        closed: false,
    }
}

const fn from_zero(high: f64) -> Allowed {
    Allowed::Range {
        low: 0.0,
        high,
        closed: true,
    }
}

/// The seasons a tree species dresses for.
pub const SEASONS: &[&str] = &["spring", "summer", "autumn", "winter"];
/// How people stand or walk.
pub const MOTIONS: &[&str] = &["scatter", "boids"];
/// How an OBJ names its objects.
pub const OBJ_OBJECTS: &[&str] = &["each", "kind"];

/// Every parameter with a range or a set of words, by its key as the TOML spells it.
pub const ALLOWED: &[(&str, Allowed)] = &[
    (
        "tile_size",
        Allowed::Range {
            low: 1.0,
            high: 1e6,
            closed: true,
        },
    ),
    ("fence.gate_width", size(100.0)),
    ("kura.width", size(100.0)),
    ("kura.depth", size(100.0)),
    ("kura.min_width", size(100.0)),
    ("kura.min_depth", size(100.0)),
    ("frontage.min_length", size(1000.0)),
    ("machiya.depth", size(1000.0)),
    (
        "layers.streets.default_width",
        size(crate::model::MAX_STREET_WIDTH),
    ),
    ("layers.footprints.storey_height", size(100.0)),
    ("layers.footprints.default_height", size(1000.0)),
    ("layers.street_widths.max_distance", size(1e5)),
    ("kura.min_frontage", from_zero(1000.0)),
    ("kura.depth_ratio", from_zero(1000.0)),
    ("kura.gap", from_zero(1000.0)),
    ("kura.back_margin", from_zero(1000.0)),
    ("kura.side_margin", from_zero(1000.0)),
    ("kura.overlap_tolerance", from_zero(1000.0)),
    ("simplify.tolerance", from_zero(1000.0)),
    ("machiya.min_depth", from_zero(1000.0)),
    (
        "simplify.max_vertices",
        Allowed::Range {
            low: 1.0,
            high: 1e8,
            closed: true,
        },
    ),
    ("frontage.max_angle_deg", size(180.0)),
    ("people.per_100m", from_zero(MAX_PER_100M)),
    ("people.edge_margin", from_zero(100.0)),
    ("people.min_spacing", from_zero(100.0)),
    ("people.clearance", from_zero(100.0)),
    ("people.max_turn_deg", from_zero(180.0)),
    ("people.motion", Allowed::OneOf(MOTIONS)),
    ("trees.per_ha", from_zero(MAX_PER_HA)),
    ("trees.per_ha_machiya", from_zero(MAX_PER_HA)),
    ("trees.min_spacing", from_zero(100.0)),
    ("trees.clearance", from_zero(100.0)),
    ("trees.style", Allowed::OneOf(&TREE_STYLES)),
    ("trees.season", Allowed::OneOf(SEASONS)),
    ("output.formats", Allowed::ListOf(FORMATS)),
    ("output.glb_compression", Allowed::OneOf(GLB_COMPRESSIONS)),
    ("output.obj_objects", Allowed::OneOf(OBJ_OBJECTS)),
];

/// What `key` may be, when it has an entry.
pub fn allowed(key: &str) -> Option<Allowed> {
    ALLOWED.iter().find(|(k, _)| *k == key).map(|(_, a)| *a)
}

/// Checks a number against its entry of [`ALLOWED`] (which it must have).
pub fn check_number(key: &str, value: f64) -> Result<(), String> {
    let Some(Allowed::Range { low, high, closed }) = allowed(key) else {
        return Ok(());
    };
    let above = if closed { value >= low } else { value > low };
    if value.is_finite() && above && value <= high {
        return Ok(());
    }
    let value = crate::model::number::Num(value);
    Err(match (closed, low) {
        (false, 0.0) => format!("`{key}` must be a positive number up to {high}, got {value}"),
        (true, 0.0) => format!("`{key}` must be from 0 to {high}, got {value}"),
        (true, _) => format!("`{key}` must be from {low} to {high}, got {value}"),
        (false, _) => format!("`{key}` must be more than {low} and at most {high}, got {value}"),
    })
}

/// Checks a word against its entry of [`ALLOWED`] (which it must have).
pub fn check_word(key: &str, value: &str) -> Result<(), String> {
    let Some(Allowed::OneOf(words)) = allowed(key) else {
        return Ok(());
    };
    match words.contains(&value) {
        true => Ok(()),
        false => Err(format!(
            "`{key}` must be {}, got \"{value}\"",
            words
                .iter()
                .map(|w| format!("\"{w}\""))
                .collect::<Vec<_>>()
                .join(" or ")
        )),
    }
}

impl Allowed {
    /// As JSON for the workbench: `{min, max, minExclusive}` or `{values}` or `{each}`.
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            Allowed::Range { low, high, closed } => {
                serde_json::json!({ "min": low, "max": high, "minExclusive": !closed })
            }
            Allowed::OneOf(words) => serde_json::json!({ "values": words }),
            Allowed::ListOf(words) => serde_json::json!({ "each": words }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

    /// Every entry is what the build enforces: a parameter file setting a number past its
    /// range, or a word not listed, is refused naming the key; the bounds themselves pass.
    #[test]
    fn every_entry_is_what_validate_enforces() {
        let dir = tempfile::tempdir().unwrap();
        let try_text = |key: &str, value: String| {
            let (table, name) = key.rsplit_once('.').map_or(("", key), |(t, n)| (t, n));
            let text = match table {
                "" => format!("{name} = {value}\n"),
                t => format!("[{t}]\n{name} = {value}\n"),
            };
            let p = dir.path().join("p.toml");
            std::fs::write(&p, text).unwrap();
            Params::from_path(&p).map(|_| ()).map_err(|e| e.to_string())
        };
        let defaults = serde_json::to_value(Params::default()).unwrap();
        for (key, a) in ALLOWED {
            let default = key.split('.').fold(&defaults, |v, k| &v[k]);
            let integer = default.is_u64();
            let num = |x: f64| match integer {
                true => format!("{}", x as u64),
                false => format!("{x:?}"),
            };
            match *a {
                Allowed::Range { low, high, closed } => {
                    // Bounds that other keys do not hold back (a kura's minimum within its
                    // size) pass; past them, refused.
                    if !key.starts_with("kura.") {
                        assert!(try_text(key, num(high)).is_ok(), "{key} = {high}");
                    }
                    let e = try_text(key, num(high * 2.0 + 1.0)).unwrap_err();
                    assert!(e.contains(key), "{key}: {e}");
                    if closed && low > 0.0 || !closed && !integer {
                        let below = if closed { low - 0.5 } else { low };
                        let e = try_text(key, num(below)).unwrap_err();
                        assert!(e.contains(key), "{key} below: {e}");
                    }
                }
                Allowed::OneOf(words) => {
                    for w in words {
                        let ok = try_text(key, format!("\"{w}\""));
                        assert!(ok.is_ok(), "{key} = {w}: {ok:?}");
                    }
                    let e = try_text(key, "\"nonsense\"".into()).unwrap_err();
                    assert!(e.contains(key), "{key}: {e}");
                }
                Allowed::ListOf(words) => {
                    let e = try_text(key, "[\"nonsense\"]".into()).unwrap_err();
                    assert!(e.contains(key), "{key}: {e}");
                    assert!(try_text(key, format!("[\"{}\"]", words[0])).is_ok());
                }
            }
        }
    }
}
