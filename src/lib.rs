//! # skeletonise
//!
//! Collapse polygons to skeletons for cartographic generalisation: Voronoi
//! (VD), densified Voronoi (DVD), constrained Delaunay (CDT), straight
//! skeleton (StSk) and medial axis (MA); automatic pruning and leg extension;
//! the deviation and distortion metrics of the skeletonisation-comparison
//! paper; a YAML pipeline from any OGR source to a GeoPackage.
//!
//! The per-feature path ([`process`]) is pure Rust on owned [`geo`] types;
//! GDAL is touched only by `io`.
//!
//! Cargo features: `gdal` (the reader and writer `io`, the run driver
//! `pipeline` and `external`'s join of another tool's lines) and `cli` (the
//! `skeletonise` binary; implies `gdal`), both on by default. With
//! `--no-default-features` the core — methods, pruning, extension, scoring,
//! selection, the pipeline file model and the per-feature path — builds
//! without GDAL, for bindings and distributed engines that bring their own
//! I/O.

//! ## Quick start
//!
//! One polygon through every step, as the command line's per-feature path
//! runs it: the medial axis of a 100 × 10 strip is its centre line, and it
//! scores a distortion of zero.
//!
//! ```
//! use geo::{polygon, Geometry};
//! use skeletonise::process::{process, ProcessParams, Processed};
//!
//! let strip = Geometry::Polygon(polygon![
//!     (x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 10.), (x: 0., y: 10.)
//! ]);
//! let Processed::Done(outcome) = process(Some(&strip), &ProcessParams::all_steps()) else {
//!     panic!("a strip is skeletonised");
//! };
//! let (method, skeleton) = outcome.chosen();
//! assert_eq!(method.as_str(), "MA");
//! assert!(skeleton.scores.unwrap().distortion < 1e-9);
//! ```
//!
//! A pipeline file (`config::load`) gives the same parameters, and
//! `pipeline::run` (with the `gdal` feature) reads any OGR source and writes
//! the GeoPackage.

#![warn(missing_docs)]

pub(crate) mod clock;
pub mod collapse;
pub mod config;
pub mod connect;
#[cfg(feature = "gdal")]
pub mod external;
pub mod feature;
pub mod geometry;
pub mod graph;
#[cfg(feature = "gdal")]
pub mod io;
pub mod label;
pub mod layer;
pub mod methods;
pub mod narrow;
pub mod neighbours;
pub mod numbers;
pub mod output;
pub mod partition;
#[cfg(feature = "gdal")]
pub mod pipeline;
pub mod process;
pub mod report;
#[cfg(feature = "gdal")]
pub mod reporting;
pub mod score;
pub mod streets;
