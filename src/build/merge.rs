//! `edo-city merge`: the shard outputs of one city (`build --shard I/N`) made one build,
//! byte-identical to a full build's. A shard's directory is input like any other: its
//! manifest is checked against the first shard's (count, program, parameters, input,
//! origin), and every file it lists is taken only as `output::listed` takes a file.

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::shards::{
    finish_formats, first_difference, manifests_in, names, read_manifest, write_manifest_and_report,
};
use super::{write_err, BuildError};
use crate::output::report::{self, Manifest, Report};

/// Why shard outputs cannot be merged; each names the manifest or file and what to do.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No directory given.
    #[error("merge needs at least one directory")]
    NoDirectory,
    /// No shard manifest in the directories (comma-separated).
    #[error("no shard manifests (manifest.shard-I-of-N.json) in {0}")]
    NoShards(String),
    /// The first shard's count is out of range.
    #[error(
        "{path}: a shard count of {count} is not within 1..={}; the manifest is damaged: run \
         the shards again",
        super::MAX_SHARDS
    )]
    Count {
        /// The manifest.
        path: String,
        /// The count it gives.
        count: usize,
    },
    /// A shard of another build (count, program, parameters, input or origin).
    #[error("{path} belongs to another build than {first} ({why}): merge the shards of one build")]
    OtherBuild {
        /// Its manifest.
        path: String,
        /// The first shard's manifest.
        first: String,
        /// The first difference.
        why: String,
    },
    /// A shard's number is out of range.
    #[error(
        "{path}: its shard number is not within 1..={count}; the manifest is damaged: \
         run that shard again"
    )]
    Number {
        /// Its manifest.
        path: String,
        /// The shard count.
        count: usize,
    },
    /// Shards without a manifest (`I/N`, comma-separated).
    #[error("shard(s) {0} have not finished (no manifest): run them, then merge again")]
    Unfinished(String),
    /// A file a shard lists is missing, truncated or other.
    #[error("shard {shard}'s manifest {manifest} {cause}: run that shard again, then merge")]
    Unlisted {
        /// The shard, `I/N`.
        shard: String,
        /// Its manifest.
        manifest: String,
        /// What is wrong with the file.
        cause: crate::output::listed::Unlisted,
    },
    /// Two shards list one shared file with other bytes.
    #[error(
        "shards {} and {} disagree on `{file}` ({} and {} list other \
         bytes): they were built by other programs or parameters; run the \
         shards of one build again, then merge",
        shards[0], shards[1], manifests[0], manifests[1]
    )]
    Disagree {
        /// The two shards, `I/N`.
        shards: [String; 2],
        /// The file.
        file: String,
        /// Their manifests.
        manifests: [String; 2],
    },
    /// Two shards list one tile with other files.
    #[error(
        "tile {tile} is listed by two shards with other files (the second is \
         shard {shard}, {manifest}): run the shards of one build again, then merge"
    )]
    TileTwice {
        /// The tile.
        tile: String,
        /// The second shard, `I/N`.
        shard: String,
        /// Its manifest.
        manifest: String,
    },
}

/// Merges the shard outputs in `dirs` into the first: tiles of the others are copied over,
/// then `manifest.json`, `report.json`, `plan.gpkg` (when the formats name it) and (with
/// `draw_plan`) `plan.png` are written for the whole city, byte-identical to a full build's, and the shard manifests are removed.
pub fn merge(dirs: &[PathBuf], draw_plan: bool) -> Result<Report, BuildError> {
    let Some(target) = dirs.first() else {
        return Err(MergeError::NoDirectory.into());
    };
    let mut shards: Vec<(PathBuf, PathBuf, Manifest)> = Vec::new();
    for dir in dirs {
        for path in manifests_in(dir) {
            let m = read_manifest(&path)?;
            if m.shard.is_some() {
                shards.push((dir.clone(), path, m));
            }
        }
    }
    let Some((_, _, first)) = shards.first() else {
        let dirs = dirs.iter().map(|d| d.display().to_string());
        return Err(MergeError::NoShards(dirs.collect::<Vec<_>>().join(", ")).into());
    };
    let count = first.shard.map(|s| s[1]).unwrap_or(0);
    if count == 0 || count > super::MAX_SHARDS {
        let path = shards[0].1.display().to_string();
        return Err(MergeError::Count { path, count }.into());
    }
    let mut seen = vec![false; count];
    for (_, path, m) in &shards {
        if let Some(why) = difference(first, m) {
            return Err(MergeError::OtherBuild {
                path: path.display().to_string(),
                first: shards[0].1.display().to_string(),
                why,
            }
            .into());
        }
        match m.shard {
            Some([i, _]) if (1..=count).contains(&i) => seen[i - 1] = true,
            _ => {
                let path = path.display().to_string();
                return Err(MergeError::Number { path, count }.into());
            }
        }
    }
    let missing: Vec<String> = (1..=count)
        .filter(|i| !seen[i - 1])
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Unfinished(missing.join(", ")).into());
    }
    let _lock = crate::output::lock::OutLock::acquire(target)?;
    let (tiles, files) = gather(&shards)?;
    // Every file is copied under a temporary name and checked against its shard's manifest
    // as it streams by (a file of the target itself is checked in place); only when all are
    // in are they renamed, so a truncated, missing or stray file stops the merge with the
    // target as it was, and no file is held in memory.
    let mut staged = Vec::new();
    for (f, (dir, shard, manifest)) in files.values() {
        let listed = |cause| MergeError::Unlisted {
            shard: shard.clone(),
            manifest: manifest.display().to_string(),
            cause,
        };
        match *dir == target {
            true => crate::output::listed::check(dir, f).map_err(listed)?,
            false => staged.push(crate::output::listed::copy(dir, target, f).map_err(listed)?),
        }
    }
    for s in staged {
        s.commit().map_err(|e| write_err(target, e))?;
    }
    let mut merged = first.clone();
    merged.shard = None;
    merged.tiles = tiles.into_values().collect();
    finish_formats(target, &mut merged, None)?;
    // The whole city's plan, as a full build draws it (shards leave it to the merge); drawn
    // before the manifest, which is written last, so a failing plan leaves no merged manifest.
    // The shards' manifests hold the input's path (the merged one will not).
    let input = PathBuf::from(&first.input.input);
    let templates = first.input.templates.as_ref().map(PathBuf::from);
    super::merge_plan_files(&merged, &input, templates.as_deref(), draw_plan, target)?;
    // The first shard wrote the texture set its parameters chose into `target/textures`.
    let rep = write_manifest_and_report(target, &merged)?;
    for (_, path, m) in &shards {
        let _ = std::fs::remove_file(path);
        let (_, report_name) = names(m.shard);
        let _ = std::fs::remove_file(path.with_file_name(report_name));
    }
    Ok(rep)
}

/// Where each shard's file comes from: its directory, the shard (`I/N`) and its manifest.
type Origin<'a> = (&'a PathBuf, String, &'a PathBuf);

/// The merged city's tiles, and every file to bring into the target once (tiles, their
/// shared models, `links.json`), each with the shard it is taken from. Two shards listing
/// one path with other contents (a shared model grown otherwise) are refused, naming both.
#[allow(clippy::type_complexity)]
fn gather<'a>(
    shards: &'a [(PathBuf, PathBuf, Manifest)],
) -> Result<
    (
        BTreeMap<String, report::ManifestTile>,
        BTreeMap<&'a str, (&'a report::ManifestFile, Origin<'a>)>,
    ),
    BuildError,
> {
    let mut tiles = BTreeMap::new();
    let mut files: BTreeMap<&str, (&report::ManifestFile, Origin)> = BTreeMap::new();
    for (k, (dir, path, m)) in shards.iter().enumerate() {
        let shard = m.shard.map(|[i, n]| format!("{i}/{n}")).unwrap_or_default();
        let links = m.files.iter().filter(|f| f.path == "links.json");
        // The links are the same in every shard: the first one's.
        let links = links.filter(|_| k == 0);
        for f in m.tiles.iter().flat_map(|t| t.files()).chain(links) {
            if let Some((g, (_, other, other_path))) = files.get(f.path.as_str()) {
                if g.sha256 != f.sha256 || g.bytes != f.bytes {
                    return Err(MergeError::Disagree {
                        shards: [other.clone(), shard],
                        file: f.path.clone(),
                        manifests: [other_path.display().to_string(), path.display().to_string()],
                    }
                    .into());
                }
                continue;
            }
            files.insert(f.path.as_str(), (f, (dir, shard.clone(), path)));
        }
        for t in &m.tiles {
            if let Some(before) = tiles.insert(t.id.clone(), t.clone()) {
                if before != *t {
                    return Err(MergeError::TileTwice {
                        tile: t.id.clone(),
                        shard,
                        manifest: path.display().to_string(),
                    }
                    .into());
                }
            }
        }
    }
    Ok((tiles, files))
}

/// What makes shard manifest `m` part of another build than `first`: the shard count, the
/// program and its version, the first differing parameter, the input, or the origin. The input's path may differ (shards
/// run on other machines); what was read from it may not.
fn difference(first: &Manifest, m: &Manifest) -> Option<String> {
    if m.shard.map(|s| s[1]) != first.shard.map(|s| s[1]) {
        return Some("the shard count differs".into());
    }
    if (&m.tool, &m.version) != (&first.tool, &first.version) {
        return Some(format!(
            "it was written by {} {}, the other by {} {}",
            m.tool, m.version, first.tool, first.version
        ));
    }
    let a = serde_json::to_value(&first.params).expect("parameters serialise");
    let b = serde_json::to_value(&m.params).expect("parameters serialise");
    if let Some(k) = first_difference(&a, &b, "") {
        return Some(format!("the parameter `{k}` differs"));
    }
    let strip = |s: &report::InputSummary| report::InputSummary {
        input: String::new(),
        ..s.clone()
    };
    if strip(&first.input) != strip(&m.input) {
        return Some(
            "what was read from the input differs (its layers, counts or skips, or the input \
             path as typed, which names the layer files: give every shard the same input path)"
                .into(),
        );
    }
    (first.origin != m.origin).then(|| "the origin differs".into())
}
