//! edo-city: GIS lots and streets in, a tiled 3D city of Edo-era Kyoto out.
//!
//! The method is Kosaka et al. 2008, "Automatic generation of 3D city models from GIS data".
//! The pipeline reads in one direction, one module per stage:
//! [`input`] -> [`analyse`] -> [`generate`] -> [`output`], driven by [`build`], over the plain
//! data of [`model`] and the plane geometry of [`geom`]; [`materials`] is the texture library
//! every stage names materials from. See ARCHITECTURE.md for the codemap and the rules each
//! stage keeps (tests/architecture.rs checks them).

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod analyse;
pub mod author;
pub mod bounded;
pub mod build;
pub mod compare;
pub mod generate;
pub mod geom;
pub mod growers;
pub mod init;
pub mod input;
pub mod materials;
pub mod model;
pub mod output;
pub mod params;
pub mod rng;
pub mod synth;
pub mod templates;
