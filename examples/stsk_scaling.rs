//! Times the straight skeleton (StSk) on a synthetic wavy ellipse of `n`
//! vertices (no holes), to check how the running time grows with `n`.
//!
//! `cargo run --release --example stsk_scaling -- <n> [<n> ...]`

use skeletonise::geometry::PreparedPolygon;
use skeletonise::methods::straight_skeleton::straight_skeleton_with_stats;
use skeletonise::methods::MethodContext;
use std::time::Instant;

/// An ellipse (3000 × 1000) with 50 waves of amplitude 30 and 3000 of
/// amplitude 5 on its radius.
fn wavy_ellipse(n: usize) -> geo::Polygon<f64> {
    let pts: Vec<geo::Coord<f64>> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 1000.0 + 30.0 * (t * 50.0).sin() + 5.0 * (t * 3000.0).sin();
            geo::Coord {
                x: 5e6 + r * 3.0 * t.cos(),
                y: 6e6 + r * t.sin(),
            }
        })
        .collect();
    geo::Polygon::new(geo::LineString(pts), vec![])
}

fn main() {
    let ns: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse().expect("vertex count"))
        .collect();
    if ns.is_empty() {
        eprintln!("usage: stsk_scaling <n> [<n> ...]");
        std::process::exit(2);
    }
    for n in ns {
        let pp = PreparedPolygon::new(&wavy_ellipse(n)).expect("valid polygon");
        let t = Instant::now();
        match straight_skeleton_with_stats(&pp, &MethodContext::default()) {
            Ok((g, s)) => println!(
                "n = {n}: {:.3} s, {} edges, {} wavefront vertices, {} pops, at most {} queued, {} edges tried (predicted {:.0}), {} candidates kept (predicted {:.0})",
                t.elapsed().as_secs_f64(),
                g.edges().len(),
                s.vertices,
                s.pops,
                s.max_queue,
                s.tried,
                s.predicted.0,
                s.candidates,
                s.predicted.1
            ),
            Err(e) => println!(
                "n = {n}: error {e} after {:.3} s",
                t.elapsed().as_secs_f64()
            ),
        }
    }
}
