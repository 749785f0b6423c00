//! Runs `DVD` (or `VD`) on every polygon part of one layer, in parallel, and
//! prints the point, node and edge counts and the wall time of the skeleton
//! step alone (reading excluded). Used by `scripts/bench-dvd.sh`.
//!
//! ```text
//! cargo run --release --example dvd_layer -- SOURCE LAYER [factor:K | spacing:D | vd] [--threads N]
//! ```

use rayon::prelude::*;
use skeletonise::geometry::{densify::Density, PreparedPolygon};
use skeletonise::io::read_layer_polygons;
use skeletonise::methods::MethodContext;
use skeletonise::methods::{voronoi::Voronoi, SkeletonMethod};
use skeletonise::process::polygon_parts;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: dvd_layer SOURCE LAYER [factor:K | spacing:D | vd] [--threads N]";
    let (Some(source), Some(layer)) = (args.first(), args.get(1)) else {
        return Err(usage.into());
    };
    let mut method = Voronoi::densified(Density::Factor(4), 2_000_000);
    let mut label = "DVD factor:4".to_string();
    let mut threads = 0;
    let mut rest = args[2..].iter();
    while let Some(a) = rest.next() {
        if a == "--threads" {
            threads = rest.next().ok_or(usage)?.parse()?;
        } else if a == "vd" {
            method = Voronoi::plain();
            label = "VD".into();
        } else if let Some(k) = a.strip_prefix("factor:") {
            method = Voronoi::densified(Density::Factor(k.parse()?), 2_000_000);
            label = format!("DVD {a}");
        } else if let Some(d) = a.strip_prefix("spacing:") {
            method = Voronoi::densified(Density::Spacing(d.parse()?), 2_000_000);
            label = format!("DVD {a}");
        } else {
            return Err(usage.into());
        }
    }
    if threads > 0 {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()?;
    }
    let features = read_layer_polygons(source, layer)?;
    let parts: Vec<PreparedPolygon> = features
        .iter()
        .flat_map(|(_, g)| polygon_parts(Some(g)).unwrap_or_default())
        .filter_map(|p| PreparedPolygon::new(&p).ok())
        .collect();
    let start = Instant::now();
    let results: Vec<_> = parts
        .par_iter()
        .map(|p| method.skeletonise(p, &MethodContext::default()))
        .collect();
    let secs = start.elapsed().as_secs_f64();
    let points: usize = parts
        .iter()
        .map(|p| method.sites(p).map(|s| s.len()).unwrap_or(0))
        .sum();
    let (mut nodes, mut edges, mut failed) = (0, 0, 0);
    for r in &results {
        match r {
            Ok(g) => {
                nodes += g.nodes().len();
                edges += g.edges().len();
            }
            Err(_) => failed += 1,
        }
    }
    println!(
        "{layer}\t{label}\tparts={}\tfailed={failed}\tpoints={points}\tnodes={nodes}\tedges={edges}\tseconds={secs:.4}",
        parts.len()
    );
    Ok(())
}
