//! What every layer of `plan.gpkg` is made from and with: the sources ([`PlanSources`]), the
//! lookups ([`Index`]), and the values of a row (a text, NULL when empty; a count; a real,
//! NULL unless finite). The layers' own files (`layers.rs`, `houses.rs`, `places.rs`) take
//! them from here, and `layers.rs` alone calls the others: one direction.

use std::collections::HashMap;

use geo_types::{Coord, Geometry, LineString, Polygon};
use rstar::RTree;

use super::Value;
use crate::geom::segment::Segment;
use crate::model::{Dataset, KuraDecision, Lot, Plan, PlannedHouse, Skipped};
use crate::params::Params;

/// What `plan.gpkg` is made from: the input read, the analysis and the parameters.
pub struct PlanSources<'a> {
    /// The input as read.
    pub data: &'a Dataset,
    /// The analysis.
    pub plan: &'a Plan,
    /// The build's parameters.
    pub params: &'a Params,
    /// The band behind its frontage a machiya's body fills (`analyse::house::house_band`:
    /// its template decides it); `None` for a footprint building.
    pub band: &'a (dyn Fn(&PlannedHouse) -> Option<(f64, f64)> + Sync),
}

/// Lookups every layer needs: lots by id, skips by layer and id, the streets' segments.
pub(super) struct Index<'a> {
    /// Lots read, by id.
    pub lots: HashMap<&'a str, &'a Lot>,
    /// The skips of each (layer, id), in report order.
    skips: HashMap<(&'a str, &'a str), Vec<&'a Skipped>>,
    /// Features a landmark displaced: (kind, id) -> landmark.
    pub displaced: HashMap<(&'a str, &'a str), &'a str>,
    /// Every street's segments, the street's index in `value`.
    streets: RTree<Segment>,
}

impl<'a> Index<'a> {
    /// The lots by id alone: where a skipped record without an outline of its own is drawn.
    pub(super) fn lots_of(data: &'a Dataset) -> Index<'a> {
        Index {
            lots: data.lots.iter().map(|l| (l.id.as_str(), l)).collect(),
            skips: HashMap::new(),
            displaced: HashMap::new(),
            streets: RTree::new(),
        }
    }

    /// Every lookup, with `skipped`: the skips analysis knows of (generation's are marked
    /// afterwards).
    pub(super) fn of(s: &'a PlanSources, skipped: impl Iterator<Item = &'a Skipped>) -> Index<'a> {
        let (data, plan) = (s.data, s.plan);
        let mut index = Index::lots_of(data);
        for k in skipped {
            index
                .skips
                .entry((k.layer.as_str(), k.id.as_str()))
                .or_default()
                .push(k);
        }
        for d in &plan.landmark_report.displaced {
            index
                .displaced
                .entry((d.kind.as_str(), d.id.as_str()))
                .or_insert(d.landmark.as_str());
        }
        let segments = data.streets.iter().enumerate().flat_map(|(i, st)| {
            st.line.0.windows(2).map(move |w| Segment {
                a: [w[0].x, w[0].y],
                b: [w[1].x, w[1].y],
                value: i as f64,
            })
        });
        index.streets = RTree::bulk_load(segments.collect());
        index
    }

    /// The first skip of a feature: its layer, its id and its record (a skip of a repeated
    /// id names another record than the feature built under that id).
    pub fn skip_of(&self, layer: &str, id: &str, record: usize) -> Option<&'a Skipped> {
        self.skips
            .get(&(layer, id))?
            .iter()
            .find(|k| k.record.is_none_or(|r| r == record))
            .copied()
    }

    /// The id of the street nearest a point.
    pub(super) fn street_at(&self, p: Coord<f64>, data: &'a Dataset) -> Option<&'a str> {
        let nearest = self.streets.nearest_neighbor(&[p.x, p.y])?;
        data.streets
            .get(nearest.value as usize)
            .map(|s| s.id.as_str())
    }
}

/// A string value, or NULL when empty.
pub(super) fn text_or_null(s: &str) -> Value {
    match s {
        "" => Value::Null,
        s => Value::Text(s.to_string()),
    }
}

/// An optional string value.
pub(super) fn optional(s: Option<&str>) -> Value {
    s.map_or(Value::Null, text_or_null)
}

/// An integer value.
pub(super) fn count(v: usize) -> Value {
    Value::Integer(v as i64)
}

/// A real value, NULL unless finite.
pub(super) fn real_or_null(v: f64) -> Value {
    if v.is_finite() {
        Value::Real(v)
    } else {
        Value::Null
    }
}

/// A ring of map points as a polygon.
pub(super) fn polygon_of(points: Vec<Coord<f64>>) -> Geometry<f64> {
    Geometry::Polygon(Polygon::new(LineString::from(points), Vec::new()))
}

/// Every planned house, lot by lot, in the plan's order.
pub(super) fn planned_houses(plan: &Plan) -> impl Iterator<Item = &PlannedHouse> {
    plan.houses.values().flatten()
}

/// What section 4.2 decided for a machiya's kura, in words: (decision, why).
pub(super) fn kura_words(k: &KuraDecision, avoid: bool) -> (&'static str, &'static str) {
    match k {
        KuraDecision::NotCandidate => (
            "not a candidate",
            "frontage narrower than kura.min_frontage or lot shallower than kura.depth_ratio \
             times it",
        ),
        KuraDecision::NoRoom => ("refused", "no room behind the house"),
        KuraDecision::Collides(_) if avoid => (
            "refused",
            "its plot overlaps another machiya's (kura.collision = true)",
        ),
        KuraDecision::Collides(_) => ("placed", "its plot overlaps another machiya's"),
        KuraDecision::Clear(_) => ("placed", ""),
    }
}

/// The layer a planned house was read from: `lots`, or `footprints`.
pub(super) fn house_layer(h: &PlannedHouse) -> &'static str {
    match h.is_footprint() {
        true => "footprints",
        false => "lots",
    }
}

/// The outlines reading kept of skipped records, by (layer, record, id).
pub(super) fn shapes_of(data: &Dataset) -> HashMap<(&str, Option<usize>, &str), &Polygon<f64>> {
    data.skipped_shapes
        .iter()
        .map(|k| ((k.layer.as_str(), Some(k.record), k.id.as_str()), &k.shape))
        .collect()
}
