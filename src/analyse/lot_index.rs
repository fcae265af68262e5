//! The lots by their bounding boxes, for finding the lot a point stands in (a tree, a
//! garden polygon's centre) without visiting every lot of a city for each.

use geo::{BoundingRect, Contains};
use geo_types::{Coord, Point};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};

use crate::model::Dataset;

/// The lots by their bounding boxes.
pub struct LotIndex<'a> {
    data: &'a Dataset,
    tree: RTree<GeomWithData<Rectangle<[f64; 2]>, usize>>,
}

impl<'a> LotIndex<'a> {
    /// Every lot of `data` with a bounding box.
    pub fn new(data: &'a Dataset) -> LotIndex<'a> {
        let boxes = data
            .lots
            .iter()
            .enumerate()
            .filter_map(|(i, l)| {
                let r = l.outline.bounding_rect()?;
                Some(GeomWithData::new(
                    Rectangle::from_corners([r.min().x, r.min().y], [r.max().x, r.max().y]),
                    i,
                ))
            })
            .collect();
        LotIndex {
            data,
            tree: RTree::bulk_load(boxes),
        }
    }

    /// The first lot (in input order) whose outline holds `p`.
    pub fn containing(&self, p: Coord<f64>) -> Option<usize> {
        let q = AABB::from_point([p.x, p.y]);
        self.tree
            .locate_in_envelope_intersecting(&q)
            .map(|g| g.data)
            .filter(|&i| self.data.lots[i].outline.contains(&Point(p)))
            .min()
    }
}
