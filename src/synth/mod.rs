//! `edo-city synth`: writes a Kyoto-like shapefile directory of any size.
//!
//! A grid of square blocks of 40 jo (121.2 m) with streets between them (every fourth street a
//! wide avenue). Town lots are narrow, deep strips ("eel's beds", unagi no nedoko) along every
//! block face; the lots on the north and south faces reach up to half the block deep, those on
//! the east and west faces hold the corners. Attributes are written in Shift_JIS with a
//! `.cpg`, as Japanese municipal data is, and about a quarter of the town lots carry a machiya
//! type in kanji. Coordinates are JGD2011 plane rectangular zone VI metres near central Kyoto.
//!
//! Two profiles ([`Profile`]): `grid`, the first town (lots 1.5 to 5 ken wide, a few whole
//! samurai or temple blocks), and `kyoto`, the composition of the real towns users build
//! (quarters of walled samurai estates with their halls, a kura behind about half the houses,
//! repeated ids).

mod estates;
mod layout;
mod write;

use std::path::Path;

pub use layout::make_town;
pub use write::{stamp_dbf_date, write_blocks, write_lots, DBF_DATE};

/// One ken (間), the unit of frontage, in metres.
pub const KEN: f64 = 1.818;
/// One jo (丈) in metres.
pub const JO: f64 = 3.03;
/// A block's side: 40 jo (121.2 m).
const BLOCK: f64 = 40.0 * JO;
/// South-west corner of the synthetic town (zone VI: x east, y north).
const BASE: [f64; 2] = [-23_000.0, -110_000.0];

/// The kind of town `synth` makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Profile {
    /// Town lots 1.5 to 5 ken wide with slanted side lines (few kura survive collision
    /// avoidance), 5 % of the blocks whole samurai lots and 3 % temples. The first synthetic
    /// town; the tests' towns.
    #[default]
    Grid,
    /// The composition of a real Kyoto-like town of ~30,000 lots (issue 59): quarters of
    /// walled samurai estates of ~200 m of wall each with a gate and an omoya hall (4.7 % of
    /// the lots), town lots 2 to 6 ken wide and mostly square (a kura behind about half the
    /// houses), 6 % of the records repeating the id before them. What the benchmarks build.
    Kyoto,
}

/// Why a synthetic town cannot be made or written; each names the option or the file.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    /// No such profile.
    #[error(
        "unknown synth profile {0:?}: give grid (the first synthetic town) or kyoto \
         (the composition of real towns: estates, kura, repeated ids)"
    )]
    Profile(String),
    /// `--lots` out of range.
    #[error("--lots must be from 1 to {MAX_LOTS}, got {0}")]
    Lots(usize),
    /// The directory holds files (and `--force` was not given).
    #[error(
        "{dir} is not empty (it holds {holds}): synth would overwrite its files, and a \
         lots.csv there would be joined onto the synthetic lots; give an empty or \
         new directory, or --force"
    )]
    NotEmpty {
        /// The directory.
        dir: String,
        /// One file it holds.
        holds: String,
    },
    /// The path is a file.
    #[error("{0} is not a directory")]
    NotADirectory(String),
    /// The directory cannot be made.
    #[error("cannot create {dir}: {cause}")]
    Create {
        /// The directory.
        dir: String,
        /// What the operating system said.
        cause: std::io::Error,
    },
    /// A file cannot be written.
    #[error("cannot write {path}: {cause}")]
    Write {
        /// The file.
        path: String,
        /// What the shapefile writer or the operating system said.
        cause: String,
    },
}

impl Profile {
    /// The profile of a name (`grid`, `kyoto`).
    pub fn parse(name: &str) -> Result<Self, SynthError> {
        match name {
            "grid" => Ok(Profile::Grid),
            "kyoto" => Ok(Profile::Kyoto),
            _ => Err(SynthError::Profile(name.to_string())),
        }
    }

    /// The gate attribute of a whole-block estate or temple: the grid's have none.
    fn gate(self) -> &'static str {
        match self {
            Profile::Grid => "",
            Profile::Kyoto => "1",
        }
    }
}

/// An axis-aligned rectangle, counter-clockwise from its south-west corner.
fn rect(x0: f64, y0: f64, w: f64, h: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]]
}

/// What `synth` wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SynthSummary {
    /// Lots written.
    pub lots: usize,
    /// Of them town lots (machiya).
    pub machiya: usize,
    /// Of them samurai estates (buke).
    pub estates: usize,
    /// Records whose id repeats the record's before them (the build skips them).
    pub repeated_ids: usize,
    /// Blocks written.
    pub blocks: usize,
    /// Street centrelines written.
    pub streets: usize,
}

/// A lot before it is written: outline (counter-clockwise) and attributes.
#[derive(Debug, Clone)]
pub struct SynthLot {
    /// The lot's id, from 1.
    pub id: u64,
    /// Its outline, counter-clockwise, not closed.
    pub ring: Vec<[f64; 2]>,
    /// Its use (`machiya`, `buke`, ...).
    pub lot_use: &'static str,
    /// Its machiya type in kanji, or "" (drawn by the build).
    pub mtype: &'static str,
    /// Its district.
    pub district: &'static str,
    /// Its gate attribute (`1`: on the edge facing the street), or "" for none. The lots
    /// layer has a gate field only when a lot has a gate.
    pub gate: &'static str,
}

/// A synthetic town in memory.
#[derive(Debug, Clone)]
pub struct Town {
    /// The lots, in id order.
    pub lots: Vec<SynthLot>,
    /// Block outlines, counter-clockwise.
    pub blocks: Vec<Vec<[f64; 2]>>,
    /// Street centrelines with their full width.
    pub streets: Vec<(Vec<[f64; 2]>, f64)>,
}

/// The largest town `synth` makes (ten times the largest benchmark).
pub const MAX_LOTS: usize = 10_000_000;

/// Writes a town of `lots_wanted` lots of `profile` into `dir`: `lots.shp`, `blocks.shp`,
/// `streets.shp`, each with its `.cpg` and `.prj`. A directory that already holds files is
/// refused unless `force`: synth would overwrite a user's shapefiles, and a `lots.csv` left
/// there would be joined onto the synthetic lots.
pub fn write_town(
    dir: &Path,
    lots_wanted: usize,
    seed: u64,
    profile: Profile,
    force: bool,
) -> Result<SynthSummary, SynthError> {
    if lots_wanted == 0 || lots_wanted > MAX_LOTS {
        return Err(SynthError::Lots(lots_wanted));
    }
    if !force {
        if let Ok(mut entries) = std::fs::read_dir(dir) {
            if let Some(e) = entries.next() {
                let name = e.map(|e| e.file_name().to_string_lossy().into_owned());
                return Err(SynthError::NotEmpty {
                    dir: dir.display().to_string(),
                    holds: name.unwrap_or_default(),
                });
            }
        } else if dir.exists() {
            return Err(SynthError::NotADirectory(dir.display().to_string()));
        }
    }
    std::fs::create_dir_all(dir).map_err(|e| SynthError::Create {
        dir: dir.display().to_string(),
        cause: e,
    })?;
    let Town {
        lots,
        blocks,
        streets,
    } = make_town(lots_wanted, seed, profile);
    write_lots(&dir.join("lots.shp"), &lots)?;
    write_blocks(&dir.join("blocks.shp"), &blocks)?;
    write::write_streets(&dir.join("streets.shp"), &streets)?;
    Ok(SynthSummary {
        lots: lots.len(),
        machiya: lots.iter().filter(|l| l.lot_use == "machiya").count(),
        estates: lots.iter().filter(|l| l.lot_use == "buke").count(),
        repeated_ids: lots.windows(2).filter(|w| w[0].id == w[1].id).count(),
        blocks: blocks.len(),
        streets: streets.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exactly_the_lots_asked_for_and_deterministic() {
        for profile in [Profile::Grid, Profile::Kyoto] {
            for wanted in [1, 7, 1000, 5000] {
                let a = make_town(wanted, 3, profile).lots;
                let b = make_town(wanted, 3, profile).lots;
                assert_eq!(a.len(), wanted, "{profile:?}");
                assert!(a
                    .iter()
                    .zip(&b)
                    .all(|(x, y)| x.ring == y.ring && x.mtype == y.mtype && x.id == y.id));
            }
        }
    }

    #[test]
    fn the_kyoto_profile_has_the_real_towns_estates_and_repeated_ids() {
        let lots = make_town(30_000, 1, Profile::Kyoto).lots;
        let estates = lots.iter().filter(|l| l.lot_use == "buke").count();
        let repeats = lots.windows(2).filter(|w| w[0].id == w[1].id).count();
        // The real town: 1,433 estates and 1,815 repeated ids in 30,676 records.
        assert!((900..2000).contains(&estates), "{estates}");
        assert!((1400..2300).contains(&repeats), "{repeats}");
        let grid = make_town(30_000, 1, Profile::Grid).lots;
        assert!(grid.windows(2).all(|w| w[0].id != w[1].id));
        assert!(grid.iter().all(|l| l.gate.is_empty()));
    }
}
