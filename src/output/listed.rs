//! The files a manifest lists, as another run reads them: `merge` (the shards' tiles and
//! models), `--tiles` over a directory a killed run left, the levels of detail read back
//! from the leaves. A manifest is input like any other: a shard's manifest that lists
//! `../planted.sh` with its true length and sha256 made `merge` write beside the build
//! (issue 57). So every listed path is checked before it is joined to a directory, and the
//! file it names is found only inside that directory after links are resolved, only as a
//! regular file, its size compared before a byte is read and its bytes hashed as they stream
//! by, never held whole.

use std::io::{Read, Write};
use std::path::{Component, Path, PathBuf};

use sha2::{Digest, Sha256};

use super::report::ManifestFile;

/// The longest listed path taken.
const MAX_PATH: usize = 1024;
/// Names at the top of an output directory that only the run owning it writes: a listed
/// file never replaces them.
const RESERVED: [&str; 4] = [
    "manifest.json",
    "report.json",
    ".edo-city.lock",
    ".edo-city.writing",
];

/// Why a listed file was not taken.
#[derive(Debug, thiserror::Error)]
pub enum Unlisted {
    /// The path is not one a build writes (absolute, `..`, a hidden or reserved name).
    #[error("lists the path `{0}`, which no build writes (absolute, `..`, or a reserved name)")]
    Path(String),
    /// It lies outside the directory once links are resolved, or is not a regular file.
    #[error("lists `{0}`, which is a link out of its directory or not a regular file")]
    Outside(String),
    /// Missing or unreadable.
    #[error("lists `{path}`, which cannot be read ({cause})")]
    Io {
        /// The listed path.
        path: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
    /// Its size or content is not what the manifest says.
    #[error("lists `{path}` as {listed} bytes, but it holds {found} or another sha256: it was cut short or changed")]
    Differs {
        /// The listed path.
        path: String,
        /// The listed size.
        listed: u64,
        /// The size found (as much as was read).
        found: u64,
    },
}

/// `path` (as a manifest lists it) as a relative path of plain names, or why not.
pub fn relative(path: &str) -> Result<&Path, Unlisted> {
    let bad = || Unlisted::Path(excerpt(path));
    let p = Path::new(path);
    let plain = !path.is_empty()
        && path.len() <= MAX_PATH
        && !path.contains(['\\', '\0'])
        && p.components()
            .all(|c| matches!(c, Component::Normal(n) if !n.to_string_lossy().starts_with('.')));
    if !plain || RESERVED.contains(&path) || is_shard_file(path) {
        return Err(bad());
    }
    Ok(p)
}

/// A shard's own manifest or report: written by that shard alone.
fn is_shard_file(path: &str) -> bool {
    (path.starts_with("manifest.shard-") || path.starts_with("report.shard-"))
        && !path.contains('/')
}

/// The file `dir/path`, checked: a plain relative path, inside `dir` after every link is
/// resolved, a regular file.
pub fn locate(dir: &Path, path: &str) -> Result<PathBuf, Unlisted> {
    let rel = relative(path)?;
    let io = |cause| Unlisted::Io {
        path: excerpt(path),
        cause,
    };
    let root = dir.canonicalize().map_err(io)?;
    let real = dir.join(rel).canonicalize().map_err(io)?;
    let regular = std::fs::metadata(&real).is_ok_and(|m| m.is_file());
    if !real.starts_with(&root) || !regular {
        return Err(Unlisted::Outside(excerpt(path)));
    }
    Ok(real)
}

/// Whether `dir/f.path` is a file [`locate`] finds, of the size `f` lists: for a rebuild
/// into a locked directory that keeps files of the build before (its bytes are that build's
/// own), where hashing every kept file would cost what keeping it saves.
pub fn at_size(dir: &Path, f: &ManifestFile) -> bool {
    locate(dir, &f.path)
        .ok()
        .and_then(|real| std::fs::metadata(real).ok())
        .is_some_and(|m| m.len() == f.bytes)
}

/// Checks that `dir/f.path` is the file `f` lists: its size first (nothing is read when it
/// differs), then its sha256, read a piece at a time.
pub fn check(dir: &Path, f: &ManifestFile) -> Result<(), Unlisted> {
    let real = locate(dir, &f.path)?;
    stream(&real, f, &mut std::io::sink())
}

/// Copies `from/f.path` to `to/f.path` as [`check`] checks it, through a temporary file
/// beside the target that is renamed only when what was copied is what `f` lists (else it
/// is removed). The target's folders are made inside `to` (a link among them that leads out
/// is refused). Returns the temporary, to be renamed by [`commit`] once every file is in.
pub fn copy(from: &Path, to: &Path, f: &ManifestFile) -> Result<Staged, Unlisted> {
    let real = locate(from, &f.path)?;
    let target = inside(to, &f.path)?;
    let tmp = super::atomic::temporary_for(&target);
    let io = |cause| Unlisted::Io {
        path: excerpt(&f.path),
        cause,
    };
    let staged = Staged { tmp, target };
    let mut out = std::io::BufWriter::new(std::fs::File::create(&staged.tmp).map_err(io)?);
    stream(&real, f, &mut out)?;
    out.into_inner().map_err(|e| io(e.into_error()))?;
    Ok(staged)
}

/// A file copied under its temporary name, removed unless [`commit`]ted.
#[derive(Debug)]
pub struct Staged {
    tmp: PathBuf,
    target: PathBuf,
}

impl Staged {
    /// Renames the temporary over its target.
    pub fn commit(self) -> std::io::Result<()> {
        std::fs::rename(&self.tmp, &self.target)?;
        std::mem::forget(self);
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.tmp);
    }
}

/// `to/path` with its folders made, each inside `to` after links are resolved.
fn inside(to: &Path, path: &str) -> Result<PathBuf, Unlisted> {
    let rel = relative(path)?;
    let io = |cause| Unlisted::Io {
        path: excerpt(path),
        cause,
    };
    let root = to.canonicalize().map_err(io)?;
    let target = root.join(rel);
    let parent = target.parent().unwrap_or(&root);
    std::fs::create_dir_all(parent).map_err(io)?;
    if !parent.canonicalize().map_err(io)?.starts_with(&root) {
        return Err(Unlisted::Outside(excerpt(path)));
    }
    // A link (or directory) where the file goes would be followed by no one but is not ours.
    if std::fs::symlink_metadata(&target).is_ok_and(|m| !m.is_file()) {
        return Err(Unlisted::Outside(excerpt(path)));
    }
    Ok(target)
}

/// Streams the regular file `real` into `sink`, checking it against `f`: its size before
/// reading, its sha256 after (at most one byte past the listed size is read).
fn stream(real: &Path, f: &ManifestFile, sink: &mut impl Write) -> Result<(), Unlisted> {
    let io = |cause| Unlisted::Io {
        path: excerpt(&f.path),
        cause,
    };
    let differs = |found| Unlisted::Differs {
        path: excerpt(&f.path),
        listed: f.bytes,
        found,
    };
    let (file, meta) = crate::bounded::open(real).map_err(|e| match e {
        crate::bounded::Refusal::Io(e) => io(e),
        _ => Unlisted::Outside(excerpt(&f.path)),
    })?;
    if meta.len() != f.bytes {
        return Err(differs(meta.len()));
    }
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut r = file.take(f.bytes.saturating_add(1));
    let mut read = 0u64;
    loop {
        let n = r.read(&mut buf).map_err(io)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
        sink.write_all(&buf[..n]).map_err(io)?;
        read += n as u64;
    }
    if read != f.bytes || super::hex(&h.finalize()) != f.sha256 {
        return Err(differs(read));
    }
    Ok(())
}

/// At most 120 characters of a listed path, for a message.
fn excerpt(s: &str) -> String {
    match s.char_indices().nth(120) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listed(path: &str, bytes: &[u8]) -> ManifestFile {
        ManifestFile {
            path: path.into(),
            bytes: bytes.len() as u64,
            sha256: crate::output::sha256_hex(bytes),
        }
    }

    #[test]
    fn only_plain_paths_of_a_build_are_taken() {
        for ok in [
            "tiles/1_2.glb",
            "tiles/models/sakura_0.bin",
            "tileset.json",
            "crowds/1_2.csv",
        ] {
            assert!(relative(ok).is_ok(), "{ok}");
        }
        for bad in [
            "",
            "../planted.sh",
            "tiles/../../x",
            "/etc/passwd",
            "../.config/autostart/x.desktop",
            "tiles/.hidden",
            "./tiles/a.glb",
            "manifest.json",
            "report.json",
            "manifest.shard-1-of-2.json",
            ".edo-city.lock",
            "tiles\\..\\x",
        ] {
            assert!(matches!(relative(bad), Err(Unlisted::Path(_))), "{bad}");
        }
        assert!(relative(&"a/".repeat(600)).is_err(), "too long");
    }

    #[test]
    fn files_are_found_inside_checked_as_they_stream_and_copied_whole_or_not_at_all() {
        let top = tempfile::tempdir().unwrap();
        let (a, b) = (top.path().join("a"), top.path().join("b"));
        std::fs::create_dir_all(a.join("tiles")).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        std::fs::write(a.join("tiles/t.glb"), b"tile").unwrap();
        std::fs::write(top.path().join("secret"), b"secret").unwrap();
        let f = listed("tiles/t.glb", b"tile");
        check(&a, &f).unwrap();
        copy(&a, &b, &f).unwrap().commit().unwrap();
        assert_eq!(std::fs::read(b.join("tiles/t.glb")).unwrap(), b"tile");

        // Another size: refused before it is read; the same size, other bytes: after.
        let e = check(&a, &listed("tiles/t.glb", b"tiles")).unwrap_err();
        assert!(matches!(e, Unlisted::Differs { found: 4, .. }), "{e}");
        let e = copy(&a, &b, &listed("tiles/t.glb", b"TILE")).unwrap_err();
        assert!(matches!(e, Unlisted::Differs { .. }), "{e}");
        let left: Vec<_> = std::fs::read_dir(b.join("tiles")).unwrap().collect();
        assert_eq!(left.len(), 1, "no temporary left");

        // Links out, FIFOs and devices are not files of the build.
        std::os::unix::fs::symlink(top.path().join("secret"), a.join("tiles/l.glb")).unwrap();
        let e = check(&a, &listed("tiles/l.glb", b"secret")).unwrap_err();
        assert!(matches!(e, Unlisted::Outside(_)), "{e}");
        std::os::unix::fs::symlink("/dev/zero", a.join("tiles/z.glb")).unwrap();
        assert!(check(&a, &listed("tiles/z.glb", b"")).is_err());
        let fifo = a.join("tiles/p.glb");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let e = check(&a, &listed("tiles/p.glb", b"")).unwrap_err();
        assert!(matches!(e, Unlisted::Outside(_)), "{e}");

        // A folder of the target that is a link out is not written through.
        std::os::unix::fs::symlink(top.path(), b.join("crowds")).unwrap();
        std::fs::create_dir_all(a.join("crowds")).unwrap();
        std::fs::write(a.join("crowds/c.csv"), b"c").unwrap();
        let e = copy(&a, &b, &listed("crowds/c.csv", b"c")).unwrap_err();
        assert!(matches!(e, Unlisted::Outside(_)), "{e}");
        assert!(!top.path().join("c.csv").exists());
    }
}
