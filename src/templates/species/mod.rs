//! Tree species (ki no shu 木の種), one TOML file each in `templates/trees/`: how a species
//! grows (an L-system with its turtle, or space colonization), how tall it stands, how its
//! skeleton is meshed (tube sides, what LOD1 prunes, leaves, bark) and its leaves by season.
//! Editable without code; errors carry `file:line:column` as the other templates do.
//!
//! A species knows nothing of lots: the city plants it (`analyse::trees`), the mesher builds
//! its levels of detail from the skeleton it grows (`generate::tree`).

use rand_pcg::Pcg64;

mod parse;

use crate::growers::colonization::{self, GroupReport};
use crate::growers::lsystem::{LSystem, TurtleParams};
use crate::growers::skeleton::Skeleton;
pub use parse::parse;

/// The seed of each species' sample tree: its crown shape is measured on it, its billboard
/// texture rendered from it, and `<out>/species/` holds its LOD0.
pub const SAMPLE_SEED: u64 = 1;

/// The seasons a build may show (`trees.season`).
pub const SEASONS: [&str; 4] = ["spring", "summer", "autumn", "winter"];

/// A grown tree: its skeleton and what its grower reports (the L-system's symbols; space
/// colonization's stop reason, iterations and groups).
#[derive(Debug, Clone)]
pub struct Grown {
    /// The skeleton, `height` metres tall, standing at the origin.
    pub skeleton: Skeleton,
    /// The grower's numbers, as JSON keys of `edo-city tree --report`.
    pub report: serde_json::Value,
}

/// How a species grows its skeleton.
#[derive(Debug, Clone)]
pub enum Grower {
    /// A bracketed L-system read by the 3D turtle (seed 003).
    LSystem {
        /// Axiom, rules, generations.
        system: LSystem,
        /// What the turtle's symbols mean in metres and degrees.
        turtle: TurtleParams,
    },
    /// Space colonization with vector-field control, in groups (seed 001).
    Colonization {
        /// Step, influence, kill, field.
        params: colonization::Params,
        /// Trunk, branches, roots.
        groups: Vec<colonization::Group>,
        /// Radius of a branch tip, metres (at the species' nominal height).
        tip_radius: f64,
        /// The pipe model's exponent, 2 to 3.
        pipe_exponent: f64,
        /// Roots within this many metres of the trunk are shown above ground in the city
        /// (`[roots] exposed`).
        roots_exposed: f64,
    },
}

/// What a tip carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeafKind {
    /// Leaf cards around each tip, placed by the golden angle (phyllotaxis).
    Cluster,
    /// Narrow cards along the tip, as pine needles.
    Needles,
    /// No leaves.
    None,
}

/// How a skeleton is meshed.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshSpec {
    /// Sides of the LOD0 tubes.
    pub sides: u8,
    /// LOD1 prunes branches thinner than this share of the trunk's base radius into leaf
    /// cards.
    pub twig: f64,
    /// The bark material.
    pub bark: u16,
    /// Leaves.
    pub leaf: LeafKind,
    /// A leaf card's size, metres (at the species' nominal height).
    pub leaf_size: f64,
    /// Leaf cards per leafy node.
    pub per_tip: u32,
    /// How many nodes from each tip up carry leaves (1: the tip alone).
    pub leaf_nodes: u32,
}

/// A tree species.
#[derive(Debug, Clone)]
pub struct Species {
    /// Its name (romaji): `sakura`.
    pub name: String,
    /// Its kanji: 桜.
    pub kanji: String,
    /// What it is.
    pub description: String,
    /// The file it was read from.
    pub file: String,
    /// `lsystem` or `colonization`.
    pub method: &'static str,
    /// [low, high] metres: a planted tree's height is drawn between.
    pub height: [f64; 2],
    /// The library texture rendered from this species (its billboards and LOD2).
    pub billboard: u16,
    /// How it grows.
    pub grower: Grower,
    /// How it is meshed.
    pub mesh: MeshSpec,
    /// The leaf material of each season of [`SEASONS`]; `None` for bare branches.
    pub leaves: [Option<u16>; 4],
}

impl Species {
    /// Grows one skeleton with `rng` (the per-feature RNG of the tree), scaled so that it
    /// stands `height` metres tall.
    pub fn grow(&self, height: f64, rng: &mut Pcg64) -> Result<Grown, String> {
        let fail =
            |e: &dyn std::fmt::Display| format!("{}: species `{}`: {e}", self.file, self.name);
        let (mut sk, report) = match &self.grower {
            Grower::LSystem { system, turtle } => {
                let word = system.expand(rng).map_err(|e| fail(&e))?;
                let sk = crate::growers::lsystem::turtle::interpret(&word, turtle);
                (sk, serde_json::json!({ "symbols": word.modules.len() }))
            }
            Grower::Colonization {
                params,
                groups,
                tip_radius,
                pipe_exponent,
                ..
            } => {
                let (mut sk, reports) =
                    colonization::grow(params, groups, rng).map_err(|e| fail(&e))?;
                sk.pipe_radii(*tip_radius, *pipe_exponent);
                let report = colonization_report(params, &reports, &sk);
                (sk, report)
            }
        };
        let (_, hi) = sk.bounds();
        if !(hi[2] > 0.0 && hi[2].is_finite()) {
            return Err(format!(
                "{}: species `{}` grows nothing above the ground",
                self.file, self.name
            ));
        }
        sk.scale(height / hi[2]);
        Ok(Grown {
            skeleton: sk,
            report,
        })
    }

    /// [`Species::grow`], then the roots as the city shows them: those within
    /// `roots_exposed` of the trunk along the ground, the rest (hidden below it) dropped.
    pub fn grow_in_city(&self, height: f64, rng: &mut Pcg64) -> Result<Grown, String> {
        let mut g = self.grow(height, rng)?;
        g.skeleton
            .expose_roots(self.roots_exposed() * height / self.nominal_height());
        Ok(g)
    }

    /// How far from the trunk roots show above ground (0 for none or an L-system).
    pub fn roots_exposed(&self) -> f64 {
        match &self.grower {
            Grower::Colonization { roots_exposed, .. } => *roots_exposed,
            Grower::LSystem { .. } => 0.0,
        }
    }

    /// The leaf material shown in `season` (one of [`SEASONS`]).
    pub fn leaf_material(&self, season: &str) -> Option<u16> {
        let k = SEASONS.iter().position(|s| *s == season).unwrap_or(1);
        self.leaves[k]
    }

    /// The mean of the species' height range.
    pub fn nominal_height(&self) -> f64 {
        (self.height[0] + self.height[1]) / 2.0
    }
}

/// The report keys of a colonized tree: each group's, and their sums (the first group that
/// did not use up its points gives the stop reason, else `all_killed`). The tree's `edges`
/// are the skeleton's, not the groups' sum: a group that starts on the stem counts the
/// stem's edges it starts from as its own (kusu, seed 1, summed 1,876 edges over 1,873
/// nodes).
fn colonization_report(
    p: &colonization::Params,
    reports: &[GroupReport],
    sk: &Skeleton,
) -> serde_json::Value {
    let group = |r: &GroupReport| {
        serde_json::json!({
            "name": r.name,
            "stop": r.stop.as_str(),
            "iterations": r.iterations,
            "nodes": r.nodes,
            "edges": r.edges,
            "points_left": r.points_left,
            "oscillations": r.oscillations,
            "step": p.step,
            "influence": p.influence,
            "kill": p.kill,
        })
    };
    let stop = reports
        .iter()
        .map(|r| r.stop)
        .find(|s| *s != colonization::Stop::AllKilled)
        .unwrap_or(colonization::Stop::AllKilled);
    serde_json::json!({
        "stop": stop.as_str(),
        "iterations": reports.iter().map(|r| r.iterations).sum::<usize>(),
        "edges": sk.nodes.iter().filter(|n| n.parent.is_some()).count(),
        "points_left": reports.iter().map(|r| r.points_left).sum::<usize>(),
        "step": p.step,
        "influence": p.influence,
        "kill": p.kill,
        "groups": reports.iter().map(group).collect::<Vec<_>>(),
    })
}
