//! Reading a user's template directory (`--templates`, `machiya.templates`) within bounds.
//!
//! The directory is the user's, but what lies under it is not always what they think: a
//! link to `/`, two folders linking to each other, a FIFO named `x.toml`, a 4 GB file left
//! in it. `--templates /` used to walk the whole file system and two self-links ran for
//! minutes. Each folder is entered once (by its resolved path), at most [`MAX_DEPTH`]
//! folders deep; at most [`MAX_FILES`] template files are read, each a regular file of at
//! most [`MAX_FILE_BYTES`], checked before it is opened. Past a bound the build stops with
//! an error naming the directory and the bound: a template folder that large is a mistake.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use super::TemplateError;
use crate::bounded::{Confined, Refusal};

/// Folders below the template directory that are searched.
pub const MAX_DEPTH: usize = 8;
/// Template and species files a directory may hold.
pub const MAX_FILES: usize = 10_000;
/// Bytes of one template or species file (the largest shipped one is about 8 KB).
pub const MAX_FILE_BYTES: u64 = 1 << 20;
/// Folders a walk may enter.
const MAX_FOLDERS: usize = 10_000;

/// Every `*.toml` under `dir`, sorted, recursively, leaving out the folders `skip` names
/// (tree species live in `trees/`, in their own format); `recurse` false reads `dir` alone.
pub fn toml_files(dir: &Path, skip: &str, recurse: bool) -> Result<Vec<PathBuf>, TemplateError> {
    let mut walk = Walk {
        root: dir,
        seen: HashSet::new(),
        files: Vec::new(),
    };
    walk.folder(dir, skip, if recurse { MAX_DEPTH } else { 0 })?;
    walk.files.sort();
    Ok(walk.files)
}

/// The text of one template or species file, refused when it is not a regular file or larger
/// than [`MAX_FILE_BYTES`].
pub fn read(path: &Path) -> Result<String, TemplateError> {
    crate::bounded::read_text(path, MAX_FILE_BYTES).map_err(|e| {
        let hint = match e {
            Refusal::NotRegular | Refusal::TooLarge { .. } => ": remove it",
            Refusal::Grew { .. } | Refusal::Io(_) => "",
        };
        TemplateError::Invalid(format!("{} {e}{hint}", path.display()))
    })
}

/// The text of the file `name` that the file `by` names beside itself (a species' hull
/// OBJ), read only inside `by`'s folder after its links are resolved ([`Confined`]: not
/// `../x`, `/etc/x` or a link out; `/dev/zero` used to be read until memory ran out), a
/// regular file of at most `cap` bytes. A refusal names the path as written, never what
/// lies outside.
pub fn read_beside(by: &Path, name: &str, cap: u64) -> Result<String, String> {
    let folder = by
        .parent()
        .filter(|f| !f.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let places = format!("the folder of {}", by.display());
    let bytes =
        Confined::new([folder], &places).read(&folder.join(name), &format!("`{name}`"), cap)?;
    String::from_utf8(bytes).map_err(|_| format!("`{name}` is not UTF-8 text"))
}

struct Walk<'a> {
    root: &'a Path,
    /// Folders entered, by their resolved paths: a link loop enters each once.
    seen: HashSet<PathBuf>,
    files: Vec<PathBuf>,
}

impl Walk<'_> {
    fn too_many(&self, what: String) -> TemplateError {
        TemplateError::Invalid(format!(
            "template directory {}: {what}; name a directory of templates only",
            self.root.display()
        ))
    }

    fn folder(&mut self, dir: &Path, skip: &str, depth_left: usize) -> Result<(), TemplateError> {
        let io = |cause| TemplateError::Io {
            dir: dir.display().to_string(),
            cause,
        };
        let real = std::fs::canonicalize(dir).map_err(io)?;
        if !self.seen.insert(real) {
            return Ok(());
        }
        if self.seen.len() > MAX_FOLDERS {
            return Err(self.too_many(format!("more than {MAX_FOLDERS} folders")));
        }
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(io)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        entries.sort();
        for p in entries {
            // Follows links, as the user's folders may be links; `seen` ends a loop.
            let Ok(meta) = std::fs::metadata(&p) else {
                continue; // a dangling link holds no template
            };
            if meta.is_dir() {
                if p.file_name().is_some_and(|n| n == skip) || depth_left == 0 {
                    continue;
                }
                self.folder(&p, skip, depth_left - 1)?;
            } else if p.extension().is_some_and(|x| x == "toml") {
                self.files.push(p);
                if self.files.len() > MAX_FILES {
                    return Err(self.too_many(format!("more than {MAX_FILES} *.toml files")));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn link_loops_are_entered_once_and_the_species_folder_is_left_out() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::create_dir_all(d.join("a/b")).unwrap();
        std::fs::create_dir_all(d.join("trees")).unwrap();
        std::fs::write(d.join("a/b/x.toml"), "").unwrap();
        std::fs::write(d.join("trees/sugi.toml"), "").unwrap();
        std::fs::write(d.join("top.toml"), "").unwrap();
        std::fs::write(d.join("notes.txt"), "").unwrap();
        std::os::unix::fs::symlink(d, d.join("a/b/up")).unwrap();
        std::os::unix::fs::symlink(d.join("a"), d.join("a/self")).unwrap();
        let files = toml_files(d, "trees", true).unwrap();
        let names: Vec<_> = files
            .iter()
            .map(|p| p.strip_prefix(d).unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["a/b/x.toml", "top.toml"]);
        let flat = toml_files(&d.join("trees"), "", false).unwrap();
        assert_eq!(flat.len(), 1);
        assert_eq!(toml_files(d, "trees", false).unwrap().len(), 1, "top alone");
    }

    #[test]
    fn a_pipe_or_a_huge_file_is_refused_before_it_is_read() {
        let tmp = tempfile::tempdir().unwrap();
        let fifo = tmp.path().join("x.toml");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let e = read(&fifo).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let big = tmp.path().join("big.toml");
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(MAX_FILE_BYTES + 1).unwrap();
        let e = read(&big).unwrap_err().to_string();
        assert!(e.contains("more than the 1048576"), "{e}");
    }
}
