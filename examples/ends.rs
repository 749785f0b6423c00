//! Line ends and selection on a layer, feature by feature: does the chosen
//! skeleton score as well as the best candidate, and do its ends stay on
//! the medial axis and run on into the polygon's tips?
//!
//! ```text
//! cargo run --release --example ends -- PIPELINE.yaml SOURCE LAYER [--set KEY=VALUE]...
//!     [--list N] [--wkt FILE.csv]
//! ```
//!
//! The pipeline's steps run in-process on every feature of `LAYER` (the
//! same `process` the `run` command calls). Printed, one markdown row:
//! `| layer | features | mean Z chosen | mean Z best | chosen ≤ 2 best + tie | ends | hooks | off-axis ends |`
//!
//! * *best*: the candidate of the feature with the smallest Z;
//!   *chosen ≤ 2 best + tie*: the share of features whose chosen Z is at most
//!   twice that plus the `select` step's `tie`.
//! * *hooks*: ends turning by more than 60° over their last local width
//!   ([`skeletonise::score::defects`]).
//! * *off-axis ends*: ends whose last stretch (one local width of the line,
//!   `2 r` where `r` is the distance to ∂P one local width back,
//!   [`skeletonise::graph::line::end_width_point`]) comes farther than that
//!   width `2 r` from the raw (unpruned) medial axis of the polygon.
//!
//! `--list N` prints the N worst features by chosen Z over best Z, by Z and
//! by off-axis distance; `--wkt FILE.csv` writes, for every listed feature,
//! its polygon, raw medial axis, chosen and best skeleton as WKT rows
//! (`fid,kind,label,wkt`) for `scripts/ends_picture.py`.

use rayon::prelude::*;
use rstar::{primitives::GeomWithData, primitives::Line, PointDistance, RTree};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::line::{end_width_point, point_at};
use skeletonise::graph::{polyline_length, SkeletonGraph};
use skeletonise::io::{InputSpec, Reader};
use skeletonise::methods::{build, MethodContext, MethodId, SkeletonParams};
use skeletonise::process::{polygon_parts, process, Processed};
use skeletonise::score::defects::{end_turn, HOOK_DEG};
use std::fmt::Write as _;

type Seg = GeomWithData<Line<[f64; 2]>, ()>;

/// What one feature gives.
struct Record {
    fid: i64,
    chosen: String,
    z_chosen: f64,
    best: String,
    z_best: f64,
    ends: usize,
    hooks: usize,
    off: usize,
    /// Largest off-axis distance of an end over its local width.
    off_ratio: f64,
    wkt: Vec<(String, String, String)>,
}

fn raw_medial_axis(p: &PreparedPolygon) -> Option<SkeletonGraph> {
    let params = SkeletonParams {
        methods: vec![MethodId::MA],
        ..Default::default()
    };
    build(MethodId::MA, &params)
        .skeletonise(p, &MethodContext::default())
        .ok()
}

fn segments(g: &SkeletonGraph) -> RTree<Seg> {
    let mut out = Vec::new();
    for i in 0..g.edges().len() {
        let c = g.edge_coords(skeletonise::graph::EdgeId::from_index(i));
        for w in c.windows(2) {
            out.push(GeomWithData::new(
                Line::new([w[0].x, w[0].y], [w[1].x, w[1].y]),
                (),
            ));
        }
    }
    RTree::bulk_load(out)
}

/// Ends of `lines` on `p`: (ends, hooks, off-axis, worst off ratio).
fn ends_of(
    lines: &geo::MultiLineString<f64>,
    p: &PreparedPolygon,
    axis: &RTree<Seg>,
) -> (usize, usize, usize, f64) {
    let all = SkeletonGraph::from_lines(lines);
    let g = all.filter_edges(|e, _| {
        let c = all.edge_coords(e);
        p.boundary()
            .contains_with_tolerance(c[c.len() / 2], 1e-6 * p.extent())
    });
    let adj = g.adjacency();
    let (mut ends, mut hooks, mut off, mut worst) = (0, 0, 0, 0.0f64);
    for n in 0..g.nodes().len() {
        if adj[n].len() != 1 {
            continue;
        }
        let line = g.line_from(skeletonise::graph::NodeId::from_index(n), &adj);
        if polyline_length(&line) <= 0.0 {
            continue;
        }
        ends += 1;
        if end_turn(&line, p).is_some_and(|t| t > HOOK_DEG) {
            hooks += 1;
        }
        let (w, r) = end_width_point(&line, p);
        let width = 2.0 * r;
        if width <= 0.0 {
            continue;
        }
        let steps = 32;
        let dev = (0..=steps)
            .map(|i| {
                let q = point_at(&line, w * i as f64 / steps as f64);
                axis.nearest_neighbor(&[q.x, q.y])
                    .map_or(0.0, |s| s.distance_2(&[q.x, q.y]).sqrt())
            })
            .fold(0.0f64, f64::max);
        worst = worst.max(dev / width);
        if dev > width {
            off += 1;
        }
    }
    (ends, hooks, off, worst)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: ends PIPELINE.yaml SOURCE LAYER [--set KEY=VALUE]... [--list N] [--wkt FILE.csv]");
        std::process::exit(2);
    }
    let (mut sets, mut list, mut wkt_out) = (Vec::new(), 0usize, None);
    let mut i = 4;
    while i < args.len() {
        match args[i].as_str() {
            "--set" if i + 1 < args.len() => sets.push(args[i + 1].clone()),
            "--list" if i + 1 < args.len() => list = args[i + 1].parse().unwrap_or(0),
            "--wkt" if i + 1 < args.len() => wkt_out = Some(args[i + 1].clone()),
            _ => {
                eprintln!("unknown argument {}", args[i]);
                std::process::exit(2)
            }
        }
        i += 2;
    }
    let pipeline =
        skeletonise::config::load(std::path::Path::new(&args[1]), &sets).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(78)
        });
    let params = pipeline.process_params();
    let tie = params.select.map_or(0.0, |s| s.tie);
    let layer = &args[3];
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
    let want_wkt = wkt_out.is_some();
    let mut records: Vec<Record> = feats
        .par_iter()
        .filter_map(|(fid, g)| {
            let g = g.as_ref()?;
            let parts: Vec<PreparedPolygon> = polygon_parts(Some(g))
                .ok()?
                .iter()
                .filter_map(|p| PreparedPolygon::new(p).ok())
                .collect();
            let Processed::Done(o) = process(Some(g), &params) else {
                eprintln!("{layer}: feature {fid:?} not measured: the pipeline rejects it");
                return None;
            };
            let (m, s) = o.chosen();
            let z = |s: &skeletonise::process::CandidateSkeleton| {
                s.scores.map_or(f64::NAN, |s| s.distortion)
            };
            let best = o
                .candidates
                .iter()
                .filter_map(|c| {
                    let r = c.result.as_ref().ok()?;
                    let zc = z(r);
                    (!zc.is_nan() && !r.geometry.0.is_empty()).then_some((c, zc))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let mut rec = Record {
                fid: fid.map_or(-1, |f| f as i64),
                chosen: m.to_string(),
                z_chosen: z(s),
                best: best.map_or(String::new(), |b| b.0.method.to_string()),
                z_best: best.map_or(f64::NAN, |b| b.1),
                ends: 0,
                hooks: 0,
                off: 0,
                off_ratio: 0.0,
                wkt: Vec::new(),
            };
            let mut axes = Vec::new();
            for p in &parts {
                let Some(axis) = raw_medial_axis(p) else {
                    continue;
                };
                let (e, h, off, worst) = ends_of(&s.geometry, p, &segments(&axis));
                rec.ends += e;
                rec.hooks += h;
                rec.off += off;
                rec.off_ratio = rec.off_ratio.max(worst);
                axes.push(axis);
            }
            if want_wkt {
                use wkt::ToWkt;
                rec.wkt
                    .push(("polygon".into(), String::new(), g.wkt_string()));
                for a in &axes {
                    rec.wkt.push((
                        "axis".into(),
                        String::new(),
                        a.to_multilinestring().wkt_string(),
                    ));
                }
                rec.wkt.push((
                    "chosen".into(),
                    format!("{} Z={:.6}", rec.chosen, rec.z_chosen),
                    s.geometry.wkt_string(),
                ));
                if let Some((c, zb)) = best {
                    if let Ok(r) = &c.result {
                        rec.wkt.push((
                            "best".into(),
                            format!("{} Z={zb:.6}", c.method),
                            r.geometry.wkt_string(),
                        ));
                    }
                }
            }
            Some(rec)
        })
        .collect();
    let n = records.len().max(1) as f64;
    let finite = |v: f64| if v.is_nan() { 0.0 } else { v };
    let within = records
        .iter()
        .filter(|r| r.z_chosen.is_nan() || r.z_chosen <= 2.0 * r.z_best + tie)
        .count();
    let ends: usize = records.iter().map(|r| r.ends).sum();
    let hooks: usize = records.iter().map(|r| r.hooks).sum();
    let off: usize = records.iter().map(|r| r.off).sum();
    let pct = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
    println!(
        "| {layer} | {} | {:.6} | {:.6} | {:.1} % ({} over) | {ends} | {hooks} ({:.2} %) | {off} ({:.2} %) |",
        records.len(),
        records.iter().map(|r| finite(r.z_chosen)).sum::<f64>() / n,
        records.iter().map(|r| finite(r.z_best)).sum::<f64>() / n,
        pct(within, records.len()),
        records.len() - within,
        pct(hooks, ends),
        pct(off, ends),
    );
    if list == 0 {
        return;
    }
    let mut listed = std::collections::BTreeSet::new();
    let show = |title: &str, rs: &[&Record], listed: &mut std::collections::BTreeSet<i64>| {
        println!("\n{title}");
        for r in rs {
            listed.insert(r.fid);
            println!(
                "  fid {:>6}  chosen {:>4} Z {:.6}  best {:>4} Z {:.6}  ends {} hooks {} off {} (worst {:.2} widths)",
                r.fid, r.chosen, r.z_chosen, r.best, r.z_best, r.ends, r.hooks, r.off, r.off_ratio
            );
        }
    };
    let excess = |r: &Record| finite(r.z_chosen) / (2.0 * finite(r.z_best) + tie).max(1e-300);
    records.sort_by(|a, b| excess(b).total_cmp(&excess(a)));
    let top: Vec<&Record> = records.iter().take(list).collect();
    show("worst by chosen Z / (2 best Z + tie)", &top, &mut listed);
    records.sort_by(|a, b| finite(b.z_chosen).total_cmp(&finite(a.z_chosen)));
    let top: Vec<&Record> = records.iter().take(list).collect();
    show("worst by chosen Z", &top, &mut listed);
    records.sort_by(|a, b| b.off_ratio.total_cmp(&a.off_ratio));
    let top: Vec<&Record> = records.iter().take(list).collect();
    show(
        "worst by off-axis distance / local width",
        &top,
        &mut listed,
    );
    records.sort_by_key(|r| std::cmp::Reverse(r.hooks));
    let top: Vec<&Record> = records.iter().filter(|r| r.hooks > 0).take(list).collect();
    show("with hooks", &top, &mut listed);
    if let Some(path) = wkt_out {
        let mut out = String::from("fid,kind,label,wkt\n");
        for r in records.iter().filter(|r| listed.contains(&r.fid)) {
            for (k, l, w) in &r.wkt {
                let _ = writeln!(out, "{},{k},\"{l}\",\"{w}\"", r.fid);
            }
        }
        std::fs::write(&path, out).unwrap_or_else(|e| {
            eprintln!("{path}: {e}");
            std::process::exit(1)
        });
    }
}
