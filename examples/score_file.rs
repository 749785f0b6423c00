//! Scores skeletons made by any tool with the paper's metrics, or this
//! library's own method for comparison.
//!
//! ```text
//! cargo run --release --example score_file -- POLYGONS LAYER \
//!     (--skeletons SRC LAYER [--fid-field NAME] | --method ID [--raw]) [--csv OUT.csv]
//! ```
//!
//! With `--skeletons`, each skeleton feature is joined to a polygon by the
//! integer field `--fid-field` (the polygon's FID), or else by feature order;
//! several skeleton features of one polygon are scored together. With
//! `--method` (VD, DVD, CDT, StSk, MA) the skeleton is built here, pruned and
//! extended with the default options unless `--raw`. Prints the number of
//! features, mean coverage, mean s (deviation), S and Z over the features with
//! hits; `--csv` writes one row per feature.

use geo::{Geometry, MultiLineString};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::{extend::ExtendParams, prune::PruneParams};
use skeletonise::io::{read_layer_polygons, InputSpec, Reader};
use skeletonise::methods::{MethodId, SkeletonParams};
use skeletonise::process::{polygon_parts, process, ProcessParams, Processed};
use skeletonise::score::{metrics, score_skeleton, Bar, ScoreParams, Scores};
use std::collections::HashMap;
use std::io::Write;

type Error = Box<dyn std::error::Error>;

/// Every line of a geometry (lines of collections included).
fn lines_of(g: &Geometry<f64>, out: &mut MultiLineString<f64>) {
    match g {
        Geometry::LineString(l) => out.0.push(l.clone()),
        Geometry::MultiLineString(m) => out.0.extend(m.0.iter().cloned()),
        Geometry::Line(l) => out.0.push(geo::LineString(vec![l.start, l.end])),
        Geometry::GeometryCollection(c) => c.0.iter().for_each(|g| lines_of(g, out)),
        _ => {}
    }
}

/// Skeleton lines per polygon FID (joined by `fid_field`), or in order.
fn read_skeletons(
    source: &str,
    layer: &str,
    fid_field: Option<&str>,
    polygon_fids: &[Option<u64>],
) -> Result<Vec<MultiLineString<f64>>, Error> {
    let mut by_fid: HashMap<u64, MultiLineString<f64>> = HashMap::new();
    let mut in_order = Vec::new();
    let mut r = Reader::open(&InputSpec::layer(source, layer))?;
    let field = match fid_field {
        Some(name) => Some(
            r.info()
                .fields
                .iter()
                .position(|f| f.name.eq_ignore_ascii_case(name))
                .ok_or_else(|| format!("no field `{name}` in the skeleton layer `{layer}`"))?,
        ),
        None => None,
    };
    r.read::<skeletonise::io::IoError>(1024, false, |batch| {
        for f in batch {
            let mut m = MultiLineString(Vec::new());
            if let Some(g) = &f.geometry {
                lines_of(g, &mut m);
            }
            match field {
                Some(i) => {
                    let key = f.attributes[i]
                        .as_text()
                        .and_then(|t| t.parse::<f64>().ok())
                        .map(|v| v as u64);
                    if let Some(k) = key {
                        by_fid
                            .entry(k)
                            .or_insert_with(|| MultiLineString(Vec::new()))
                            .0
                            .extend(m.0);
                    }
                }
                None => in_order.push(m),
            }
        }
        Ok(())
    })?;
    Ok(match field {
        Some(_) => polygon_fids
            .iter()
            .map(|fid| {
                fid.and_then(|k| by_fid.remove(&k))
                    .unwrap_or_else(|| MultiLineString(Vec::new()))
            })
            .collect(),
        None => {
            in_order.resize(polygon_fids.len(), MultiLineString(Vec::new()));
            in_order
        }
    })
}

/// Scores `lines` against every part of `g`; part indices kept distinct.
fn score_lines(g: &Geometry<f64>, lines: &MultiLineString<f64>) -> Option<Scores> {
    let mut all: Vec<Bar> = Vec::new();
    for part in polygon_parts(Some(g)).ok()? {
        let Ok(p) = PreparedPolygon::new(&part) else {
            continue;
        };
        let offset = all.iter().filter_map(|b| b.hit).map(|h| h.part + 1).max();
        let (_, mut b) = score_skeleton(&p, lines);
        for h in b.iter_mut().filter_map(|b| b.hit.as_mut()) {
            h.part += offset.unwrap_or(0);
        }
        all.extend(b);
    }
    Some(metrics(&all))
}

fn score_method(g: &Geometry<f64>, m: MethodId, raw: bool) -> Option<Scores> {
    let params = ProcessParams {
        skeleton: SkeletonParams {
            methods: vec![m],
            ..SkeletonParams::default()
        },
        prune: (!raw).then(PruneParams::default),
        extend: (!raw).then(ExtendParams::default),
        score: Some(ScoreParams::default()),
        ..ProcessParams::default()
    };
    match process(Some(g), &params) {
        Processed::Done(o) => o.chosen().1.scores,
        _ => None,
    }
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: score_file POLYGONS LAYER (--skeletons SRC LAYER [--fid-field NAME] | --method ID [--raw]) [--csv OUT.csv]";
    if args.len() < 4 {
        return Err(usage.into());
    }
    let (poly_src, poly_layer) = (&args[0], &args[1]);
    let opt = |name: &str, k: usize| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + k))
            .cloned()
    };
    let polygons = read_layer_polygons(poly_src, poly_layer)?;
    let fids: Vec<Option<u64>> = polygons.iter().map(|(f, _)| *f).collect();
    let (label, scores): (String, Vec<Option<Scores>>) =
        if let (Some(src), Some(layer)) = (opt("--skeletons", 1), opt("--skeletons", 2)) {
            let sk = read_skeletons(&src, &layer, opt("--fid-field", 1).as_deref(), &fids)?;
            let s = polygons
                .iter()
                .zip(&sk)
                .map(|((_, g), l)| score_lines(g, l))
                .collect();
            (format!("{src}:{layer}"), s)
        } else if let Some(m) = opt("--method", 1) {
            let id: MethodId = m.parse()?;
            let raw = args.iter().any(|a| a == "--raw");
            let s = polygons
                .iter()
                .map(|(_, g)| score_method(g, id, raw))
                .collect();
            (format!("{m}{}", if raw { " (raw)" } else { "" }), s)
        } else {
            return Err(usage.into());
        };
    if let Some(path) = opt("--csv", 1) {
        let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(
            w,
            "fid,bars,hits,coverage,deviation,deviation_parts,distortion_sum,distortion"
        )?;
        for (fid, s) in fids.iter().zip(&scores) {
            let s = s.unwrap_or_default();
            writeln!(
                w,
                "{},{},{},{},{},{},{},{}",
                fid.map_or(String::new(), |f| f.to_string()),
                s.bars,
                s.hits,
                s.coverage,
                s.deviation,
                s.deviation_parts,
                s.distortion_sum,
                s.distortion
            )?;
        }
    }
    let n = scores.len();
    let scored: Vec<Scores> = scores.iter().flatten().copied().collect();
    let hit: Vec<&Scores> = scored.iter().filter(|s| s.hits > 0).collect();
    let mean =
        |f: &dyn Fn(&Scores) -> f64| hit.iter().map(|s| f(s)).sum::<f64>() / hit.len() as f64;
    let coverage = scored.iter().map(|s| s.coverage).sum::<f64>() / n.max(1) as f64;
    println!(
        "{poly_layer}\t{label}\tfeatures {n}\twith hits {}\tmean coverage {coverage:.4}\tmean s {:.2}\tmean S {:.2}\tmean Z {:.4}",
        hit.len(),
        mean(&|s| s.deviation),
        mean(&|s| s.deviation_parts),
        mean(&|s| s.distortion),
    );
    Ok(())
}
