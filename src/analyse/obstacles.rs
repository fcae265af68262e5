//! What a person or a tree must not stand in: houses, kura and fences, in one R-tree.
//!
//! Built once from the plan after kura and fences are decided, so the billboards of section
//! 4.4 see exactly what will be built. A house is its lot cut to the band behind its frontage
//! where the house stands (the same `house_end` the kura placement uses); a footprint
//! building is its whole outline; a kura its rectangle; a fence its segment with a half
//! thickness.

use geo::{Contains, Distance, Euclidean};
use geo_types::{Coord, Point, Polygon};
use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{Envelope, RTree, RTreeObject, AABB};

use super::house::{frame_of, house_end, local_ring};
use crate::geom::segment::segment_distance_2;
use crate::model::{sane, PlannedFence, PlannedHouse};
use crate::params::Params;
use crate::templates::Catalog;

/// Half the thickness counted for a wall or fence (a tsuiji's base is about 0.9 m).
const WALL_HALF: f64 = 0.45;

enum Obstacle {
    /// The part of `outline` with `v < v_max` in the frame `(a, v)`.
    House {
        outline: Polygon<f64>,
        a: Coord<f64>,
        v: Coord<f64>,
        v_max: f64,
    },
    Rect(Polygon<f64>),
    Wall([f64; 2], [f64; 2]),
}

/// The buildings, kura and fences of a city, indexed by their bounding boxes.
pub struct Obstacles {
    tree: RTree<GeomWithData<Rectangle<[f64; 2]>, usize>>,
    items: Vec<Obstacle>,
}

impl Obstacles {
    /// Every house and kura that will be built (kura as `kura.collision` decides) and every
    /// fence segment.
    pub fn new<'a>(
        houses: impl Iterator<Item = &'a PlannedHouse>,
        fences: impl Iterator<Item = &'a PlannedFence>,
        catalog: &Catalog,
        params: &Params,
    ) -> Obstacles {
        Obstacles::build(houses, fences, std::iter::empty(), catalog, params)
    }

    /// Houses (in parallel: a city has hundreds of thousands), fences and areas, then one
    /// bulk load.
    fn build<'a>(
        houses: impl Iterator<Item = &'a PlannedHouse>,
        fences: impl Iterator<Item = &'a PlannedFence>,
        areas: impl Iterator<Item = Vec<Coord<f64>>>,
        catalog: &Catalog,
        params: &Params,
    ) -> Obstacles {
        let houses: Vec<&PlannedHouse> = houses.collect();
        let per_house: Vec<Vec<Obstacle>> = houses
            .par_iter()
            .map(|m| house_obstacles(m, catalog, params))
            .collect();
        let mut items = super::concat(per_house);
        for s in fences {
            items.push(Obstacle::Wall([s.a.x, s.a.y], [s.b.x, s.b.y]));
        }
        items.extend(areas.map(area));
        let boxes = items
            .par_iter()
            .enumerate()
            .filter_map(|(i, o)| Some(GeomWithData::new(envelope(o)?, i)))
            .collect();
        Obstacles {
            tree: RTree::bulk_load(boxes),
            items,
        }
    }

    /// Everything `plan` builds so far: houses, kura, fences and gates, halls, rock gardens
    /// and the landmarks' footprints.
    pub fn of_plan(plan: &crate::model::Plan, catalog: &Catalog, params: &Params) -> Obstacles {
        Obstacles::build(
            plan.houses.values().flatten(),
            plan.fences.values().flatten(),
            plan.halls
                .values()
                .flatten()
                .map(|h| h.outline())
                .chain(plan.gardens.values().flatten().map(|g| g.outline()))
                .chain(
                    plan.landmarks
                        .values()
                        .flatten()
                        .map(|l| crate::geom::ring::open(l.footprint.exterior()).to_vec())
                        .filter(|r| r.len() >= 3),
                ),
            catalog,
            params,
        )
    }

    /// More rectangles (halls' plots, rock gardens) as obstacles too, so the steps after them
    /// keep out; inserted into the tree ([`Obstacles::hit`] asks only whether any obstacle is
    /// hit, so the tree's shape never changes an answer).
    pub fn add_areas(&mut self, areas: impl Iterator<Item = Vec<Coord<f64>>>) {
        for ring in areas {
            let o = area(ring);
            if let Some(e) = envelope(&o) {
                self.tree.insert(GeomWithData::new(e, self.items.len()));
            }
            self.items.push(o);
        }
    }

    /// Whether `p` lies in an obstacle or within `clearance` of one.
    pub fn hit(&self, p: Coord<f64>, clearance: f64) -> bool {
        let c = clearance.max(0.0) + WALL_HALF;
        let query = AABB::from_corners([p.x - c, p.y - c], [p.x + c, p.y + c]);
        self.tree
            .locate_in_envelope_intersecting(&query)
            .any(|g| hits(&self.items[g.data], p, clearance.max(0.0)))
    }
}

/// The obstacles one area's searches can meet: those whose boxes reach within the clearance
/// of a lot's bounding box, taken from the tree once. A hall's or a garden's plot search asks
/// thousands of points of one lot; walking the city-wide tree for each was most of the
/// halls' time. A point outside the area is asked of the whole tree, so the answer is
/// always [`Obstacles::hit`]'s.
pub struct Near<'a> {
    all: &'a Obstacles,
    area: AABB<[f64; 2]>,
    clearance: f64,
    items: Vec<(AABB<[f64; 2]>, &'a Obstacle)>,
}

impl Obstacles {
    /// The obstacles a point of `outline`'s bounding box can hit with `clearance` (a lot's:
    /// its plot searches ask only about points inside it).
    pub fn near(&self, outline: &Polygon<f64>, clearance: f64) -> Near<'_> {
        let (lo, hi) = match geo::BoundingRect::bounding_rect(outline) {
            Some(r) => (r.min(), r.max()),
            // No points: an area of one point, and every other goes to the whole tree.
            None => (Coord::zero(), Coord::zero()),
        };
        let c = clearance.max(0.0) + WALL_HALF;
        let query = AABB::from_corners([lo.x - c, lo.y - c], [hi.x + c, hi.y + c]);
        let items = (self.tree.locate_in_envelope_intersecting(&query))
            .map(|g| (g.envelope(), &self.items[g.data]))
            .collect();
        Near {
            all: self,
            area: AABB::from_corners([lo.x, lo.y], [hi.x, hi.y]),
            clearance,
            items,
        }
    }
}

impl Near<'_> {
    /// Whether `p` lies in an obstacle or within the clearance of one.
    pub fn hit(&self, p: Coord<f64>) -> bool {
        if !self.area.contains_point(&[p.x, p.y]) {
            return self.all.hit(p, self.clearance);
        }
        let c = self.clearance.max(0.0) + WALL_HALF;
        let query = AABB::from_corners([p.x - c, p.y - c], [p.x + c, p.y + c]);
        (self.items.iter())
            .any(|(e, o)| e.intersects(&query) && hits(o, p, self.clearance.max(0.0)))
    }
}

/// Whether every point of a plot's sample grid (`nx` x `ny`, rows of `i` for each `j`;
/// `at(i, j)` the point) is `free`, asking first the point that was not last time (`miss`,
/// updated). The searches try plot after plot a step apart, and most fail at the wall or
/// house the one before failed at: asked first, it answers in one question instead of a
/// row of them. The answer is a conjunction, so the order never changes it.
pub fn grid_free(
    nx: usize,
    ny: usize,
    at: impl Fn(usize, usize) -> Coord<f64>,
    free: impl Fn(Coord<f64>) -> bool,
    miss: &mut Option<(usize, usize)>,
) -> bool {
    if let Some((i, j)) = *miss {
        if i < nx && j < ny && !free(at(i, j)) {
            return false;
        }
    }
    for j in 0..ny {
        for i in 0..nx {
            if *miss != Some((i, j)) && !free(at(i, j)) {
                *miss = Some((i, j));
                return false;
            }
        }
    }
    true
}

/// A house's obstacles: its built band, and its kura when one is built.
fn house_obstacles(m: &PlannedHouse, catalog: &Catalog, params: &Params) -> Vec<Obstacle> {
    let f = frame_of(m);
    let depth = local_ring(m, f).iter().map(|p| p[1]).fold(0.0, f64::max);
    let mut out = vec![Obstacle::House {
        outline: m.outline.clone(),
        a: f.a,
        v: f.v,
        v_max: house_end(m, depth, catalog, params),
    }];
    if let Some(r) = m.kura.to_build(params.kura.collision) {
        let q = f.quad(r);
        out.push(Obstacle::Rect(Polygon::new(
            q.iter().chain(&q[..1]).copied().collect(),
            vec![],
        )));
    }
    out
}

/// An open ring as a closed rectangle-like obstacle.
fn area(mut ring: Vec<Coord<f64>>) -> Obstacle {
    if let Some(&first) = ring.first() {
        ring.push(first);
    }
    Obstacle::Rect(Polygon::new(ring.into(), vec![]))
}

fn envelope(o: &Obstacle) -> Option<Rectangle<[f64; 2]>> {
    let (lo, hi) = match o {
        Obstacle::House { outline: p, .. } | Obstacle::Rect(p) => {
            let r = geo::BoundingRect::bounding_rect(p)?;
            ([r.min().x, r.min().y], [r.max().x, r.max().y])
        }
        Obstacle::Wall(a, b) => (
            [a[0].min(b[0]) - WALL_HALF, a[1].min(b[1]) - WALL_HALF],
            [a[0].max(b[0]) + WALL_HALF, a[1].max(b[1]) + WALL_HALF],
        ),
    };
    (sane(lo.into()) && sane(hi.into())).then(|| Rectangle::from_corners(lo, hi))
}

fn hits(o: &Obstacle, p: Coord<f64>, clearance: f64) -> bool {
    let near = |poly: &Polygon<f64>| {
        if clearance == 0.0 {
            poly.contains(&p)
        } else {
            Euclidean.distance(&Point(p), poly) < clearance
        }
    };
    match o {
        Obstacle::House {
            outline,
            a,
            v,
            v_max,
        } => {
            let depth = (p.x - a.x) * v.x + (p.y - a.y) * v.y;
            depth < v_max + clearance && near(outline)
        }
        Obstacle::Rect(poly) => near(poly),
        Obstacle::Wall(a, b) => {
            let reach = WALL_HALF + clearance;
            segment_distance_2([p.x, p.y], *a, *b) < reach * reach
        }
    }
}

/// Distance from `p` to the nearest edge of `poly` (exterior or hole).
pub fn boundary_distance(p: Coord<f64>, poly: &Polygon<f64>) -> f64 {
    std::iter::once(poly.exterior())
        .chain(poly.interiors())
        .flat_map(|r| r.lines())
        .map(|l| segment_distance_2([p.x, p.y], [l.start.x, l.start.y], [l.end.x, l.end.y]))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Frontage, KuraDecision};

    fn house(kura: KuraDecision) -> PlannedHouse {
        let outline = Polygon::new(
            vec![(0.0, 0.0), (6.0, 0.0), (6.0, 30.0), (0.0, 30.0), (0.0, 0.0)].into(),
            vec![],
        );
        PlannedHouse {
            id: "1".into(),
            record: 0,
            outline,
            frontage: Frontage {
                a: Coord { x: 0.0, y: 0.0 },
                b: Coord { x: 6.0, y: 0.0 },
                fallback: false,
            },
            mtype: "hiraya".into(),
            type_given: true,
            district: None,
            tile: "0_0".into(),
            ground: 0.0,
            source: crate::model::HouseSource::Lot,
            attrs: vec![],
            kura,
        }
    }

    #[test]
    fn the_house_band_and_the_kura_are_obstacles_the_garden_is_not() {
        let catalog = Catalog::load(None).unwrap();
        let params = Params::default();
        let m = house(KuraDecision::Clear([1.0, 22.0, 5.0, 27.0]));
        let obs = Obstacles::new(std::iter::once(&m), std::iter::empty(), &catalog, &params);
        let at = |x, y| Coord { x, y };
        assert!(obs.hit(at(3.0, 2.0), 0.0), "in the house");
        assert!(obs.hit(at(3.0, 24.0), 0.0), "in the kura");
        assert!(!obs.hit(at(3.0, 18.0), 0.0), "in the garden between them");
        assert!(!obs.hit(at(3.0, -3.0), 0.0), "in the street");
        assert!(obs.hit(at(3.0, -0.2), 0.3), "too close to the house");
        assert!(obs.hit(at(3.0, 20.0 + 1.5), 1.0), "too close to the kura");
    }

    #[test]
    fn a_fence_keeps_its_thickness_and_clearance() {
        let catalog = Catalog::load(None).unwrap();
        let params = Params::default();
        let f = PlannedFence {
            id: "w".into(),
            record: 0,
            layer: "fences".into(),
            template: "fence".into(),
            kind: crate::model::FenceKind::Wall,
            edge: 0,
            a: Coord { x: 0.0, y: 0.0 },
            b: Coord { x: 10.0, y: 0.0 },
            start_mitre: 0.0,
            end_mitre: 0.0,
            ground: 0.0,
            ground_end: 0.0,
            room: 5.0,
            district: None,
            tile: "0_0".into(),
            attrs: vec![],
        };
        let obs = Obstacles::new(std::iter::empty(), std::iter::once(&f), &catalog, &params);
        assert!(obs.hit(Coord { x: 5.0, y: 0.3 }, 0.0));
        assert!(!obs.hit(Coord { x: 5.0, y: 0.6 }, 0.0));
        assert!(obs.hit(Coord { x: 5.0, y: 1.0 }, 1.0));
        assert!(!obs.hit(Coord { x: 12.0, y: 0.0 }, 1.0));
    }

    #[test]
    fn an_area_s_obstacles_answer_as_the_whole_tree_does() {
        let catalog = Catalog::load(None).unwrap();
        let params = Params::default();
        let m = house(KuraDecision::Clear([1.0, 22.0, 5.0, 27.0]));
        let mut obs = Obstacles::new(std::iter::once(&m), std::iter::empty(), &catalog, &params);
        obs.add_areas(std::iter::once(vec![
            Coord { x: 9.0, y: 9.0 },
            Coord { x: 12.0, y: 9.0 },
            Coord { x: 12.0, y: 12.0 },
        ]));
        for clearance in [0.0, 0.3, 1.0] {
            // The area covers half the house; points are asked inside it and beyond it.
            let area = Polygon::new(
                vec![
                    (-1.0, 10.0),
                    (8.0, 10.0),
                    (8.0, 30.0),
                    (-1.0, 30.0),
                    (-1.0, 10.0),
                ]
                .into(),
                vec![],
            );
            let near = obs.near(&area, clearance);
            let mut asked = 0;
            for i in 0..60 {
                for j in 0..90 {
                    let p = Coord {
                        x: -3.0 + 0.25 * i as f64,
                        y: -2.0 + 0.4 * j as f64,
                    };
                    assert_eq!(near.hit(p), obs.hit(p, clearance), "{p:?} at {clearance}");
                    asked += usize::from(obs.hit(p, clearance));
                }
            }
            assert!(asked > 100, "the points meet the house and the kura");
        }
    }

    #[test]
    fn a_grid_is_free_whatever_point_is_asked_first() {
        // A fixed scatter of blocked points (an LCG) on grids of every size up to 6 x 6.
        let mut x: u64 = 99;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            x >> 33
        };
        let mut failed = 0;
        for _ in 0..400 {
            let (nx, ny) = (1 + next() as usize % 6, 1 + next() as usize % 6);
            let blocked: Vec<(usize, usize)> = (0..next() % 3)
                .map(|_| (next() as usize % 7, next() as usize % 7))
                .collect();
            let at = |i: usize, j: usize| Coord {
                x: i as f64,
                y: j as f64,
            };
            let free = |c: Coord<f64>| !blocked.contains(&(c.x as usize, c.y as usize));
            let plain = (0..ny).all(|j| (0..nx).all(|i| free(at(i, j))));
            let mut miss = [None, Some((0, 0)), Some((6, 6)), Some((2, 1))][next() as usize % 4];
            assert_eq!(grid_free(nx, ny, at, free, &mut miss), plain);
            if !plain {
                failed += 1;
                let (i, j) = miss.unwrap();
                assert!(
                    i < nx && j < ny && blocked.contains(&(i, j)),
                    "the miss kept"
                );
            }
        }
        assert!(failed > 50, "{failed} grids blocked");
    }
}
