//! Trees of a species (seeds 003 and 001 in the city): which species each tree is, whether it
//! is grown or drawn as its species' billboard, and how tall it may stand so that its crown
//! stays inside its lot (or, for a point in a street, its margin) and clear of buildings,
//! kura and fences by `trees.clearance`: a crown too wide for its room is first narrowed (down
//! to [`MIN_SQUEEZE`] of its width, as a gardener prunes a tree in a narrow yard), then the
//! whole tree made smaller; one that would stand under [`MIN_HEIGHT`] is left out.
//!
//! Runs after `billboards::plan_billboards` on the whole city's plan, so a tile regenerated
//! alone gets the same trees. The species is drawn from its own stream,
//! `feature_rng(seed, "trees/species", id)`, so the billboards' draws stay as they were.

use std::collections::{BTreeMap, HashMap};

use geo_types::Coord;
use rand::RngExt;

use super::obstacles::{boundary_distance, Obstacles};
use crate::model::{
    BillboardKind, Dataset, Plan, Skipped, TreeForm, Warning, WarningClass, MIN_SQUEEZE,
};
use crate::params::Params;
use crate::rng::feature_rng;
use crate::templates::species::SAMPLE_SEED;
use crate::templates::{Catalog, Species};

/// A grown tree fitted below this height, metres, is left out: there is no room for it.
pub const MIN_HEIGHT: f64 = 1.5;

/// Gives every tree of the plan its species, height and crown (see the module's doc).
pub fn plant(
    data: &Dataset,
    plan: &mut Plan,
    obstacles: &Obstacles,
    catalog: &Catalog,
    params: &Params,
) {
    if !params.trees.enabled || plan.billboards.is_empty() {
        return;
    }
    let lots = super::lot_index::LotIndex::new(data);
    let mut crowns = Crowns::default();
    let given: HashMap<&str, bool> = data
        .trees
        .iter()
        .flatten()
        .map(|p| (p.id.as_str(), p.height.is_some()))
        .collect();
    let file = params.layers.trees.file.clone();
    let [tlo, thi] = params.trees.height;
    let mut no_room = 0usize;
    let mut warned: BTreeMap<String, ()> = BTreeMap::new();
    let mut warnings = Vec::new();
    let mut skipped = Vec::new();
    for list in plan.billboards.values_mut() {
        list.retain_mut(|b| {
            if b.kind != BillboardKind::Tree {
                return true;
            }
            let district = b.district.as_deref();
            let style = params.trees_style(district);
            let lot = lots.containing(b.at);
            let lot_use = lot.map_or("", |l| data.lots[l].lot_use.name());
            let named = b.tree.take().map(|t| t.species);
            let species: Option<&Species> =
                match &named {
                    Some(name) => match catalog.species.get(name) {
                        Some(s) => Some(s),
                        None => {
                            warnings.push(Warning::feature(
                                "trees",
                                &file,
                                &b.id,
                                format!(
                                "{file}: trees {}: species `{name}` is not in templates/trees/ \
                                 ({}); one was drawn",
                                b.id,
                                catalog.species.keys().cloned().collect::<Vec<_>>().join(", ")
                            ),
                            ));
                            None
                        }
                    },
                    None => None,
                };
            let species = match species {
                Some(s) => s,
                None if style == "billboard" => return true,
                None => match draw(
                    catalog,
                    params,
                    district,
                    lot_use,
                    style,
                    params.seed_for("trees"),
                    &b.id,
                ) {
                    Ok(s) => s,
                    Err(key) => {
                        if warned.insert(key.clone(), ()).is_none() {
                            warnings.push(
                                Warning::new(
                                    WarningClass::Billboards,
                                    format!(
                                        "`{key}` names no species of method \"{style}\"; those \
                                         trees stay billboards (see `edo-city tree`)"
                                    ),
                                )
                                .for_key(&key),
                            );
                        }
                        return true;
                    }
                },
            };
            // A named species is grown by its own method whatever the style asks, unless the
            // style is billboards.
            let grown = style != "billboard";
            if !given.get(b.id.as_str()).copied().unwrap_or(false) {
                // The drawn height, moved from the trees' range into the species' own.
                let t = if thi > tlo {
                    ((b.height - tlo) / (thi - tlo)).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                b.height = species.height[0] + t * (species.height[1] - species.height[0]);
            }
            let ratio = match crowns.ratio(species) {
                Ok(r) => r,
                Err(e) => {
                    if warned.insert(species.name.clone(), ()).is_none() {
                        warnings.push(Warning::new(WarningClass::Billboards, e));
                    }
                    return true;
                }
            };
            let mut crown = ratio * b.height;
            let mut squeeze = 1.0;
            if grown {
                let edge = lot.map_or(f64::INFINITY, |l| {
                    boundary_distance(b.at, &data.lots[l].outline)
                });
                let room = (edge - params.trees.clearance).min(obstacle_room(
                    obstacles,
                    b.at,
                    crown,
                    params.trees.clearance,
                ));
                if crown > room && room >= crown * MIN_SQUEEZE {
                    squeeze = room / crown;
                    crown = room;
                } else if crown > room {
                    squeeze = MIN_SQUEEZE;
                    let fitted = b.height * room.max(0.0) / (crown * MIN_SQUEEZE);
                    if fitted < MIN_HEIGHT {
                        if given.contains_key(b.id.as_str()) {
                            skipped.push(Skipped {
                                layer: "trees".into(),
                                file: file.clone(),
                                id: b.id.clone(),
                                record: None,
                                reason: format!(
                                    "no room for the crown of a {}: {:.1} m to the nearest \
                                     building, fence or lot edge",
                                    species.name,
                                    room.max(0.0) + params.trees.clearance
                                ),
                            });
                        } else {
                            no_room += 1;
                        }
                        return false;
                    }
                    b.height = fitted;
                    crown = room;
                }
            }
            b.texture = crate::materials::MATERIALS[species.billboard as usize]
                .name
                .to_string();
            b.tree = Some(TreeForm {
                species: species.name.clone(),
                grown,
                lot: lot.map(|l| data.lots[l].id.clone()),
                crown,
                squeeze,
            });
            true
        });
    }
    if no_room > 0 {
        warnings.push(Warning::new(
            WarningClass::Billboards,
            format!(
                "{no_room} generated tree(s) had no room for a crown at least {MIN_HEIGHT} m \
                 tall and were left out (`trees.clearance`, `trees.min_spacing`)"
            ),
        ));
    }
    plan.warnings.extend(warnings);
    plan.skipped.extend(skipped);
}

/// A species for a tree of `lot_use` in `district`, by weight among those of method `style`;
/// `Err(key)` names the parameter whose row has none.
fn draw<'c>(
    catalog: &'c Catalog,
    params: &Params,
    district: Option<&str>,
    lot_use: &str,
    style: &str,
    seed: u64,
    id: &str,
) -> Result<&'c Species, String> {
    let key = || {
        let table = match district.and_then(|d| params.district.get(d)) {
            Some(d) if d.tree_species.is_some() => {
                format!("district.{}.tree_species", district.unwrap_or_default())
            }
            _ => "trees.species".to_string(),
        };
        format!(
            "{table}.{}",
            if lot_use.is_empty() {
                "default"
            } else {
                lot_use
            }
        )
    };
    let row = params.tree_species(district, lot_use).ok_or_else(key)?;
    let pool: Vec<(&Species, f64)> = row
        .iter()
        .filter_map(|(name, &w)| catalog.species.get(name).map(|s| (s, w)))
        .filter(|(s, w)| s.method == style && *w > 0.0)
        .collect();
    let total: f64 = pool.iter().map(|p| p.1).sum();
    if pool.is_empty() || total <= 0.0 {
        return Err(key());
    }
    let mut pick = feature_rng(seed, "trees/species", id).random::<f64>() * total;
    for (s, w) in &pool {
        pick -= w;
        if pick < 0.0 {
            return Ok(s);
        }
    }
    Ok(pool[pool.len() - 1].0)
}

/// The largest crown radius up to `crown` that stays `clearance` clear of every obstacle.
fn obstacle_room(obstacles: &Obstacles, at: Coord<f64>, crown: f64, clearance: f64) -> f64 {
    if !obstacles.hit(at, crown + clearance) {
        return crown;
    }
    let (mut lo, mut hi) = (0.0, crown);
    if obstacles.hit(at, clearance) {
        return 0.0;
    }
    // Twelve halvings: the radius to within crown / 4096.
    for _ in 0..12 {
        let mid = (lo + hi) / 2.0;
        if obstacles.hit(at, mid + clearance) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// Each species' crown radius as a share of its height, measured once on its sample tree.
#[derive(Default)]
struct Crowns(BTreeMap<String, Result<f64, String>>);

impl Crowns {
    fn ratio(&mut self, s: &Species) -> Result<f64, String> {
        self.0
            .entry(s.name.clone())
            .or_insert_with(|| {
                let h = s.nominal_height();
                let mut rng = feature_rng(SAMPLE_SEED, "tree", &s.name);
                let grown = s.grow_in_city(h, &mut rng)?;
                let (r, _) = grown.skeleton.extent(s.mesh.leaf_size);
                Ok(r / h)
            })
            .clone()
    }
}
