//! Rock-garden designs a person kept (issue 42): the file `edo-city serve --designs` writes
//! and a build reads through `[garden] designs`. Each design is one garden's genome (its
//! stones: place, size, group) with the garden it was made for (its key: a lot id, or
//! `area-<id>` for a polygon of the gardens layer), the size of that garden, the seed the
//! designer ran with and the generations that led to it (which candidates were picked).
//!
//! The file is JSON, one object with `edo_city_designs` (the format's version, 1) and
//! `designs`, sorted by garden key: the same designs are the same bytes. Coordinates are the
//! garden's own (metres, x along the viewing side, y away from it), so a design survives a
//! rebuild that moves nothing, and is refused with a reason where the new garden is too small.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The version of the designs format this build reads and writes.
pub const DESIGNS_VERSION: u32 = 1;
/// The largest designs file read, bytes.
pub const MAX_DESIGNS_BYTES: u64 = 64 << 20;
/// The most designs a file may hold.
pub const MAX_DESIGNS: usize = 100_000;
/// The most stones a design may hold.
pub const MAX_STONES: usize = 64;
/// The most generations a design's history may hold.
pub const MAX_HISTORY: usize = 10_000;

/// A designs file.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Designs {
    /// The format's version: [`DESIGNS_VERSION`].
    pub edo_city_designs: u32,
    /// The designs, one per garden, sorted by key.
    pub designs: Vec<Design>,
}

/// One stone of a design, in garden coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignStone {
    /// Along the viewing side, metres from its left end.
    pub x: f64,
    /// Away from the viewing side, metres.
    pub y: f64,
    /// Diameter in plan, metres.
    pub size: f64,
    /// Its group (from 0); within a group the stones are largest first.
    pub group: usize,
}

/// One generation of the session that made a design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Generation {
    /// The generation bred (1 = the first after the random start).
    pub generation: usize,
    /// The candidates the person picked, by their place in the generation before; empty
    /// when the GA chose by itself.
    pub picks: Vec<usize>,
    /// The best fitness of the generation bred.
    pub best: f64,
}

/// One kept design.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Design {
    /// The garden it is for: a lot id, or `area-<id>` for a polygon of the gardens layer.
    pub lot: String,
    /// The seed of the designer's GA.
    pub seed: u64,
    /// Width along the viewing side and depth of the garden it was made for, metres.
    pub size: [f64; 2],
    /// The stones.
    pub stones: Vec<DesignStone>,
    /// Its fitness (seed 000's eq. 1) in that garden.
    pub fitness: f64,
    /// Its degree of violation of each of the five rules there, by rule name.
    #[serde(default)]
    pub scores: BTreeMap<String, f64>,
    /// The generations that led to it, in order.
    #[serde(default)]
    pub history: Vec<Generation>,
    /// Which candidate of the last generation was kept (its place in it).
    #[serde(default)]
    pub kept: usize,
}

impl Design {
    /// What is wrong with the design, if anything: the reason it is skipped.
    pub fn problem(&self) -> Option<String> {
        if self.lot.is_empty() || self.lot.len() > 256 {
            return Some("an unusable design: its `lot` is empty or longer than 256 bytes".into());
        }
        let metres = |v: f64| v.is_finite() && v > 0.0 && v <= 1000.0;
        if !(metres(self.size[0]) && metres(self.size[1])) {
            return Some(format!(
                "an unusable design: its `size` must be two numbers from 0 to 1000 metres, got {:?}",
                self.size
            ));
        }
        if self.stones.is_empty() || self.stones.len() > MAX_STONES {
            return Some(format!(
                "an unusable design: it has {} stones, not 1 to {MAX_STONES}",
                self.stones.len()
            ));
        }
        if self.history.len() > MAX_HISTORY {
            return Some(format!(
                "an unusable design: its history has {} generations, past {MAX_HISTORY}",
                self.history.len()
            ));
        }
        for (k, s) in self.stones.iter().enumerate() {
            let finite = s.x.is_finite() && s.y.is_finite();
            if !finite || !metres(s.size) || s.group >= MAX_STONES {
                return Some(format!(
                    "an unusable design: stone {k} is not a place, a size from 0 to 1000 m and \
                     a group below {MAX_STONES}: {s:?}"
                ));
            }
        }
        None
    }

    /// The first stone that does not lie inside a `width` x `depth` garden (with its whole
    /// plan, a millimetre's slack), if any: why the design no longer fits.
    pub fn outside(&self, width: f64, depth: f64) -> Option<String> {
        const SLACK: f64 = 1e-3;
        self.stones.iter().enumerate().find_map(|(k, s)| {
            let r = s.size / 2.0;
            let inside = s.x - r >= -SLACK
                && s.x + r <= width + SLACK
                && s.y - r >= -SLACK
                && s.y + r <= depth + SLACK;
            (!inside).then(|| {
                format!(
                    "the design no longer fits: stone {k} at ({:.2}, {:.2}) m, {:.2} m across, \
                     lies outside the {:.2} x {:.2} m garden placed now (designed for {:.2} x \
                     {:.2} m)",
                    s.x, s.y, s.size, width, depth, self.size[0], self.size[1]
                )
            })
        })
    }

    /// The stones as the city's gardens keep them: (x, y, size, group).
    pub fn stone_rows(&self) -> Vec<[f64; 4]> {
        self.stones
            .iter()
            .map(|s| [s.x, s.y, s.size, s.group as f64])
            .collect()
    }
}

impl Designs {
    /// Parses a designs file's text; the error says what is wrong in words a person can act on.
    pub fn parse(text: &str) -> Result<Designs, String> {
        let d: Designs = serde_json::from_str(text).map_err(|e| {
            format!("not a designs file ({e}); it is written by `edo-city serve --designs`")
        })?;
        if d.edo_city_designs != DESIGNS_VERSION {
            return Err(format!(
                "designs format {} is not the one this edo-city reads ({DESIGNS_VERSION})",
                d.edo_city_designs
            ));
        }
        if d.designs.len() > MAX_DESIGNS {
            return Err(format!(
                "{} designs, past the {MAX_DESIGNS} a file may hold",
                d.designs.len()
            ));
        }
        Ok(d)
    }

    /// The file's text: pretty JSON, designs sorted by key, a newline at the end.
    pub fn to_text(&self) -> String {
        let mut d = self.clone();
        d.edo_city_designs = DESIGNS_VERSION;
        d.designs.sort_by(|a, b| a.lot.cmp(&b.lot));
        serde_json::to_string_pretty(&d).unwrap_or_default() + "\n"
    }

    /// The design for `lot`, if the file has one.
    pub fn get(&self, lot: &str) -> Option<&Design> {
        self.designs.iter().find(|d| d.lot == lot)
    }

    /// Puts `design` in, in place of the one of its lot.
    pub fn put(&mut self, design: Design) {
        self.designs.retain(|d| d.lot != design.lot);
        self.designs.push(design);
        self.designs.sort_by(|a, b| a.lot.cmp(&b.lot));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn design(lot: &str) -> Design {
        Design {
            lot: lot.into(),
            seed: 3,
            size: [10.0, 4.0],
            stones: vec![
                DesignStone {
                    x: 2.0,
                    y: 1.0,
                    size: 1.0,
                    group: 0,
                },
                DesignStone {
                    x: 8.0,
                    y: 3.0,
                    size: 0.5,
                    group: 1,
                },
            ],
            fitness: 2.5,
            scores: BTreeMap::new(),
            history: vec![Generation {
                generation: 1,
                picks: vec![0, 2],
                best: 2.5,
            }],
            kept: 0,
        }
    }

    #[test]
    fn a_file_reads_back_as_written_sorted_by_lot() {
        let mut d = Designs::default();
        d.put(design("b"));
        d.put(design("a"));
        d.put(design("b"));
        let text = d.to_text();
        let back = Designs::parse(&text).unwrap();
        assert_eq!(back.designs.len(), 2);
        assert_eq!(back.designs[0].lot, "a");
        assert_eq!(back.to_text(), text);
        assert!(back.get("b").is_some() && back.get("c").is_none());
    }

    #[test]
    fn garbage_and_other_versions_are_refused_with_a_reason() {
        assert!(Designs::parse("garbage")
            .unwrap_err()
            .contains("not a designs file"));
        let v2 = r#"{"edo_city_designs": 2, "designs": []}"#;
        assert!(Designs::parse(v2).unwrap_err().contains("format 2"));
        let extra = r#"{"edo_city_designs": 1, "designs": [], "x": 1}"#;
        assert!(Designs::parse(extra).is_err());
    }

    #[test]
    fn bad_designs_and_designs_too_big_for_their_garden_say_why() {
        assert_eq!(design("a").problem(), None);
        let mut d = design("a");
        d.stones[1].size = f64::NAN;
        assert!(d.problem().unwrap().contains("stone 1"));
        let mut d = design("a");
        d.stones.clear();
        assert!(d.problem().unwrap().contains("0 stones"));
        let d = design("a");
        assert_eq!(d.outside(10.0, 4.0), None);
        assert_eq!(d.outside(8.3, 3.3), None);
        let why = d.outside(8.0, 4.0).unwrap();
        assert!(
            why.contains("stone 1") && why.contains("8.00 x 4.00"),
            "{why}"
        );
    }
}
