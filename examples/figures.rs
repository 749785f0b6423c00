//! Writes the README pictures: one training river and one island, the raw
//! skeleton of every method that succeeds beside its final skeleton from the
//! default pipeline (`prune`: significance, every method pruned to the
//! medial axis's legs; `extend`: centred), as `skeletonise run` writes it.
//!
//! ```text
//! cargo run --release --example figures [-- path/to/gshhg-train.gpkg [out_dir]]
//! ```
//!
//! Writes `docs/img/skeletons-river.svg` and `docs/img/skeletons-island.svg`
//! (polygon grey, skeleton red, one row per method; each caption gives the
//! number of legs and the skeleton's distortion Z). Methods that fail on a
//! polygon are skipped.

use geo::{Area, Coord, Geometry, LineString, Polygon};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::io::read_layer_polygons;
use skeletonise::methods::MethodId;
use skeletonise::process::{process, ProcessParams, Processed};
use std::fmt::Write as _;

/// Width of one panel in SVG units.
const PANEL_W: f64 = 360.0;
/// Margin around and between panels.
const GAP: f64 = 12.0;
/// Height of a panel's caption line.
const CAPTION: f64 = 16.0;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let source = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "tests/data/gshhg-train.gpkg".into());
    let out_dir = args.get(2).cloned().unwrap_or_else(|| "docs/img".into());
    std::fs::create_dir_all(&out_dir)?;
    for (layer, name) in [
        ("river_danube", "skeletons-river"),
        ("islands_hebrides", "skeletons-island"),
    ] {
        // The largest polygon of the layer: the river itself, the largest island.
        let polygon = read_layer_polygons(&source, layer)?
            .into_iter()
            .flat_map(|(_, g)| match g {
                Geometry::Polygon(p) => vec![p],
                Geometry::MultiPolygon(mp) => mp.0,
                _ => Vec::new(),
            })
            .max_by(|a, b| a.unsigned_area().total_cmp(&b.unsigned_area()))
            .ok_or("layer has no polygon")?;
        let svg = figure(&polygon, layer)?;
        let path = format!("{out_dir}/{name}.svg");
        std::fs::write(&path, svg)?;
        println!("wrote {path}");
    }
    Ok(())
}

/// Maps CRS coordinates to panel coordinates (local frame, y down).
struct Frame {
    min: Coord<f64>,
    max_y: f64,
    scale: f64,
}

impl Frame {
    fn xy(&self, c: Coord<f64>) -> (f64, f64) {
        (
            (c.x - self.min.x) * self.scale,
            (self.max_y - c.y) * self.scale,
        )
    }

    fn path(&self, line: &[Coord<f64>], close: bool) -> String {
        let mut s = String::new();
        for (i, &c) in line.iter().enumerate() {
            let (x, y) = self.xy(c);
            let _ = write!(s, "{}{x:.1} {y:.1}", if i == 0 { "M" } else { "L" });
        }
        if close {
            s.push('Z');
        }
        s
    }
}

fn figure(polygon: &Polygon<f64>, layer: &str) -> Result<String, Box<dyn std::error::Error>> {
    let p = PreparedPolygon::new(polygon)?;
    let (lo, hi) = (p.boundary().bbox_min(), p.boundary().bbox_max());
    let scale = PANEL_W / (hi.x - lo.x).max(hi.y - lo.y);
    let frame = Frame {
        min: lo,
        max_y: hi.y,
        scale,
    };
    let (pw, ph) = ((hi.x - lo.x) * scale, (hi.y - lo.y) * scale);
    let rings: String = p
        .rings()
        .map(|r: &LineString<f64>| frame.path(&r.0, true))
        .collect();

    // The default pipeline, and the same with neither prune nor extend.
    let final_params = ProcessParams::all_steps();
    let raw_params = ProcessParams {
        prune: None,
        extend: None,
        ..final_params.clone()
    };
    let geom = Geometry::Polygon(polygon.clone());
    let run = |params: &ProcessParams| match process(Some(&geom), params) {
        Processed::Done(o) => Ok(o),
        other => Err(format!("{layer}: {other:?}")),
    };
    let (raw, done) = (run(&raw_params)?, run(&final_params)?);
    type Row = (MethodId, Panel, Panel);
    let mut rows: Vec<Row> = Vec::new();
    for (r, d) in raw.candidates.iter().zip(&done.candidates) {
        let dm = d.method;
        match (&r.result, &d.result) {
            (Ok(r), Ok(d)) => rows.push((dm, Panel::of(r), Panel::of(d))),
            (Err(e), _) | (_, Err(e)) => eprintln!("{layer}: {} skipped: {e}", d.method),
        }
    }

    let row_h = CAPTION + ph + GAP;
    let (w, h) = (2.0 * pw + 3.0 * GAP, GAP + rows.len() as f64 * row_h);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    for (i, (m, raw, done)) in rows.iter().enumerate() {
        for (k, (g, label)) in [(raw, "raw"), (done, "pruned + extended")]
            .into_iter()
            .enumerate()
        {
            let (x0, y0) = (GAP + k as f64 * (pw + GAP), GAP + i as f64 * row_h);
            let (legs, z) = (g.legs, g.z);
            let _ = writeln!(
                s,
                r#"<text x="{x0:.1}" y="{:.1}">{layer} · {m} · {label} · {legs} leg{} · Z {z:.4}</text>"#,
                y0 + CAPTION - 4.0,
                if legs == 1 { "" } else { "s" }
            );
            let _ = writeln!(
                s,
                r#"<g transform="translate({x0:.1} {:.1})">"#,
                y0 + CAPTION
            );
            let _ = writeln!(
                s,
                r##"<path d="{rings}" fill="#ddd" stroke="#999" stroke-width="0.5" fill-rule="evenodd"/>"##
            );
            let lines: String = g.lines.0.iter().map(|l| frame.path(&l.0, false)).collect();
            let _ = writeln!(
                s,
                r##"<path d="{lines}" fill="none" stroke="#d00" stroke-width="1" stroke-linejoin="round"/>"##
            );
            s.push_str("</g>\n");
        }
    }
    s.push_str("</svg>\n");
    Ok(s)
}

/// What one panel draws: a candidate's lines, legs and distortion.
struct Panel {
    lines: geo::MultiLineString<f64>,
    legs: usize,
    z: f64,
}

impl Panel {
    fn of(c: &skeletonise::process::CandidateSkeleton) -> Self {
        Self {
            lines: c.geometry.clone(),
            legs: c.legs,
            z: c.scores.map_or(f64::NAN, |s| s.distortion),
        }
    }
}
