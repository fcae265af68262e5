//! The files a finished build's plan is drawn into again from its input: `plan.png` for
//! `edo-city plan`, and `plan.png` and `plan.gpkg` for `merge` (a shard has only part of
//! the city, so the merge reads the whole input again, as a full build read it).

use std::path::{Path, PathBuf};

use super::{
    absolute, gpkg_err, kura_view, load_catalog, read_and_analyse, shards, write_err, BuildError,
    NoProgress,
};
use crate::analyse;
use crate::model::{Dataset, Plan};
use crate::output::{self, report};
use crate::params::Params;

/// Why the build a published manifest describes cannot be read again (to draw its plan).
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The manifest does not say where the input is.
    #[error(
        "give the input directory with --input (the build read `{0}`; its manifest, \
         published with the city, does not say where it is)"
    )]
    WhereInput(String),
    /// The directory given is not the build's input (its fingerprint differs).
    #[error(
        "{given} is not the input of the build in {out} (it read `{read}`): give that directory"
    )]
    OtherInput {
        /// The directory given.
        given: String,
        /// The build's directory.
        out: String,
        /// The input the build read.
        read: String,
    },
    /// The manifest does not say where the templates are.
    #[error(
        "give the template directory the build used with --templates (it used `{0}`; \
         its manifest does not say where it is)"
    )]
    WhereTemplates(String),
    /// A parameter's path was left out of the published manifest.
    #[error(
        "the build's parameter `{0}` names a path outside the input, which its \
         published manifest leaves out: give the build's parameter file with --params"
    )]
    PathLeftOut(String),
    /// The parameter file given is not the build's.
    #[error("--params is not the parameter file of this build: `{0}` differs")]
    OtherParams(String),
    /// No such tile.
    #[error("no tile {tile} in this build; `edo-city tiles {input}` lists them")]
    NoTile {
        /// The tile asked for.
        tile: String,
        /// The input directory.
        input: String,
    },
    /// Nothing to draw.
    #[error("nothing to draw: no lots or footprints")]
    NothingToDraw,
}

/// Draws the plan of an earlier build from its parameters and the input read again: `input`
/// (and `templates`) as given, else those an older manifest recorded by their paths (a
/// published manifest names them alone, so they must be given); with `tile`, only that tile
/// at full resolution.
pub fn draw_plan_of(
    out: &Path,
    tile: Option<&str>,
    input: Option<&Path>,
    templates: Option<&Path>,
    params: Option<&Params>,
) -> Result<Vec<u8>, BuildError> {
    let mut manifest = shards::previous_manifest(out, "`edo-city plan` draws a finished build")?;
    manifest.params = plan_params(&manifest.params, params)?;
    let recorded = PathBuf::from(&manifest.input.input);
    let input = match input {
        Some(i) => i.to_path_buf(),
        None if recorded.is_absolute() && recorded.is_dir() => recorded,
        None => return Err(ReplayError::WhereInput(manifest.input.input.clone()).into()),
    };
    let id = report::input_id(&absolute(&input));
    if !manifest.input.input_id.is_empty() && manifest.input.input_id != id {
        return Err(ReplayError::OtherInput {
            given: input.display().to_string(),
            out: out.display().to_string(),
            read: manifest.input.input.clone(),
        }
        .into());
    }
    let templates = match (templates, &manifest.input.templates) {
        (Some(t), _) => Some(t.to_path_buf()),
        (None, None) => None,
        (None, Some(t)) if Path::new(t).is_absolute() && Path::new(t).is_dir() => {
            Some(PathBuf::from(t))
        }
        (None, Some(t)) => return Err(ReplayError::WhereTemplates(t.clone()).into()),
    };
    draw_plan_from(&manifest, tile, &input, templates.as_deref())
}

/// The parameters to read the input again with: the manifest's, or the file given when the
/// published manifest left out paths outside the input (refused when it is not the one
/// the build used).
fn plan_params(recorded: &Params, given: Option<&Params>) -> Result<Params, BuildError> {
    let mut left_out = Vec::new();
    let published = serde_json::to_value(recorded).expect("parameters serialise");
    report::unpublished_keys(&published, "", &mut left_out);
    let Some(given) = given else {
        return match left_out.first() {
            None => Ok(recorded.clone()),
            Some(key) => Err(ReplayError::PathLeftOut(key.to_string()).into()),
        };
    };
    let mut theirs = serde_json::to_value(given).expect("parameters serialise");
    report::publish_paths(&mut theirs);
    let mut ours = published;
    report::publish_paths(&mut ours);
    match shards::first_difference(&ours, &theirs, "") {
        None => Ok(given.clone()),
        Some(key) => Err(ReplayError::OtherParams(key).into()),
    }
}

/// Draws the plan of the build a manifest describes, reading `input` again (see
/// [`draw_plan_of`]).
pub fn draw_plan_from(
    manifest: &report::Manifest,
    tile: Option<&str>,
    input: &Path,
    templates: Option<&Path>,
) -> Result<Vec<u8>, BuildError> {
    let params = &manifest.params;
    let catalog = load_catalog(params, templates)?;
    let (data, plan, _, _) = read_and_analyse(input, params, &catalog, &NoProgress)?;
    draw_analysed(&data, &plan, params, tile, input)
}

/// The plan image of an analysed city, or of one of its tiles.
fn draw_analysed(
    data: &Dataset,
    plan: &Plan,
    params: &Params,
    tile: Option<&str>,
    input: &Path,
) -> Result<Vec<u8>, BuildError> {
    let bounds = match tile {
        None => None,
        Some(id) => {
            let tiles = shards::list_tiles(plan, params.tile_size, params.tile_origin);
            let t = tiles
                .iter()
                .find(|t| t.id == id)
                .ok_or_else(|| ReplayError::NoTile {
                    tile: id.to_string(),
                    input: input.display().to_string(),
                })?;
            Some(t.bounds)
        }
    };
    let grid = (params.tile_size, params.tile_origin);
    output::plan::View::fit(data, bounds)
        .and_then(|view| output::plan::draw_plan(data, plan, &view, grid, kura_view(params), None))
        .ok_or_else(|| ReplayError::NothingToDraw.into())
}

/// What `merge` writes from the input read again, as a full build writes it beside its
/// tiles: `plan.png` (with `draw_plan`) and `plan.gpkg` (when the formats name gpkg). The
/// input and parameters are the shards' (`manifest` is the merged one).
pub fn merge_plan_files(
    manifest: &report::Manifest,
    input: &Path,
    templates: Option<&Path>,
    draw_plan: bool,
    out: &Path,
) -> Result<(), BuildError> {
    let params = &manifest.params;
    let gpkg = params.output.formats.iter().any(|f| f == "gpkg");
    if !draw_plan && !gpkg {
        let _ = std::fs::remove_file(out.join(output::PLAN_GPKG));
        return Ok(());
    }
    let catalog = load_catalog(params, templates)?;
    let (data, plan, _, _) = read_and_analyse(input, params, &catalog, &NoProgress)?;
    if draw_plan {
        let png = draw_analysed(&data, &plan, params, None, input)?;
        let path = out.join("plan.png");
        output::atomic::write_atomic(&path, &png).map_err(|e| write_err(&path, e))?;
    }
    let path = out.join(output::PLAN_GPKG);
    if !gpkg {
        let _ = std::fs::remove_file(&path);
    } else {
        let band = |m: &crate::model::PlannedHouse| analyse::house::house_band(m, &catalog, params);
        let sources = output::gpkg::PlanSources {
            data: &data,
            plan: &plan,
            params,
            band: &band,
        };
        output::gpkg::write_plan(&path, &sources, manifest).map_err(gpkg_err)?;
    }
    Ok(())
}
