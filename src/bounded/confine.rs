//! Reading a file that a user's data names (a landmark's model, its MTL, a texture, a glTF
//! buffer, a species' hull) only inside the directories the user gave for it.
//!
//! A model file comes from anywhere (a download, a colleague's export) and names further
//! files by paths of its own: `map_Kd /home/me/.ssh/id.png`, a buffer `../../x` or
//! `file:///dev/zero`. Whatever such a file names ends up in the published tiles, so a build
//! reads it only when it lies inside an allowed directory (for a landmark the input directory
//! or the `landmarks.models_dir` the parameter file names; for a hull its species file's
//! folder) after every link is resolved, is a
//! regular file (no device, FIFO or directory), and is no larger than a cap checked before
//! reading. A refusal names the path as written, never what lies outside: whether an
//! outside file exists is not told.

use std::path::{Component, Path, PathBuf};

use super::Refusal;

/// Directories a build may read named files from.
#[derive(Debug, Clone, Default)]
pub struct Confined {
    /// Each allowed directory, absolute and without `.`/`..` (as written) ...
    lexical: Vec<PathBuf>,
    /// ... and with its links resolved (when it exists).
    canonical: Vec<PathBuf>,
    /// The directories in words, for a refusal ("the input directory, or ...").
    places: String,
}

impl Confined {
    /// Allows reading inside each of `roots`, which a refusal names as `places`.
    pub fn new<'a>(roots: impl IntoIterator<Item = &'a Path>, places: &str) -> Self {
        let mut c = Confined {
            places: places.to_string(),
            ..Confined::default()
        };
        for root in roots {
            c.lexical.push(normalise(root));
            if let Ok(r) = std::fs::canonicalize(root) {
                c.canonical.push(r);
            }
        }
        c
    }

    /// Reads `path` (shown as `shown` in messages), refusing anything outside the allowed
    /// directories, anything but a regular file, and anything over `cap` bytes.
    pub fn read(&self, path: &Path, shown: &str, cap: u64) -> Result<Vec<u8>, String> {
        let real = self.resolve(path, shown)?;
        super::read(&real, cap).map_err(|e| {
            let hint = match e {
                Refusal::NotRegular => ": name a file",
                Refusal::TooLarge { .. } => ": make it smaller",
                Refusal::Grew { .. } | Refusal::Io(_) => "",
            };
            format!("{shown} {e}{hint}")
        })
    }

    /// `path` with its links resolved, if it lies inside an allowed directory both as written
    /// and as resolved.
    pub fn resolve(&self, path: &Path, shown: &str) -> Result<PathBuf, String> {
        let outside = || {
            format!(
                "{shown} lies outside {}: copy the file there and name it by a relative path",
                self.places
            )
        };
        let lexical = normalise(path);
        if !self.lexical.iter().any(|r| lexical.starts_with(r)) {
            return Err(outside());
        }
        let real = std::fs::canonicalize(&lexical).map_err(|_| {
            format!("{shown} does not exist (paths are relative to the file that names them)")
        })?;
        if !self.canonical.iter().any(|r| real.starts_with(r)) {
            return Err(outside());
        }
        Ok(real)
    }
}

impl Confined {
    /// Whether `path` lies inside an allowed directory as written and with its links
    /// resolved, for a path that need not exist yet (a parameter a page sets): the nearest
    /// part of it that exists is resolved and the rest added. A part that exists but does
    /// not resolve (a link to nowhere, a loop) is outside.
    pub fn contains(&self, path: &Path) -> bool {
        let lexical = normalise(path);
        if !self.lexical.iter().any(|r| lexical.starts_with(r)) {
            return false;
        }
        let mut at = lexical.as_path();
        let mut rest = Vec::new();
        loop {
            match std::fs::canonicalize(at) {
                Ok(real) => {
                    let full = rest.iter().rev().fold(real, |p, c| p.join(c));
                    return self.canonical.iter().any(|r| full.starts_with(r));
                }
                Err(_) if std::fs::symlink_metadata(at).is_ok() => return false,
                Err(_) => match (at.parent(), at.file_name()) {
                    (Some(parent), Some(name)) => {
                        rest.push(name);
                        at = parent;
                    }
                    _ => return false,
                },
            }
        }
    }
}

/// `path` made absolute with `.` and `..` taken out as written (no file system access, so
/// nothing is learnt of paths outside).
fn normalise(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_yet_to_be_made_is_inside_as_written_and_as_resolved() {
        let top = tempfile::tempdir().unwrap();
        let inside = top.path().join("in");
        std::fs::create_dir(&inside).unwrap();
        let c = Confined::new([inside.as_path()], "the directory");
        assert!(c.contains(&inside.join("a.csv")));
        assert!(c.contains(&inside.join("new/deeper/a.csv")));
        assert!(!c.contains(&inside.join("../a.csv")));
        assert!(!c.contains(Path::new("/etc/passwd")));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(top.path(), inside.join("up")).unwrap();
            assert!(!c.contains(&inside.join("up/a.csv")));
            std::os::unix::fs::symlink("/nowhere/at/all", inside.join("dangling")).unwrap();
            assert!(!c.contains(&inside.join("dangling")));
            std::os::unix::fs::symlink(inside.join("loop"), inside.join("loop")).unwrap();
            assert!(!c.contains(&inside.join("loop/x")));
        }
    }

    #[test]
    fn reads_inside_and_refuses_outside_links_devices_and_large_files() {
        let top = tempfile::tempdir().unwrap();
        let inside = top.path().join("in");
        std::fs::create_dir(&inside).unwrap();
        std::fs::write(inside.join("a.png"), b"abc").unwrap();
        std::fs::write(top.path().join("secret.png"), b"secret").unwrap();
        let c = Confined::new([inside.as_path()], "the directory");
        assert_eq!(c.read(&inside.join("a.png"), "a.png", 10).unwrap(), b"abc");
        let up = c.read(&inside.join("../secret.png"), "../secret.png", 10);
        assert!(up.unwrap_err().contains("outside"));
        let abs = c.read(&top.path().join("secret.png"), "s", 10);
        assert!(abs.unwrap_err().contains("outside"));
        // A missing outside file gets the same answer as an existing one.
        let missing = c.read(&top.path().join("nothing.png"), "s", 10);
        assert!(missing.unwrap_err().contains("outside"));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(top.path().join("secret.png"), inside.join("l.png"))
                .unwrap();
            assert!(c
                .read(&inside.join("l.png"), "l", 10)
                .unwrap_err()
                .contains("outside"));
            std::os::unix::fs::symlink("/dev/zero", inside.join("z.png")).unwrap();
            assert!(c
                .read(&inside.join("z.png"), "z", 10)
                .unwrap_err()
                .contains("outside"));
            let dev = Confined::new([Path::new("/dev")], "/dev");
            let e = dev.read(Path::new("/dev/zero"), "zero", 10).unwrap_err();
            assert!(e.contains("not a regular file"), "{e}");
        }
        let e = c.read(&inside.join("a.png"), "a.png", 2).unwrap_err();
        assert!(e.contains("more than"), "{e}");
        assert!(c
            .read(&inside, "in", 10)
            .unwrap_err()
            .contains("not a regular file"));
    }
}
