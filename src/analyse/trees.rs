//! Trees of a species (seeds 003 and 001 in the city): which species each tree is, whether it
//! is grown or drawn as its species' billboard, and how tall it may stand so that its crown
//! stays inside its lot (or, for a point in a street, its margin) and clear of buildings,
//! kura and fences by `trees.clearance`: a crown too wide for its room is first narrowed (down
//! to [`MIN_SQUEEZE`] of its width, as a gardener prunes a tree in a narrow yard), then the
//! whole tree made smaller; one that would stand under [`MIN_HEIGHT`] is left out.
//!
//! Runs after `billboards::plan_billboards` on the whole city's billboards, so a tile regenerated
//! alone gets the same trees. The species is drawn from its own stream,
//! `feature_rng(seed, "trees/species", id)`, so the billboards' draws stay as they were.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use geo_types::Coord;
use rand::RngExt;

use super::obstacles::{boundary_distance, Obstacles};
use super::product::{ByTile, Notes};
use crate::model::{
    BillboardKind, Dataset, PlannedBillboard, Skipped, TreeForm, Warning, WarningClass, MIN_SQUEEZE,
};
use crate::params::Params;
use crate::rng::feature_rng;
use crate::templates::species::SAMPLE_SEED;
use crate::templates::{Catalog, Species};

/// A grown tree fitted below this height, metres, is left out: there is no room for it.
pub const MIN_HEIGHT: f64 = 1.5;

/// Gives every tree among `billboards` its species, height and crown, or leaves it out
/// (see the module's doc).
pub fn plant(
    data: &Dataset,
    billboards: &mut ByTile<PlannedBillboard>,
    obstacles: &Obstacles,
    catalog: &Catalog,
    params: &Params,
) -> Notes {
    if !params.trees.enabled || billboards.is_empty() {
        return Notes::default();
    }
    let mut planting = Planting {
        data,
        obstacles,
        catalog,
        params,
        lots: super::lot_index::LotIndex::new(data),
        crowns: Crowns::default(),
        given: (data.trees.iter().flatten())
            .map(|p| (p.id.as_str(), p.height.is_some()))
            .collect(),
        file: params.layers.trees.file.clone(),
        no_room: 0,
        warned: BTreeSet::new(),
        warnings: Vec::new(),
        skipped: Vec::new(),
    };
    for list in billboards.values_mut() {
        list.retain_mut(|b| b.kind != BillboardKind::Tree || planting.tree(b));
    }
    if planting.no_room > 0 {
        planting.warnings.push(Warning::new(
            WarningClass::Billboards,
            format!(
                "{} generated tree(s) had no room for a crown at least {MIN_HEIGHT} m \
                 tall and were left out (`trees.clearance`, `trees.min_spacing`)",
                planting.no_room
            ),
        ));
    }
    Notes {
        warnings: planting.warnings,
        skipped: planting.skipped,
    }
}

/// What planting the city's trees reads and what it has noticed so far.
struct Planting<'a> {
    data: &'a Dataset,
    obstacles: &'a Obstacles,
    catalog: &'a Catalog,
    params: &'a Params,
    lots: super::lot_index::LotIndex<'a>,
    crowns: Crowns,
    /// The trees of the points layer, with whether the layer gives their height.
    given: HashMap<&'a str, bool>,
    file: String,
    /// Generated trees left out for want of room (one warning for all).
    no_room: usize,
    /// The keys and species already warned of.
    warned: BTreeSet<String>,
    warnings: Vec<Warning>,
    skipped: Vec<Skipped>,
}

impl<'a> Planting<'a> {
    /// Plants tree `b`: its species, height and crown; `false` when it is left out (no room).
    /// A tree that stays a billboard is kept as it is.
    fn tree(&mut self, b: &mut PlannedBillboard) -> bool {
        let (params, data) = (self.params, self.data);
        let district = b.district.as_deref();
        let style = params.trees_style(district);
        let lot = self.lots.containing(b.at);
        let lot_use = lot.map_or("", |l| data.lots[l].lot_use.name());
        let named = b.tree.take().map(|t| t.species);
        let species = match self.named(b, named.as_deref()) {
            Some(s) => s,
            None if style == "billboard" => return true,
            None => match draw(
                self.catalog,
                params,
                district,
                lot_use,
                style,
                params.seed_for("trees"),
                &b.id,
            ) {
                Ok(s) => s,
                Err(key) => {
                    let warning = Warning::new(
                        WarningClass::Billboards,
                        format!(
                            "`{key}` names no species of method \"{style}\"; those trees stay \
                             billboards (see `edo-city tree`)"
                        ),
                    )
                    .for_key(&key);
                    self.warn_once(key, warning);
                    return true;
                }
            },
        };
        // A named species is grown by its own method whatever the style asks, unless the
        // style is billboards.
        let grown = style != "billboard";
        if !self.given.get(b.id.as_str()).copied().unwrap_or(false) {
            b.height = in_species_range(b.height, params.trees.height, species);
        }
        let ratio = match self.crowns.ratio(species) {
            Ok(r) => r,
            Err(e) => {
                let warning = Warning::new(WarningClass::Billboards, e);
                self.warn_once(species.name.clone(), warning);
                return true;
            }
        };
        let (mut crown, mut squeeze) = (ratio * b.height, 1.0);
        if grown {
            match self.fit(b, species, lot, crown) {
                Some(fitted) => (crown, squeeze) = fitted,
                None => return false,
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
    }

    /// The species the points layer names for `b`, if it names one the catalog has (else a
    /// warning, and one is drawn).
    fn named(&mut self, b: &PlannedBillboard, named: Option<&str>) -> Option<&'a Species> {
        let name = named?;
        let found = self.catalog.species.get(name);
        if found.is_none() {
            let file = &self.file;
            self.warnings.push(Warning::feature(
                "trees",
                file,
                &b.id,
                format!(
                    "{file}: trees {}: species `{name}` is not in templates/trees/ ({}); one \
                     was drawn",
                    b.id,
                    (self.catalog.species.keys().cloned())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        found
    }

    /// `warning`, the first time `key` has one.
    fn warn_once(&mut self, key: String, warning: Warning) {
        if self.warned.insert(key) {
            self.warnings.push(warning);
        }
    }

    /// A grown tree's crown fitted to its room (the lot's edge, buildings, kura and fences
    /// by the clearance): narrowed first, then the tree made smaller (`b.height`). The crown
    /// and squeeze, or `None` when the tree would stand under [`MIN_HEIGHT`] (a tree of the
    /// points layer is then skipped with the reason, a generated one counted).
    fn fit(
        &mut self,
        b: &mut PlannedBillboard,
        species: &Species,
        lot: Option<usize>,
        crown: f64,
    ) -> Option<(f64, f64)> {
        let clearance = self.params.trees.clearance;
        let edge = lot.map_or(f64::INFINITY, |l| {
            boundary_distance(b.at, &self.data.lots[l].outline)
        });
        let room = (edge - clearance).min(obstacle_room(self.obstacles, b.at, crown, clearance));
        // (Not `crown <= room`: a room that is not a number leaves the crown as it is.)
        let too_wide = crown > room;
        if !too_wide {
            return Some((crown, 1.0));
        }
        if room >= crown * MIN_SQUEEZE {
            return Some((room, room / crown));
        }
        let fitted = b.height * room.max(0.0) / (crown * MIN_SQUEEZE);
        if fitted < MIN_HEIGHT {
            if self.given.contains_key(b.id.as_str()) {
                self.skipped.push(Skipped {
                    layer: "trees".into(),
                    file: self.file.clone(),
                    id: b.id.clone(),
                    record: None,
                    reason: format!(
                        "no room for the crown of a {}: {:.1} m to the nearest building, \
                         fence or lot edge",
                        species.name,
                        room.max(0.0) + clearance
                    ),
                });
            } else {
                self.no_room += 1;
            }
            return None;
        }
        b.height = fitted;
        Some((room, MIN_SQUEEZE))
    }
}

/// A drawn height moved from the trees' range `range` into the species' own.
fn in_species_range(height: f64, range: [f64; 2], species: &Species) -> f64 {
    let [lo, hi] = range;
    let t = if hi > lo {
        ((height - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    species.height[0] + t * (species.height[1] - species.height[0])
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
