//! Every integration test in one test binary (one link, one process: the
//! tests of all modules run in parallel instead of one binary after another).
//! A module that needs the binary or GDAL is compiled with that feature only;
//! run one with `cargo test --test all MODULE::` (e.g. `golden::`).

mod common;

#[cfg(feature = "cli")]
mod bad_input;
#[cfg(feature = "cli")]
mod cli;
#[cfg(feature = "cli")]
mod collapse;
mod fuzz;
#[cfg(feature = "cli")]
mod golden;
#[cfg(feature = "cli")]
mod kill;
mod labels;
mod medial_axis;
mod network;
#[cfg(feature = "cli")]
mod partition;
#[cfg(feature = "cli")]
mod postgis;
mod prune_extend;
mod quality;
#[cfg(feature = "gdal")]
mod reader;
#[cfg(feature = "cli")]
mod readme;
mod registry;
#[cfg(feature = "cli")]
mod reliability;
#[cfg(feature = "cli")]
mod report;
mod rough;
mod score;
#[cfg(feature = "gdal")]
mod step_registry;
mod straight_skeleton;
mod streets;
mod voronoi;
