//! Where a command may write a file the user names (`check --gpkg`, `compare --gpkg` and
//! `--plan`, `plan -o`). Such a path is typed by hand, and a slip costs data:
//! `check IN --gpkg IN/lots.shp` replaced the input layer and `compare A B --gpkg
//! A/manifest.json` replaced a build's manifest (issue 57). So a target is refused when it
//! lies inside a directory the command reads (the input, a build: their files are theirs,
//! and a file added there becomes part of the next build or comparison), and when it exists
//! and is not a file of the kind written (a GeoPackage over a GeoPackage, a PNG over a PNG;
//! an empty file holds nothing to lose). Nothing is written until it passes.

use std::io::Read;
use std::path::{Path, PathBuf};

/// What kind of file a command writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A GeoPackage (SQLite with the `GPKG` application id).
    GeoPackage,
    /// A PNG image.
    Png,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::GeoPackage => "GeoPackage",
            Kind::Png => "PNG image",
        }
    }

    /// Whether `head` (a file's first 100 bytes or fewer) begins a file of this kind.
    fn begins(self, head: &[u8]) -> bool {
        match self {
            Kind::GeoPackage => {
                // SQLite's header, and the application id at byte 68: "GPKG" (1.2+) or
                // "GP10"/"GP11" (1.0, 1.1).
                head.starts_with(b"SQLite format 3\0")
                    && head.len() >= 72
                    && matches!(&head[68..72], b"GPKG" | b"GP10" | b"GP11")
            }
            Kind::Png => head.starts_with(b"\x89PNG\r\n\x1a\n"),
        }
    }
}

/// Why a target was refused.
#[derive(Debug, thiserror::Error)]
pub enum Refused {
    /// Inside a directory the command reads.
    #[error(
        "{path} lies inside {what} ({dir}), which this command reads: write it elsewhere, \
         e.g. beside that directory"
    )]
    Inside {
        /// The target as given.
        path: PathBuf,
        /// What the directory is ("the input directory", "build A").
        what: String,
        /// The directory as given.
        dir: PathBuf,
    },
    /// An existing file of another kind (or a directory, link or device).
    #[error("{path} exists and is not a {kind}: it was left as it is; name a new file")]
    Other {
        /// The target as given.
        path: PathBuf,
        /// The kind that would be written.
        kind: &'static str,
    },
}

/// Checks that a file of `kind` may be written at `path`: outside every directory of
/// `reads` (each with what it is, for the message), and over nothing but a file of the same
/// kind.
pub fn check(path: &Path, kind: Kind, reads: &[(&Path, &str)]) -> Result<(), Refused> {
    let resolved = resolve(path);
    for (dir, what) in reads {
        let Ok(dir_real) = dir.canonicalize() else {
            continue;
        };
        if resolved.starts_with(&dir_real) {
            return Err(Refused::Inside {
                path: path.to_path_buf(),
                what: what.to_string(),
                dir: dir.to_path_buf(),
            });
        }
    }
    let other = || Refused::Other {
        path: path.to_path_buf(),
        kind: kind.name(),
    };
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return Ok(());
    };
    if !meta.is_file() {
        return Err(other());
    }
    if meta.len() == 0 {
        return Ok(());
    }
    let mut head = Vec::with_capacity(100);
    let (file, _) = crate::bounded::open(path).map_err(|_| other())?;
    file.take(100).read_to_end(&mut head).map_err(|_| other())?;
    match kind.begins(&head) {
        true => Ok(()),
        false => Err(other()),
    }
}

/// `path` with its folder's links resolved (the file itself may not exist yet).
fn resolve(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    match (abs.parent(), abs.file_name()) {
        (Some(parent), Some(name)) => parent
            .canonicalize()
            .map(|p| p.join(name))
            .unwrap_or(abs.clone()),
        _ => abs,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_builds_and_other_kinds_of_file_are_never_written_over() {
        let top = tempfile::tempdir().unwrap();
        let input = top.path().join("in");
        std::fs::create_dir(&input).unwrap();
        std::fs::write(input.join("lots.shp"), b"shapes").unwrap();
        let reads = [(input.as_path(), "the input directory")];
        let e = check(&input.join("lots.shp"), Kind::GeoPackage, &reads).unwrap_err();
        assert!(e.to_string().contains("inside the input directory"), "{e}");
        // A new file there too, and through a link to it.
        assert!(check(&input.join("new.gpkg"), Kind::GeoPackage, &reads).is_err());
        std::os::unix::fs::symlink(&input, top.path().join("link")).unwrap();
        let via = top.path().join("link/new.gpkg");
        assert!(check(&via, Kind::GeoPackage, &reads).is_err());

        let text = top.path().join("notes.txt");
        std::fs::write(&text, b"a historian's notes").unwrap();
        let e = check(&text, Kind::GeoPackage, &reads).unwrap_err();
        assert!(e.to_string().contains("is not a GeoPackage"), "{e}");
        assert!(check(&text, Kind::Png, &[]).is_err());
        assert!(check(top.path(), Kind::Png, &[]).is_err(), "a directory");

        let mut gpkg = b"SQLite format 3\0".to_vec();
        gpkg.resize(100, 0);
        gpkg[68..72].copy_from_slice(b"GPKG");
        let old = top.path().join("old.gpkg");
        std::fs::write(&old, &gpkg).unwrap();
        assert!(check(&old, Kind::GeoPackage, &reads).is_ok());
        gpkg[68..72].copy_from_slice(b"\0\0\0\0");
        std::fs::write(&old, &gpkg).unwrap();
        assert!(
            check(&old, Kind::GeoPackage, &reads).is_err(),
            "plain SQLite"
        );
        let png = top.path().join("a.png");
        std::fs::write(&png, b"\x89PNG\r\n\x1a\nrest").unwrap();
        assert!(check(&png, Kind::Png, &reads).is_ok());
        std::fs::write(top.path().join("empty"), b"").unwrap();
        assert!(check(&top.path().join("empty"), Kind::Png, &reads).is_ok());
        assert!(check(&top.path().join("new.gpkg"), Kind::GeoPackage, &reads).is_ok());
    }
}
