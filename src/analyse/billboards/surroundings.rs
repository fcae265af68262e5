//! What a billboard point stands on and faces: the district and ground of the nearest lot
//! (the DEM's ground when there is one) and the direction of the nearest street.

use geo::Centroid;
use geo_types::Coord;
use rstar::primitives::GeomWithData;
use rstar::RTree;

use crate::geom::segment::Segment;
use crate::model::{sane, Dataset};

/// Where a point is and what it stands on: the district and ground of the nearest lot (the
/// DEM's ground when there is one), the direction of the nearest street.
pub(super) struct Surroundings<'a> {
    lots: RTree<GeomWithData<[f64; 2], usize>>,
    info: Vec<(Option<&'a str>, f64)>,
    streets: RTree<Segment>,
    pub(super) dem: Option<&'a crate::model::dem::Dem>,
}

impl<'a> Surroundings<'a> {
    pub(super) fn new(data: &'a Dataset) -> Surroundings<'a> {
        let mut points = Vec::new();
        let mut info = Vec::new();
        let lots = data
            .lots
            .iter()
            .map(|l| (&l.outline, &l.district, l.ground));
        let fps = data
            .footprints
            .iter()
            .map(|f| (&f.outline, &f.district, f.ground));
        for (outline, district, ground) in lots.chain(fps) {
            if let Some(c) = outline
                .centroid()
                .filter(|c| c.x().is_finite() && c.y().is_finite())
            {
                points.push(GeomWithData::new([c.x(), c.y()], info.len()));
                info.push((district.as_deref(), ground));
            }
        }
        // People face along their street: the centrelines, else the block edges (which run
        // along the streets too).
        let mut segs: Vec<Segment> = data
            .streets
            .iter()
            .flat_map(|s| s.line.lines())
            .map(|l| segment(l.start, l.end))
            .collect();
        if segs.is_empty() {
            segs = data
                .blocks
                .iter()
                .flat_map(|b| b.exterior().lines())
                .map(|l| segment(l.start, l.end))
                .collect();
        }
        segs.retain(|s| sane(s.a.into()) && sane(s.b.into()) && s.a != s.b);
        Surroundings {
            lots: RTree::bulk_load(points),
            info,
            streets: RTree::bulk_load(segs),
            dem: data.dem.as_ref(),
        }
    }

    /// The district of the lot nearest `p`.
    pub(super) fn district(&self, p: Coord<f64>) -> Option<&'a str> {
        self.lots
            .nearest_neighbor(&[p.x, p.y])
            .and_then(|g| self.info[g.data].0)
    }

    /// District and ground at `p`.
    pub(super) fn at(&self, p: Coord<f64>, ground: Option<f64>) -> (Option<String>, f64) {
        let near = self
            .lots
            .nearest_neighbor(&[p.x, p.y])
            .map(|g| self.info[g.data]);
        let district = near.and_then(|n| n.0).map(str::to_string);
        let ground = match self.dem {
            Some(dem) => dem.sample(p).z,
            None => ground.or(near.map(|n| n.1)).unwrap_or(0.0),
        };
        (district, ground)
    }

    /// Direction of the street nearest `p`, radians.
    pub(super) fn street_angle(&self, p: Coord<f64>) -> f64 {
        self.streets
            .nearest_neighbor(&[p.x, p.y])
            .map_or(0.0, |s| (s.b[1] - s.a[1]).atan2(s.b[0] - s.a[0]))
    }
}

fn segment(a: Coord<f64>, b: Coord<f64>) -> Segment {
    Segment {
        a: [a.x, a.y],
        b: [b.x, b.y],
        value: 0.0,
    }
}
