//! Rock gardens in temple lots (seed 000 in the city): each lot of `garden.uses` gets the
//! largest open rectangle (Ryoanji's 5:2, along the lot's longest edge) that stays inside the
//! lot and `garden.clearance` clear of every planned house, kura, wall and gate; its viewing
//! side faces the lot's gate (else the lot's longest edge, usually its street); the GA of
//! `growers::garden` designs its stones from `feature_rng(seed, "gardens", lot id)`. A lot
//! without such a rectangle of at least `garden.min_size` is reported as skipped with why.
//! The polygons of the gardens layer (`layers.gardens`) get a garden each, whatever their
//! lot's use, in the same way inside their own outline (keyed `area-<id>`, viewpoint the gate
//! of the lot holding the polygon's centre); a lot holding one gets no second garden.
//! Where a lot has its main hall (the first its use lists in `halls.uses`, planned before the
//! gardens), the garden faces the hall instead of the gate: a temple's garden is seen from its
//! hall's veranda, as Ryoanji's from its hojo. Runs before the billboards, which keep out of
//! the gardens.

use std::collections::{HashMap, HashSet};

use geo::{Centroid, Contains, Point};
use geo_types::{Coord, Polygon};
use rayon::prelude::*;

use super::obstacles::{boundary_distance, grid_free, Obstacles};
use super::product::{ByTile, Gardens, Halls};
use crate::growers::garden::ga::{self, Candidate, GaParams};
use crate::growers::garden::{Layout, Settings};
use crate::model::design::Design;
use crate::model::{
    tile::tile_id, Dataset, FenceKind, GardenArea, GardenStat, Lot, PlannedFence, PlannedGarden,
    Skipped,
};
use crate::params::Params;

/// Where one garden is to go: a lot of `garden.uses`, or a polygon of the gardens layer.
struct Site<'a> {
    /// The garden's name in object names and its RNG key (see [`PlannedGarden::lot`]).
    key: String,
    /// The lot, for the report (empty for a gardens-layer polygon in no lot).
    lot: String,
    /// The gardens-layer polygon's id and record, when it is one.
    area: Option<(String, usize)>,
    /// The ground it must fit in.
    outline: &'a Polygon<f64>,
    /// How far the garden keeps from `outline`'s edge: `garden.clearance` inside a lot, a
    /// hand's breadth inside a polygon the user drew as the garden itself.
    edge: f64,
    /// The lot's gate, the viewpoint.
    gate: Option<Coord<f64>>,
    /// Ground elevation.
    ground: f64,
}

/// Plans every garden and reports each lot; a gardens-layer polygon that gets none is also
/// skipped, with the reason. A lot's main hall among `halls`, else its first gate among
/// `fences`, is its viewpoint.
pub fn plan_gardens(
    data: &Dataset,
    fences: &ByTile<PlannedFence>,
    halls: &Halls,
    obstacles: &Obstacles,
    params: &Params,
) -> Gardens {
    let g = &params.garden;
    let mut out = Gardens::default();
    if !g.enabled {
        return out;
    }
    // A lot's viewpoint: the middle of its first hall (a temple's main hall, whose veranda
    // a garden is seen from, as Ryoanji's from its hojo), else its first gate.
    let mut gates: HashMap<&str, Coord<f64>> = HashMap::new();
    // The main hall is the first its lot's use lists, when it was placed.
    let mut main: HashMap<&str, &str> = HashMap::new();
    for r in &halls.reports {
        main.entry(r.lot.as_str())
            .or_insert(if r.placed { r.template.as_str() } else { "" });
    }
    let main_halls = halls
        .by_tile
        .values()
        .flatten()
        .filter(|h| main.get(h.lot.as_str()) == Some(&h.template.as_str()));
    for h in main_halls {
        gates.entry(h.lot.as_str()).or_insert(h.centre());
    }
    for f in fences.values().flatten() {
        if f.kind == FenceKind::Gate {
            gates.entry(f.id.as_str()).or_insert(Coord {
                x: (f.a.x + f.b.x) / 2.0,
                y: (f.a.y + f.b.y) / 2.0,
            });
        }
    }
    let layer_file = data
        .layers
        .iter()
        .find(|l| l.role == "gardens")
        .map(|l| l.file.clone())
        .unwrap_or_default();
    // The first lot (input order) holding the area's centre, found through the lots' boxes.
    let index = (!data.gardens.is_empty()).then(|| super::lot_index::LotIndex::new(data));
    let holder = |area: &GardenArea| -> Option<&Lot> {
        let c = area.outline.centroid()?;
        Some(&data.lots[index.as_ref()?.containing(c.0)?])
    };
    let mut sites: Vec<Site> = Vec::new();
    let mut drawn: HashSet<&str> = HashSet::new();
    for area in &data.gardens {
        let lot = holder(area);
        if let Some(l) = lot {
            drawn.insert(l.id.as_str());
        }
        sites.push(Site {
            key: format!("area-{}", area.id),
            lot: lot.map(|l| l.id.clone()).unwrap_or_default(),
            area: Some((area.id.clone(), area.record)),
            outline: &area.outline,
            edge: 0.1,
            gate: lot.and_then(|l| gates.get(l.id.as_str()).copied()),
            ground: lot.map_or(0.0, |l| l.ground),
        });
    }
    for lot in &data.lots {
        if g.uses.iter().any(|u| u == lot.lot_use.name()) && !drawn.contains(lot.id.as_str()) {
            sites.push(Site {
                key: lot.id.clone(),
                lot: lot.id.clone(),
                area: None,
                outline: &lot.outline,
                edge: g.clearance,
                gate: gates.get(lot.id.as_str()).copied(),
                ground: lot.ground,
            });
        }
    }
    let kept: HashMap<&str, &(usize, Design)> =
        data.designs.iter().map(|d| (d.1.lot.as_str(), d)).collect();
    let designed: Vec<Designed> = sites
        .par_iter()
        .map(|site| {
            let d = kept.get(site.key.as_str()).map(|d| &d.1);
            design(site, d, obstacles, params)
        })
        .collect();
    let mut refused: Vec<Option<String>> = designed.iter().map(|d| d.refused.clone()).collect();
    let mut results: Vec<(GardenStat, Option<PlannedGarden>)> =
        designed.into_iter().map(|d| (d.stat, d.garden)).collect();
    drop_overlaps(&mut results, &sites);
    for (k, (stat, _)) in results.iter_mut().enumerate() {
        if stat.kept && !stat.placed {
            refused[k] = Some(format!("the design's garden is not built: {}", stat.reason));
            stat.kept = false;
        }
    }
    refuse_designs(data, &sites, &refused, &mut out.skipped);
    for ((stat, garden), site) in results.into_iter().zip(&sites) {
        if let (false, Some((id, record))) = (stat.placed, &site.area) {
            out.skipped.push(Skipped {
                layer: "gardens".into(),
                file: layer_file.clone(),
                id: id.clone(),
                record: Some(*record),
                reason: stat.reason.clone(),
            });
        }
        out.reports.push(stat);
        if let Some(gd) = garden {
            out.by_tile.entry(gd.tile.clone()).or_default().push(gd);
        }
    }
    out
}

/// Lists as skipped each kept design that was not placed: refused by its site (`refused`,
/// by site), or for a garden this build does not have.
fn refuse_designs(
    data: &Dataset,
    sites: &[Site],
    refused: &[Option<String>],
    out: &mut Vec<Skipped>,
) {
    let at: HashMap<&str, usize> = sites
        .iter()
        .enumerate()
        .map(|(k, s)| (s.key.as_str(), k))
        .collect();
    for (record, d) in &data.designs {
        let reason = match at.get(d.lot.as_str()) {
            Some(&k) => match &refused[k] {
                Some(r) => r.clone(),
                None => continue,
            },
            None => format!(
                "a design for no garden of this build: `{}` is no lot of `garden.uses` and no \
                 polygon of the gardens layer (was the lot renamed, or its use changed?)",
                d.lot
            ),
        };
        out.push(Skipped {
            layer: "designs".into(),
            file: data
                .layers
                .iter()
                .find(|l| l.role == "designs")
                .map(|l| l.file.clone())
                .unwrap_or_default(),
            id: d.lot.clone(),
            record: Some(*record),
            reason,
        });
    }
}

/// Drops a garden placed through one before it. Sites are planned each on its own, so two
/// overlapping polygons of the gardens layer (or a drawn polygon reaching into a temple lot
/// with a garden of its own) gave gardens stacked through each other without a word. The
/// first in site order (the layer's records, then the lots) keeps its place; a later one
/// whose rectangle overlaps it (more than touching: each is shrunk by a centimetre) is not
/// built, and its report names the other.
fn drop_overlaps(results: &mut [(GardenStat, Option<PlannedGarden>)], sites: &[Site]) {
    use geo::{BoundingRect, Intersects};
    use rstar::primitives::{GeomWithData, Rectangle};
    use rstar::{RTree, AABB};
    let mut kept: RTree<GeomWithData<Rectangle<[f64; 2]>, usize>> = RTree::new();
    let mut plots: Vec<Option<Polygon<f64>>> = vec![None; results.len()];
    for i in 0..results.len() {
        let Some(garden) = &results[i].1 else {
            continue;
        };
        let plot = shrunk(&garden.outline(), 0.01);
        let Some(b) = plot.bounding_rect() else {
            continue;
        };
        let (lo, hi) = ([b.min().x, b.min().y], [b.max().x, b.max().y]);
        let under = kept
            .locate_in_envelope_intersecting(&AABB::from_corners(lo, hi))
            .map(|k| k.data)
            .filter(|&j| plots[j].as_ref().is_some_and(|p| p.intersects(&plot)))
            .min();
        match under {
            Some(j) => {
                let stat = &mut results[i].0;
                stat.placed = false;
                stat.reason = format!(
                    "its garden would overlap the one of {}, planned first: draw the gardens \
                     apart, or as one polygon",
                    sites[j].name()
                );
                stat.size = [0.0; 2];
                stat.fitness = 0.0;
                stat.stones = 0;
                stat.layout.clear();
                results[i].1 = None;
            }
            None => {
                kept.insert(GeomWithData::new(Rectangle::from_corners(lo, hi), i));
                plots[i] = Some(plot);
            }
        }
    }
}

/// A convex outline moved `by` metres in toward its centre (along each corner's diagonal).
fn shrunk(ring: &[Coord<f64>], by: f64) -> Polygon<f64> {
    let n = ring.len().max(1) as f64;
    let c = ring.iter().fold(Coord { x: 0.0, y: 0.0 }, |s, q| Coord {
        x: s.x + q.x / n,
        y: s.y + q.y / n,
    });
    let moved = ring
        .iter()
        .map(|&q| {
            let d = (q.x - c.x).hypot(q.y - c.y);
            let k = if d > by { (d - by) / d } else { 0.0 };
            Coord {
                x: c.x + (q.x - c.x) * k,
                y: c.y + (q.y - c.y) * k,
            }
        })
        .collect();
    Polygon::new(geo_types::LineString(moved), vec![])
}

impl Site<'_> {
    /// How a report names the site: the gardens layer's polygon, else the lot.
    fn name(&self) -> String {
        match &self.area {
            Some((id, _)) => format!("garden polygon `{id}`"),
            None => format!("lot `{}`", self.lot),
        }
    }
}

/// One site's garden, and why its kept design was refused (when it had one that was).
struct Designed {
    stat: GardenStat,
    garden: Option<PlannedGarden>,
    refused: Option<String>,
}

/// One site's garden: its place, then its design: the one kept for it in `garden.designs`
/// when it fits the place, else the GA's.
fn design(site: &Site, kept: Option<&Design>, obstacles: &Obstacles, p: &Params) -> Designed {
    let g = &p.garden;
    let stat = |placed, reason: String, size, fitness, stones| GardenStat {
        lot: site.lot.clone(),
        area: site.area.as_ref().map(|a| a.0.clone()),
        placed,
        reason,
        size,
        fitness,
        stones,
        ..GardenStat::default()
    };
    let Some((corner, angle, size)) = place(site, obstacles, p) else {
        let reason = format!(
            "no open rectangle of at least {} x {} m clear of buildings and walls by {} m",
            g.min_size * 2.5,
            g.min_size,
            g.clearance
        );
        let refused = kept.map(|_| format!("the design's garden is not built: {reason}"));
        return Designed {
            stat: stat(false, reason, [0.0; 2], 0.0, 0),
            garden: None,
            refused,
        };
    };
    let s = Settings::sized(size[0], size[1]);
    let refused = kept.and_then(|d| d.outside(size[0], size[1]));
    let (best, from_design) = match kept {
        Some(d) if refused.is_none() => {
            (Candidate::of(Layout::from_rows(&d.stone_rows()), &s), true)
        }
        _ => {
            let gp = GaParams {
                population: g.population,
                gathered: true,
                ..GaParams::default()
            };
            let mut rng = crate::rng::feature_rng(p.seed_for("gardens"), "gardens", &site.key);
            let (pop, _) = ga::run(&s, &gp, g.generations, &mut rng);
            (pop.best().clone(), false)
        }
    };
    let stones: Vec<[f64; 4]> = best.layout.to_rows();
    let (sn, cs) = angle.sin_cos();
    let centre = Coord {
        x: corner.x + size[0] / 2.0 * cs - size[1] / 2.0 * sn,
        y: corner.y + size[0] / 2.0 * sn + size[1] / 2.0 * cs,
    };
    let garden = PlannedGarden {
        lot: site.key.clone(),
        corner,
        angle,
        size,
        ground: site.ground,
        tile: tile_id(centre, p.tile_size, p.tile_origin),
        stones: stones.clone(),
    };
    let scores = crate::growers::garden::rules::WEIGHTS
        .iter()
        .zip(best.scores)
        .map(|((rule, _), v)| (rule.to_string(), v))
        .collect();
    Designed {
        stat: GardenStat {
            scores,
            key: site.key.clone(),
            corner: [corner.x, corner.y],
            angle,
            ground: site.ground,
            layout: stones,
            kept: from_design,
            ..stat(
                true,
                String::new(),
                size,
                best.fitness,
                best.layout.stones.len(),
            )
        },
        garden: Some(garden),
        refused: refused.map(|r| format!("{r}; the GA designed the garden instead")),
    }
}

/// The largest open rectangle of the site: (corner of its viewing side, that side's angle,
/// [width, depth]).
fn place(site: &Site, obstacles: &Obstacles, p: &Params) -> Option<(Coord<f64>, f64, [f64; 2])> {
    let (g, outline, gate) = (&p.garden, site.outline, site.gate);
    let ring = &outline.exterior().0;
    // The lot's longest edge sets the axes.
    let theta = ring
        .windows(2)
        .max_by(|a, b| {
            let l = |w: &[Coord<f64>]| (w[1].x - w[0].x).hypot(w[1].y - w[0].y);
            l(a).total_cmp(&l(b))
        })
        .map(|w| (w[1].y - w[0].y).atan2(w[1].x - w[0].x))?;
    let (sn, cs) = theta.sin_cos();
    let to_local = |q: Coord<f64>| (q.x * cs + q.y * sn, -q.x * sn + q.y * cs);
    let to_map = |u: f64, v: f64| Coord {
        x: u * cs - v * sn,
        y: u * sn + v * cs,
    };
    let (mut u0, mut u1, mut v0, mut v1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &q in ring {
        let (u, v) = to_local(q);
        u0 = u0.min(u);
        u1 = u1.max(u);
        v0 = v0.min(v);
        v1 = v1.max(v);
    }
    if !(u1 - u0).is_finite() || u1 - u0 > 5000.0 || v1 - v0 > 5000.0 {
        return None;
    }
    let near = obstacles.near(outline, g.clearance);
    let free = |q: Coord<f64>| {
        outline.contains(&Point(q)) && boundary_distance(q, outline) >= site.edge && !near.hit(q)
    };
    let mut w = g.max_width.min(u1 - u0);
    while w * 0.4 >= g.min_size {
        let d = w * 0.4;
        let step = (w / 4.0).max(0.5);
        let (nx, ny) = ((w / 2.0).ceil() as usize + 1, (d / 2.0).ceil() as usize + 1);
        let (mut v, mut miss) = (v0, None);
        while v + d <= v1 {
            let mut u = u0;
            while u + w <= u1 {
                let at = |i: usize, j: usize| {
                    to_map(
                        u + w * i as f64 / (nx - 1) as f64,
                        v + d * j as f64 / (ny - 1) as f64,
                    )
                };
                if grid_free(nx, ny, at, free, &mut miss) {
                    return Some(orient((u, v, w, d), theta, gate, &to_map));
                }
                u += step;
            }
            v += step;
        }
        w *= 0.85;
    }
    None
}

/// The viewing side of a rectangle (u, v, w, d) in the lot's frame: the side nearest the
/// gate, else the one along the lot's longest edge (v = min).
fn orient(
    (u, v, w, d): (f64, f64, f64, f64),
    theta: f64,
    gate: Option<Coord<f64>>,
    to_map: &dyn Fn(f64, f64) -> Coord<f64>,
) -> (Coord<f64>, f64, [f64; 2]) {
    use std::f64::consts::{FRAC_PI_2, PI};
    // (corner, angle, size, the side's midpoint).
    let sides = [
        (to_map(u, v), theta, [w, d], to_map(u + w / 2.0, v)),
        (
            to_map(u + w, v + d),
            theta + PI,
            [w, d],
            to_map(u + w / 2.0, v + d),
        ),
        (
            to_map(u, v + d),
            theta - FRAC_PI_2,
            [d, w],
            to_map(u, v + d / 2.0),
        ),
        (
            to_map(u + w, v),
            theta + FRAC_PI_2,
            [d, w],
            to_map(u + w, v + d / 2.0),
        ),
    ];
    let k = match gate {
        None => 0,
        Some(gp) => (0..4)
            .min_by(|&a, &b| {
                let dist = |k: usize| (sides[k].3.x - gp.x).hypot(sides[k].3.y - gp.y);
                dist(a).total_cmp(&dist(b))
            })
            .unwrap_or(0),
    };
    (sides[k].0, sides[k].1, sides[k].2)
}
