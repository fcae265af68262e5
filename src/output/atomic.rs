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
    write_pieces(path, 1, |_| bytes)
}

/// Writes `count` pieces, `piece(i)` asked for in order, through a temporary file.
fn write_pieces<'a>(
    path: &Path,
    count: usize,
    mut piece: impl FnMut(usize) -> &'a [u8],
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
        fs::rename(&tmp, path)
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
pub fn write_atomic_hashed(path: &Path, parts: &[&[u8]]) -> std::io::Result<String> {
    use sha2::{Digest, Sha256};
    /// Bytes hashed and written at a time: well inside a core's L2 cache.
    const PIECE: usize = 256 * 1024;
    let pieces: Vec<&[u8]> = parts.iter().flat_map(|p| p.chunks(PIECE)).collect();
    let mut h = Sha256::new();
    write_pieces(path, pieces.len(), |i| {
        h.update(pieces[i]);
        pieces[i]
    })?;
    Ok(super::hex(&h.finalize()))
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

    #[test]
    fn a_failed_write_reports_the_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing-subdir").join("a.obj");
        assert!(write_atomic(&p, b"x").is_err());
    }
}
