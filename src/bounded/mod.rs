//! Reading a file that a user named, within bounds.
//!
//! A build reads files that the user's data and parameters name: landmark models and what
//! they name, template and species files, a species' hull, texture sets. A name can point at
//! a FIFO (the read blocks for ever), a device (`/dev/zero` is read until memory runs out) or
//! a file far larger than any real one. [`read`] opens only a regular file, checks its size
//! against a cap before it opens it, and reads at most one byte past the cap, so a file that
//! grows while it is read is refused too. Callers say what the file is and what to do.
//! [`open`] is the one door every reader of a user's or another build's file goes through:
//! it looks at the kind before opening, opens without blocking (a FIFO swapped in after the
//! look would otherwise hold the open until a writer comes), and looks again at what it
//! opened, so only a regular file is ever read.
//! [`Confined`] adds where: a file a user's file names is read only inside the directories
//! given for it, after its links are resolved.

use std::fs::{File, Metadata};
use std::io::Read;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;

use thiserror::Error;

mod confine;
pub use confine::Confined;

/// Why a file was not read.
#[derive(Debug, Error)]
pub enum Refusal {
    /// A directory, a device, a FIFO or a socket.
    #[error("is not a regular file (a directory, device or pipe)")]
    NotRegular,
    /// Larger than the cap before it was opened.
    #[error("is {bytes} bytes, more than the {cap} it may have")]
    TooLarge {
        /// Its size.
        bytes: u64,
        /// The most it may have.
        cap: u64,
    },
    /// Past the cap while it was read.
    #[error("grew past {cap} bytes while read")]
    Grew {
        /// The most it may have.
        cap: u64,
    },
    /// It could not be opened or read, or (as text) is not UTF-8.
    #[error("cannot be read ({0})")]
    Io(#[from] std::io::Error),
}

/// The regular file `path`, open for reading, with its metadata as opened. A directory,
/// device, FIFO or socket is refused before it is opened, and again after (it may have been
/// swapped in between): the open never blocks, and nothing but a regular file is read.
pub fn open(path: &Path) -> Result<(File, Metadata), Refusal> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(Refusal::NotRegular);
    }
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(Refusal::NotRegular);
    }
    Ok((file, meta))
}

/// [`open`] as `File::open` is used: the file alone, a refusal as an I/O error that says
/// what the file is not ("is not a regular file ...").
pub fn file(path: &Path) -> std::io::Result<File> {
    match open(path) {
        Ok((file, _)) => Ok(file),
        Err(Refusal::Io(e)) => Err(e),
        Err(e) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            e.to_string(),
        )),
    }
}

/// The bytes of the regular file `path`, of at most `cap` bytes.
pub fn read(path: &Path, cap: u64) -> Result<Vec<u8>, Refusal> {
    let (file, meta) = open(path)?;
    if meta.len() > cap {
        return Err(Refusal::TooLarge {
            bytes: meta.len(),
            cap,
        });
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(cap.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > cap {
        return Err(Refusal::Grew { cap });
    }
    Ok(bytes)
}

/// The text of the regular file `path`, of at most `cap` bytes of UTF-8.
pub fn read_text(path: &Path, cap: u64) -> Result<String, Refusal> {
    String::from_utf8(read(path, cap)?)
        .map_err(|e| Refusal::Io(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_the_cap_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.txt");
        std::fs::write(&f, "12345").unwrap();
        assert_eq!(read(&f, 5).unwrap(), b"12345");
        assert_eq!(read_text(&f, 9).unwrap(), "12345");
        let e = read(&f, 4).unwrap_err();
        assert_eq!(e.to_string(), "is 5 bytes, more than the 4 it may have");
        assert!(matches!(
            read(dir.path(), 1 << 20),
            Err(Refusal::NotRegular)
        ));
        assert!(matches!(
            read(Path::new("/dev/zero"), 1 << 20),
            Err(Refusal::NotRegular)
        ));
        let fifo = dir.path().join("p.png");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        assert!(matches!(read(&fifo, 1 << 20), Err(Refusal::NotRegular)));
        assert!(matches!(
            read(&dir.path().join("none"), 1),
            Err(Refusal::Io(_))
        ));
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        assert!(read_text(&f, 9)
            .unwrap_err()
            .to_string()
            .contains("cannot be read"));
    }
}
