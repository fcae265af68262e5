//! The key of a build's analysis: the program, the parameters, and the contents of every
//! file the analysis may read, found exactly as the build finds them.
//!
//! The key used to take each file's size and time of writing: a `lots.dbf` rewritten with the
//! same size and `touch -r` reused a stale analysis, and `models_dir` and
//! `machiya.templates` (which the build resolves against the current directory) were looked
//! for under the input directory. Now each file's bytes go into the key (sha256, with the
//! CPU's SHA instructions where it has them: at a million lots, hashing the 198 MB input and
//! checking the cache file's own sha256 made a cached tile 4.3 s instead of 3.5 s, against
//! 16.3 s without the cache).
//!
//! What is hashed: the input directory (but not an `--out` inside it); the template
//! directory `load_catalog` reads (`--templates`, else `machiya.templates`); the top level of
//! the texture set; `landmarks.models_dir`; and every file a parameter names outside the input
//! (a DEM or table kept elsewhere, with the files beside it of the same stem). Each folder
//! is entered once by its resolved path, at most [`MAX_DEPTH`] deep; only regular files are
//! read (a FIFO or device is named, not opened). Past [`MAX_FILES`] files or [`MAX_BYTES`]
//! bytes (an input directory that is someone's home) there is no key and no cache: the build
//! analyses, as it would without one.

use std::collections::HashSet;
use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::build::{absolute, BuildOptions};

/// Folders below each hashed directory that are entered.
pub const MAX_DEPTH: usize = 16;
/// Files hashed for one key.
pub const MAX_FILES: usize = 100_000;
/// Bytes hashed for one key.
pub const MAX_BYTES: u64 = 8 << 30;

/// The key of `opts`' analysis, or `None` when the files to hash are past the bounds.
pub fn key(opts: &BuildOptions) -> Option<[u8; 32]> {
    let params = serde_json::to_value(&opts.params).unwrap_or_default();
    let input = absolute(&opts.input);
    let mut k = Keyer::new(absolute(&opts.out));
    k.h.update(env!("CARGO_PKG_VERSION").as_bytes());
    if let Ok(exe) = std::env::current_exe() {
        k.program(&exe);
    }
    k.h.update(params.to_string().as_bytes());
    k.tree("input", &opts.input, MAX_DEPTH, None)?;
    let templates = opts.templates.clone().or_else(|| {
        let t = &opts.params.machiya.templates;
        (!t.is_empty()).then(|| PathBuf::from(t))
    });
    if let Some(dir) = templates {
        k.tree("templates", &dir, MAX_DEPTH, None)?;
    }
    if !opts.params.textures.is_empty() {
        // The set's own PNGs, as `texture_library` reads them: `textures = "/"` is one folder.
        k.tree("textures", Path::new(&opts.params.textures), 0, Some("png"))?;
    }
    let models = crate::input::models_dir(&opts.input, &opts.params);
    k.tree("models", &models, MAX_DEPTH, None)?;
    let mut named = Vec::new();
    strings(&params, &mut named);
    for s in named {
        // As the build resolves a layer, table or DEM file: against the input directory.
        let p = absolute(&opts.input.join(s));
        if p.starts_with(&input) || input.starts_with(&p) {
            continue;
        }
        if p.is_file() {
            k.siblings(&p)?;
        }
    }
    Some(k.h.finalize().into())
}

/// Every string in the parameters (a file a layer, table or DEM names is among them).
fn strings<'a>(v: &'a serde_json::Value, out: &mut Vec<&'a str>) {
    match v {
        serde_json::Value::String(s) if !s.is_empty() => out.push(s),
        serde_json::Value::Array(a) => a.iter().for_each(|v| strings(v, out)),
        serde_json::Value::Object(o) => o.values().for_each(|v| strings(v, out)),
        _ => {}
    }
}

/// The hash being built, and what it has taken in so far.
struct Keyer {
    h: Sha256,
    /// The output directory, resolved: never hashed (it changes with every build).
    out: PathBuf,
    /// Folders entered, resolved: a link loop, or the input named twice, is hashed once.
    seen: HashSet<PathBuf>,
    files: usize,
    bytes: u64,
    buf: Vec<u8>,
}

impl Keyer {
    fn new(out: PathBuf) -> Self {
        Keyer {
            h: Sha256::new(),
            out,
            seen: HashSet::new(),
            files: 0,
            bytes: 0,
            buf: vec![0; 1 << 20],
        }
    }

    /// The program by its path, size and time of writing (a rebuilt binary is another key;
    /// hashing 30 MB of it on every run would buy nothing).
    fn program(&mut self, exe: &Path) {
        self.h.update(exe.as_os_str().as_encoded_bytes());
        if let Ok(m) = fs::metadata(exe) {
            self.h.update(m.len().to_le_bytes());
            let t = m
                .modified()
                .ok()
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
            self.h.update(t.map_or(0, |t| t.as_nanos()).to_le_bytes());
        }
    }

    /// Every file under `dir` (resolved as the build resolves it: against the current
    /// directory), `depth` folders deep, by names relative to `dir`; only those ending in
    /// `.<ext>` (any case) when `ext` is given.
    fn tree(&mut self, label: &str, dir: &Path, depth: usize, ext: Option<&str>) -> Option<()> {
        self.h.update(b"\0tree\0");
        self.h.update(label.as_bytes());
        self.h.update(absolute(dir).as_os_str().as_encoded_bytes());
        self.folder(dir, Path::new(""), depth, ext)
    }

    fn folder(&mut self, dir: &Path, rel: &Path, depth: usize, ext: Option<&str>) -> Option<()> {
        let Ok(real) = fs::canonicalize(dir) else {
            self.h.update(b"\0missing\0");
            return Some(());
        };
        if real == self.out || !self.seen.insert(real) {
            self.h.update(b"\0again\0");
            self.h.update(rel.as_os_str().as_encoded_bytes());
            return Some(());
        }
        let Ok(entries) = fs::read_dir(dir) else {
            self.h.update(b"\0unreadable\0");
            return Some(());
        };
        let wanted = |n: &std::ffi::OsStr| {
            ext.is_none_or(|x| {
                let n = n.to_string_lossy().to_lowercase();
                n.strip_suffix(x).is_some_and(|stem| stem.ends_with('.'))
            })
        };
        let mut names: Vec<_> = entries
            .filter_map(|e| e.ok().map(|e| e.file_name()))
            .filter(|n| wanted(n))
            .collect();
        names.sort();
        for name in names {
            let (path, rel) = (dir.join(&name), rel.join(&name));
            self.h.update(b"\0entry\0");
            self.h.update(rel.as_os_str().as_encoded_bytes());
            match fs::metadata(&path) {
                Ok(m) if m.is_dir() && depth > 0 => self.folder(&path, &rel, depth - 1, ext)?,
                Ok(m) if m.is_dir() => self.h.update(b"\0deep\0"),
                Ok(m) if m.is_file() => self.contents(&path, m.len())?,
                // A FIFO, device or dangling link: named, never opened.
                _ => self.h.update(b"\0special\0"),
            }
        }
        Some(())
    }

    /// A named file and the files beside it of the same stem (`lots.dbf` beside `lots.shp`).
    fn siblings(&mut self, file: &Path) -> Option<()> {
        self.h.update(b"\0named\0");
        self.h.update(file.as_os_str().as_encoded_bytes());
        let (Some(dir), Some(stem)) = (file.parent(), file.file_stem()) else {
            return Some(());
        };
        let Ok(entries) = fs::read_dir(dir) else {
            return Some(());
        };
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.file_stem() == Some(stem))
            .collect();
        paths.sort();
        for p in paths {
            if let Some(m) = fs::metadata(&p).ok().filter(|m| m.is_file()) {
                self.h.update(p.as_os_str().as_encoded_bytes());
                self.contents(&p, m.len())?;
            }
        }
        Some(())
    }

    /// A regular file's size and bytes, within the key's bounds.
    fn contents(&mut self, path: &Path, len: u64) -> Option<()> {
        self.files += 1;
        self.bytes = self.bytes.saturating_add(len);
        if self.files > MAX_FILES || self.bytes > MAX_BYTES {
            return None;
        }
        self.h.update(len.to_le_bytes());
        // A FIFO swapped in since it was listed is refused, not waited on.
        let Ok(file) = crate::bounded::file(path) else {
            self.h.update(b"\0unreadable\0");
            return Some(());
        };
        // Read no more than it was long when listed: a growing file ends the key, not the run.
        let mut r = file.take(len);
        let mut read = 0u64;
        loop {
            match r.read(&mut self.buf) {
                Ok(0) => break,
                Ok(n) => {
                    self.h.update(&self.buf[..n]);
                    read += n as u64;
                }
                Err(_) => return None,
            }
        }
        // Shorter than listed: the file changed while hashed; no cache this time.
        (read == len).then_some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::cache::tests::written_at;

    fn opts(input: &Path, out: &Path) -> BuildOptions {
        BuildOptions {
            input: input.to_path_buf(),
            out: out.to_path_buf(),
            params: crate::params::Params::default(),
            templates: None,
            threads: 1,
            plan_image: false,
            selection: crate::build::Selection::All,
            force: false,
            cache: None,
            reuse: None,
        }
    }

    #[test]
    fn an_edit_of_the_same_size_and_time_changes_the_key() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in");
        fs::create_dir_all(input.join("out")).unwrap();
        let dbf = input.join("lots.dbf");
        fs::write(&dbf, "abc").unwrap();
        written_at(&dbf, 1);
        let o = opts(&input, &input.join("out"));
        let before = key(&o).unwrap();
        assert_eq!(key(&o), Some(before), "the same files, the same key");
        fs::write(input.join("out/tile.glb"), "new").unwrap();
        assert_eq!(
            key(&o),
            Some(before),
            "an --out inside the input is not hashed"
        );
        fs::write(&dbf, "abd").unwrap();
        written_at(&dbf, 1);
        assert_ne!(key(&o), Some(before), "same size and time, other bytes");
    }

    #[test]
    fn directories_the_build_resolves_against_the_current_directory_are_hashed_there() {
        let dir = tempfile::tempdir().unwrap();
        let (input, models, templates) = (
            dir.path().join("in"),
            dir.path().join("models"),
            dir.path().join("tpl"),
        );
        for d in [&input, &models, &templates] {
            fs::create_dir_all(d).unwrap();
        }
        fs::write(models.join("hall.obj"), "v 0 0 0").unwrap();
        fs::write(templates.join("x.toml"), "a").unwrap();
        let mut o = opts(&input, &dir.path().join("out"));
        o.params.landmarks.models_dir = models.display().to_string();
        o.params.machiya.templates = templates.display().to_string();
        let before = key(&o).unwrap();
        fs::write(models.join("hall.obj"), "v 0 0 1").unwrap();
        let after_model = key(&o).unwrap();
        assert_ne!(after_model, before, "a model of models_dir changed");
        fs::write(templates.join("x.toml"), "b").unwrap();
        assert_ne!(key(&o).unwrap(), after_model, "a template changed");
    }

    #[test]
    fn a_file_the_parameters_name_outside_the_input_is_in_the_key() {
        let dir = tempfile::tempdir().unwrap();
        let (input, elsewhere) = (dir.path().join("in"), dir.path().join("elsewhere"));
        fs::create_dir_all(&input).unwrap();
        fs::create_dir_all(&elsewhere).unwrap();
        fs::write(input.join("lots.shp"), "x").unwrap();
        fs::write(elsewhere.join("dem.asc"), "1").unwrap();
        fs::write(elsewhere.join("dem.prj"), "p").unwrap();
        let mut o = opts(&input, &dir.path().join("out"));
        o.params.layers.lots.file = "../elsewhere/dem.asc".into();
        let before = key(&o).unwrap();
        fs::write(elsewhere.join("dem.prj"), "q").unwrap();
        assert_ne!(
            key(&o).unwrap(),
            before,
            "a sidecar of the named file changed"
        );
    }

    #[test]
    fn link_loops_pipes_and_the_root_as_texture_set_end_quickly() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in");
        fs::create_dir_all(&input).unwrap();
        std::os::unix::fs::symlink(&input, input.join("self")).unwrap();
        std::os::unix::fs::symlink(dir.path(), input.join("up")).unwrap();
        let fifo = input.join("lots.dbf");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let mut o = opts(&input, &dir.path().join("out"));
        o.params.textures = "/".into();
        assert!(key(&o).is_some(), "a pipe is named, not opened; loops end");
    }

    #[test]
    fn past_the_bounds_there_is_no_key() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("in");
        fs::create_dir_all(&input).unwrap();
        // A sparse file larger than the bound: nothing is read past the bound's check.
        let f = fs::File::create(input.join("huge.bin")).unwrap();
        f.set_len(MAX_BYTES + 1).unwrap();
        assert!(key(&opts(&input, &dir.path().join("out"))).is_none());
    }
}
