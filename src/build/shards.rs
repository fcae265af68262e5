//! Building part of a city: single tiles, shards for a cluster, and merging shard outputs.
//!
//! A hypothesis's output directory belongs to one input and one parameter set: a run with
//! others refuses unless `--force`, so that two hypotheses never mix in one directory.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::{write_err, BuildError, BuildOptions, Selection};
use crate::model::Plan;
use crate::output::atomic::write_atomic;
use crate::output::report::{self, Manifest, Report};

/// Manifests found in an output directory: the full build's and any shards'.
pub(super) fn manifests_in(out: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let Ok(entries) = std::fs::read_dir(out) else {
        return found;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name == "manifest.json"
            || (name.starts_with("manifest.shard-") && name.ends_with(".json"))
        {
            found.push(e.path());
        }
    }
    found.sort();
    found
}

/// Why the output directory does not allow the run; each names the directory or the file.
#[derive(Debug, thiserror::Error)]
pub enum OutDirError {
    /// A manifest there cannot be read (a FIFO, a device, too large, unreadable).
    #[error("{path} {cause}")]
    Unreadable {
        /// The manifest.
        path: String,
        /// Why.
        cause: crate::bounded::Refusal,
    },
    /// A manifest there is not one this version writes.
    #[error(
        "{path} is not a manifest of this edo-city version ({cause}); use another --out or --force"
    )]
    NotAManifest {
        /// The manifest.
        path: String,
        /// What the JSON reader said.
        cause: serde_json::Error,
    },
    /// It holds a build of other parameters or another input.
    #[error(
        "{out} holds another build ({why} in {manifest}): give --force to replace it, or \
         build this hypothesis into another --out"
    )]
    Another {
        /// The output directory.
        out: String,
        /// The first difference.
        why: String,
        /// The manifest's file name.
        manifest: String,
    },
    /// As [`OutDirError::Another`], for `--tiles`, which `--force` does not let through.
    #[error(
        "{out} holds another build ({why} in {manifest}): --tiles only rewrites tiles of \
         a build with the same input and parameters, even with --force; build the \
         whole city (without --tiles) to replace it"
    )]
    AnotherForTiles {
        /// The output directory.
        out: String,
        /// The first difference.
        why: String,
        /// The manifest's file name.
        manifest: String,
    },
    /// Nothing was read, and an earlier build is there: it is left as it was.
    #[error(
        "nothing to build (no lots or footprints were read), and {out} holds an earlier build \
         ({manifest}): it was left as it was; check the input and `layers.*.file`, or build into \
         another --out"
    )]
    NothingOverEarlier {
        /// The output directory.
        out: String,
        /// The manifest found.
        manifest: String,
    },
    /// A run that needs a finished build finds none.
    #[error("{needs}, but {out} holds no finished build (no manifest.json): {hint}")]
    Unfinished {
        /// What wants it, e.g. "--tiles rewrites tiles of an earlier full build".
        needs: String,
        /// The output directory.
        out: String,
        /// What to do.
        hint: &'static str,
    },
}

/// Why `--tiles` or `--shard` cannot select tiles.
#[derive(Debug, thiserror::Error)]
pub enum SelectionError {
    /// A tile id is empty.
    #[error(
        "--tiles {0}: a tile id is empty (two commas in a row, or one at an end); \
         give ids such as 1108_760,1109_760"
    )]
    EmptyId(String),
    /// No feature falls in these tiles.
    #[error("no feature falls in tile(s) {unknown}; `edo-city tiles <input>` lists the {tiles} tiles of this input")]
    NoFeature {
        /// The tiles asked for with nothing in them, comma-separated.
        unknown: String,
        /// How many tiles the input has.
        tiles: usize,
    },
    /// I/N out of range.
    #[error(
        "--shard {index}/{count}: give I/N with 1 <= I <= N <= {}",
        super::MAX_SHARDS
    )]
    Shard {
        /// I.
        index: usize,
        /// N.
        count: usize,
    },
}

/// The largest manifest read (a million lots' is tens of MB; its skips can make it more).
pub const MAX_MANIFEST_BYTES: u64 = 2 << 30;

/// The bytes of a manifest, through `bounded` (a FIFO or device named so is refused).
pub(crate) fn manifest_bytes(path: &Path) -> Result<Vec<u8>, BuildError> {
    crate::bounded::read(path, MAX_MANIFEST_BYTES).map_err(|cause| {
        OutDirError::Unreadable {
            path: path.display().to_string(),
            cause,
        }
        .into()
    })
}

pub(super) fn read_manifest(path: &Path) -> Result<Manifest, BuildError> {
    let bytes = manifest_bytes(path)?;
    serde_json::from_slice(&bytes).map_err(|cause| {
        OutDirError::NotAManifest {
            path: path.display().to_string(),
            cause,
        }
        .into()
    })
}

/// The first key where two JSON values differ, as a dotted path.
pub(crate) fn first_difference(
    a: &serde_json::Value,
    b: &serde_json::Value,
    path: &str,
) -> Option<String> {
    use serde_json::Value as V;
    match (a, b) {
        (V::Object(x), V::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter().find_map(|k| {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                match (x.get(k), y.get(k)) {
                    (Some(va), Some(vb)) => first_difference(va, vb, &p),
                    _ => Some(p),
                }
            })
        }
        _ if a == b => None,
        _ => Some(if path.is_empty() {
            "(whole value)".into()
        } else {
            path.to_string()
        }),
    }
}

/// Refuses to write into a directory built from another input or other parameters.
pub fn check_out_dir(opts: &BuildOptions) -> Result<(), BuildError> {
    // `--tiles` keeps the earlier build's other tiles: with other parameters the manifest
    // would stamp them on tiles they did not make, so `--force` does not cover it.
    let tiles = matches!(opts.selection, Selection::Tiles(_));
    if (opts.force || opts.reuse.is_some()) && !tiles {
        return Ok(());
    }
    // Compared as published: a published manifest names paths outside the input by their
    // fingerprints only.
    let mut current = serde_json::to_value(&opts.params).expect("parameters serialise");
    report::publish_paths(&mut current);
    let input = super::absolute(&opts.input);
    for path in manifests_in(&opts.out) {
        let Ok(bytes) = manifest_bytes(&path) else {
            continue;
        };
        let mut old: serde_json::Value = serde_json::from_slice(&bytes).unwrap_or_default();
        if let Some(params) = old.get_mut("params") {
            report::publish_paths(params);
        }
        let diff = first_difference(&old["params"], &current, "")
            .map(|k| format!("the parameter `{k}` differs"))
            .or_else(|| {
                let old_input = old["input"]["input"].as_str().unwrap_or_default();
                // A published manifest holds the input's fingerprint, a shard's its path.
                let same = match old["input"]["input_id"].as_str() {
                    Some(id) => id == report::input_id(&input),
                    None => super::absolute(Path::new(old_input)) == input,
                };
                (!same).then(|| format!("it was built from another input ({old_input})"))
            });
        if let Some(why) = diff {
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            let (out, manifest) = (opts.out.display().to_string(), name.to_string());
            return Err(match tiles {
                false => OutDirError::Another { out, why, manifest },
                true => OutDirError::AnotherForTiles { out, why, manifest },
            }
            .into());
        }
    }
    Ok(())
}

/// A run that would build nothing (no lots or footprints were read) never replaces an
/// earlier build: its tiles would all be removed as stale.
pub fn refuse_empty(opts: &BuildOptions, plan: &Plan) -> Result<(), BuildError> {
    if !plan.tiles.is_empty() {
        return Ok(());
    }
    match manifests_in(&opts.out).first() {
        Some(found) => Err(OutDirError::NothingOverEarlier {
            out: opts.out.display().to_string(),
            manifest: found
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into(),
        }
        .into()),
        None => Ok(()),
    }
}

/// The manifest of the earlier full build that `--tiles` updates.
/// The manifest of the finished build in `out`; `needs` says, for the error, what wants it
/// (e.g. "--tiles rewrites tiles of an earlier full build").
pub fn previous_manifest(out: &Path, needs: &str) -> Result<Manifest, BuildError> {
    let path = out.join("manifest.json");
    if !path.exists() {
        let hint = match manifests_in(out).is_empty() {
            true => "build the whole city into it first",
            false => "it holds shard outputs: run `edo-city merge` on them first",
        };
        return Err(OutDirError::Unfinished {
            needs: needs.to_string(),
            out: out.display().to_string(),
            hint,
        }
        .into());
    }
    read_manifest(&path)
}

/// Features per tile, for balancing and listing.
fn features(plan: &Plan) -> BTreeMap<&str, usize> {
    plan.tiles
        .iter()
        .map(|id| (id.as_str(), plan.houses.get(id).map_or(0, Vec::len)))
        .collect()
}

/// Shard (0-based) of every tile: the heaviest tiles first, each to the lightest shard so far
/// (ties to the lowest shard, then tile id order), so shards are balanced by feature count
/// and the assignment depends on nothing but the plan.
pub fn shard_of_tiles(plan: &Plan, count: usize) -> BTreeMap<String, usize> {
    let mut tiles: Vec<(&str, usize)> = features(plan).into_iter().collect();
    tiles.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    let mut load = vec![0usize; count.max(1)];
    let mut out = BTreeMap::new();
    for (id, n) in tiles {
        let (shard, _) = load
            .iter()
            .enumerate()
            .min_by_key(|(i, l)| (**l, *i))
            .expect("at least one shard");
        load[shard] += n;
        out.insert(id.to_string(), shard);
    }
    out
}

/// The ids of the tiles this run writes.
pub fn select(plan: &Plan, selection: &Selection) -> Result<HashSet<String>, BuildError> {
    match selection {
        Selection::All => Ok(plan.tiles.iter().cloned().collect()),
        Selection::Tiles(ids) => {
            if ids.is_empty() || ids.iter().any(|id| id.trim().is_empty()) {
                return Err(SelectionError::EmptyId(ids.join(",")).into());
            }
            let unknown: Vec<&String> = ids.iter().filter(|id| !plan.tiles.contains(*id)).collect();
            if !unknown.is_empty() {
                return Err(SelectionError::NoFeature {
                    unknown: unknown
                        .iter()
                        .map(|s| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                    tiles: plan.tiles.len(),
                }
                .into());
            }
            Ok(ids.iter().cloned().collect())
        }
        Selection::Shard { index, count } => {
            if *count == 0 || *index == 0 || index > count || *count > super::MAX_SHARDS {
                return Err(SelectionError::Shard {
                    index: *index,
                    count: *count,
                }
                .into());
            }
            Ok(shard_of_tiles(plan, *count)
                .into_iter()
                .filter(|(_, s)| *s == index - 1)
                .map(|(id, _)| id)
                .collect())
        }
    }
}

pub(super) fn names(shard: Option<[usize; 2]>) -> (String, String) {
    match shard {
        Some([i, n]) => (
            format!("manifest.shard-{i}-of-{n}.json"),
            format!("report.shard-{i}-of-{n}.json"),
        ),
        None => ("manifest.json".into(), "report.json".into()),
    }
}

/// Writes the report, then the manifest (last: a manifest always describes complete tiles).
///
/// A shard's manifest keeps the input's absolute path (`merge` reads the input again to draw
/// the whole city's plan, and removes it); the city's own manifest and report name the
/// input and templates directories alone ([`report::InputSummary::published`]).
pub fn write_manifest_and_report(out: &Path, manifest: &Manifest) -> Result<Report, BuildError> {
    let (manifest_name, report_name) = names(manifest.shard);
    let published;
    let manifest = match manifest.shard {
        Some(_) => manifest,
        None => {
            published = Manifest {
                input: manifest.input.published(),
                params: report::published_params(&manifest.params),
                ..manifest.clone()
            };
            &published
        }
    };
    let rep = report::assemble_report(manifest);
    write_json(&out.join(report_name), &rep)?;
    write_json(&out.join(manifest_name), manifest)?;
    Ok(rep)
}

fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), BuildError> {
    let bytes = serde_json::to_vec_pretty(value).expect("serialises");
    write_atomic(path, &bytes).map_err(|e| write_err(path, e))
}

/// Deletes the tiles (and the levels of detail above them) an earlier build into the same
/// directory listed in its manifest that this build did not write, so the directory holds
/// one consistent city. Files the tool did not write itself are never touched.
pub fn remove_stale_tiles(out: &Path, manifest: &Manifest) {
    let Ok(old) = read_manifest(&out.join("manifest.json")) else {
        return;
    };
    let current: HashSet<&str> = (manifest.tiles.iter())
        .flat_map(|t| t.files().map(|f| f.path.as_str()))
        .chain(manifest.files.iter().map(|f| f.path.as_str()))
        .collect();
    let old_files = (old.tiles.iter())
        .flat_map(|t| t.files().map(|f| f.path.clone()).collect::<Vec<_>>())
        .chain(old.files.iter().map(|f| f.path.clone()));
    for path in old_files {
        let ours = path.starts_with("tiles/")
            || path.starts_with(crate::output::crowds::DIR)
            || path == crate::output::cityjson::FILE;
        let safe = ours && crate::output::listed::relative(&path).is_ok();
        if safe && !current.contains(path.as_str()) {
            let _ = std::fs::remove_file(out.join(&path));
        }
    }
    let _ = std::fs::remove_dir(out.join(crate::output::tiles3d::LOD_DIR));
    let _ = std::fs::remove_dir(out.join(crate::output::glb::MODELS_DIR));
    let _ = std::fs::remove_dir(out.join(crate::output::cityjson::TEMPLATES_DIR));
    let _ = std::fs::remove_dir(out.join(crate::output::crowds::DIR));
}

/// Deletes the texture files an earlier build listed that this one did not write (an
/// earlier layout kept them in `textures/`), and that directory once it is empty.
pub fn remove_stale_textures(out: &Path, textures: &[report::ManifestFile]) {
    let Ok(old) = read_manifest(&out.join("manifest.json")) else {
        return;
    };
    let current: HashSet<&str> = textures.iter().map(|f| f.path.as_str()).collect();
    for f in &old.textures {
        let safe = (f.path.starts_with("textures/") || f.path.starts_with("tiles/textures/"))
            && crate::output::listed::relative(&f.path).is_ok();
        if safe && !current.contains(f.path.as_str()) {
            let _ = std::fs::remove_file(out.join(&f.path));
        }
    }
    let _ = std::fs::remove_dir(out.join("textures"));
}

/// Runs every format's whole-build step (`tileset.json`) over `manifest`, listing the files
/// it writes in the manifest and what it noticed in the warnings.
pub fn finish_formats(
    out: &Path,
    manifest: &mut Manifest,
    memory: Option<&std::sync::Arc<crate::output::tiles3d::memory::Memory>>,
) -> Result<(), BuildError> {
    let mut warnings = Vec::new();
    // What the sinks wrote before is written again; the build's own files (links.json) stay.
    manifest.files.retain(|f| f.path == "links.json");
    let output = crate::params::OutputParams {
        formats: manifest.formats.clone(),
        ..manifest.params.output.clone()
    };
    // The whole-build steps draw no tile: no atlas needed. They run side by side (the
    // city model's copy beside the levels of detail: at 30,052 lots a tenth of its cost);
    // their files and warnings are taken in the formats' order, so the manifest is the same.
    let sinks = crate::output::sinks(&output, None, &report::params_id(&manifest.params), memory);
    let done: Vec<_> = {
        use rayon::prelude::*;
        let m: &Manifest = manifest;
        sinks
            .par_iter()
            .map(|sink| {
                let mut said = Vec::new();
                sink.finish(out, m, &mut said).map(|files| (files, said))
            })
            .collect()
    };
    for result in done {
        let (files, said) = result.map_err(|e| write_err(out, e))?;
        manifest.files.extend(files);
        warnings.extend(said);
    }
    manifest.input.warnings.extend(
        warnings
            .into_iter()
            .map(|m| crate::model::Warning::new(crate::model::WarningClass::Build, m)),
    );
    Ok(())
}

/// One line of `edo-city tiles`.
#[derive(Debug, Clone, Serialize)]
pub struct TileInfo {
    /// The tile's id.
    pub id: String,
    /// Machiya in the tile.
    pub machiya: usize,
    /// Footprint houses in the tile.
    pub footprints: usize,
    /// [xmin, ymin, xmax, ymax] of the tile, projected metres.
    pub bounds: [f64; 4],
}

/// The tiles a build of this plan would write, with what falls in each.
pub fn list_tiles(plan: &Plan, tile_size: f64, origin: [f64; 2]) -> Vec<TileInfo> {
    plan.tiles
        .iter()
        .map(|id| {
            let lots = plan.houses.get(id).map_or(&[][..], Vec::as_slice);
            // A tile named in the data: the extent of its houses (a tile of walls alone has
            // none, and is given the empty box it always had).
            let bounds =
                crate::model::tile::tile_bounds(id, tile_size, origin).unwrap_or_else(|| {
                    crate::geom::bbox::bbox(
                        lots.iter()
                            .flat_map(|m| m.outline.exterior().0.iter().copied()),
                    )
                    .unwrap_or([f64::MAX, f64::MAX, f64::MIN, f64::MIN])
                });
            TileInfo {
                id: id.clone(),
                machiya: lots.iter().filter(|m| !m.is_footprint()).count(),
                footprints: lots.iter().filter(|m| m.is_footprint()).count(),
                bounds,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Frontage, PlannedHouse};
    use geo_types::{Coord, LineString, Polygon};

    fn plan_with(counts: &[(&str, usize)]) -> Plan {
        let lot = PlannedHouse {
            id: "x".into(),
            record: 0,
            outline: Polygon::new(LineString::from(vec![(0., 0.), (1., 0.), (1., 1.)]), vec![]),
            frontage: Frontage {
                a: Coord { x: 0., y: 0. },
                b: Coord { x: 1., y: 0. },
                fallback: false,
            },
            mtype: "hiraya".into(),
            type_given: false,
            district: None,
            tile: String::new(),
            ground: 0.0,
            source: crate::model::HouseSource::Lot,
            attrs: Vec::new(),
            kura: Default::default(),
        };
        let mut plan = Plan::default();
        for (id, n) in counts {
            plan.tiles.insert(id.to_string());
            plan.houses.insert(id.to_string(), vec![lot.clone(); *n]);
        }
        plan
    }

    #[test]
    fn shards_are_balanced_disjoint_and_cover_every_tile() {
        let plan = plan_with(&[
            ("a", 50),
            ("b", 40),
            ("c", 30),
            ("d", 20),
            ("e", 10),
            ("f", 10),
        ]);
        let shards = shard_of_tiles(&plan, 3);
        assert_eq!(shards.len(), 6);
        let mut load = [0; 3];
        for (id, s) in &shards {
            load[*s] += plan.houses[id].len();
        }
        assert_eq!(load.iter().sum::<usize>(), 160);
        assert!(
            load.iter().max().unwrap() - load.iter().min().unwrap() <= 10,
            "{load:?}"
        );
        assert_eq!(shards, shard_of_tiles(&plan, 3), "deterministic");
    }

    #[test]
    fn first_difference_names_the_key() {
        let a = serde_json::json!({"seed": 1, "machiya": {"depth": 12.0}});
        let b = serde_json::json!({"seed": 1, "machiya": {"depth": 10.0}});
        assert_eq!(
            first_difference(&a, &b, "").as_deref(),
            Some("machiya.depth")
        );
        assert_eq!(first_difference(&a, &a, ""), None);
    }
}
