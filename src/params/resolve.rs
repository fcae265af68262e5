//! A parameter file as a TOML table: the defaults, the `extends` chain overlaid on them, each
//! file's keys checked against the schema first (so errors name that file's line and column),
//! and `garden.designs` anchored to the file that names it.

use std::path::Path;

use super::{partial, ParamsError, DEFAULT_TOML};

/// The defaults, then every file of an `extends` chain from the root down, each overlaid on
/// the one it extends. Each file's own keys are checked against the schema first, so an
/// error carries that file's name, line and column.
pub(super) fn resolved_table(
    text: &str,
    path: &str,
    base_dir: &Path,
    chain: &mut Vec<String>,
) -> Result<toml::Table, ParamsError> {
    let parse = |t: &str, p: &str| -> Result<toml::Table, ParamsError> {
        t.parse::<toml::Table>().map_err(|e| ParamsError::Parse {
            path: p.to_string(),
            message: crate::model::source::toml_at(t, &e),
        })
    };
    check_user_keys(text, path)?;
    let mut user = parse(text, path)?;
    anchor_designs(&mut user, base_dir);
    let mut merged = match user.remove("extends") {
        None => parse(DEFAULT_TOML, "params/default.toml")?,
        Some(toml::Value::String(name)) => {
            let file = base_dir.join(&name);
            if !file.exists() && (name == "default" || name == "default.toml") {
                // The shipped defaults, wherever the tool runs from.
                parse(DEFAULT_TOML, "params/default.toml")?
            } else {
                let key = file.display().to_string();
                if chain.contains(&key) {
                    return Err(ParamsError::Invalid {
                        path: path.to_string(),
                        message: format!("`extends` loops back to {key}"),
                    });
                }
                chain.push(key.clone());
                let parent_text = super::read_file(&file).map_err(|cause| ParamsError::Io {
                    path: format!("{key} (extended by {path})"),
                    cause,
                })?;
                let dir = file.parent().unwrap_or(Path::new("."));
                resolved_table(&parent_text, &key, dir, chain)?
            }
        }
        Some(other) => {
            return Err(ParamsError::Invalid {
                path: path.to_string(),
                message: format!("`extends` must be a file name, got {other}"),
            })
        }
    };
    // `type_mix`, `values` and `constants` are replaced whole: a user who lists types means
    // exactly those.
    merge(&mut merged, user);
    Ok(merged)
}

/// `garden.designs` and `input.overrides`, when relative, made relative to `base_dir` (the
/// directory of the file that names it: a parameter file kept beside its designs or its
/// overrides works from anywhere), and
/// absolute: the analysis cache's key (`build::cache::key`) hashes the file the parameter
/// names, which a path relative to the current directory would not find.
fn anchor_designs(table: &mut toml::Table, base_dir: &Path) {
    for (section, key) in [("garden", "designs"), ("input", "overrides")] {
        anchor(table, section, key, base_dir);
    }
}

/// `[section] key`, a file name, anchored to `base_dir` (see [`anchor_designs`]).
fn anchor(table: &mut toml::Table, section: &str, key: &str, base_dir: &Path) {
    let Some(toml::Value::Table(t)) = table.get_mut(section) else {
        return;
    };
    if let Some(toml::Value::String(file)) = t.get_mut(key) {
        if !file.is_empty() && Path::new(file.as_str()).is_relative() {
            let joined = base_dir.join(file.as_str());
            let absolute = std::path::absolute(&joined).unwrap_or(joined);
            *file = absolute.display().to_string();
        }
    }
}

/// Overlays `user` on `base`, table by table; `type_mix` is replaced whole, and each row of
/// a species table (`trees.species.<use>`, `district.<id>.tree_species.<use>`): a user who
/// lists a use's species means exactly those.
fn merge(base: &mut toml::Table, user: toml::Table) {
    for (key, value) in user {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(u))
                if matches!(key.as_str(), "species" | "tree_species") =>
            {
                for (row, weights) in u {
                    b.insert(row, weights);
                }
            }
            (Some(toml::Value::Table(b)), toml::Value::Table(u))
                if !matches!(key.as_str(), "type_mix" | "values" | "constants") =>
            {
                merge(b, u)
            }
            (_, v) => {
                base.insert(key, v);
            }
        }
    }
}

/// Parses the user's own text against the schema, every field optional, so that an unknown
/// key or a wrong type is reported with the line and column of the user's file.
fn check_user_keys(text: &str, path: &str) -> Result<(), ParamsError> {
    toml::from_str::<partial::Params>(text)
        .map(|_| ())
        .map_err(|e| ParamsError::Parse {
            path: path.to_string(),
            message: crate::model::source::toml_at(text, &e),
        })
}
