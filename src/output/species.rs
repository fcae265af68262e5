//! `<out>/species/`: for users who instance trees themselves (Blender's collection
//! instances, a game engine), the LOD0 of every species the build planted, grown from its
//! sample tree, and `placements.csv`: where each tree of the city stands, turned and scaled.
//!
//! With `trees.variants` (default 8) the tiles' grown trees are each one of their species'
//! variants, scaled: `<name>_<k>.obj` is variant k at LOD1 (as the tiles mesh it) at the
//! species' nominal height, and a placement's `variant`, `scale`, `squeeze` and `rotation`
//! put it where the tile has it: the tiles' trees are such copies. With `variants = 0` each tree is grown from its
//! own skeleton, and an instance of the sample is the same species at the same height and
//! turn, not the same branches.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::report::ManifestFile;
use super::{atomic, obj};
use crate::generate::species::SpeciesModels;
use crate::model::{Plan, PlannedBillboard, TreeForm};
use crate::templates::Catalog;

/// Writes the species directory (or removes an earlier build's when no tree has a species):
/// `models` ([`crate::generate::species::species_models`]) of the `trees` of `plan`. Returns
/// its files for the manifest. `alone`: whether this run holds the directory alone (not a
/// shard beside others), so it may sweep a killed run's temporaries.
pub fn write_species(
    out: &Path,
    plan: &Plan,
    trees: &[(&PlannedBillboard, &TreeForm)],
    models: &SpeciesModels,
    catalog: &Catalog,
    alone: bool,
) -> std::io::Result<Vec<ManifestFile>> {
    let dir = out.join("species");
    if trees.is_empty() {
        if dir.is_dir() {
            std::fs::remove_dir_all(&dir)?;
        }
        return Ok(Vec::new());
    }
    std::fs::create_dir_all(&dir)?;
    if alone {
        atomic::remove_leftover_temporaries(&dir);
    }
    let mut files = Vec::new();
    let mut put = |name: String, bytes: &[u8]| -> std::io::Result<()> {
        files.push(super::write_listed(
            out,
            format!("species/{name}"),
            &[bytes],
        )?);
        Ok(())
    };
    let mtl = obj::mtl::mtl_text_at("../tiles/textures/");
    let mut heights = BTreeMap::new();
    for s in &models.samples {
        let mut buf = Vec::new();
        obj::write_tile(&mut buf, &s.name, [0.0, 0.0], [&s.mesh]);
        put(format!("{}.obj", s.name), &buf)?;
        put(format!("{}.mtl", s.name), mtl.as_bytes())?;
        heights.insert(s.name.as_str(), s.height);
    }
    // Every variant a grown tree is, at LOD1 and the species' nominal height.
    for (name, k, mesh) in &models.variants {
        let mut buf = Vec::new();
        obj::write_tile(&mut buf, &format!("{name}_{k}"), [0.0, 0.0], [&**mesh]);
        put(format!("{name}_{k}.obj"), &buf)?;
        put(format!("{name}_{k}.mtl"), mtl.as_bytes())?;
    }
    let mut csv = String::from("id,tile,species,lot,x,y,z,rotation,scale,squeeze,style,variant\n");
    for (b, t) in trees {
        let Some(h) = heights.get(t.species.as_str()) else {
            continue;
        };
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.3},{:.3},{:.3},{:.2},{:.4},{:.4},{},{}",
            quote(&b.id),
            b.tile,
            t.species,
            quote(t.lot.as_deref().unwrap_or("")),
            b.at.x - plan.origin[0],
            b.ground,
            -(b.at.y - plan.origin[1]),
            b.facing.to_degrees(),
            b.height / h,
            t.squeeze,
            match catalog.species.get(&t.species) {
                Some(s) if t.grown => s.method,
                _ => "billboard",
            },
            models
                .variant_of(b, t)
                .map_or(String::new(), |k| k.to_string()),
        );
    }
    put("placements.csv".into(), csv.as_bytes())?;
    Ok(files)
}

/// A CSV field, quoted when it holds a comma, a quote or a line break (placements.csv and
/// crowds/*.csv).
pub(crate) fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
