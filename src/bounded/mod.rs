//! Reading a file that a user named, within bounds.
//!
//! A build reads files that the user's data and parameters name: landmark models and what
//! they name, template and species files, a species' hull, texture sets. A name can point at
//! a FIFO (the read blocks for ever), a device (`/dev/zero` is read until memory runs out) or
//! a file far larger than any real one. [`read`] opens only a regular file, checks its size
//! against a cap before it opens it, and reads at most one byte past the cap, so a file that
//! grows while it is read is refused too. Callers say what the file is and what to do.
//! [`Confined`] adds where: a file a user's file names is read only inside the directories
//! given for it, after its links are resolved.

use std::io::Read;
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

/// The bytes of the regular file `path`, of at most `cap` bytes.
pub fn read(path: &Path, cap: u64) -> Result<Vec<u8>, Refusal> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(Refusal::NotRegular);
    }
    if meta.len() > cap {
        return Err(Refusal::TooLarge {
            bytes: meta.len(),
            cap,
        });
    }
    let file = std::fs::File::open(path)?;
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
