//! The analysis cache: a full build keeps what it read and analysed ([`Dataset`] and
//! [`Plan`]) so that `--tiles` can skip both.
//!
//! Regenerating one tile used to read and analyse the whole city (every frontage, kura, wall,
//! hall, garden GA, person and tree), because a tile sees its neighbours. That analysis is a
//! function of the input files, the parameters, the templates and the program, so a full
//! build writes its input and plan to a cache file under a key of exactly those, and
//! `--tiles` with the same key reads them back instead of reading the input and analysing.
//! Anything else (no cache, another key, a damaged or cut file) means both run as before:
//! the cache can make a run faster, never different.
//!
//! The cache lives outside the output directory (which holds only the city, to be copied to
//! a web server as it is): `$EDO_CITY_CACHE`, else `$XDG_CACHE_HOME/edo-city`, else
//! `~/.cache/edo-city`; `EDO_CITY_CACHE=off` (or empty) turns it off. One file per output
//! directory, the newest [`KEEP`] kept, and no more than [`KEEP_BYTES`] together.

use std::fs;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::model::{Dataset, Plan};

mod key;
pub use key::key;

/// The first bytes of a cache file; a new layout of the file gets a new number.
const MAGIC: &[u8; 24] = b"edo-city analysis v3\n\0\0\0";
/// Cache files kept (one per output directory, the most recently written).
pub const KEEP: usize = 16;
/// Bytes the kept files may take together (a million-lot city's file is about 480 MB); the
/// newest file is kept whatever its size.
pub const KEEP_BYTES: u64 = 4 << 30;

/// What a build did with the cache, for the summary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CacheUse {
    /// No cache directory (turned off, or no home directory).
    #[default]
    Off,
    /// `--tiles` found the plan of this input and these parameters and skipped the analysis.
    Reused,
    /// The analysis ran (nothing cached, or it was made from other input or parameters).
    Analysed,
}

/// The cache directory the environment names (`var` looks a variable up): `EDO_CITY_CACHE`
/// (`off` or empty: none), else `$XDG_CACHE_HOME/edo-city`, else `~/.cache/edo-city`. The
/// command line reads it once and passes it in [`super::BuildOptions::cache`]: the library
/// reads no environment of its own.
pub fn dir_from(var: impl Fn(&str) -> Option<std::ffi::OsString>) -> Option<PathBuf> {
    match var("EDO_CITY_CACHE") {
        Some(v) if v.is_empty() || v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => match var("XDG_CACHE_HOME").filter(|v| !v.is_empty()) {
            Some(x) => Some(PathBuf::from(x).join("edo-city")),
            None => Some(PathBuf::from(var("HOME")?).join(".cache/edo-city")),
        },
    }
}

/// Where the cache file of output directory `out` is in the cache directory `dir`.
pub fn file_for(dir: &Path, out: &Path) -> PathBuf {
    let out = super::absolute(out);
    let name = crate::output::sha256_hex(out.as_os_str().as_encoded_bytes());
    dir.join(format!("{}.plan", &name[..24]))
}

/// The input and plan cached for `out` under `key`, or `None` (no file, another key,
/// damaged).
pub fn load(file: &Path, key: &[u8; 32]) -> Option<(Dataset, Plan)> {
    let mut r = BufReader::new(crate::bounded::file(file).ok()?);
    let mut head = [0u8; 24 + 32];
    r.read_exact(&mut head).ok()?;
    if &head[..24] != MAGIC || &head[24..] != key {
        return None;
    }
    let mut body = Vec::new();
    r.read_to_end(&mut body).ok()?;
    // The body ends in its own sha256: a flipped bit or a cut file is no plan.
    let split = body.len().checked_sub(32)?;
    let (body, digest) = body.split_at(split);
    if Sha256::digest(body).as_slice() != digest {
        return None;
    }
    let (mut data, plan): (Dataset, Plan) = postcard::from_bytes(body).ok()?;
    data.share_field_names();
    Some((data, plan))
}

/// Writes `data` and `plan` for `out` under `key` (a temporary renamed into place, so a
/// reader sees the old file or the new one), then forgets all but the newest [`KEEP`]
/// files. Failing to cache never fails a build: the next `--tiles` analyses instead.
pub fn store(file: &Path, key: &[u8; 32], data: &Dataset, plan: &Plan) {
    let Some(dir) = file.parent() else {
        return;
    };
    if fs::create_dir_all(dir).is_err() {
        return;
    }
    let tmp = file.with_extension(format!("tmp-{}", std::process::id()));
    let written = (|| -> std::io::Result<()> {
        let mut w = BufWriter::new(fs::File::create(&tmp)?);
        w.write_all(MAGIC)?;
        w.write_all(key)?;
        let mut hashed = Hashed {
            inner: &mut w,
            h: Sha256::new(),
        };
        postcard::to_io(&(data, plan), &mut hashed).map_err(std::io::Error::other)?;
        let digest = hashed.h.finalize();
        w.write_all(&digest)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        fs::rename(&tmp, file)
    })();
    if written.is_err() {
        let _ = fs::remove_file(&tmp);
        return;
    }
    evict(dir);
}

/// A writer that hashes what passes through it.
struct Hashed<W> {
    inner: W,
    h: Sha256,
}

impl<W: Write> Write for Hashed<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.h.update(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// Removes all but the [`KEEP`] most recently written plans, and the older ones beyond
/// [`KEEP_BYTES`].
fn evict(dir: &Path) {
    remove_orphans(dir);
    evict_beyond(dir, KEEP, KEEP_BYTES);
}

/// Removes the temporaries of builds killed while they wrote the cache
/// (`<key>.tmp-<pid>` whose process is gone; they were never removed and each holds a whole
/// plan). Only where `/proc` tells which processes run.
fn remove_orphans(dir: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for path in entries.filter_map(|e| e.ok()).map(|e| e.path()) {
        let pid = path
            .extension()
            .and_then(|x| x.to_str())
            .and_then(|x| x.strip_prefix("tmp-"))
            .and_then(|p| p.parse::<u32>().ok());
        if let Some(pid) = pid {
            if !Path::new(&format!("/proc/{pid}")).exists() {
                let _ = fs::remove_file(&path);
            }
        }
    }
}

/// Keeps the newest plans while there are at most `keep` of `keep_bytes` together (the
/// newest always).
fn evict_beyond(dir: &Path, keep: usize, keep_bytes: u64) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let mut plans: Vec<(std::time::SystemTime, u64, PathBuf)> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "plan"))
        .filter_map(|p| {
            let m = fs::metadata(&p).ok()?;
            Some((m.modified().ok()?, m.len(), p))
        })
        .collect();
    // Newest first: each is kept while the count and the bytes allow.
    plans.sort_by(|a, b| b.cmp(a));
    let mut bytes = 0u64;
    for (i, (_, len, p)) in plans.iter().enumerate() {
        bytes = bytes.saturating_add(*len);
        if i > 0 && (i >= keep || bytes > keep_bytes) {
            let _ = fs::remove_file(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_directory_is_the_one_the_environment_names() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |k: &str| {
                (pairs.iter())
                    .find(|(n, _)| *n == k)
                    .map(|(_, v)| std::ffi::OsString::from(v))
            }
        };
        assert_eq!(
            dir_from(env(&[("EDO_CITY_CACHE", "off"), ("HOME", "/h")])),
            None
        );
        assert_eq!(dir_from(env(&[("EDO_CITY_CACHE", "")])), None);
        let given = dir_from(env(&[("EDO_CITY_CACHE", "/c"), ("HOME", "/h")]));
        assert_eq!(given, Some(PathBuf::from("/c")));
        let xdg = dir_from(env(&[("XDG_CACHE_HOME", "/x"), ("HOME", "/h")]));
        assert_eq!(xdg, Some(PathBuf::from("/x/edo-city")));
        let home = dir_from(env(&[("XDG_CACHE_HOME", ""), ("HOME", "/h")]));
        assert_eq!(home, Some(PathBuf::from("/h/.cache/edo-city")));
        assert_eq!(dir_from(env(&[])), None, "no home: no cache");
    }
    use geo::polygon;

    #[test]
    fn a_plan_comes_back_as_it_went_in() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("x.plan");
        let mut plan = Plan {
            origin: [0.1 + 0.2, f64::NAN],
            ..Plan::default()
        };
        plan.tiles.insert("3_4".into());
        plan.garden_reports.push(crate::model::GardenStat {
            lot: "L1".into(),
            area: None,
            placed: false,
            reason: String::new(),
            size: [1.0 / 3.0, 2.0],
            fitness: 0.7,
            stones: 0,
            scores: [("axis".to_string(), 0.1 + 0.2)].into_iter().collect(),
            corner: [0.1 + 0.2, 5.0],
            layout: vec![[0.1, 0.2, 1.0 / 3.0, 1.0]],
            kept: true,
            ..Default::default()
        });
        let mut data = Dataset::default();
        let mut names = crate::model::FieldNames::default();
        for id in ["a", "b"] {
            let attrs: crate::model::Attrs =
                [(names.intern("id"), id.into())].into_iter().collect();
            data.lots.push(crate::model::Lot {
                id: id.into(),
                record: 0,
                outline: polygon![(x: 0.0, y: 0.0), (x: 1.0, y: 0.0), (x: 0.0, y: 1.0)],
                lot_use: crate::model::LotUse::Other("畑".into()),
                mtype: None,
                district: None,
                tile: None,
                attrs,
                ground: -0.0,
            });
        }
        data.warnings.push(crate::model::Warning::new(
            crate::model::WarningClass::Layer,
            "w",
        ));
        let key = [7u8; 32];
        store(&file, &key, &data, &plan);
        let (data_back, back) = load(&file, &key).expect("the same key reads the plan");
        assert_eq!(data_back.warnings, data.warnings);
        let [a, b] = &data_back.lots[..] else {
            panic!("two lots went in");
        };
        assert_eq!(a.attrs, data.lots[0].attrs);
        assert_eq!(a.lot_use, data.lots[0].lot_use);
        assert_eq!(a.outline, data.lots[0].outline);
        assert!(a.ground.is_sign_negative(), "-0 stays -0");
        // The names are shared again as reading shares them.
        let name = |l: &crate::model::Lot| l.attrs.iter().next().unwrap().0.as_ptr();
        assert_eq!(name(a), name(b));
        assert_eq!(back.origin[0].to_bits(), plan.origin[0].to_bits());
        assert!(back.origin[1].is_nan());
        assert_eq!(back.tiles, plan.tiles);
        assert_eq!(back.garden_reports, plan.garden_reports);
        assert!(
            load(&file, &[8u8; 32]).is_none(),
            "another key reads nothing"
        );
        // A file cut short is not a plan.
        let bytes = fs::read(&file).unwrap();
        fs::write(&file, &bytes[..bytes.len() - 3]).unwrap();
        assert!(load(&file, &key).is_none());
    }

    /// Sets `f`'s time of writing to `secs` after a fixed day long past (as `touch -r`
    /// does); the key's tests use it too.
    pub(super) fn written_at(f: &Path, secs: u64) {
        let t = std::time::UNIX_EPOCH + std::time::Duration::from_secs(1_000_000 + secs);
        let file = fs::File::options().write(true).open(f).unwrap();
        file.set_modified(t).unwrap();
    }

    #[test]
    fn every_flipped_bit_of_a_cache_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("x.plan");
        let mut data = Dataset::default();
        data.warnings.push(crate::model::Warning::new(
            crate::model::WarningClass::Layer,
            "a warning long enough to flip bits in",
        ));
        let key = [3u8; 32];
        store(&file, &key, &data, &Plan::default());
        let bytes = fs::read(&file).unwrap();
        assert!(load(&file, &key).is_some());
        for i in 0..bytes.len() {
            for bit in [0, 3, 7] {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                fs::write(&file, &b).unwrap();
                assert!(load(&file, &key).is_none(), "byte {i} bit {bit} accepted");
            }
        }
    }

    #[test]
    fn temporaries_of_killed_builds_are_removed_and_a_running_ones_kept() {
        let dir = tempfile::tempdir().unwrap();
        // A pid that no process has: above the kernel's pid_max (at most 2^22).
        let dead = dir.path().join("k.tmp-4999999");
        let alive = dir.path().join(format!("k.tmp-{}", std::process::id()));
        fs::write(&dead, "half").unwrap();
        fs::write(&alive, "half").unwrap();
        store(
            &dir.path().join("new.plan"),
            &[0u8; 32],
            &Dataset::default(),
            &Plan::default(),
        );
        assert!(!dead.exists(), "a killed build's temporary went");
        assert!(alive.exists(), "a running build's stays");
    }

    #[test]
    fn only_the_newest_files_are_kept() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..KEEP + 3 {
            let f = dir.path().join(format!("{i:02}.plan"));
            store(&f, &[0u8; 32], &Dataset::default(), &Plan::default());
            // Distinct times, oldest first, whatever the file system's clock resolution.
            written_at(&f, i as u64);
        }
        let new = dir.path().join("new.plan");
        store(&new, &[0u8; 32], &Dataset::default(), &Plan::default());
        let mut left: Vec<String> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left.len(), KEEP);
        assert!(left.contains(&"new.plan".to_string()));
        assert!(
            !left.contains(&"00.plan".to_string()),
            "the oldest went first"
        );
    }

    #[test]
    fn the_kept_files_stay_within_their_bytes_and_the_newest_stays() {
        let dir = tempfile::tempdir().unwrap();
        for (i, name) in ["old", "mid", "new"].iter().enumerate() {
            let f = dir.path().join(format!("{name}.plan"));
            fs::write(&f, [0u8; 100]).unwrap();
            written_at(&f, i as u64);
        }
        let left = || {
            let mut v: Vec<String> = fs::read_dir(dir.path())
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        };
        evict_beyond(dir.path(), 16, 250);
        assert_eq!(left(), ["mid.plan", "new.plan"]);
        evict_beyond(dir.path(), 16, 10);
        assert_eq!(left(), ["new.plan"], "the newest is kept whatever its size");
    }
}
