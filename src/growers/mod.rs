//! The procedural growers: models that know nothing of GIS, lots or files. Each takes plain
//! numbers and a seed and returns positions, skeletons or layouts; the city side of each
//! (where it goes, what it is given) is in `analyse/`, its meshes in `generate/`.
//!
//! - [`boids`]: crowds by the boids of Reynolds with the three zones of Oyama et al.
//!   (seed 004), measured by their order parameters lambda1-3.
//! - [`colonization`]: space colonization with vector-field control (seed 001).
//! - [`garden`]: dry rock gardens by a GA with the Ryoanji rules (seed 000).
//! - [`lsystem`]: bracketed, stochastic and parametric L-systems and the 3D turtle (seed 003).
//! - [`skeleton`]: the branching skeleton the tree growers return and the tree mesher takes.
//! - [`v3`]: the 3D vectors they use.

pub mod boids;
pub mod colonization;
pub mod garden;
pub mod lsystem;
pub mod skeleton;
pub mod v3;
