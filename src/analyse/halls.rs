//! Halls of estates and temples: for each lot whose use lists hall templates
//! (`halls.uses`), each template in turn gets the largest plot of its proportions
//! (`plot_width` x `plot_depth`, down to `min_scale` of it) that lies inside the lot and
//! `halls.clearance` clear of its edge, the planned houses, kura, walls and gates, and the
//! halls placed before it. The plot faces the lot's first gate (its u axis along the gate's
//! wall, v away from it), else the lot's edge nearest a street; a main hall takes the deepest such
//! plot on the gate's axis, a gate (`near_gate = 1`) the nearest. A hall with no room is
//! reported with why; the lot stays open ground. Runs before the gardens, trees and people,
//! which keep out of the halls.

use std::collections::HashMap;

use geo::{Contains, Point};
use geo_types::{Coord, Polygon};
use rayon::prelude::*;

use super::obstacles::{boundary_distance, grid_free, Obstacles};
use super::product::{ByTile, Halls};
use super::street::StreetEdges;
use crate::model::{tile::tile_id, Dataset, FenceKind, HallStat, Lot, PlannedFence, PlannedHall};
use crate::params::Params;
use crate::templates::{Catalog, Kind, Template};

/// How much smaller each try is than the one before.
const SHRINK: f64 = 0.9;
/// The widest lot searched, metres: a larger one is damaged data.
const MAX_LOT: f64 = 5000.0;
/// The most positions tried across a lot, each way, for one plot size.
const MAX_STEPS: f64 = 150.0;

/// Plans the halls of every lot and reports each; a lot's first gate among `fences` faces
/// its halls.
pub fn plan_halls(
    data: &Dataset,
    fences: &ByTile<PlannedFence>,
    edges: &StreetEdges,
    obstacles: &Obstacles,
    catalog: &Catalog,
    params: &Params,
) -> Halls {
    let h = &params.halls;
    let mut out = Halls::default();
    if !h.enabled || h.uses.values().all(Vec::is_empty) {
        return out;
    }
    // A lot's first gate (its wall segment) faces the hall.
    let mut gates: HashMap<&str, (Coord<f64>, Coord<f64>)> = HashMap::new();
    for f in fences.values().flatten() {
        if f.kind == FenceKind::Gate {
            gates.entry(f.id.as_str()).or_insert((f.a, f.b));
        }
    }
    let lots: Vec<(&Lot, &Vec<String>)> = data
        .lots
        .iter()
        .filter_map(|l| Some((l, h.uses.get(l.lot_use.name())?)))
        .filter(|(_, names)| !names.is_empty())
        .collect();
    let results: Vec<Vec<(HallStat, Option<PlannedHall>)>> = lots
        .par_iter()
        .map(|(lot, names)| {
            let gate = gates.get(lot.id.as_str()).copied();
            let mut halls = place_lot(lot, names, gate, edges, obstacles, catalog, params);
            if let Some(dem) = &data.dem {
                // On the DEM, a hall's flat base is the lowest ground under its plot, as a
                // house's is under its lot: never floating.
                for hall in halls.iter_mut().filter_map(|(_, h)| h.as_mut()) {
                    hall.ground = hall
                        .outline()
                        .into_iter()
                        .map(|c| dem.sample(c).z)
                        .fold(f64::INFINITY, f64::min);
                }
            }
            halls
        })
        .collect();
    for (stat, hall) in results.into_iter().flatten() {
        out.reports.push(stat);
        if let Some(hl) = hall {
            out.by_tile.entry(hl.tile.clone()).or_default().push(hl);
        }
    }
    out
}

/// The halls of one lot, in the order its use lists them.
fn place_lot(
    lot: &Lot,
    names: &[String],
    gate: Option<(Coord<f64>, Coord<f64>)>,
    edges: &StreetEdges,
    obstacles: &Obstacles,
    catalog: &Catalog,
    params: &Params,
) -> Vec<(HallStat, Option<PlannedHall>)> {
    let mut placed: Vec<Polygon<f64>> = Vec::new();
    let mut out = Vec::new();
    let frame = facing(lot, gate, edges);
    for name in names {
        let stat = |placed, reason: String, size| HallStat {
            lot: lot.id.clone(),
            lot_use: lot.lot_use.name().to_string(),
            template: name.clone(),
            placed,
            reason,
            size,
        };
        let Some(t) = catalog.get(name).filter(|t| t.kind == Kind::Hall) else {
            // build checks the names first; a user catalog could still lack one.
            out.push((
                stat(false, format!("no hall template `{name}`"), [0.0; 2]),
                None,
            ));
            continue;
        };
        let overrides = catalog.overrides(&t.name, lot.district.as_deref());
        let plot = Plot::of(t, &overrides);
        let Some(frame) = frame else {
            out.push((
                stat(false, "the lot has no edge to face".into(), [0.0; 2]),
                None,
            ));
            continue;
        };
        match find(
            lot,
            &frame,
            &plot,
            &placed,
            obstacles,
            params.halls.clearance,
        ) {
            Some((corner, size)) => {
                let mut hall = PlannedHall {
                    lot: lot.id.clone(),
                    record: lot.record,
                    template: t.name.clone(),
                    corner: frame.map(corner),
                    u: frame.u,
                    size,
                    ground: lot.ground,
                    district: lot.district.clone(),
                    tile: String::new(),
                };
                hall.tile = tile_id(hall.centre(), params.tile_size, params.tile_origin);
                let ring = hall.outline();
                placed.push(Polygon::new(
                    ring.iter().chain(&ring[..1]).copied().collect(),
                    vec![],
                ));
                out.push((stat(true, String::new(), size), Some(hall)));
            }
            None => {
                let reason = format!(
                    "no open plot of {:.1} x {:.1} m (down to {:.0} % of {} x {} m) clear of the \
                     lot's edge, walls and buildings by {} m",
                    plot.width * plot.min_scale,
                    plot.depth * plot.min_scale,
                    plot.min_scale * 100.0,
                    plot.width,
                    plot.depth,
                    params.halls.clearance
                );
                out.push((stat(false, reason, [0.0; 2]), None));
            }
        }
    }
    out
}

/// What a hall template asks of its plot.
struct Plot {
    width: f64,
    depth: f64,
    min_scale: f64,
    near_gate: bool,
}

impl Plot {
    fn of(t: &Template, overrides: &[(usize, f64)]) -> Plot {
        let p = |k: &str, d: f64| {
            t.param(overrides, k)
                .filter(|x| x.is_finite() && *x > 0.0)
                .unwrap_or(d)
        };
        Plot {
            width: p("plot_width", 20.0).min(MAX_LOT),
            depth: p("plot_depth", 15.0).min(MAX_LOT),
            min_scale: p("min_scale", 0.5).clamp(0.05, 1.0),
            near_gate: t.param(overrides, "near_gate").unwrap_or(0.0) != 0.0,
        }
    }
}

/// The frame a lot's halls face: u along its gate's wall (else the edge nearest a street,
/// else its longest edge), v into the lot, the origin at the gate's (or edge's) middle.
fn facing(
    lot: &Lot,
    gate: Option<(Coord<f64>, Coord<f64>)>,
    edges: &StreetEdges,
) -> Option<crate::geom::frame::Frame> {
    let ring = &lot.outline.exterior().0;
    let len = |e: &(Coord<f64>, Coord<f64>)| (e.1.x - e.0.x).hypot(e.1.y - e.0.y);
    // Nearest the street first (to the decimetre), then longest.
    let street = |e: &(Coord<f64>, Coord<f64>)| {
        if edges.is_empty() {
            return 0;
        }
        let mid = Coord {
            x: (e.0.x + e.1.x) / 2.0,
            y: (e.0.y + e.1.y) / 2.0,
        };
        (edges.distance(mid) * 10.0).round().min(1e12) as i64
    };
    let (a, b) = match gate {
        Some(g) => g,
        None => ring
            .windows(2)
            .map(|w| (w[0], w[1]))
            .filter(|e| len(e) > 1.0)
            .min_by(|x, y| street(x).cmp(&street(y)).then(len(y).total_cmp(&len(x))))?,
    };
    let len = (b.x - a.x).hypot(b.y - a.y);
    if len.is_nan() || len <= 1e-9 {
        return None;
    }
    let mid = Coord {
        x: (a.x + b.x) / 2.0,
        y: (a.y + b.y) / 2.0,
    };
    let mut u = Coord {
        x: (b.x - a.x) / len,
        y: (b.y - a.y) / len,
    };
    // v must point into the lot: towards its centre.
    let c = lot
        .outline
        .exterior()
        .0
        .iter()
        .fold(Coord { x: 0.0, y: 0.0 }, |s, p| Coord {
            x: s.x + p.x,
            y: s.y + p.y,
        });
    let n = (lot.outline.exterior().0.len().max(1)) as f64;
    let towards = Coord {
        x: c.x / n - mid.x,
        y: c.y / n - mid.y,
    };
    if -u.y * towards.x + u.x * towards.y < 0.0 {
        u = Coord { x: -u.x, y: -u.y };
    }
    Some(crate::geom::frame::Frame::along(mid, u))
}

/// The plot: its (u, v) corner in `frame` and its size, the largest that fits.
fn find(
    lot: &Lot,
    frame: &crate::geom::frame::Frame,
    plot: &Plot,
    placed: &[Polygon<f64>],
    obstacles: &Obstacles,
    clearance: f64,
) -> Option<([f64; 2], [f64; 2])> {
    let outline = &lot.outline;
    let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &q in &outline.exterior().0 {
        let [u, v] = frame.local(q);
        u0 = u0.min(u);
        u1 = u1.max(u);
        v0 = v0.min(v);
        v1 = v1.max(v);
    }
    if !(u1 - u0).is_finite() || u1 - u0 > MAX_LOT || v1 - v0 > MAX_LOT {
        return None;
    }
    let near = obstacles.near(outline, clearance);
    let free = |q: Coord<f64>| {
        outline.contains(&Point(q))
            && boundary_distance(q, outline) >= clearance
            && !near.hit(q)
            && placed
                .iter()
                .all(|p| !p.contains(&Point(q)) && boundary_distance(q, p) >= clearance)
    };
    let mut scale = 1.0;
    while scale >= plot.min_scale - 1e-9 {
        let (w, d) = (plot.width * scale, plot.depth * scale);
        scale *= SHRINK;
        if w > u1 - u0 || d > v1 - v0 {
            continue;
        }
        // Sample the plot every 2 m or less: with the clearance, nothing between samples
        // can be missed but a wall thinner than the gap, and walls count half a metre more.
        let (nx, ny) = ((w / 2.0).ceil() as usize + 1, (d / 2.0).ceil() as usize + 1);
        // A sixth of the plot, and never more than 150 steps across the lot: a precinct a
        // kilometre wide is searched in seconds, not minutes.
        let step = (w.min(d) / 6.0)
            .max(0.5)
            .max((u1 - u0).max(v1 - v0) / MAX_STEPS);
        // Across: centred on the gate's axis (u = 0) first, then alternately either side.
        let mut us: Vec<f64> = Vec::new();
        let (lo, hi) = (u0, u1 - w);
        let centre = (-w / 2.0).clamp(lo, hi);
        us.push(centre);
        let mut k = 1.0;
        while centre - k * step >= lo || centre + k * step <= hi {
            for c in [centre - k * step, centre + k * step] {
                if (lo..=hi).contains(&c) {
                    us.push(c);
                }
            }
            k += 1.0;
        }
        // Along: a gate as near the lot's front as it fits, a main hall as deep.
        let count = ((v1 - d - v0) / step).floor().max(0.0) as usize;
        let vs: Vec<f64> = (0..=count)
            .map(|i| {
                if plot.near_gate {
                    v0 + i as f64 * step
                } else {
                    v1 - d - i as f64 * step
                }
            })
            .collect();
        let mut miss = None;
        for &v in &vs {
            for &u in &us {
                let at = |i: usize, j: usize| {
                    frame.map([
                        u + w * i as f64 / (nx - 1) as f64,
                        v + d * j as f64 / (ny - 1) as f64,
                    ])
                };
                if grid_free(nx, ny, at, free, &mut miss) {
                    return Some(([u, v], [w, d]));
                }
            }
        }
    }
    None
}
