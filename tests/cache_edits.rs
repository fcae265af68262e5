//! The analysis cache never gives a tile that a full build would not: random edits of the
//! input, of templates and models named relative to the current directory, and of the cache
//! file itself, each keeping the edited file's size and time of writing (as `touch -r` does),
//! then `--tiles` of every tile, always byte-identical to a full build of the edited state.

mod common;

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use common::*;
use proptest::prelude::*;

/// One edit, each keeping the file's size and its time of writing.
#[derive(Debug, Clone)]
enum Edit {
    /// A digit of a lot record's `id` in `lots.dbf`.
    Dbf { record: usize, at: usize, digit: u8 },
    /// `eave_height` of `hiraya` in the template directory `machiya.templates` names.
    Template { tenths: u8 },
    /// A digit of the landmark model in `landmarks.models_dir`.
    Model { nth: usize, digit: u8 },
    /// A bit of the cache file.
    Cache { at: usize, bit: u8 },
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0usize..40, 0usize..3, 1u8..10).prop_map(|(record, at, digit)| Edit::Dbf {
            record,
            at,
            digit
        }),
        (0u8..10).prop_map(|tenths| Edit::Template { tenths }),
        (0usize..200, 0u8..10).prop_map(|(nth, digit)| Edit::Model { nth, digit }),
        (0usize..100_000, 0u8..8).prop_map(|(at, bit)| Edit::Cache { at, bit }),
    ]
}

/// Rewrites `path` with `change` applied, then gives it back its size-preserving bytes'
/// old time of writing.
fn rewrite_keeping_time(path: &Path, change: impl FnOnce(&mut Vec<u8>)) {
    let time: SystemTime = std::fs::metadata(path).unwrap().modified().unwrap();
    let mut bytes = std::fs::read(path).unwrap();
    let len = bytes.len();
    change(&mut bytes);
    assert_eq!(bytes.len(), len, "an edit keeps the size");
    std::fs::write(path, &bytes).unwrap();
    std::fs::File::options()
        .write(true)
        .open(path)
        .unwrap()
        .set_modified(time)
        .unwrap();
}

/// The digit `want`, or the next one when `old` is already it: every edit changes a byte.
fn other(old: u8, want: u8) -> u8 {
    match b'0' + want == old {
        true => b'0' + (want + 1) % 10,
        false => b'0' + want,
    }
}

struct Town {
    work: PathBuf,
    cache: PathBuf,
}

impl Town {
    /// The fixture with a landmark whose model lies in `models/` and a template directory
    /// `tpl/`, both beside the input and named relative to the current directory (`work`).
    fn new(work: &Path) -> Town {
        let input = work.join("in");
        copy_fixture("kyoto-small", &input);
        let models = work.join("models");
        std::fs::create_dir_all(&models).unwrap();
        let shipped = fixture("landmark-models");
        for f in ["kura.obj", "kura.mtl"] {
            std::fs::copy(shipped.join(f), models.join(f)).unwrap();
        }
        std::fs::create_dir_all(work.join("tpl")).unwrap();
        let hiraya = Path::new(env!("CARGO_MANIFEST_DIR")).join("templates/machiya/hiraya.toml");
        std::fs::copy(hiraya, work.join("tpl/hiraya.toml")).unwrap();
        std::fs::write(
            input.join("landmarks.csv"),
            "id,model,kind,x,y,rotation,scale,z\nstore,kura.obj,,-22985.4,-109989.6,0,1,\n",
        )
        .unwrap();
        std::fs::write(
            work.join("params.toml"),
            "[layers.landmarks]\nfile = \"landmarks.csv\"\n[landmarks]\nmodels_dir = \"models\"\n\
             [machiya]\ntemplates = \"tpl\"\n",
        )
        .unwrap();
        Town {
            work: work.to_path_buf(),
            cache: work.join("cache"),
        }
    }

    /// Runs a build from `work` (so `models` and `tpl` resolve there); its summary. OBJ
    /// tiles only: they are what is compared, and the analysis cached is the same for every
    /// format (the GLB levels of detail and plan.gpkg made the suite's longest test longer).
    fn build(&self, out: &str, cache: &Path, extra: &[&str]) -> String {
        let o = edo_city()
            .current_dir(&self.work)
            .env("EDO_CITY_CACHE", cache)
            .args(["build", "in", "--out", out, "--params", "params.toml"])
            .args(["--format", "obj", "--no-plan"])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    fn apply(&self, e: &Edit) {
        match *e {
            Edit::Dbf { record, at, digit } => {
                rewrite_keeping_time(&self.work.join("in/lots.dbf"), |b| {
                    let count = u32::from_le_bytes(b[4..8].try_into().unwrap()) as usize;
                    let header = u16::from_le_bytes([b[8], b[9]]) as usize;
                    let len = u16::from_le_bytes([b[10], b[11]]) as usize;
                    // The `id` field's digits (its first 10 bytes): a space or a letter
                    // there is no number, and the build would rightly refuse the layer.
                    let start = header + (record % count) * len + 1;
                    let digits: Vec<usize> = (start..start + 10)
                        .filter(|&i| b[i].is_ascii_digit())
                        .collect();
                    let i = digits[at % digits.len()];
                    b[i] = other(b[i], digit);
                })
            }
            Edit::Template { tenths } => {
                rewrite_keeping_time(&self.work.join("tpl/hiraya.toml"), |b| {
                    let text = String::from_utf8(b.clone()).unwrap();
                    let at = text.find("eave_height = 3.").unwrap() + "eave_height = 3.".len();
                    b[at] = other(b[at], tenths);
                })
            }
            Edit::Model { nth, digit } => {
                rewrite_keeping_time(&self.work.join("models/kura.obj"), |b| {
                    let digits: Vec<usize> =
                        (0..b.len()).filter(|&i| b[i].is_ascii_digit()).collect();
                    let i = digits[nth % digits.len()];
                    b[i] = other(b[i], digit);
                })
            }
            Edit::Cache { at, bit } => {
                for f in std::fs::read_dir(&self.cache).unwrap() {
                    rewrite_keeping_time(&f.unwrap().path(), |b| {
                        let i = at % b.len();
                        b[i] ^= 1 << bit;
                    });
                }
            }
        }
    }
}

/// The tile ids of a build.
fn tile_ids(out: &Path) -> Vec<String> {
    read_json(&out.join("manifest.json"))["tiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect()
}

/// Every file of every tile of `full` is the same in `out`.
fn same_tiles(full: &Path, out: &Path) -> Result<(), TestCaseError> {
    for id in tile_ids(full) {
        for ext in ["obj", "mtl"] {
            let name = format!("tiles/{id}.{ext}");
            let a = std::fs::read(full.join(&name)).unwrap();
            let b = std::fs::read(out.join(&name)).unwrap();
            prop_assert!(a == b, "{name} differs from the full build's");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn tiles_after_any_edit_equal_a_full_build(edits in prop::collection::vec(edit(), 1..4)) {
        let tmp = tempfile::tempdir().unwrap();
        let town = Town::new(tmp.path());
        let reused = |summary: &str| summary.contains("analysis   reused");
        town.build("out", &town.cache, &[]);
        for (n, e) in edits.iter().enumerate() {
            town.apply(e);
            let full = format!("full{n}");
            town.build(&full, Path::new("off"), &[]);
            let ids = tile_ids(&tmp.path().join(&full)).join(",");
            let first = town.build("out", &town.cache, &["--tiles", &ids]);
            same_tiles(&tmp.path().join(&full), &tmp.path().join("out"))?;
            // Every edit changes a byte: analysed again ...
            prop_assert!(!reused(&first), "{e:?} reused a stale analysis");
            // ... and cached: the next run reads it, and still equals the full build.
            let again = town.build("out", &town.cache, &["--tiles", &ids]);
            prop_assert!(reused(&again), "{e:?}: the new analysis was not cached");
            same_tiles(&tmp.path().join(&full), &tmp.path().join("out"))?;
        }
    }
}
