//! The ledger of every layer: each record read is built or listed as skipped, never lost.
//!
//! Reading and analysis fill a [`Ledger`] per layer (records read, records that gave no
//! feature, records split into several parts); the report closes it with every skip of every
//! stage, generation included. A record that is neither built nor skipped is a defect of
//! edo-city, not of the data: the report says so in a warning and `unaccounted` counts it, and
//! the tests hold it at zero for every corpus case and random town.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use serde::{Deserialize, Serialize};

use crate::model::{Dataset, Skipped};

/// What one layer's records became, as far as reading and analysis know.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Ledger {
    /// The layer's role (`lots`, `streets`, ...).
    pub role: String,
    /// The layer's file.
    pub file: String,
    /// Records in the file.
    pub read: usize,
    /// Records that gave the next stage no feature (each must have a skip entry).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub no_feature: Vec<usize>,
    /// Records that became several features (multipart), with their number of parts.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub parts: BTreeMap<usize, usize>,
    /// Feature id -> record, for skips that name only their feature.
    #[serde(skip)]
    pub ids: HashMap<String, usize>,
}

/// A layer's closed account, for the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Account {
    /// The layer's role.
    pub role: String,
    /// The layer's file.
    pub file: String,
    /// Records in the file.
    pub read: usize,
    /// Records with at least one feature built.
    pub built: usize,
    /// Records with at least one feature skipped (a multipart record can be both).
    pub skipped: usize,
    /// Records with features built and others skipped, so counted in `built` and in
    /// `skipped`: read = built + skipped - partly + unaccounted. A record of two rings, one
    /// of them a hole lying outside the other (read as a polygon of its own, as GDAL reads
    /// it) and too small for a garden, was "read 1, built 1, skipped 1" without this.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub partly: usize,
    /// Records neither built nor skipped: always 0, or edo-city has a defect.
    pub unaccounted: usize,
    /// The first unaccounted records, to report.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unaccounted_records: Vec<usize>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The ledgers of every layer read, from the dataset.
pub fn ledgers(data: &Dataset) -> Vec<Ledger> {
    data.layers
        .iter()
        .map(|layer| {
            let features: Vec<(usize, &str)> = match layer.role.as_str() {
                "lots" => data
                    .lots
                    .iter()
                    .map(|l| (l.record, l.id.as_str()))
                    .collect(),
                "footprints" => data
                    .footprints
                    .iter()
                    .map(|f| (f.record, f.id.as_str()))
                    .collect(),
                "fences" => data
                    .fence_lines
                    .iter()
                    .map(|f| (f.record, f.id.as_str()))
                    .collect(),
                "gardens" => data
                    .gardens
                    .iter()
                    .map(|g| (g.record, g.id.as_str()))
                    .collect(),
                "water" => data
                    .water
                    .iter()
                    .map(|g| (g.record, g.id.as_str()))
                    .collect(),
                "landmarks" => data
                    .landmarks
                    .iter()
                    .map(|g| (g.record, g.id.as_str()))
                    .collect(),
                "links" => data
                    .links
                    .iter()
                    .map(|g| (g.record, g.id.as_str()))
                    .collect(),
                "people" | "trees" => {
                    let points = match layer.role.as_str() {
                        "people" => &data.people,
                        _ => &data.trees,
                    };
                    points
                        .iter()
                        .flatten()
                        .map(|p| (p.record, p.id.as_str()))
                        .collect()
                }
                role => data
                    .records
                    .get(role)
                    .into_iter()
                    .flatten()
                    .map(|r| (*r, ""))
                    .collect(),
            };
            let mut per_record: BTreeMap<usize, usize> = BTreeMap::new();
            let mut ids = HashMap::new();
            for (record, id) in &features {
                *per_record.entry(*record).or_default() += 1;
                if !id.is_empty() {
                    ids.insert(id.to_string(), *record);
                }
            }
            Ledger {
                role: layer.role.clone(),
                file: layer.file.clone(),
                read: layer.features,
                no_feature: (0..layer.features)
                    .filter(|r| !per_record.contains_key(r))
                    .collect(),
                parts: per_record.into_iter().filter(|(_, n)| *n > 1).collect(),
                ids,
            }
        })
        .collect()
}

/// Closes each ledger with every skip of the build; adds a warning per layer that lost
/// records.
pub fn close(
    ledgers: &[Ledger],
    skipped: &[Skipped],
    warnings: &mut Vec<crate::model::Warning>,
) -> Vec<Account> {
    ledgers
        .iter()
        .map(|l| {
            // Distinct skipped features per record.
            let mut skipped_ids: BTreeMap<usize, BTreeSet<&str>> = BTreeMap::new();
            for s in skipped
                .iter()
                .filter(|s| s.layer == l.role && s.file == l.file)
            {
                if let Some(r) = s.record.or_else(|| l.ids.get(&s.id).copied()) {
                    skipped_ids.entry(r).or_default().insert(s.id.as_str());
                }
            }
            let no_feature: BTreeSet<usize> = l.no_feature.iter().copied().collect();
            let mut a = Account {
                role: l.role.clone(),
                file: l.file.clone(),
                read: l.read,
                ..Account::default()
            };
            for r in 0..l.read {
                let parts = match no_feature.contains(&r) {
                    true => 0,
                    false => l.parts.get(&r).copied().unwrap_or(1),
                };
                let skips = skipped_ids.get(&r).map_or(0, |s| s.len());
                if skips > 0 {
                    a.skipped += 1;
                }
                if skips < parts {
                    a.built += 1;
                    a.partly += (skips > 0) as usize;
                }
                if parts == 0 && skips == 0 {
                    a.unaccounted += 1;
                    if a.unaccounted_records.len() < 20 {
                        a.unaccounted_records.push(r);
                    }
                }
            }
            if a.unaccounted > 0 {
                warnings.push(
                    crate::model::Warning::new(
                        crate::model::WarningClass::Build,
                        format!(
                    "{}: {} record(s) were neither built nor listed as skipped (records {:?}); \
                     this is a defect of edo-city: please report it with the file",
                    a.file, a.unaccounted, a.unaccounted_records
                ),
                    )
                    .in_layer(&a.role, &a.file),
                );
            }
            a
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skip(layer: &str, id: &str, record: Option<usize>) -> Skipped {
        Skipped {
            layer: layer.into(),
            file: "f.shp".into(),
            id: id.into(),
            record,
            reason: "r".into(),
        }
    }

    #[test]
    fn a_record_with_no_feature_and_no_skip_is_unaccounted() {
        let l = Ledger {
            role: "lots".into(),
            file: "f.shp".into(),
            read: 4,
            no_feature: vec![1, 2],
            parts: [(3, 2)].into(),
            ids: [("c-1".to_string(), 3), ("c-2".to_string(), 3)].into(),
        };
        let mut w = Vec::new();
        // Record 1 skipped at reading, record 2 lost; record 3 has one of two parts skipped.
        let a = close(
            &[l],
            &[skip("lots", "x", Some(1)), skip("lots", "c-2", None)],
            &mut w,
        );
        assert_eq!(a[0].built, 2, "records 0 and 3");
        assert_eq!(a[0].skipped, 2, "records 1 and 3");
        assert_eq!(a[0].partly, 1, "record 3");
        assert_eq!(
            a[0].read,
            a[0].built + a[0].skipped - a[0].partly + a[0].unaccounted
        );
        assert_eq!(a[0].unaccounted, 1);
        assert_eq!(a[0].unaccounted_records, vec![2]);
        assert_eq!(w.len(), 1);
        assert!(w[0].message.contains("defect"), "{}", w[0]);
        assert_eq!(w[0].class, crate::model::WarningClass::Build);
    }

    #[test]
    fn skips_of_another_layer_do_not_count() {
        let l = Ledger {
            role: "lots".into(),
            file: "f.shp".into(),
            read: 1,
            no_feature: vec![0],
            ..Ledger::default()
        };
        let mut w = Vec::new();
        let a = close(&[l], &[skip("fences", "x", Some(0))], &mut w);
        assert_eq!(a[0].unaccounted, 1);
    }
}
