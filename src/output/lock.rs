//! One run at a time in an output directory, or the shards of one city together.
//!
//! Two builds started together into the same `--out` would both pass the "holds another
//! build" guard (neither has written a manifest yet) and leave tiles of both behind one
//! manifest. Every command that writes into an output directory (`build`, `merge`) first takes
//! an exclusive lock on `<out>/.edo-city.lock` and holds it until it returns; a second run
//! refuses at once, naming the holder's process. Shards (`build --shard I/N`) write disjoint
//! tiles and their own manifests, so they run together on a cluster's shared directory: each
//! takes the lock shared, which keeps out a full build and `merge` while any shard runs.
//! The lock is the operating system's (`flock` on Linux, through std's `File::lock`): it ends
//! with the process, so a run killed by SIGKILL never blocks the next one. The holder removes
//! the file before it lets go; a run that locked a file which was removed meanwhile opens it
//! again, so two runs never hold two different files of the same name.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The name of the lock file inside an output directory.
pub const LOCK_FILE: &str = ".edo-city.lock";

/// A lock on an output directory (exclusive, or shared by shards), released when dropped.
#[derive(Debug)]
pub struct OutLock {
    file: File,
    path: PathBuf,
    shared: bool,
}

/// Why the lock could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another run holds the directory.
    #[error(
        "{dir} is in use by another edo-city run{holder}: wait for it to finish, or build \
         into another --out"
    )]
    Busy {
        /// The output directory.
        dir: String,
        /// " (process N)" when the holder wrote its pid, else empty.
        holder: String,
    },
    /// The lock file cannot be made or locked (permissions, a read-only disk).
    #[error("cannot lock {path}: {cause}")]
    Io {
        /// The lock file.
        path: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
}

impl OutLock {
    /// Locks `dir` (which must exist) for this process alone, or says who holds it.
    pub fn acquire(dir: &Path) -> Result<OutLock, LockError> {
        OutLock::take(dir, false)
    }

    /// Locks `dir` for this shard and any other shards, or says which run holds it alone.
    pub fn acquire_shared(dir: &Path) -> Result<OutLock, LockError> {
        OutLock::take(dir, true)
    }

    fn take(dir: &Path, shared: bool) -> Result<OutLock, LockError> {
        let path = dir.join(LOCK_FILE);
        let io = |cause| LockError::Io {
            path: path.display().to_string(),
            cause,
        };
        let mut file = loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            let locked = match shared {
                true => file.try_lock_shared(),
                false => file.try_lock(),
            };
            match locked {
                Ok(()) if same_file(&file, &path) => break file,
                // The holder removed it between our open and our lock: open the new one.
                Ok(()) => continue,
                Err(TryLockError::WouldBlock) => {
                    let mut pid = String::new();
                    let _ = file.read_to_string(&mut pid);
                    let pid = pid.trim();
                    return Err(LockError::Busy {
                        dir: dir.display().to_string(),
                        holder: match pid.is_empty() {
                            true => String::new(),
                            false => format!(" (process {pid})"),
                        },
                    });
                }
                Err(TryLockError::Error(e)) => return Err(io(e)),
            }
        };
        // The holder's pid, for the message another run prints (shards leave it empty: they
        // are many).
        if !shared {
            file.set_len(0).map_err(io)?;
            file.seek(SeekFrom::Start(0)).map_err(io)?;
            write!(file, "{}", std::process::id()).map_err(io)?;
        }
        Ok(OutLock { file, path, shared })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Whether `path` still names the file `file` has open.
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &File, path: &Path) -> bool {
    path.exists()
}

impl Drop for OutLock {
    fn drop(&mut self) {
        // Removed while still held alone (see the module's doc), so the directory holds only
        // the build; the OS lock goes with the file handle. A shard removes it only when it
        // is the last (its shared lock turns exclusive); else the file stays for the last
        // shard or `merge` to remove.
        let alone = !self.shared || self.file.try_lock().is_ok();
        if alone {
            let _ = std::fs::remove_file(&self.path);
        }
        let _ = self.file.unlock();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_on_the_same_directory_is_refused_until_the_first_is_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let first = OutLock::acquire(dir.path()).unwrap();
        let err = OutLock::acquire(dir.path()).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("in use by another edo-city run"), "{msg}");
        assert!(msg.contains(&std::process::id().to_string()), "{msg}");
        drop(first);
        assert!(
            !dir.path().join(LOCK_FILE).exists(),
            "the holder removes the file"
        );
        let again = OutLock::acquire(dir.path()).unwrap();
        assert!(again.path().ends_with(LOCK_FILE));
    }

    #[test]
    fn shards_share_the_directory_and_keep_out_a_whole_build_until_the_last_is_done() {
        let dir = tempfile::tempdir().unwrap();
        let a = OutLock::acquire_shared(dir.path()).unwrap();
        let b = OutLock::acquire_shared(dir.path()).unwrap();
        let err = OutLock::acquire(dir.path()).unwrap_err();
        assert!(err.to_string().contains("in use by another edo-city run"));
        drop(a);
        assert!(dir.path().join(LOCK_FILE).exists(), "b still holds it");
        assert!(OutLock::acquire(dir.path()).is_err());
        drop(b);
        assert!(
            !dir.path().join(LOCK_FILE).exists(),
            "the last shard removes it"
        );
        let whole = OutLock::acquire(dir.path()).unwrap();
        assert!(OutLock::acquire_shared(dir.path()).is_err());
        drop(whole);
    }
}
