//! The binary's own modules (not part of the library): what `main.rs` prints and draws.

pub mod progress;
pub mod summary;
