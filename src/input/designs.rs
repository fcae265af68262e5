//! The designs file `[garden] designs` names (`model::design`): the rock gardens a person
//! kept in the browser. The file as a whole must be a designs file (else the build stops
//! with an error naming it); a design in it that is not usable (no stones, a size that is no
//! size, a second design for the same garden) is skipped with its record and reason, and the
//! rest are kept for `analyse::gardens`, which places each exactly or skips it with why.

use std::path::Path;

use super::InputError;
use crate::model::design::{Designs, MAX_DESIGNS_BYTES};
use crate::model::{Dataset, LayerInfo, Skipped};
use crate::params::Params;

/// Reads the designs file into `data.designs`, listed as the layer `designs` so that the
/// report's ledger accounts for every design: placed, or skipped with its reason.
pub fn read_designs(params: &Params, data: &mut Dataset) -> Result<(), InputError> {
    let name = &params.garden.designs;
    if name.is_empty() || !params.garden.enabled {
        return Ok(());
    }
    let path = Path::new(name);
    let bad = |message: String| InputError::Layer {
        file: name.clone(),
        message,
    };
    // The report names it by its file name alone: the path may lie outside the input, and
    // a build publishes no one's directories.
    let label = path
        .file_name()
        .map_or_else(|| name.clone(), |n| n.to_string_lossy().into_owned());
    let text = crate::bounded::read_text(path, MAX_DESIGNS_BYTES).map_err(|e| {
        let what = match e {
            crate::bounded::Refusal::NotRegular => "name a regular file",
            crate::bounded::Refusal::TooLarge { .. } | crate::bounded::Refusal::Grew { .. } => {
                "keep fewer designs in it"
            }
            crate::bounded::Refusal::Io(_) => {
                "`garden.designs` names it, relative to the parameter file (`edo-city serve \
                 --designs FILE` writes one)"
            }
        };
        bad(format!("the designs file {e}: {what}"))
    })?;
    let designs = Designs::parse(&text).map_err(bad)?;
    data.layers.push(LayerInfo {
        role: "designs".into(),
        file: label.clone(),
        features: designs.designs.len(),
        encoding: "UTF-8".into(),
        crs: "garden coordinates".into(),
        reprojected: false,
        vertices_before: 0,
        vertices_after: 0,
    });
    let mut seen: std::collections::HashMap<String, usize> = Default::default();
    for (record, d) in designs.designs.into_iter().enumerate() {
        let why = d.problem().or_else(|| {
            seen.get(&d.lot).map(|first| {
                format!(
                    "a second design for one garden: `{}` has one at record {first}",
                    d.lot
                )
            })
        });
        match why {
            Some(reason) => data.skipped.push(Skipped {
                layer: "designs".into(),
                file: label.clone(),
                id: if d.lot.len() <= 256 {
                    d.lot.clone()
                } else {
                    format!("record {record}")
                },
                record: Some(record),
                reason,
            }),
            None => {
                seen.insert(d.lot.clone(), record);
                data.records
                    .entry("designs".into())
                    .or_default()
                    .insert(record);
                data.designs.push((record, d));
            }
        }
    }
    Ok(())
}
