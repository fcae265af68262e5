//! Plain data passed between the pipeline stages.
//!
//! Every stage takes these types and returns new ones; none of them does I/O. Keeping them
//! here (and not inside a stage) lets the stages depend on the data, never on each other:
//! `model` depends on nothing of ours.

pub mod as_json;
pub mod attrs;
pub mod crowd;
mod dataset;
pub mod dem;
pub mod design;
pub mod landmark;
pub mod number;
pub mod object;
pub mod overrides;
mod plan;
pub mod precinct;
pub mod source;
pub mod tile;
pub mod warning;

pub use attrs::{Attrs, FieldNames};
pub use crowd::{CrowdStat, MeanLambdas, Walk, WalkKey};
pub use dataset::*;
pub use landmark::{LandmarkRecord, LandmarkReport, Model, PlannedLandmark};
pub use plan::*;
pub use precinct::{GardenStat, GroundHeight, HallStat, PlannedGarden, PlannedGround, PlannedHall};
/// A tile id `<col>_<row>` on the fixed grid.
pub use tile::TileId;
pub use warning::{Warning, WarningClass};

use geo_types::Coord;

/// Coordinates this far from the CRS's origin (metres; the Earth is 4e7 m round) come from
/// damaged data: their squares overflow, and with them the R-trees' distance arithmetic.
/// `input/` skips polygons with such a vertex; later stages leave such points out of their
/// indexes.
pub const FAR: f64 = 1e8;

/// The lowest and highest ground an elevation may give, metres (the shore of the Dead Sea
/// lies at -430 m, the top of Everest at 8,849 m). Outside them a number is damaged data or a
/// no-data value nobody declared (GDAL's float32 -3.4e38): DEM cells are then no-data, lots
/// and footprints are skipped.
pub const ELEVATION_RANGE: std::ops::RangeInclusive<f64> = -1000.0..=9000.0;

/// The widest street taken from the data or the parameters, metres (the widest avenues are
/// about 100 m; a larger number is a unit error or damaged data).
pub const MAX_STREET_WIDTH: f64 = 200.0;

/// Whether a point is nearer than [`FAR`] to the CRS's origin.
pub fn sane(c: Coord<f64>) -> bool {
    c.x.abs() < FAR && c.y.abs() < FAR
}
