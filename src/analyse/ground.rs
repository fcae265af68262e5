//! What each tile's ground is cut from (`[ground]`): the street surfaces (the centrelines
//! buffered by half their widths, or the city blocks whose complement the streets are), the
//! water polygons and the lots touching the tile, and how high the ground stands. Every tile
//! a lot touches gets a ground (a tile holding only the corner of a large estate too), so the
//! tiles of a town put together are one continuous ground. Generation does the cutting, tile
//! by tile (`generate::ground`).

use std::collections::BTreeSet;

use geo::algorithm::buffer::{BufferStyle, LineCap, LineJoin};
use geo::{BoundingRect, Buffer, Centroid};
use geo_types::Polygon;
use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use super::product::Grounds;
use crate::model::tile::tile_bounds;
use crate::model::{sane, Dataset, GroundHeight, PlannedGround, TileId};
use crate::params::Params;

/// The most tiles one lot may add (a lot larger than this many tiles is damaged data).
const MAX_TILES_A_LOT: i64 = 400;
/// The angle each straight piece of a street's round end or bend turns, radians: about six
/// pieces a half circle, within 10 cm of the circle on a 6 m street (geo's default, 0.2,
/// gave a Chino tile 480 KB of ground).
const ROUND_STEP: f64 = 0.5;
/// How far around a tile the lots its height is interpolated from are gathered, metres.
const HEIGHT_REACH: f64 = 200.0;

type Index = RTree<GeomWithData<Rectangle<[f64; 2]>, usize>>;

fn index<'a>(polys: impl Iterator<Item = &'a Polygon<f64>>) -> Index {
    RTree::bulk_load(
        polys
            .enumerate()
            .filter_map(|(i, p)| {
                let r = p.bounding_rect()?;
                let (lo, hi) = ([r.min().x, r.min().y], [r.max().x, r.max().y]);
                (sane(r.min()) && sane(r.max()))
                    .then(|| GeomWithData::new(Rectangle::from_corners(lo, hi), i))
            })
            .collect(),
    )
}

fn near(index: &Index, b: [f64; 4]) -> Vec<usize> {
    let mut ids: Vec<usize> = index
        .locate_in_envelope_intersecting(&AABB::from_corners([b[0], b[1]], [b[2], b[3]]))
        .map(|g| g.data)
        .collect();
    ids.sort_unstable();
    ids
}

/// The tiles (column, row) a polygon's box touches, when they are few enough to be a lot's
/// ([`MAX_TILES_A_LOT`]) and its coordinates sane.
fn tiles_of(p: &Polygon<f64>, size: f64, origin: [f64; 2]) -> Option<(Range, Range)> {
    let r = p.bounding_rect()?;
    if !(sane(r.min()) && sane(r.max())) {
        return None;
    }
    let col = |x: f64| ((x - origin[0]) / size).floor() as i64;
    let row = |y: f64| ((y - origin[1]) / size).floor() as i64;
    let (c0, c1, r0, r1) = (
        col(r.min().x),
        col(r.max().x),
        row(r.min().y),
        row(r.max().y),
    );
    ((c1 - c0 + 1) * (r1 - r0 + 1) <= MAX_TILES_A_LOT).then_some((c0..=c1, r0..=r1))
}

type Range = std::ops::RangeInclusive<i64>;

/// How many tiles the lots and footprints touch with `params`' grid, counted up to `cap`
/// (one more when there are more): what a build would write, known before anything is
/// analysed, so a `tile_size` of 2 m over a city is refused or warned of by its key before
/// it makes tens of thousands of files (issue 57).
pub fn tiles_touched(data: &Dataset, params: &Params, cap: usize) -> usize {
    let (size, origin) = (params.tile_size, params.tile_origin);
    let outlines =
        (data.lots.iter().map(|l| &l.outline)).chain(data.footprints.iter().map(|f| &f.outline));
    let mut seen = std::collections::HashSet::new();
    for p in outlines {
        let Some((cols, rows)) = tiles_of(p, size, origin) else {
            continue;
        };
        for c in cols {
            for r in rows.clone() {
                seen.insert((c, r));
                if seen.len() > cap {
                    return seen.len();
                }
            }
        }
    }
    seen.len()
}

/// The ground of every tile to write: those `built`, and the tiles the lots touch.
pub fn plan_ground(data: &Dataset, built: &BTreeSet<TileId>, params: &Params) -> Grounds {
    let g = &params.ground;
    let mut out = Grounds::default();
    if !g.enabled {
        return out;
    }
    let (size, origin) = (params.tile_size, params.tile_origin);
    for lot in &data.lots {
        let Some((cols, rows)) = tiles_of(&lot.outline, size, origin) else {
            continue;
        };
        for c in cols {
            for rr in rows.clone() {
                let id = format!("{c}_{rr}");
                if !built.contains(&id) {
                    out.tiles.insert(id);
                }
            }
        }
    }
    let from_blocks = match g.streets.as_str() {
        "blocks" => true,
        "centrelines" => false,
        _ => data.streets.is_empty(),
    };
    // Each centreline buffered on its own (round ends and joins); crossings are joined by
    // the union each tile makes.
    let streets: Vec<Polygon<f64>> = if from_blocks {
        Vec::new()
    } else {
        data.streets
            .par_iter()
            .flat_map_iter(|s| {
                let style = BufferStyle::new(s.width / 2.0)
                    .line_cap(LineCap::Round(ROUND_STEP))
                    .line_join(LineJoin::Round(ROUND_STEP));
                s.line.buffer_with_style(style).0
            })
            .collect()
    };
    let street_index = index(streets.iter());
    let block_index = index(data.blocks.iter());
    let water_index = index(data.water.iter().map(|w| &w.outline));
    let lot_index = index(data.lots.iter().map(|l| &l.outline));
    let heights = heights(data);
    let flat = match heights.first() {
        Some((_, z0)) if heights.iter().any(|(_, z)| z != z0) => None,
        Some((_, z0)) => Some(*z0),
        None => Some(0.0),
    };
    let height_index = RTree::bulk_load(
        heights
            .iter()
            .enumerate()
            .map(|(i, (c, _))| GeomWithData::new(*c, i))
            .collect(),
    );
    let tiles: Vec<&TileId> = built.union(&out.tiles).collect();
    let grounds: Vec<(String, PlannedGround)> = tiles
        .par_iter()
        .filter_map(|id| {
            let b = tile_bounds(id, size, origin)?;
            let height = match flat {
                Some(z) => GroundHeight::Flat(z),
                None => {
                    let reach = AABB::from_corners(
                        [b[0] - HEIGHT_REACH, b[1] - HEIGHT_REACH],
                        [b[2] + HEIGHT_REACH, b[3] + HEIGHT_REACH],
                    );
                    let mut ids: Vec<usize> = height_index
                        .locate_in_envelope(&reach)
                        .map(|p| p.data)
                        .collect();
                    ids.sort_unstable();
                    GroundHeight::Points(ids.into_iter().map(|i| heights[i]).collect())
                }
            };
            let ground = PlannedGround {
                bounds: b,
                streets: near(&street_index, b)
                    .into_iter()
                    .map(|i| streets[i].clone())
                    .collect(),
                blocks: from_blocks.then(|| {
                    near(&block_index, b)
                        .into_iter()
                        .map(|i| data.blocks[i].clone())
                        .collect()
                }),
                water: near(&water_index, b)
                    .into_iter()
                    .map(|i| data.water[i].outline.clone())
                    .collect(),
                lots: near(&lot_index, b)
                    .into_iter()
                    .map(|i| {
                        let l = &data.lots[i];
                        (l.outline.clone(), l.lot_use.name().to_string())
                    })
                    .collect(),
                height,
            };
            Some(((*id).clone(), ground))
        })
        .collect();
    out.by_tile = grounds.into_iter().collect();
    out
}

/// The lots' (and footprints') centres and elevations, on the DEM where there is one.
fn heights(data: &Dataset) -> Vec<([f64; 2], f64)> {
    let outlines = data
        .lots
        .iter()
        .map(|l| (&l.outline, l.ground))
        .chain(data.footprints.iter().map(|f| (&f.outline, f.ground)));
    outlines
        .filter_map(|(o, z)| {
            let c = o.centroid()?;
            let z = match &data.dem {
                Some(dem) => dem.sample(c.0).z,
                None => z,
            };
            (sane(c.0) && z.is_finite()).then_some(([c.x(), c.y()], z))
        })
        .collect()
}
