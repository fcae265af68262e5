//! `edo-city check` (a build's report with nothing written), and the input-wide part of
//! every report: what reading and analysis found, the same for every tile.

use std::path::Path;

use rayon::prelude::*;

use super::{
    absolute, gpkg_err, layer_files, load_catalog, read_and_analyse, BuildError, NoProgress,
};
use crate::generate;
use crate::model::{Dataset, Plan};
use crate::output::{self, report};
use crate::params::Params;

/// What `edo-city check` found: the build's report, as it would be, with nothing written
/// but, with `gpkg`, its problems as GIS layers (`problems` where they are, `warnings`).
pub fn check(
    input: &Path,
    params: &Params,
    templates: Option<&Path>,
    gpkg: Option<&Path>,
) -> Result<report::Report, BuildError> {
    if let Some(path) = gpkg {
        let mut reads = vec![(input, "the input directory")];
        reads.extend(templates.map(|t| (t, "the templates directory")));
        output::target::check(path, output::target::Kind::GeoPackage, &reads)?;
    }
    let catalog = load_catalog(params, templates)?;
    let (data, plan, _, _) = read_and_analyse(input, params, &catalog, &NoProgress)?;
    let files = layer_files(input, params);
    let variants = generate::variant::Variants::of(params);
    // Generate every tile (to find the houses that cannot be built), write nothing.
    let tiles: Vec<report::ManifestTile> = plan
        .tiles
        .par_iter()
        .map(|id| {
            // The ground is never skipped: checking needs no boolean operations.
            let tile = generate::TilePlan {
                surface: None,
                ..generate::TilePlan::of(&plan, id)
            };
            let meshes =
                generate::generate_tile(&tile, &catalog, params, &variants, plan.origin, &files);
            report::ManifestTile {
                id: id.clone(),
                obj: None,
                mtl: None,
                glb: None,
                crowds: None,
                cityjson: None,
                models: Vec::new(),
                bounds: None,
                centre: [0.0; 2],
                stats: meshes.stats,
            }
        })
        .collect();
    let manifest = report::Manifest {
        tool: "edo-city".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        shard: None,
        origin: plan.origin,
        frame: String::new(),
        crs: data.crs.clone(),
        crs_wkt: data.crs_wkt.clone(),
        tile_size: params.tile_size,
        params: params.clone(),
        input: input_summary(input, templates, &data, &plan),
        tiles,
        formats: Vec::new(),
        files: Vec::new(),
        textures: Vec::new(),
        species: Vec::new(),
    };
    let report = report::assemble_report(&manifest);
    if let Some(path) = gpkg {
        output::gpkg::write_problems(path, &data, params, &report.skipped, &report.warnings)
            .map_err(gpkg_err)?;
    }
    Ok(report)
}

/// The input-wide part of the report.
pub(super) fn input_summary(
    input: &Path,
    templates: Option<&Path>,
    data: &Dataset,
    plan: &Plan,
) -> report::InputSummary {
    let mut s = report::InputSummary {
        input: absolute(input).display().to_string(),
        templates: templates.map(|t| t.display().to_string()),
        crs: data.crs.clone(),
        layers: data.layers.clone(),
        lots: data.lots.len(),
        footprints_read: data.footprints.len(),
        frontage_fallback: plan.frontage_fallback,
        skipped: data.skipped.clone(),
        tables: data.joins.clone(),
        warnings: data.warnings.clone(),
        ..Default::default()
    };
    for lot in &data.lots {
        *s.lots_by_use
            .entry(lot.lot_use.name().to_string())
            .or_default() += 1;
    }
    s.skipped.extend(plan.skipped.iter().cloned());
    s.warnings.extend(plan.warnings.iter().cloned());
    s.ledgers = output::accounting::ledgers(data);
    s.crowds = plan.crowds.clone();
    s.gardens = plan.garden_reports.clone();
    s.halls = plan.hall_reports.clone();
    // Placed landmarks come from the manifest's tiles (what was written); the rest is the
    // whole city's.
    s.landmarks = crate::model::LandmarkReport {
        placed: Vec::new(),
        ..plan.landmark_report.clone()
    };
    // A skip that names only its feature gets its record, so the ledger closes after the
    // manifest's round trip too (`--tiles`, `merge`).
    for skip in s.skipped.iter_mut().filter(|k| k.record.is_none()) {
        if let Some(l) = s
            .ledgers
            .iter()
            .find(|l| l.role == skip.layer && l.file == skip.file)
        {
            skip.record = l.ids.get(&skip.id).copied();
        }
    }
    s.input_id = report::input_id(Path::new(&s.input));
    relative_to_input(&mut s, input);
    s
}

/// Names the input's files relative to the input directory in everything the summary says
/// (layer files, skips, tables, warnings, ledgers): the manifest is published with the
/// city, and where the user keeps their data is none of its business.
fn relative_to_input(s: &mut report::InputSummary, input: &Path) {
    let prefixes: Vec<String> = [input.to_path_buf(), absolute(input)]
        .iter()
        .map(|p| format!("{}/", p.display()))
        .filter(|p| p != "/")
        .collect();
    let strip = |text: &mut String| {
        for p in &prefixes {
            if text.contains(p.as_str()) {
                *text = text.replace(p.as_str(), "");
            }
        }
    };
    for l in &mut s.layers {
        strip(&mut l.file);
    }
    for k in &mut s.skipped {
        strip(&mut k.file);
        strip(&mut k.reason);
    }
    for t in &mut s.tables {
        strip(&mut t.file);
    }
    for w in &mut s.warnings {
        strip(&mut w.message);
        if let Some(f) = &mut w.file {
            strip(f);
        }
    }
    for l in &mut s.ledgers {
        strip(&mut l.file);
    }
}
