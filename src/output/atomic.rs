//! Writing files so that a reader never sees half of one: write a temporary file beside the
//! target, then rename it over the target (atomic on POSIX file systems).

use std::fs;
use std::io::Write;
use std::path::Path;

/// Fault injection: with `EDO_CITY_SIMULATE_DISK_BYTES=N` in the environment, the disk is
/// full after `N` bytes written through [`write_atomic`] by this process, and a write fails
/// the way a full disk fails it (`ENOSPC`) after writing what still fitted. Tests use it to
/// show a full disk loses nothing; without the variable it does nothing. (The one piece of
/// process-wide state, because a disk is one for all threads.)
fn disk_room(want: usize) -> Option<usize> {
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::sync::OnceLock;
    static ROOM: OnceLock<Option<AtomicU64>> = OnceLock::new();
    let room = ROOM.get_or_init(|| {
        std::env::var("EDO_CITY_SIMULATE_DISK_BYTES")
            .ok()
            .and_then(|v| v.trim().parse::<u64>().ok())
            .map(AtomicU64::new)
    });
    let room = room.as_ref()?;
    let mut left = room.load(Ordering::SeqCst);
    loop {
        let take = left.min(want as u64);
        match room.compare_exchange(left, left - take, Ordering::SeqCst, Ordering::SeqCst) {
            Ok(_) => return Some(take as usize),
            Err(now) => left = now,
        }
    }
}

/// Writes `bytes` to `path` through a temporary file in the same directory.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_pieces(path, 1, |_| bytes, Old::Freed)
}

/// What becomes of the file a write replaces.
#[derive(Clone, Copy)]
enum Old {
    /// Freed by the rename, on the writer's thread.
    Freed,
    /// Kept under a second name for a [`Retired`] sweep to free (see [`rename_retiring`]).
    Retired,
}

/// Writes `count` pieces, `piece(i)` asked for in order, through a temporary file.
fn write_pieces<'a>(
    path: &Path,
    count: usize,
    mut piece: impl FnMut(usize) -> &'a [u8],
    old: Old,
) -> std::io::Result<()> {
    let tmp = temporary_for(path);
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        for i in 0..count {
            let bytes = piece(i);
            match disk_room(bytes.len()) {
                Some(fits) if fits < bytes.len() => {
                    f.write_all(&bytes[..fits])?;
                    return Err(std::io::Error::from_raw_os_error(28)); // ENOSPC
                }
                _ => f.write_all(bytes)?,
            }
        }
        f.flush()?;
        drop(f);
        match old {
            Old::Freed => fs::rename(&tmp, path),
            Old::Retired => rename_retiring(&tmp, path),
        }
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Writes the file made of `parts`, one after the other, like [`write_atomic`] (a GLB's head
/// and its BIN chunk are never copied into one buffer), and returns its sha256 in lower-case
/// hex, taken a piece at a time just before the piece is written: the bytes are hashed while
/// the write still finds them in the cache (a tile is read from memory once, not twice).
/// A build's files are written this way: the file it replaces is retired
/// ([`rename_retiring`]), so the caller holds a [`Retired`] for the directory.
pub fn write_atomic_hashed(path: &Path, parts: &[&[u8]]) -> std::io::Result<String> {
    use sha2::{Digest, Sha256};
    /// Bytes hashed and written at a time: well inside a core's L2 cache.
    const PIECE: usize = 256 * 1024;
    let pieces: Vec<&[u8]> = parts.iter().flat_map(|p| p.chunks(PIECE)).collect();
    let mut h = Sha256::new();
    write_pieces(
        path,
        pieces.len(),
        |i| {
            h.update(pieces[i]);
            pieces[i]
        },
        Old::Retired,
    )?;
    Ok(super::hex(&h.finalize()))
}

/// Renames `tmp` over `target`, first giving `target`, when it is a file, a second name (a
/// hard link, [`retired_name`]), so that the rename does not free its blocks. On a file
/// system mounted with `discard` (ext4 on most cloud disks, this project's machines among
/// them) freeing a file waits for the disk to trim its blocks: renames over the tiles of an
/// earlier build made the workbench's city-wide rebuild 1.5 s (a fifth) slower than a build
/// into an empty directory (measured, 2026-12-07). A [`Retired`] frees the second names on a
/// thread of its own. Where hard links fail (a file system without them, a second name
/// still there from an earlier write of the same file), the rename frees the old file as a
/// plain one does.
pub fn rename_retiring(tmp: &Path, target: &Path) -> std::io::Result<()> {
    let _ = fs::hard_link(target, retired_name(target));
    fs::rename(tmp, target)
}

/// The second name [`rename_retiring`] gives a file it replaces: hidden, beside it, this
/// process's, and of the shape [`remove_leftover_temporaries`] sweeps when a killed run left
/// it (`.<file>.tmp-<pid>-<n>-0`).
fn retired_name(path: &Path) -> std::path::PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}{}", retired_suffix()))
}

/// What ends the name of every file this process retired.
fn retired_suffix() -> String {
    format!(".tmp-{}-0", run_token())
}

/// The files a build replaced in its directory, freed beside its work and for good when it
/// is dropped: a build (and a merge) holds one from its first write of a file through
/// [`write_atomic_hashed`] to its end, on every path out (a failed build leaves no second
/// name behind either).
pub struct Retired {
    dir: std::path::PathBuf,
    sweeps: std::sync::Mutex<Vec<std::thread::JoinHandle<()>>>,
}

impl Retired {
    /// For the build writing into `dir`.
    pub fn new(dir: &Path) -> Retired {
        Retired {
            dir: dir.to_path_buf(),
            sweeps: std::sync::Mutex::new(Vec::new()),
        }
    }

    /// Frees what was retired so far on a thread of its own, while the caller goes on (a
    /// build after its tiles, beside the levels of detail).
    pub fn sweep_beside(&self) {
        let dir = self.dir.clone();
        let sweep = std::thread::spawn(move || sweep_retired(&dir));
        self.sweeps
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(sweep);
    }
}

impl Drop for Retired {
    fn drop(&mut self) {
        let sweeps = std::mem::take(self.sweeps.get_mut().unwrap_or_else(|e| e.into_inner()));
        for sweep in sweeps {
            let _ = sweep.join();
        }
        sweep_retired(&self.dir);
    }
}

/// How many folders deep under a build's directory its files lie (`tiles/lod/x.glb`).
const DEPTH: usize = 3;

/// Removes the second names this process gave the files it replaced under `dir` (and its
/// folders, [`DEPTH`] deep; links are not followed). Nothing else is touched: another
/// process's names differ, and so do this process's temporaries still being written.
fn sweep_retired(dir: &Path) {
    let suffix = retired_suffix();
    let mut folders = vec![(dir.to_path_buf(), 0)];
    while let Some((folder, depth)) = folders.pop() {
        let Ok(entries) = fs::read_dir(&folder) else {
            continue;
        };
        for e in entries.flatten() {
            let Ok(kind) = e.file_type() else { continue };
            let name = e.file_name();
            let name = name.to_string_lossy();
            if kind.is_dir() && depth + 1 < DEPTH {
                folders.push((e.path(), depth + 1));
            } else if kind.is_file() && name.starts_with('.') && name.ends_with(&suffix) {
                let _ = fs::remove_file(e.path());
            }
        }
    }
}

/// The temporary name `path` is written under before its rename: beside it, hidden, and
/// swept by [`remove_leftover_temporaries`] when a killed run leaves it.
pub fn temporary_for(path: &Path) -> std::path::PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}", run_token()))
}

/// This process's part of a temporary name: its pid and a random number drawn once, so the
/// shards of a cluster writing the same texture into a shared directory never share a
/// temporary, even on two nodes where their pids are equal. (Names only: nothing written
/// depends on it.)
fn run_token() -> &'static str {
    use std::hash::{BuildHasher, Hasher};
    use std::sync::OnceLock;
    static TOKEN: OnceLock<String> = OnceLock::new();
    TOKEN.get_or_init(|| {
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u32(std::process::id());
        format!("{}-{}", std::process::id(), h.finish() % 1_000_000_000)
    })
}

/// Removes temporary files a killed run left in `dir` (names `.<file>.tmp-<pid>[-<n>]`, as
/// [`write_atomic`] makes them). Other files are never touched. Only a run that holds its
/// directory alone may call it: a shard would take the temporaries of the shards beside it.
pub fn remove_leftover_temporaries(dir: &Path) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let ours = name.starts_with('.')
            && name.rsplit_once(".tmp-").is_some_and(|(_, pid)| {
                !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit() || b == b'-')
            });
        if ours {
            let _ = fs::remove_file(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.obj");
        write_atomic(&p, b"old").unwrap();
        write_atomic(&p, b"new").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn leftovers_of_a_killed_run_are_swept_and_nothing_else() {
        let dir = tempfile::tempdir().unwrap();
        fs::write(dir.path().join(".a.obj.tmp-123"), b"half").unwrap();
        fs::write(dir.path().join(".b.obj.tmp-123-456789"), b"half").unwrap();
        fs::write(dir.path().join(".c.obj.tmp-123-456789-0"), b"retired").unwrap();
        fs::write(dir.path().join("a.obj"), b"whole").unwrap();
        fs::write(dir.path().join(".notes.tmp-x"), b"user's").unwrap();
        remove_leftover_temporaries(dir.path());
        let mut left: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, [".notes.tmp-x", "a.obj"]);
    }

    /// Hashed a piece at a time while written, a file of several pieces (and parts that end
    /// mid-piece) has the bytes and the sha256 of the whole.
    #[test]
    fn a_file_hashed_while_written_is_hashed_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.glb");
        let head: Vec<u8> = (0..1000u32).map(|i| (i % 251) as u8).collect();
        let bin: Vec<u8> = (0..700_000u32).map(|i| (i % 253) as u8).collect();
        let sha = write_atomic_hashed(&p, &[&head, &bin]).unwrap();
        let whole = [head.as_slice(), bin.as_slice()].concat();
        assert_eq!(fs::read(&p).unwrap(), whole);
        assert_eq!(sha, crate::output::sha256_hex(&whole));
        let empty = dir.path().join("empty");
        assert_eq!(
            write_atomic_hashed(&empty, &[&[]]).unwrap(),
            crate::output::sha256_hex(&[])
        );
        assert_eq!(fs::read(&empty).unwrap(), b"");
    }

    /// A build's write keeps the file it replaces under a second name until its `Retired`
    /// frees it: a reader of the target sees the old file or the new one, and the build
    /// leaves nothing behind, swept beside its work or when dropped.
    #[test]
    fn a_replaced_file_is_retired_and_freed_by_the_sweep() {
        let dir = tempfile::tempdir().unwrap();
        let tiles = dir.path().join("tiles").join("lod");
        fs::create_dir_all(&tiles).unwrap();
        let (a, b) = (dir.path().join("a.glb"), tiles.join("b.glb"));
        let retired = Retired::new(dir.path());
        write_atomic_hashed(&a, &[b"old"]).unwrap();
        write_atomic_hashed(&b, &[b"old b"]).unwrap();
        assert!(!retired_name(&a).exists(), "nothing was replaced yet");
        write_atomic_hashed(&a, &[b"new"]).unwrap();
        write_atomic_hashed(&b, &[b"new b"]).unwrap();
        assert_eq!(fs::read(&a).unwrap(), b"new");
        assert_eq!(fs::read(retired_name(&a)).unwrap(), b"old");
        assert_eq!(fs::read(retired_name(&b)).unwrap(), b"old b");
        retired.sweep_beside();
        // A third write while the sweep may be running: retired or freed, never lost.
        write_atomic_hashed(&a, &[b"newer"]).unwrap();
        drop(retired);
        assert_eq!(fs::read(&a).unwrap(), b"newer");
        assert_eq!(fs::read(&b).unwrap(), b"new b");
        assert!(!retired_name(&a).exists() && !retired_name(&b).exists());
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            2,
            "a.glb and tiles/"
        );
        assert_eq!(fs::read_dir(&tiles).unwrap().count(), 1);
        // A plain write frees what it replaces itself: no second name.
        write_atomic(&a, b"plain").unwrap();
        assert!(!retired_name(&a).exists());
    }

    /// The sweep frees this process's second names only: not another process's (a shard
    /// beside it), not a temporary being written, not a user's file, not through a link.
    #[test]
    fn the_sweep_frees_this_process_names_only() {
        let dir = tempfile::tempdir().unwrap();
        let ours = |f: &str| format!(".{f}{}", retired_suffix());
        let outside = tempfile::tempdir().unwrap();
        fs::write(outside.path().join(ours("x.glb")), b"elsewhere").unwrap();
        std::os::unix::fs::symlink(outside.path(), dir.path().join("linked")).unwrap();
        fs::write(dir.path().join(ours("a.glb")), b"retired").unwrap();
        fs::write(dir.path().join(".a.glb.tmp-1-2-0"), b"another run's").unwrap();
        fs::write(temporary_for(&dir.path().join("b.glb")), b"being written").unwrap();
        fs::write(dir.path().join(".notes"), b"user's").unwrap();
        let deep = dir.path().join("a").join("b").join("c");
        fs::create_dir_all(&deep).unwrap();
        fs::write(deep.join(ours("d.glb")), b"deeper than a build writes").unwrap();
        drop(Retired::new(dir.path()));
        let mut left: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        let writing = temporary_for(&dir.path().join("b.glb"));
        let writing = writing.file_name().unwrap().to_string_lossy();
        let mut want = vec![".a.glb.tmp-1-2-0", ".notes", "a", "linked", &writing];
        want.sort();
        assert_eq!(left, want);
        assert!(
            outside.path().join(ours("x.glb")).exists(),
            "links not followed"
        );
        assert!(deep.join(ours("d.glb")).exists());
    }

    #[test]
    fn a_failed_write_reports_the_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing-subdir").join("a.obj");
        assert!(write_atomic(&p, b"x").is_err());
    }
}
