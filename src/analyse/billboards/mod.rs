//! People and trees, section 4.4 of the paper: billboard points, from point layers or drawn
//! from the spatial probability distributions of the parameter file.
//!
//! The process is declared and deterministic: a Poisson process per source (a piece of street
//! centreline for people, a lot for trees), each source with its own RNG seeded by (seed,
//! layer, source id); points falling in a building, kura or fence (the [`Obstacles`] R-tree)
//! or outside the source are dropped; then a hard-core thinning gives the Poisson-disk
//! spacing: points are visited in the order of a random key drawn with each point and kept
//! when no kept point lies within `min_spacing`. Neither step depends on input order or on
//! the thread count.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use geo::{Area, BoundingRect, Centroid, Contains};
use geo_types::{Coord, Polygon};
use rand::RngExt;
use rand_distr::{Distribution, Poisson};
use rayon::prelude::*;

use super::obstacles::{boundary_distance, Obstacles};
use super::product::{Billboards, ByTile, Notes};
use crate::model::tile::tile_id;
use crate::model::{
    sane, BillboardKind, Dataset, PlannedBillboard, PlannedHouse, PointFeature, Skipped, TileId,
    FAR,
};
use crate::params::Params;
use crate::rng::feature_rng;
use crate::templates::Catalog;
use kind::Kind;
use surroundings::Surroundings;
use thinning::{cap_tiles, keep_spaced, thin};

mod kind;
mod surroundings;
mod thinning;

/// Streets are cut into pieces no longer than this, each a source of its own.
const PIECE: f64 = 20.0;

/// A source of generated points: a street piece or a lot.
struct Source<'a> {
    /// The lot's id, or the street piece's (made here); borrowed where it can be, since a
    /// city has a source for nearly every lot.
    id: std::borrow::Cow<'a, str>,
    /// Where its points may fall: see [`Source::tiles`].
    reach: Reach,
    district: Option<&'a str>,
    /// Expected points in the source.
    expected: f64,
    shape: SourceShape<'a>,
}

/// The ground a source's points fall on, for the tiles it is charged to.
#[derive(Clone, Copy)]
enum Reach {
    /// A street piece: the tile of its middle.
    Point(Coord<f64>),
    /// A lot: every tile its bounding box overlaps (see [`tiles_under`]).
    Box {
        bb: geo_types::Rect<f64>,
        centroid: Coord<f64>,
    },
}

impl Source<'_> {
    /// The tiles its points may fall in, with the share of its area in each: its expected
    /// count is charged against their `max_points_per_tile` by these shares. Worked out when
    /// asked, not held: at a million lots the held names took a hundred megabytes.
    fn tiles(&self, p: &Params) -> Vec<(String, f64)> {
        match self.reach {
            Reach::Point(c) => vec![(tile_id(c, p.tile_size, p.tile_origin), 1.0)],
            Reach::Box { bb, centroid } => tiles_under(bb, centroid, p),
        }
    }
}

enum SourceShape<'a> {
    /// A street piece from `a` to `b`; points within `half` of it across.
    Street {
        a: Coord<f64>,
        b: Coord<f64>,
        half: f64,
    },
    /// A lot; points anywhere inside it, `clearance` from its edges. `cover` is how much of
    /// the bounding box is planted (expected / points drawn in the box).
    Lot {
        outline: &'a Polygon<f64>,
        ground: f64,
        cover: f64,
    },
}

/// A generated or given point with its thinning key.
struct Candidate {
    key: u64,
    b: PlannedBillboard,
}

/// Plans the people and trees of the whole city: from the point layers when the data has
/// them, else generated, the generated ones only in the tiles `built` (houses, fences, halls
/// and gardens; trees behind the `houses`).
pub fn plan_billboards(
    data: &Dataset,
    built: &BTreeSet<TileId>,
    houses: &ByTile<PlannedHouse>,
    obstacles: &Obstacles,
    catalog: &Catalog,
    params: &Params,
) -> Billboards {
    let people = &params.people;
    let trees = &params.trees;
    let mut out = Billboards::default();
    if !people.enabled && !trees.enabled {
        return out;
    }
    let near = Surroundings::new(data);
    let mut all = Vec::new();
    let mut clips = std::collections::BTreeMap::new();
    // Walkers placed, per stretch and district: the crowds' counts are of those written
    // (the spacing, the tile cap and the built tiles leave some out after the walk).
    let mut placed: std::collections::BTreeMap<String, std::collections::BTreeMap<String, usize>> =
        std::collections::BTreeMap::new();
    for kind in [BillboardKind::Person, BillboardKind::Tree] {
        let k = Kind::of(kind, params);
        if !k.enabled {
            continue;
        }
        let given = match kind {
            BillboardKind::Person => data.people.as_ref(),
            BillboardKind::Tree => data.trees.as_ref(),
        };
        // Given points are all kept; generated ones are thinned to the minimum spacing.
        let spacing = if given.is_some() { 0.0 } else { k.min_spacing };
        let candidates = match given {
            Some(points) => from_points(points, &k, &near, obstacles, params, &mut out.notes),
            None => {
                let mut sources = match kind {
                    BillboardKind::Person => street_sources(data, &near, params),
                    BillboardKind::Tree => lot_sources(data, houses, catalog, params),
                };
                // Generated billboards dress the built city: a tile with no house, kura or
                // fence gets none (streets often run on past the lots).
                sources.retain(|s| s.tiles(params).iter().any(|t| built.contains(&t.0)));
                let scale = budget(&sources, &k, params, &mut out.notes.warnings);
                let drawn: Vec<Vec<Candidate>> = sources
                    .par_iter()
                    .map(|s| {
                        draw(
                            s,
                            s.tiles(params)
                                .iter()
                                .filter_map(|t| scale.get(&t.0))
                                .copied()
                                .reduce(f64::min),
                            &k,
                            &near,
                            obstacles,
                            params,
                        )
                    })
                    .collect();
                drop(sources);
                super::concat(drawn)
            }
        };
        let mut kept = thin(candidates, spacing);
        let walks = |d: Option<&str>| params.crowd_walks(d);
        let any_walk = walks(None) || params.district.keys().any(|d| walks(Some(d)));
        if kind == BillboardKind::Person && given.is_none() && any_walk {
            let walked = super::crowds::walk(kept, data, params, &|c| near.at(c, None).1, &|c| {
                obstacles.hit(c, k.clearance)
            });
            kept = keep_spaced(walked.people, spacing);
            out.crowds = walked.stats;
            out.notes.warnings.extend(walked.warnings);
            clips = walked.walks;
        }
        let capped = cap_tiles(kept, &k, &mut out.notes.warnings);
        all.extend(capped.into_iter().map(|b| (b, given.is_some())));
    }
    for (b, given) in all {
        // Built before, or by a point of the layers met earlier in this loop.
        let is_built = built.contains(&b.tile) || out.tiles.contains(&b.tile);
        if let Some(w) = clips.remove(&b.id) {
            if given || is_built {
                *placed
                    .entry(w.street.clone())
                    .or_default()
                    .entry(b.district.clone().unwrap_or_default())
                    .or_default() += 1;
                out.walks.entry(b.tile.clone()).or_default().push(w);
            }
        }
        if given {
            if !is_built {
                out.tiles.insert(b.tile.clone());
            }
        } else if !is_built {
            continue; // strayed over a tile border into a tile with nothing built
        }
        out.by_tile.entry(b.tile.clone()).or_default().push(b);
    }
    for stat in &mut out.crowds {
        stat.districts = placed.remove(&stat.street).unwrap_or_default();
        stat.agents = stat.districts.values().sum();
    }
    out
}

/// People along every street centreline, in pieces of at most [`PIECE`] metres.
fn street_sources<'a>(data: &'a Dataset, near: &Surroundings<'a>, p: &Params) -> Vec<Source<'a>> {
    let mut out = Vec::new();
    for s in &data.streets {
        for (k, line) in s.line.lines().enumerate() {
            let d = line.end - line.start;
            let len = d.x.hypot(d.y);
            if !(sane(line.start) && sane(line.end) && len > 0.0) {
                continue;
            }
            let pieces = (len / PIECE).ceil().max(1.0) as usize;
            for j in 0..pieces {
                let at = |t: f64| line.start + (line.end - line.start) * t;
                let (a, b) = (
                    at(j as f64 / pieces as f64),
                    at((j + 1) as f64 / pieces as f64),
                );
                let mid = at((j as f64 + 0.5) / pieces as f64);
                let district = near.district(mid);
                let density =
                    p.district_density(district, |d| d.people_per_100m, p.people.per_100m);
                out.push(Source {
                    id: format!("{}/{}", super::crowds::stretch_id(&s.id, k), j + 1).into(),
                    reach: Reach::Point(mid),
                    district,
                    expected: len / pieces as f64 / 100.0 * density,
                    shape: SourceShape::Street {
                        a,
                        b,
                        half: (s.width / 2.0 - p.people.edge_margin).max(0.0),
                    },
                });
            }
        }
    }
    out
}

/// Trees in estate lots (`trees.uses`) over the whole lot, and in town lots behind the
/// house (the obstacles keep them out of the house and its kura).
fn lot_sources<'a>(
    data: &'a Dataset,
    houses: &ByTile<PlannedHouse>,
    catalog: &Catalog,
    p: &Params,
) -> Vec<Source<'a>> {
    let t = &p.trees;
    // How deep each planned town lot's house is, as a share of the lot's depth.
    let mut built: HashMap<&str, f64> = HashMap::new();
    for m in houses.values().flatten().filter(|m| !m.is_footprint()) {
        let f = super::house::frame_of(m);
        let depth = super::house::local_ring(m, f)
            .iter()
            .map(|q| q[1])
            .fold(0.0, f64::max);
        let end = super::house::house_end(m, depth, catalog, p);
        built.insert(m.id.as_str(), if depth > 0.0 { end / depth } else { 1.0 });
    }
    // Nearly every lot is a source: one allocation, not a doubling chain of copies.
    let mut out = Vec::with_capacity(data.lots.len());
    for lot in &data.lots {
        let district = lot.district.as_deref();
        let (density, open) = if t.uses.iter().any(|u| u == lot.lot_use.name()) {
            (
                p.district_density(district, |d| d.trees_per_ha, t.per_ha),
                1.0,
            )
        } else if let Some(share) = built.get(lot.id.as_str()) {
            let d = p.district_density(district, |d| d.trees_per_ha_machiya, t.per_ha_machiya);
            (d, (1.0 - share).max(0.0))
        } else {
            continue;
        };
        let (Some(bb), Some(c)) = (lot.outline.bounding_rect(), lot.outline.centroid()) else {
            continue;
        };
        if !(sane(bb.min()) && sane(bb.max())) {
            continue;
        }
        let box_area = bb.width() * bb.height();
        let planted = lot.outline.unsigned_area() * open;
        if !(density > 0.0 && planted > 0.0 && box_area.is_finite()) {
            continue;
        }
        out.push(Source {
            id: lot.id.as_str().into(),
            reach: Reach::Box { bb, centroid: c.0 },
            district,
            expected: planted * density / 10_000.0,
            shape: SourceShape::Lot {
                outline: &lot.outline,
                ground: lot.ground,
                cover: planted / box_area,
            },
        });
    }
    out
}

/// The tiles a lot's bounding box overlaps, with the share of the box in each; a box over
/// more than 4,096 tiles (damaged data) is charged to its centroid's tile alone.
fn tiles_under(bb: geo_types::Rect<f64>, centroid: Coord<f64>, p: &Params) -> Vec<(String, f64)> {
    let (size, [ox, oy]) = (p.tile_size, p.tile_origin);
    let cols =
        ((bb.min().x - ox) / size).floor() as i64..=((bb.max().x - ox) / size).floor() as i64;
    let rows =
        ((bb.min().y - oy) / size).floor() as i64..=((bb.max().y - oy) / size).floor() as i64;
    let area = bb.width() * bb.height();
    let n = (cols.end() - cols.start() + 1).saturating_mul(rows.end() - rows.start() + 1);
    if area.is_nan() || area <= 0.0 || n > 4096 {
        return vec![(tile_id(centroid, size, p.tile_origin), 1.0)];
    }
    let mut out = Vec::new();
    for c in cols {
        for r in rows.clone() {
            let (x0, y0) = (ox + c as f64 * size, oy + r as f64 * size);
            let w = (bb.max().x.min(x0 + size) - bb.min().x.max(x0)).max(0.0);
            let h = (bb.max().y.min(y0 + size) - bb.min().y.max(y0)).max(0.0);
            if w * h > 0.0 {
                out.push((format!("{c}_{r}"), w * h / area));
            }
        }
    }
    out
}

/// Density scale per tile: a tile whose sources expect more than `max_points_per_tile`
/// points has its densities scaled down to it, with a warning.
fn budget(
    sources: &[Source],
    k: &Kind,
    p: &Params,
    warnings: &mut Vec<crate::model::Warning>,
) -> BTreeMap<String, f64> {
    let mut expected: BTreeMap<String, f64> = BTreeMap::new();
    for s in sources {
        for (tile, share) in s.tiles(p) {
            *expected.entry(tile).or_default() += s.expected * share;
        }
    }
    let mut scale = BTreeMap::new();
    for (tile, e) in expected {
        if e > k.max_per_tile as f64 {
            let f = k.max_per_tile as f64 / e;
            warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Billboards,
                    format!(
                        "{}: tile {tile} would get about {e:.0} {} at `{}`, more than \
                         max_points_per_tile = {}; its density was scaled by {f:.4}",
                        k.layer, k.layer, k.density_key, k.max_per_tile
                    ),
                )
                .for_key(&format!("{}.max_points_per_tile", k.layer)),
            );
            scale.insert(tile.to_string(), f);
        }
    }
    scale
}

/// The Poisson process of one source, points in obstacles or outside the source dropped.
fn draw(
    s: &Source,
    scale: Option<f64>,
    k: &Kind,
    near: &Surroundings,
    obstacles: &Obstacles,
    p: &Params,
) -> Vec<Candidate> {
    let mut rng = feature_rng(p.seed_for(k.layer), k.layer, &s.id);
    let tile_of = |c: Coord<f64>| tile_id(c, p.tile_size, p.tile_origin);
    // Lots draw in their bounding box and keep what falls on planted ground.
    let mean = match s.shape {
        SourceShape::Street { .. } => s.expected,
        SourceShape::Lot { cover, .. } => s.expected / cover,
    } * scale.unwrap_or(1.0);
    let n = match Poisson::new(mean) {
        Ok(d) if mean > 0.0 => (d.sample(&mut rng) as usize).min(4 * k.max_per_tile),
        _ => 0,
    };
    let mut out = Vec::new();
    for i in 0..n {
        let id = format!("{}/{}", s.id, i + 1);
        let (at, along, place) = match s.shape {
            SourceShape::Street { a, b, half } => {
                let d = b - a;
                let len = d.x.hypot(d.y);
                let across = Coord {
                    x: -d.y / len,
                    y: d.x / len,
                };
                let t = rng.random::<f64>();
                let off = (2.0 * rng.random::<f64>() - 1.0) * half;
                let at = a + d * t + across * off;
                // Counted in the district whose density it was drawn at.
                let ground = near.at(at, None).1;
                (at, d.y.atan2(d.x), (s.district.map(str::to_string), ground))
            }
            SourceShape::Lot {
                outline, ground, ..
            } => {
                let bb = outline.bounding_rect().expect("sources have a box");
                let at = Coord {
                    x: bb.min().x + rng.random::<f64>() * bb.width(),
                    y: bb.min().y + rng.random::<f64>() * bb.height(),
                };
                let inside = outline.contains(&at) && boundary_distance(at, outline) >= k.clearance;
                if !inside {
                    continue;
                }
                let district = s.district.map(str::to_string);
                let ground = near.dem.map_or(ground, |dem| dem.sample(at).z);
                (at, 0.0, (district, ground))
            }
        };
        // Dress before testing, so a point's values do not depend on the points dropped.
        let c = k.dress(&mut rng, id, at, along, place, tile_of);
        if !obstacles.hit(at, k.clearance) {
            out.push(c);
        }
    }
    out
}

/// Points from a point layer: each with its own RNG for what the layer does not give; a
/// point inside a building, kura or fence is skipped and reported.
fn from_points(
    points: &[PointFeature],
    k: &Kind,
    near: &Surroundings,
    obstacles: &Obstacles,
    p: &Params,
    notes: &mut Notes,
) -> Vec<Candidate> {
    let tile_of = |c: Coord<f64>| tile_id(c, p.tile_size, p.tile_origin);
    let mut out = Vec::new();
    for f in points {
        if !sane(f.at) {
            notes.skipped.push(Skipped {
                layer: k.layer.into(),
                file: k.file.into(),
                id: f.id.clone(),
                record: Some(f.record),
                reason: format!("the point lies {FAR} m or more from the CRS's origin"),
            });
            continue;
        }
        if obstacles.hit(f.at, 0.0) {
            notes.skipped.push(Skipped {
                layer: k.layer.into(),
                file: k.file.into(),
                id: f.id.clone(),
                record: Some(f.record),
                reason: "the point lies inside a building, kura or fence".into(),
            });
            continue;
        }
        let mut rng = feature_rng(p.seed_for(k.layer), k.layer, &f.id);
        let along = near.street_angle(f.at);
        let mut c = k.dress(
            &mut rng,
            f.id.clone(),
            f.at,
            along,
            near.at(f.at, None),
            tile_of,
        );
        if let Some(h) = f.height {
            c.b.height = h;
        }
        if let Some(species) = &f.species {
            // Resolved against the catalog, with the lot and crown, by `trees::plant`.
            c.b.tree = Some(crate::model::TreeForm {
                species: species.clone(),
                grown: false,
                lot: None,
                crown: 0.0,
                squeeze: 1.0,
            });
        }
        if let Some(t) = &f.texture {
            match texture_of(t, k.textures) {
                Some(name) => c.b.texture = name,
                None => notes.warnings.push(crate::model::Warning::feature(
                    k.layer,
                    k.file,
                    &f.id,
                    format!(
                        "{}: {} {}: texture `{t}` is neither a library material nor a number \
                         from 1 to {}; one was drawn",
                        k.file,
                        k.layer,
                        f.id,
                        k.textures.len()
                    ),
                )),
            }
        }
        out.push(c);
    }
    out
}

/// A texture field's value: a library material name, or a number into `textures`.
fn texture_of(raw: &str, textures: &[String]) -> Option<String> {
    let raw = raw.trim();
    if let Ok(n) = raw.parse::<usize>() {
        return (1..=textures.len())
            .contains(&n)
            .then(|| textures[n - 1].clone());
    }
    crate::materials::find(raw).map(|_| raw.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lot_over_four_tiles_is_charged_to_each_by_its_share() {
        let p = Params {
            tile_size: 100.0,
            tile_origin: [0.0, 0.0],
            ..Params::default()
        };
        let bb = geo_types::Rect::new(Coord { x: 50.0, y: 75.0 }, Coord { x: 150.0, y: 125.0 });
        let mut t = tiles_under(bb, Coord { x: 100.0, y: 100.0 }, &p);
        t.sort_by(|a, b| a.0.cmp(&b.0));
        let want: [(&str, f64); 4] = [("0_0", 0.25), ("0_1", 0.25), ("1_0", 0.25), ("1_1", 0.25)];
        assert_eq!(t.len(), 4);
        for ((id, share), (wid, wshare)) in t.iter().zip(want) {
            assert_eq!(
                (id.as_str(), (share * 1e9).round()),
                (wid, (wshare * 1e9).round())
            );
        }
        // A box over a whole country (damaged data) goes to its centroid's tile alone.
        let huge = geo_types::Rect::new(Coord { x: 0.0, y: 0.0 }, Coord { x: 1e7, y: 1e7 });
        assert_eq!(tiles_under(huge, Coord { x: 5.0, y: 5.0 }, &p).len(), 1);
    }

    #[test]
    fn a_texture_field_is_a_library_name_or_a_number_into_the_list() {
        let list = vec!["tree_01".to_string(), "tree_07".to_string()];
        assert_eq!(texture_of("2", &list).as_deref(), Some("tree_07"));
        assert_eq!(texture_of("tree_03", &list).as_deref(), Some("tree_03"));
        assert_eq!(texture_of("3", &list), None);
        assert_eq!(texture_of("oak", &list), None);
    }
}
