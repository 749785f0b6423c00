//! Runs the straight skeleton (StSk) on every polygon of one layer, in
//! parallel, and prints counts and the wall time of the skeleton step.
//!
//! `cargo run --release --example stsk_layer -- <source> <layer> [--each]`
//!
//! It also prints a fingerprint of the skeletons — their node count, total
//! length and a hash of the node positions rounded to the millimetre (in
//! metres) — so that a change meant to leave the skeleton alone can be
//! checked to do so; with `--each`, one line per feature (its index, edges
//! and total length) as well.

use rayon::prelude::*;
use skeletonise::geometry::PreparedPolygon;
use skeletonise::methods::straight_skeleton::straight_skeleton_with_stats;
use skeletonise::methods::MethodContext;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let each = args.len() == 4 && args[3] == "--each";
    let (source, layer) = match &args[..args.len().min(3)] {
        [_, s, l] if args.len() == 3 || each => (s.as_str(), l.as_str()),
        _ => {
            eprintln!("usage: stsk_layer <source> <layer> [--each]");
            std::process::exit(2);
        }
    };
    let feats = skeletonise::io::read_layer_polygons(source, layer).unwrap_or_else(|e| {
        eprintln!("cannot read {layer}: {e}");
        std::process::exit(1);
    });
    let polys: Vec<(usize, geo::Polygon<f64>)> = feats
        .into_iter()
        .enumerate()
        .flat_map(|(i, (_, g))| match g {
            geo::Geometry::Polygon(p) => vec![(i, p)],
            geo::Geometry::MultiPolygon(m) => m.0.into_iter().map(|p| (i, p)).collect(),
            _ => Vec::new(),
        })
        .collect();
    let start = Instant::now();
    let results: Vec<_> = polys
        .par_iter()
        .map(|(i, p)| {
            let t = Instant::now();
            let r = PreparedPolygon::new(p)
                .map_err(|e| e.to_string())
                .and_then(|pp| {
                    straight_skeleton_with_stats(&pp, &MethodContext::default())
                        .map_err(|e| e.to_string())
                });
            (*i, r, t.elapsed())
        })
        .collect();
    let wall = start.elapsed();
    let (mut ok, mut edges, mut vertices) = (0, 0, 0);
    let (mut nodes, mut length, mut hash) = (0usize, 0.0f64, 0u64);
    for (i, r, dt) in &results {
        match r {
            Ok((g, s)) => {
                ok += 1;
                if dt.as_secs_f64() > 1.0 {
                    eprintln!(
                        "feature {i}: {:.3} s, {} vertices in, {} wavefront vertices, {} pops ({} stale, {} missed splits), at most {} queued, {} edges tried (predicted {:.0}), {} candidates kept (predicted {:.0})",
                        dt.as_secs_f64(),
                        s.input_vertices,
                        s.vertices,
                        s.pops,
                        s.stale,
                        s.missed,
                        s.max_queue,
                        s.tried,
                        s.predicted.0,
                        s.candidates,
                        s.predicted.1
                    );
                }
                edges += g.edges().len();
                vertices += s.input_vertices;
                nodes += g.nodes().len();
                let len = (0..g.edges().len())
                    .map(|e| {
                        let c = g.edge_coords(skeletonise::graph::EdgeId::from_index(e));
                        skeletonise::graph::polyline_length(&c)
                    })
                    .sum::<f64>();
                length += len;
                if each {
                    println!("feature={i} edges={} length={len:.6}", g.edges().len());
                }
                for n in g.nodes() {
                    let (x, y) = (
                        (n.pos.x * 1e3).round() as i64,
                        (n.pos.y * 1e3).round() as i64,
                    );
                    // Order-free: a sum of mixed keys.
                    let k =
                        (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (y as u64).rotate_left(29);
                    hash = hash.wrapping_add(k.wrapping_mul(0xBF58_476D_1CE4_E5B9));
                }
            }
            Err(e) => eprintln!("feature {i}: {e} ({:.3} s)", dt.as_secs_f64()),
        }
    }
    println!(
        "layer={layer} polygons={} ok={ok} failed={} input_vertices={vertices} skeleton_edges={edges} skeleton_nodes={nodes} skeleton_length={length:.3} positions_hash={hash:016x} wall_s={:.4}",
        results.len(),
        results.len() - ok,
        wall.as_secs_f64()
    );
}
