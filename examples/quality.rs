//! Counts what a cartographer sees on every candidate skeleton of a layer:
//! hooks at line ends, self-crossings, pieces, sharp turns; with the paper's
//! metrics beside them, per method and for the chosen skeleton.
//!
//! ```text
//! cargo run --release --example quality -- PIPELINE.yaml SOURCE LAYER [--set KEY=VALUE]...
//! ```
//!
//! The pipeline's steps run in-process on every feature of `LAYER` (the
//! same `process` the `run` command calls); `scripts/quality.sh` runs it on
//! every training layer and writes `docs/quality.md`. Prints one markdown
//! table row per method and one for the chosen skeleton:
//! `| layer | skeleton | features | mean Z | mean coverage | legs | ends | hooks | hook % |
//! crossing skeletons | extra pieces | sharp turns / km | chosen | failed |`
//! (*failed*: features the method gave no candidate of), then the
//! trunk check line (`one line per polygon part`) when pruning is `trunk`.

use rayon::prelude::*;
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::planar::crossings;
use skeletonise::graph::prune::PruneMode;
use skeletonise::graph::SkeletonGraph;
use skeletonise::io::{InputSpec, Reader};
use skeletonise::process::{polygon_parts, process, Processed};
use skeletonise::score::defects::{end_turns, sharp_turns, HOOK_DEG};

#[derive(Default, Clone)]
struct Tally {
    features: usize,
    z_sum: f64,
    z_n: usize,
    cov_sum: f64,
    legs: usize,
    ends: usize,
    hooks: usize,
    crossing: usize,
    extra_pieces: usize,
    sharp: usize,
    km: f64,
    chosen: usize,
    one_line: usize,
    parts: usize,
    /// Features the method gave no candidate of (its error).
    failed: usize,
}

impl Tally {
    fn add(&mut self, o: &Tally) {
        self.features += o.features;
        self.z_sum += o.z_sum;
        self.z_n += o.z_n;
        self.cov_sum += o.cov_sum;
        self.legs += o.legs;
        self.ends += o.ends;
        self.hooks += o.hooks;
        self.crossing += o.crossing;
        self.extra_pieces += o.extra_pieces;
        self.sharp += o.sharp;
        self.km += o.km;
        self.chosen += o.chosen;
        self.one_line += o.one_line;
        self.parts += o.parts;
        self.failed += o.failed;
    }
}

fn measure(
    lines: &geo::MultiLineString<f64>,
    parts: &[PreparedPolygon],
    scores: Option<&skeletonise::score::Scores>,
    legs: usize,
) -> Tally {
    let g = SkeletonGraph::from_lines(lines);
    let mut t = Tally {
        features: 1,
        legs,
        parts: parts.len(),
        ..Default::default()
    };
    if let Some(s) = scores {
        if !s.distortion.is_nan() {
            t.z_sum = s.distortion;
            t.z_n = 1;
        }
        t.cov_sum = s.coverage;
    }
    // Ends against the polygon part they lie on.
    for p in parts {
        let sub = g.filter_edges(|e, _| {
            let c = g.edge_coords(e);
            p.boundary()
                .contains_with_tolerance(c[c.len() / 2], 1e-6 * p.extent())
        });
        let turns = end_turns(&sub, p);
        t.ends += turns.len();
        t.hooks += turns.iter().filter(|&&a| a > HOOK_DEG).count();
        let deg = sub.degrees();
        if sub.components() == 1
            && deg.iter().all(|&d| d <= 2)
            && deg.iter().filter(|&&d| d == 1).count() == 2
        {
            t.one_line += 1;
        }
        t.extra_pieces += sub.components().saturating_sub(1);
    }
    if crossings(&g) > 0 {
        t.crossing = 1;
    }
    let (n, len) = sharp_turns(&g);
    t.sharp = n;
    t.km = len / 1000.0;
    t
}

/// Prints `hook FID X Y TURN` for every hooked end of `lines`.
fn print_hooks(fid: Option<u64>, lines: &geo::MultiLineString<f64>, parts: &[PreparedPolygon]) {
    let g = SkeletonGraph::from_lines(lines);
    let adj = g.adjacency();
    for n in 0..g.nodes().len() {
        if adj[n].len() != 1 {
            continue;
        }
        let pos = g.nodes()[n].pos;
        let Some(p) = parts.iter().min_by(|a, b| {
            a.boundary()
                .distance(pos)
                .total_cmp(&b.boundary().distance(pos))
        }) else {
            continue;
        };
        let line = g.line_from(skeletonise::graph::NodeId::from_index(n), &adj);
        if let Some(t) = skeletonise::score::defects::end_turn(&line, p) {
            if t > HOOK_DEG {
                println!(
                    "hook {} {:.2} {:.2} {:.1}",
                    fid.unwrap_or(0),
                    pos.x,
                    pos.y,
                    t
                );
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: quality PIPELINE.yaml SOURCE LAYER [--set KEY=VALUE]...");
        std::process::exit(2);
    }
    let mut sets = Vec::new();
    let mut i = 4;
    while i + 1 < args.len() + 1 && i < args.len() {
        if args[i] == "--set" && i + 1 < args.len() {
            sets.push(args[i + 1].clone());
            i += 2;
        } else {
            i += 1;
        }
    }
    let pipeline =
        skeletonise::config::load(std::path::Path::new(&args[1]), &sets).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(78)
        });
    let params = pipeline.process_params();
    let layer = &args[3];
    // Read as `run` reads: repaired by GDAL when the pipeline's `prepare`
    // says `make_valid` (a `gdal_polygonize` ring touching itself is
    // invalid until then).
    let mut feats = Vec::new();
    Reader::open(&InputSpec::layer(&args[2], layer))
        .and_then(|mut r| {
            r.read(1024, params.prepare.make_valid, |batch| {
                feats.extend(batch.into_iter().map(|f| (f.fid, f.geometry)));
                Ok(())
            })
        })
        .unwrap_or_else(|e: skeletonise::io::IoError| {
            eprintln!("{e}");
            std::process::exit(1)
        });
    let methods = params.skeleton.methods.clone();
    let list_hooks = args.iter().any(|a| a == "--hooks");
    let results: Vec<(Vec<Tally>, Tally)> = feats
        .par_iter()
        .filter_map(|(fid, g)| {
            let Some(g) = g else {
                eprintln!("{layer}: feature {fid:?} not measured: no geometry");
                return None;
            };
            let parts = polygon_parts(Some(g))
                .map_err(|e| eprintln!("{layer}: feature {fid:?} not measured: {e}"))
                .ok()?;
            let parts: Vec<PreparedPolygon> = parts
                .iter()
                .filter_map(|p| PreparedPolygon::new(p).ok())
                .collect();
            let Processed::Done(o) = process(Some(g), &params) else {
                eprintln!("{layer}: feature {fid:?} not measured: the pipeline rejects it");
                return None;
            };
            let per: Vec<Tally> = o
                .candidates
                .iter()
                .map(|c| match &c.result {
                    Ok(s) => {
                        let mut t = measure(&s.geometry, &parts, s.scores.as_ref(), s.legs);
                        t.chosen = 0;
                        t
                    }
                    Err(_) => Tally {
                        failed: 1,
                        ..Default::default()
                    },
                })
                .collect();
            let (_, s) = o.chosen();
            if list_hooks {
                print_hooks(*fid, &s.geometry, &parts);
            }
            let mut chosen = measure(&s.geometry, &parts, s.scores.as_ref(), s.legs);
            chosen.chosen = 1;
            let mut per = per;
            per[o.chosen].chosen = 1;
            Some((per, chosen))
        })
        .collect();
    let mut per = vec![Tally::default(); methods.len()];
    let mut chosen = Tally::default();
    for (p, c) in &results {
        for (a, b) in per.iter_mut().zip(p) {
            a.add(b);
        }
        chosen.add(c);
    }
    let row = |name: &str, t: &Tally| {
        println!(
            "| {layer} | {name} | {} | {:.5} | {:.3} | {} | {} | {} | {:.1} % | {} | {} | {:.2} | {} | {} |",
            t.features,
            t.z_sum / t.z_n.max(1) as f64,
            t.cov_sum / t.features.max(1) as f64,
            t.legs,
            t.ends,
            t.hooks,
            100.0 * t.hooks as f64 / t.ends.max(1) as f64,
            t.crossing,
            t.extra_pieces,
            t.sharp as f64 / t.km.max(1e-9),
            t.chosen,
            t.failed
        );
    };
    for (m, t) in methods.iter().zip(&per) {
        row(m.as_str(), t);
    }
    row("**chosen**", &chosen);
    if params.prune.is_some_and(|p| p.mode == PruneMode::Trunk) {
        for (m, t) in methods.iter().zip(&per) {
            println!(
                "trunk {layer} {m}: one line per polygon part on {} of {} parts",
                t.one_line, t.parts
            );
        }
    }
}
