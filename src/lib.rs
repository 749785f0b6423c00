//! # skeletonise
//!
//! Collapse polygons to skeletons for cartographic generalisation: Voronoi
//! (VD), densified Voronoi (DVD), constrained Delaunay (CDT), straight
//! skeleton (StSk) and medial axis (MA); automatic pruning and leg extension;
//! the deviation and distortion metrics of the skeletonisation-comparison
//! paper; a YAML pipeline from any OGR source to a GeoPackage.
//!
//! The per-feature path ([`process`]) is pure Rust on owned [`geo`] types;
//! GDAL is touched only by [`io`].

#![warn(missing_docs)]

pub mod collapse;
pub mod config;
pub mod external;
pub mod feature;
pub mod geometry;
pub mod graph;
pub mod io;
pub mod methods;
pub mod output;
pub mod pipeline;
pub mod process;
pub mod report;
pub mod reporting;
pub mod score;
