//! Helpers for end-to-end tests: run the real binary, make and read real
//! GeoPackage files.
#![allow(dead_code)]

#[cfg(feature = "gdal")]
pub mod browser;

pub mod shapes;

use std::path::{Path, PathBuf};
use std::process::Output;

#[cfg(feature = "gdal")]
mod gpkg;
#[cfg(feature = "gdal")]
#[allow(unused_imports)] // each test uses some of them
pub use gpkg::*;

/// The training data shipped beside the project.
pub const TRAIN: &str = "tests/data/gshhg-train.gpkg";
/// Every layer of the training data.
pub const LAYERS: [&str; 5] = [
    "islands_hebrides",
    "lakes_scotland",
    "river_st_lawrence",
    "river_danube",
    "river_lena",
];

/// The embedded demo data.
pub const DEMO: &str = "examples/data/demo.gpkg";

/// Runs `skeletonise` with `args` in the crate root.
#[cfg(feature = "cli")]
pub fn skeletonise(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_skeletonise"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs")
}

/// Exit code and stderr as text.
pub fn code_and_err(o: &Output) -> (i32, String) {
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

/// A fresh temporary directory.
pub fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// Writes a pipeline file into `dir` and returns its path.
pub fn pipeline(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A standard pipeline reading `source`/`layer` and writing `out`.
pub fn basic_pipeline(source: &str, layer: &str, out: &Path, extra_steps: &str) -> String {
    format!(
        "input:\n  source: {source}\n  layer: {layer}\nsteps:\n  - skeleton: {{ methods: [CDT] }}\n{extra_steps}output:\n  path: {}\n",
        out.display()
    )
}

/// Absolute path of a file in the crate root.
pub fn root(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(p)
        .display()
        .to_string()
}

/// FNV-1a, 64 bit: a stable fingerprint of a text.
pub fn fingerprint(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The leaves (degree-1 nodes) of skeleton lines, joined where their end
/// points are equal bit for bit.
pub fn leaves(lines: &geo::MultiLineString<f64>) -> Vec<geo::Coord<f64>> {
    let g = skeletonise::graph::SkeletonGraph::from_lines(lines);
    let deg = g.degrees();
    (0..deg.len())
        .filter(|&i| deg[i] == 1)
        .map(|i| g.nodes()[i].pos)
        .collect()
}
