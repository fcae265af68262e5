//! A mark left in the output directory while a build writes it, so that `--tiles` never
//! stamps a manifest over files an unfinished run left.
//!
//! Every file is written whole (a temporary renamed into place) and `manifest.json` last, so
//! a run that stops half way (killed, out of space) leaves a directory whose earlier
//! manifest no longer describes its tiles. A full build rewrites them all; `--tiles` keeps the
//! others as they are on disk and the earlier manifest's entries for them: after a `--force`
//! rebuild with other parameters was killed, `--tiles` with the old ones listed wrong sha256
//! for the tiles the killed run left, and exit 0. So a build (not a shard: those are merged)
//! writes [`MARKER`] before its first file and removes it after its manifest. A `--tiles`
//! run that finds it checks every file the manifest lists (size and sha256) and refuses when
//! one differs; when all agree, the earlier run stopped before it changed anything that
//! matters.

use std::path::Path;

use super::{BuildError, BuildOptions, Selection};
use crate::output::report::{Manifest, ManifestFile};

/// The mark's name inside the output directory.
pub const MARKER: &str = ".edo-city.writing";

/// Called under the directory's lock, before anything is written: checks what an unfinished
/// run left when this run is `--tiles`, then marks the directory as being written.
pub fn begin(opts: &BuildOptions) -> Result<(), BuildError> {
    if opts.selection.is_shard() {
        return Ok(());
    }
    let marker = opts.out.join(MARKER);
    if matches!(opts.selection, Selection::Tiles(_)) && marker.exists() {
        if let Err(why) = agrees_with_manifest(&opts.out) {
            return Err(super::OptionsError::HalfWritten {
                out: opts.out.display().to_string(),
                why,
            }
            .into());
        }
    }
    std::fs::write(&marker, b"").map_err(|e| super::write_err(&marker, e))
}

/// Called once the manifest is written: the directory holds one whole build again.
pub fn end(opts: &BuildOptions) {
    if !opts.selection.is_shard() {
        let _ = std::fs::remove_file(opts.out.join(MARKER));
    }
}

/// Whether every file `out/manifest.json` lists is on disk as listed, or the first that is
/// not.
fn agrees_with_manifest(out: &Path) -> Result<(), String> {
    let path = out.join("manifest.json");
    let bytes =
        super::shards::manifest_bytes(&path).map_err(|_| "it has no manifest.json".to_string())?;
    let manifest: Manifest = serde_json::from_slice(&bytes)
        .map_err(|e| format!("its manifest.json cannot be read ({e})"))?;
    let files = manifest
        .tiles
        .iter()
        .flat_map(|t| t.files())
        .chain(&manifest.files)
        .chain(&manifest.textures)
        .chain(&manifest.species);
    for f in files {
        if !on_disk_as_listed(out, f) {
            return Err(format!("{} is not the file manifest.json lists", f.path));
        }
    }
    Ok(())
}

/// Whether `out/<f.path>` has `f`'s size and sha256 (read in pieces: tiles can be large;
/// a path that leaves `out` or names no regular file never agrees).
fn on_disk_as_listed(out: &Path, f: &ManifestFile) -> bool {
    crate::output::listed::check(out, f).is_ok()
}
