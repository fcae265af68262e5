//! Which keys a page may set, and to what paths (issue 74).
//!
//! - A key is looked up in the catalogue of parameters before anything is built from it: a
//!   key of 30,000 dotted parts made `toml_edit` build a document 30,000 tables deep and
//!   overflowed the server's stack, losing every unsaved edit.
//! - The files the workbench owns are not parameters there: `input.overrides` set from the
//!   page made the save write the rows to one file while the parameter file named another.
//! - A path a page sets (a layer's file, a template or texture directory, a landmark's
//!   model) must lie inside the input directory or beside the parameter file, as written
//!   and with its links resolved: `machiya.templates = "/etc"` answered 200. A person names
//!   other places in their parameter file itself, which the page never writes unasked.

use std::path::{Path, PathBuf};

use edo_city::bounded::Confined;
use edo_city::params::catalogue::{self, PathBase};
use serde_json::Value;

use super::super::designer::{refuse, Refusal};
use super::Workbench;

/// Keys the workbench keeps itself: a page never sets them.
const OWNED: &[&str] = &["input.overrides", "input"];

/// Refuses `key = value` from a page unless it names a parameter a page may set, and, for a
/// path, one inside the input directory or beside the parameter file.
pub fn check(bench: &Workbench, key: &str, value: &Value) -> Result<(), Refusal> {
    if OWNED.contains(&key) {
        return Err(refuse(
            403,
            format!(
                "`{key}` is the workbench's own: it keeps the lot edits in {} (edit a lot to \
                 add one); name another table in the parameter file itself, then start \
                 `serve --edit` again",
                bench.files().overrides.display()
            ),
        ));
    }
    if !catalogue::knows(key) {
        return Err(refuse(
            400,
            format!(
                "`{}` is no parameter (`edo-city params` lists them, the panel shows them)",
                excerpt(key)
            ),
        ));
    }
    let (Some(base), Some(path)) = (catalogue::path_base(key), value.as_str()) else {
        return Ok(());
    };
    if path.trim().is_empty() {
        return Ok(());
    }
    let params_dir = bench.files().params.parent().unwrap_or(Path::new("/"));
    let input = bench.input();
    let from = match base {
        PathBase::Input => input.to_path_buf(),
        PathBase::ParamsFile => params_dir.to_path_buf(),
        PathBase::WorkingDir => std::env::current_dir().unwrap_or_default(),
        PathBase::Models => models_dir(bench),
    };
    let allowed = Confined::new([input, params_dir], "");
    match allowed.contains(&from.join(path)) {
        true => Ok(()),
        false => Err(refuse(
            403,
            format!(
                "`{key}` = `{}`: a path set from the page must lie inside the input directory \
                 ({}) or beside the parameter file ({}); name other places in the parameter \
                 file itself",
                excerpt(path),
                input.display(),
                params_dir.display()
            ),
        )),
    }
}

/// Where the landmarks' models are looked for as the hypothesis stands: `models_dir` from
/// the working directory, else the input directory.
fn models_dir(bench: &Workbench) -> PathBuf {
    let dir = bench
        .current()
        .0
        .map(|p| p.landmarks.models_dir)
        .unwrap_or_default();
    match dir.is_empty() {
        true => bench.input().to_path_buf(),
        false => std::env::current_dir().unwrap_or_default().join(dir),
    }
}

/// At most 80 characters of what a page sent, for a message.
pub fn excerpt(s: &str) -> String {
    match s.char_indices().nth(80) {
        Some((i, _)) => format!("{}... ({} bytes)", &s[..i], s.len()),
        None => s.to_string(),
    }
}
