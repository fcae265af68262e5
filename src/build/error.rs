//! Why a build did not finish: one enum, each variant an error of one room of the build
//! (typed where it is made, a string only when the CLI prints it).

use std::path::Path;

use thiserror::Error;

use crate::input::InputError;
use crate::params::ParamsError;
use crate::templates::TemplateError;

/// Why a build did not finish (exit code 2); each names the file, key or directory.
#[derive(Debug, Error)]
pub enum BuildError {
    /// The parameter file is wrong.
    #[error(transparent)]
    Params(#[from] ParamsError),
    /// A template file is wrong.
    #[error(transparent)]
    Templates(#[from] TemplateError),
    /// The input cannot be read.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A parameter names a template, material or texture there is not.
    #[error(transparent)]
    Name(#[from] super::NameError),
    /// The output directory does not allow the run.
    #[error(transparent)]
    OutDir(#[from] super::shards::OutDirError),
    /// `--tiles` or `--shard` select no tiles.
    #[error(transparent)]
    Selection(#[from] super::shards::SelectionError),
    /// Shard outputs cannot be merged.
    #[error(transparent)]
    Merge(#[from] super::merge::MergeError),
    /// Another run holds the output directory.
    #[error(transparent)]
    Lock(#[from] crate::output::lock::LockError),
    /// The build's options do not allow it.
    #[error(transparent)]
    Options(#[from] OptionsError),
    /// The texture set (`textures`) cannot be used.
    #[error(transparent)]
    Textures(#[from] crate::output::TextureError),
    /// A file to write names one the build must not write over.
    #[error(transparent)]
    Target(#[from] crate::output::target::Refused),
    /// The overrides lie inside the directory the build writes.
    #[error(
        "{path} is read by this build as its overrides and lies inside its --out ({out}), \
         which the build writes over: copy it out first (in QGIS: Export > Save Features As, \
         beside the parameter file) and name the copy, or build into another --out"
    )]
    ReadsItsOutput {
        /// The overrides as the parameter file names them.
        path: String,
        /// The output directory.
        out: String,
    },
    /// The build a command works on cannot be read again.
    #[error(transparent)]
    Replay(#[from] super::ReplayError),
    // The io::Error is in the message, not a `source`: the CLI prints the chain, and it
    // would say it twice.
    /// A file could not be written (a full disk says what to do).
    #[error("cannot write {path}: {cause}{hint}")]
    Write {
        /// The file or directory that could not be written.
        path: String,
        /// What the operating system said.
        cause: std::io::Error,
        /// What to do, when there is something to say.
        hint: &'static str,
    },
}

/// What the build's options (not the parameter file) do not allow.
#[derive(Debug, Error)]
pub enum OptionsError {
    /// More worker threads than allowed.
    #[error("-j {0}: at most {max} worker threads (0 = one per core, which is fastest)", max = super::MAX_THREADS)]
    Threads(usize),
    /// The worker threads cannot be started.
    #[error("cannot start worker threads: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
    /// `tile_size` cuts the city into too many tiles.
    #[error(
        "`tile_size` = {0} m cuts this city into more than {max} tiles (files of each \
         format, and a tileset node, each): raise `tile_size` (the default is 250 m)",
        max = super::MAX_TILES
    )]
    TooManyTiles(f64),
    /// `--tiles` in a directory an earlier run left half-written.
    #[error(
        "{out} was left half-written by an earlier run that stopped (killed or failed): \
         {why}; build the whole city again (without --tiles)"
    )]
    HalfWritten {
        /// The output directory.
        out: String,
        /// How it disagrees with its manifest.
        why: String,
    },
}

/// A write that failed, as the error to show: a full disk says what to do.
pub(super) fn write_err(path: &Path, cause: std::io::Error) -> BuildError {
    // An error a step met at one file names that file.
    let at_file = cause
        .get_ref()
        .is_some_and(|e| e.is::<crate::output::AtFile>());
    let (path, cause) = match at_file {
        true => {
            let kind = cause.kind();
            match (cause.into_inner()).and_then(|e| e.downcast::<crate::output::AtFile>().ok()) {
                Some(at) => (at.path, at.cause),
                None => (path.to_path_buf(), kind.into()),
            }
        }
        false => (path.to_path_buf(), cause),
    };
    let full = cause.raw_os_error() == Some(28) || cause.kind() == std::io::ErrorKind::StorageFull;
    let hint = if full {
        ". Every file written is whole (temporaries are removed); free some space or build \
         into another --out, and run the same command again"
    } else {
        ""
    };
    BuildError::Write {
        path: path.display().to_string(),
        cause,
        hint,
    }
}
