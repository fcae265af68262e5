//! What each analysis step makes, as plain data. A step takes what it reads (the dataset,
//! the products of the steps before it, the tiles built so far) as arguments and returns its
//! own product; [`super::analyse`] files each product into the [`Plan`]. No step writes into
//! the plan, so what a step depends on is in its signature: what an edit must rerun can be
//! read off it. Only the landmarks change what came before them (they displace houses and
//! fences), and their signature says so with `&mut`.

use std::collections::{BTreeMap, BTreeSet};

use crate::model::landmark::{LandmarkReport, PaletteEntry};
use crate::model::{
    CrowdStat, GardenStat, HallStat, Plan, PlannedBillboard, PlannedGarden, PlannedGround,
    PlannedHall, PlannedLandmark, Skipped, TileId, Walk, Warning,
};

/// A step's planned objects per tile, each tile's in the order the step made them.
pub type ByTile<T> = BTreeMap<TileId, Vec<T>>;

/// What a step noticed: its warnings and the features it left out, each in the order it met
/// them (the report lists them so).
#[derive(Debug, Default)]
pub struct Notes {
    /// Warnings, in order.
    pub warnings: Vec<Warning>,
    /// Features left out, with their reasons, in order.
    pub skipped: Vec<Skipped>,
}

impl Notes {
    /// Adds them after what the plan noted before.
    pub fn file(self, plan: &mut Plan) {
        plan.warnings.extend(self.warnings);
        plan.skipped.extend(self.skipped);
    }
}

/// The halls of estates and temples (`halls::plan_halls`).
#[derive(Debug, Default)]
pub struct Halls {
    /// The halls placed, per tile of their plot's centre.
    pub by_tile: ByTile<PlannedHall>,
    /// What became of every hall a lot's use asked for, in lot order.
    pub reports: Vec<HallStat>,
}

impl Halls {
    /// Their tiles become built.
    pub fn file(self, plan: &mut Plan) {
        plan.tiles.extend(self.by_tile.keys().cloned());
        plan.halls = self.by_tile;
        plan.hall_reports = self.reports;
    }
}

/// The rock gardens (`gardens::plan_gardens`).
#[derive(Debug, Default)]
pub struct Gardens {
    /// The gardens placed, per tile of their lot.
    pub by_tile: ByTile<PlannedGarden>,
    /// What became of every lot or polygon that could have had a garden.
    pub reports: Vec<GardenStat>,
    /// Gardens-layer polygons and kept designs that got no garden.
    pub skipped: Vec<Skipped>,
}

impl Gardens {
    /// Their tiles become built.
    pub fn file(self, plan: &mut Plan) {
        plan.tiles.extend(self.by_tile.keys().cloned());
        plan.gardens = self.by_tile;
        plan.garden_reports = self.reports;
        plan.skipped.extend(self.skipped);
    }
}

/// The people and trees (`billboards::plan_billboards`, then `trees::plant`).
#[derive(Debug, Default)]
pub struct Billboards {
    /// People and trees per tile, people first.
    pub by_tile: ByTile<PlannedBillboard>,
    /// The walkers' clips, per tile, in the order of their people.
    pub walks: ByTile<Walk>,
    /// The street crowds' order parameters (`people.motion = "boids"`).
    pub crowds: Vec<CrowdStat>,
    /// Tiles that only the point layers' people and trees make built.
    pub tiles: BTreeSet<TileId>,
    /// Points skipped and what the drawing noticed.
    pub notes: Notes,
}

impl Billboards {
    /// Their given points' tiles become built.
    pub fn file(self, plan: &mut Plan) {
        plan.tiles.extend(self.tiles);
        plan.billboards = self.by_tile;
        plan.walks = self.walks;
        plan.crowds = self.crowds;
        self.notes.file(plan);
    }
}

/// The ground (`ground::plan_ground`).
#[derive(Debug, Default)]
pub struct Grounds {
    /// Tiles the lots touch: they get ground even with nothing built on it.
    pub tiles: BTreeSet<TileId>,
    /// The ground of every tile, built before or touched by a lot.
    pub by_tile: BTreeMap<TileId, PlannedGround>,
}

impl Grounds {
    /// The lots' tiles become tiles to write.
    pub fn file(self, plan: &mut Plan) {
        plan.tiles.extend(self.tiles);
        plan.grounds = self.by_tile;
    }
}

/// The landmarks (`landmarks::plan_landmarks`).
#[derive(Debug, Default)]
pub struct Landmarks {
    /// The landmarks placed, per tile of their point.
    pub by_tile: ByTile<PlannedLandmark>,
    /// The materials their models bring, in palette order.
    pub palette: Vec<PaletteEntry>,
    /// Their textures: prefixed file name and bytes.
    pub textures: Vec<(String, std::sync::Arc<Vec<u8>>)>,
    /// What became of the landmarks layer.
    pub report: LandmarkReport,
    /// Landmarks not placed and the houses they displaced, in order.
    pub skipped: Vec<Skipped>,
}

impl Landmarks {
    /// Their tiles become built.
    pub fn file(self, plan: &mut Plan) {
        plan.tiles.extend(self.by_tile.keys().cloned());
        plan.landmarks = self.by_tile;
        plan.palette = self.palette;
        plan.model_textures = self.textures;
        plan.landmark_report = self.report;
        plan.skipped.extend(self.skipped);
    }
}
