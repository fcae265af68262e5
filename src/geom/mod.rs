//! Plane geometry under every stage: one operation a file, each with a doc test. Nothing
//! here knows a lot, a street or a file; the stages (`input`, `analyse`, `generate`,
//! `output`) and the growers build on it. Where `geo` has the algorithm, it is used.
//! One codec lives here too, [`meshopt`]: the decoding of compressed glTF meshes, which
//! `input` (a landmark model) and `output` (its own tiles, read back for their parents)
//! both need, with [`buffers`], which gathers a glTF's buffers within a budget for both.

pub mod accessor;
pub mod bbox;
pub mod buffers;
pub mod clip;
pub mod crs;
pub mod frame;
pub mod meshopt;
pub mod ring;
pub mod segment;
pub mod union;
