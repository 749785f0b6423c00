//! Medial axis of every feature of one layer, in parallel; prints timings.
//!
//! ```text
//! cargo run --release --example ma_layer -- tests/data/gshhg-train.gpkg river_lena [--serial]
//! ```
//!
//! Reading is timed separately from the skeletonisation, so the numbers can
//! be set beside PostGIS's `ST_ApproximateMedialAxis` on an already loaded
//! table (see `scripts/bench-ma.sh`).

use rayon::prelude::*;
use skeletonise::geometry::PreparedPolygon;
use skeletonise::methods::medial_axis::MedialAxis;
use skeletonise::methods::MethodContext;
use skeletonise::methods::SkeletonMethod;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: ma_layer <source> <layer> [--serial]");
        std::process::exit(2);
    }
    let serial = args.iter().any(|a| a == "--serial");
    let t0 = Instant::now();
    let feats = skeletonise::io::read_layer_polygons(&args[1], &args[2]).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(1)
    });
    let parts: Vec<geo::Polygon<f64>> = feats
        .iter()
        .flat_map(|(_, g)| skeletonise::process::polygon_parts(Some(g)).unwrap_or_default())
        .collect();
    let read = t0.elapsed();
    let method = MedialAxis::default();
    let run = |p: &geo::Polygon<f64>| -> (usize, usize, usize, bool) {
        match PreparedPolygon::new(p) {
            Ok(pp) => match method.skeletonise(&pp, &MethodContext::default()) {
                Ok(g) => (pp.vertex_count(), g.nodes().len(), g.edges().len(), true),
                Err(e) => {
                    eprintln!("rejected: {e}");
                    (pp.vertex_count(), 0, 0, false)
                }
            },
            Err(e) => {
                eprintln!("rejected: {e}");
                (0, 0, 0, false)
            }
        }
    };
    let t1 = Instant::now();
    let results: Vec<_> = if serial {
        parts.iter().map(run).collect()
    } else {
        parts.par_iter().map(run).collect()
    };
    let ma = t1.elapsed();
    let vertices: usize = results.iter().map(|r| r.0).sum();
    let nodes: usize = results.iter().map(|r| r.1).sum();
    let edges: usize = results.iter().map(|r| r.2).sum();
    let rejected = results.iter().filter(|r| !r.3).count();
    println!(
        "layer={} features={} parts={} vertices={} nodes={} edges={} rejected={} threads={} read_s={:.4} ma_s={:.4}",
        args[2],
        feats.len(),
        parts.len(),
        vertices,
        nodes,
        edges,
        rejected,
        if serial { 1 } else { rayon::current_num_threads() },
        read.as_secs_f64(),
        ma.as_secs_f64()
    );
}
