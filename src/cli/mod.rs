//! The binary's own modules (not part of the library): what `main.rs` prints and draws.

pub mod args;
pub mod commands;
pub mod garden;
pub mod plants;
pub mod progress;
pub mod serve;
pub mod summary;

/// `check` found features it would skip or warnings: not an error, exit code 1.
#[derive(Debug)]
pub struct Problems(pub usize);

impl std::fmt::Display for Problems {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} problem(s) found", self.0)
    }
}

impl std::error::Error for Problems {}
