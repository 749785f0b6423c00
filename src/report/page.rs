//! The HTML of the report: summary, legend, one section per feature, the
//! statement of what was simplified; the style sheet and the script
//! (pan, zoom, bars, radius on click) are inlined from `report.css` and
//! `report.js`.

use super::draw::{self, Drawn, DrawnSkeleton, Frame, Z_CLASSES};
use super::{MethodSummary, Report, Section};
use crate::output::{CandidateRow, RunRecord};
use std::fmt::Write as _;

const CSS: &str = include_str!("report.css");
const JS: &str = include_str!("report.js");

/// Text safe in HTML content and attribute values.
pub(super) fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// How a number is shown.
#[derive(Clone, Copy)]
enum Num {
    /// Z: five decimals, as the README's tables.
    Z,
    /// Coverage: three decimals.
    Coverage,
    /// Lengths and sums: three significant digits.
    Sig,
    /// Means of counts: one decimal.
    Mean,
}

fn num(x: f64, kind: Num) -> String {
    if !x.is_finite() {
        return "–".into();
    }
    // Values too small for the fixed decimals (StSk's exact segments on a
    // convex part score ~10⁻¹²) in powers of ten rather than as zeros.
    let tiny = x != 0.0 && x.abs() < 1e-3;
    match kind {
        Num::Z if tiny && x.abs() < 5e-6 => format!("{x:.1e}"),
        Num::Z => format!("{x:.5}"),
        Num::Coverage => format!("{x:.3}"),
        Num::Sig if tiny => format!("{x:.2e}"),
        Num::Sig => draw::sig(x, 3),
        Num::Mean => format!("{x:.1}"),
    }
}

/// A table cell with its exact value for machines (`data-value`).
fn cell(key: &str, x: f64, kind: Num, class: &str) -> String {
    let value = if x.is_finite() {
        x.to_string()
    } else {
        String::new()
    };
    format!(
        r#"<td data-key="{key}" data-value="{value}"{}>{}</td>"#,
        if class.is_empty() {
            String::new()
        } else {
            format!(r#" class="{class}""#)
        },
        num(x, kind)
    )
}

/// ` (unit)` after a label, as text (escaped where it is written).
fn unit(units: &str) -> String {
    if units.is_empty() {
        String::new()
    } else {
        format!(" ({units})")
    }
}

/// The whole page.
pub(super) fn page(r: &Report) -> String {
    let mut s = String::with_capacity(64 * 1024);
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>{}</title><style>{CSS}</style></head>\n<body data-sections=\"{}\">\n",
        esc(&r.title),
        r.sections.len()
    );
    let _ = write!(s, "<header><h1>{}</h1>", esc(&r.title));
    s.push_str(&controls());
    s.push_str("</header>\n<main>\n");
    s.push_str(&summary(r));
    for sec in &r.sections {
        s.push_str(&section(sec, &r.units));
    }
    s.push_str("</main>\n");
    s.push_str(&footer(r));
    let _ = write!(s, "<script>{JS}</script>\n</body></html>\n");
    s
}

/// The legend and the bars switch, kept in view while scrolling.
fn controls() -> String {
    let mut s = String::from(
        r#"<div class="controls"><span class="legend"><svg width="28" height="14" aria-hidden="true"><rect x="1" y="1" width="26" height="12" class="poly"/></svg> polygon <svg width="28" height="14" aria-hidden="true"><path d="M2 10 L12 4 L26 8" class="skel"/></svg> skeleton <span class="chosen-swatch">★ chosen</span></span> <label><input type="checkbox" id="show-bars"> bars coloured by z</label> <span class="ramp">"#,
    );
    for (i, lo) in Z_CLASSES.iter().enumerate() {
        let label = match Z_CLASSES.get(i + 1) {
            Some(hi) => format!("{lo}–{hi}"),
            None => format!("≥ {lo}"),
        };
        let _ = write!(s, r#"<span class="swatch z{i}"></span>{label} "#);
    }
    s.push_str("</span><span class=\"help\">scroll to zoom · drag to pan · double-click to reset · click a line for r and width</span></div>");
    s
}

fn summary(r: &Report) -> String {
    let mut s = String::from(r#"<section id="summary"><h2>Summary</h2>"#);
    let _ = write!(
        s,
        "<p>{} of {} features shown: {}.</p>",
        r.sections.len(),
        r.features,
        esc(&r.selection)
    );
    let u = esc(&unit(&r.units));
    let _ = write!(
        s,
        r#"<div class="summary-row"><table id="summary-table"><thead><tr><th>method</th><th>features won</th><th>mean Z</th><th>mean s{u}</th><th>mean S{u}</th><th>mean coverage</th><th>mean legs</th><th>failed</th><th>with hits</th></tr></thead><tbody>"#
    );
    for m in &r.summary {
        s.push_str(&summary_row(m));
    }
    s.push_str("</tbody></table>");
    s.push_str(&chosen_chart(&r.summary));
    s.push_str("</div>");
    if !r.notes.is_empty() {
        s.push_str("<ul class=\"notes\">");
        for n in &r.notes {
            let _ = write!(s, "<li>{}</li>", esc(n));
        }
        s.push_str("</ul>");
    }
    if let Some(run) = &r.run {
        s.push_str(&provenance(run));
    }
    s.push_str(&index(r));
    s.push_str("</section>\n");
    s
}

fn summary_row(m: &MethodSummary) -> String {
    let best = if m.won > 0 { "won" } else { "" };
    format!(
        r#"<tr data-method="{}"><td>{}</td>{}{}{}{}{}{}{}{}</tr>"#,
        esc(&m.method),
        esc(&m.method),
        cell("won", m.won as f64, Num::Sig, best),
        cell("distortion", m.mean_distortion, Num::Z, ""),
        cell("deviation", m.mean_deviation, Num::Sig, ""),
        cell("deviation_parts", m.mean_deviation_parts, Num::Sig, ""),
        cell("coverage", m.mean_coverage, Num::Coverage, ""),
        cell("legs", m.mean_legs, Num::Mean, ""),
        cell("failed", m.failed as f64, Num::Sig, ""),
        cell("with_hits", m.with_hits as f64, Num::Sig, ""),
    )
}

/// The chosen-method counts as horizontal bars.
fn chosen_chart(methods: &[MethodSummary]) -> String {
    let max = methods.iter().map(|m| m.won).max().unwrap_or(0).max(1) as f64;
    let (row, label_w, bar_w) = (20.0, 48.0, 220.0);
    let h = row * methods.len() as f64 + 24.0;
    let mut s = format!(
        r#"<figure class="chart"><svg width="{}" height="{h}" role="img" aria-label="chosen-method counts">"#,
        label_w + bar_w + 60.0
    );
    for (i, m) in methods.iter().enumerate() {
        let y = 4.0 + i as f64 * row;
        let w = bar_w * m.won as f64 / max;
        let _ = write!(
            s,
            r#"<text x="0" y="{:.0}">{}</text><rect x="{label_w}" y="{y:.0}" width="{w:.1}" height="14" class="bar"/><text x="{:.1}" y="{:.0}">{}</text>"#,
            y + 12.0,
            esc(&m.method),
            label_w + w + 4.0,
            y + 12.0,
            m.won
        );
    }
    let _ = write!(
        s,
        r#"</svg><figcaption>chosen-method counts</figcaption></figure>"#
    );
    s
}

fn provenance(run: &RunRecord) -> String {
    let mut s = String::from(
        r#"<details class="provenance" open><summary>Run</summary><table id="run-table">"#,
    );
    let rows: [(&str, String); 8] = [
        ("pipeline", run.name.clone()),
        ("input", run.input.clone()),
        ("started (UTC)", run.started_utc.clone()),
        ("finished (UTC)", run.finished_utc.clone()),
        (
            "elapsed",
            format!("{:.2} s on {} threads", run.elapsed_s, run.threads),
        ),
        (
            "features",
            format!(
                "{} read, {} written, {} rejected, {} filtered",
                run.read, run.written, run.rejected, run.filtered
            ),
        ),
        ("tool", format!("skeletonise {}", run.tool_version)),
        ("skeleton layer", run.skeleton_layer.clone()),
    ];
    for (k, v) in rows {
        let _ = write!(s, "<tr><th>{k}</th><td>{}</td></tr>", esc(&v));
    }
    let _ = write!(
        s,
        "</table><details><summary>pipeline file</summary><pre>{}</pre></details></details>",
        esc(&run.pipeline)
    );
    s
}

fn key_label(s: &Section) -> String {
    let fid = s.src_fid.map_or_else(|| "–".into(), |f| f.to_string());
    match s.polygon_part {
        Some(p) => format!("fid {fid} part {p}"),
        None => format!("fid {fid}"),
    }
}

fn anchor(s: &Section) -> String {
    let fid = s.src_fid.map_or_else(|| "none".into(), |f| f.to_string());
    match s.polygon_part {
        Some(p) => format!("f{fid}-{p}"),
        None => format!("f{fid}"),
    }
}

fn index(r: &Report) -> String {
    if r.sections.is_empty() {
        return "<p class=\"notes\">No feature matches the selection.</p>".into();
    }
    let mut s = String::from(r#"<nav class="index">"#);
    for sec in &r.sections {
        let _ = write!(
            s,
            r##"<a href="#{}">{} <small>{}</small></a> "##,
            anchor(sec),
            key_label(sec),
            num(sec.disagreement, Num::Sig)
        );
    }
    s.push_str("</nav>");
    s
}

fn section(sec: &Section, units: &str) -> String {
    let d = draw::section(sec);
    let methods: Vec<&str> = sec.candidates.iter().map(|c| c.method.as_str()).collect();
    let chosen = sec
        .candidates
        .iter()
        .find(|c| c.chosen)
        .map_or("–", |c| c.method.as_str());
    let Frame { x0, y0, scale, .. } = d.frame;
    let mut s = format!(
        r#"<section class="feature" id="{}" data-fid="{}" data-part="{}" data-methods="{}" data-x0="{x0}" data-y0="{y0}" data-scale="{scale}" data-units="{}">"#,
        anchor(sec),
        sec.src_fid.map_or_else(String::new, |f| f.to_string()),
        sec.polygon_part.map_or_else(String::new, |p| p.to_string()),
        esc(&methods.join(" ")),
        esc(units),
    );
    let attrs: Vec<String> = sec
        .attributes
        .iter()
        .map(|(k, v)| format!("{}: <b>{}</b>", esc(k), esc(v)))
        .collect();
    let _ = write!(
        s,
        r#"<h2>{} <span class="attrs">{}</span> <span class="chosen-name">chosen: {}</span> <span class="dis">disagreement {}</span></h2>"#,
        key_label(sec),
        attrs.join(" · "),
        esc(chosen),
        num(sec.disagreement, Num::Sig)
    );
    for n in &sec.notes {
        let _ = write!(s, r#"<p class="warn">{}</p>"#, esc(n));
    }
    // Every method side by side, as the paper's figures (up to 6 in a row).
    let _ = write!(
        s,
        r#"<div class="panels" style="--n: {}">"#,
        sec.candidates.len().clamp(1, 6)
    );
    for (c, k) in sec.candidates.iter().zip(&d.skeletons) {
        s.push_str(&panel(c, k, &d));
    }
    s.push_str(r#"</div><div class="below">"#);
    s.push_str(&scores_table(sec, units));
    s.push_str(
        r#"<div class="side"><p class="info">Click a line for its node radius r and width 2r.</p>"#,
    );
    s.push_str(&simplified_note(&d));
    s.push_str("</div></div></section>\n");
    s
}

fn panel(c: &CandidateRow, k: &DrawnSkeleton, d: &Drawn) -> String {
    let Frame { w, h, .. } = d.frame;
    let pad = (w.max(h) / 40).max(1);
    let ratio = ((w + 2 * pad) as f64 / (h + 2 * pad) as f64).clamp(0.6, 2.4);
    let caption = match (&c.error, c.scores) {
        (Some(e), _) => format!(r#"<span class="error">failed: {}</span>"#, esc(e)),
        (None, Some(sc)) => format!(
            "Z {} · {} leg{}",
            num(sc.distortion, Num::Z),
            c.legs,
            if c.legs == 1 { "" } else { "s" }
        ),
        (None, None) => format!("{} legs", c.legs),
    };
    let mut s = format!(
        r#"<figure class="panel{}" data-method="{}" data-chosen="{}"><figcaption><b>{}</b>{} <span>{caption}</span></figcaption>"#,
        if c.chosen { " chosen" } else { "" },
        esc(&c.method),
        u8::from(c.chosen),
        esc(&c.method),
        if c.chosen {
            r#" <span class="star">★ chosen</span>"#
        } else {
            ""
        },
    );
    let _ = write!(
        s,
        r#"<svg class="map" viewBox="{} {} {} {}" style="aspect-ratio: {ratio:.3}" preserveAspectRatio="xMidYMid meet"><path class="poly" d="{}"/><g class="bars">"#,
        -pad,
        -pad,
        w + 2 * pad,
        h + 2 * pad,
        d.polygon
    );
    for (class, path) in &k.bars {
        let _ = write!(s, r#"<path class="z{class}" d="{path}"/>"#);
    }
    s.push_str("</g>");
    if c.error.is_none() {
        let _ = write!(
            s,
            r#"<path class="skel" d="{}" data-r="{}"/>"#,
            k.d, k.radii
        );
    }
    s.push_str(r#"<g class="pick"></g></svg></figure>"#);
    s
}

/// One row of the score table: label, key, the value per candidate, how it
/// reads, and whether smaller (`Some(true)`) or larger (`Some(false)`) is
/// better.
struct Metric {
    label: String,
    key: &'static str,
    value: fn(&CandidateRow) -> f64,
    text: fn(&CandidateRow, f64) -> String,
    smaller: Option<bool>,
}

fn score(c: &CandidateRow, f: fn(&crate::score::Scores) -> f64) -> f64 {
    match (&c.error, c.scores) {
        (None, Some(s)) => f(&s),
        _ => f64::NAN,
    }
}

fn metric(
    label: &str,
    key: &'static str,
    value: fn(&CandidateRow) -> f64,
    kind: Num,
    smaller: Option<bool>,
) -> Metric {
    let text = match kind {
        Num::Z => |_: &CandidateRow, v| num(v, Num::Z),
        Num::Coverage => |_: &CandidateRow, v| num(v, Num::Coverage),
        Num::Sig => |_: &CandidateRow, v| num(v, Num::Sig),
        Num::Mean => |_: &CandidateRow, v| num(v, Num::Mean),
    };
    Metric {
        label: label.to_string(),
        key,
        value,
        text,
        smaller,
    }
}

/// The rows of the score table, as the paper's Tab. 2 (metrics down,
/// methods across).
fn metrics(units: &str) -> Vec<Metric> {
    let u = unit(units);
    vec![
        Metric {
            text: |c, v| match (v.is_finite(), c.scores) {
                (true, Some(s)) => format!("{} / {}", s.hits, s.bars),
                _ => num(v, Num::Sig),
            },
            ..metric(
                "hits n / bars N",
                "hits",
                |c| score(c, |s| s.hits as f64),
                Num::Sig,
                None,
            )
        },
        metric(
            "coverage",
            "coverage",
            |c| score(c, |s| s.coverage),
            Num::Coverage,
            Some(false),
        ),
        metric(
            &format!("s{u}"),
            "deviation",
            |c| score(c, |s| s.deviation),
            Num::Sig,
            Some(true),
        ),
        metric(
            &format!("S{u}"),
            "deviation_parts",
            |c| score(c, |s| s.deviation_parts),
            Num::Sig,
            Some(true),
        ),
        metric(
            "SZ",
            "distortion_sum",
            |c| score(c, |s| s.distortion_sum),
            Num::Sig,
            Some(true),
        ),
        metric(
            "Z",
            "distortion",
            |c| score(c, |s| s.distortion),
            Num::Z,
            Some(true),
        ),
        Metric {
            text: |c, _| format!("{} → {}", c.legs_raw, c.legs),
            ..metric(
                "legs raw → pruned",
                "legs",
                |c| c.legs as f64,
                Num::Sig,
                None,
            )
        },
    ]
}

fn scores_table(sec: &Section, units: &str) -> String {
    let mut s = String::from(r#"<table class="scores"><thead><tr><th>method</th>"#);
    for c in &sec.candidates {
        let _ = write!(
            s,
            r#"<th{}>{}{}</th>"#,
            if c.chosen { r#" class="chosen""# } else { "" },
            esc(&c.method),
            if c.chosen { " ★" } else { "" }
        );
    }
    s.push_str("</tr></thead><tbody>");
    for m in metrics(units) {
        let values: Vec<f64> = sec.candidates.iter().map(m.value).collect();
        let best = m.smaller.and_then(|smaller| {
            values
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .reduce(|a, b| if (b < a) == smaller { b } else { a })
        });
        let _ = write!(s, r#"<tr data-key="{}"><th>{}</th>"#, m.key, esc(&m.label));
        for (c, v) in sec.candidates.iter().zip(values) {
            let class = if Some(v) == best {
                r#" class="best""#
            } else {
                ""
            };
            let value = if v.is_finite() {
                v.to_string()
            } else {
                String::new()
            };
            let _ = write!(
                s,
                r#"<td data-value="{value}"{class}>{}</td>"#,
                (m.text)(c, v)
            );
        }
        s.push_str("</tr>");
    }
    s.push_str("</tbody></table>");
    s
}

fn simplified_note(d: &Drawn) -> String {
    let (shown, total) = d.polygon_vertices;
    let skel_shown: usize = d.skeletons.iter().map(|k| k.vertices.0).sum();
    let skel_total: usize = d.skeletons.iter().map(|k| k.vertices.1).sum();
    let (bars_shown, bars_hit): (usize, usize) = d
        .skeletons
        .iter()
        .fold((0, 0), |(a, b), k| (a + k.bar_count.0, b + k.bar_count.1));
    format!(
        r#"<p class="drawn">drawn: polygon {shown} of {total} vertices, skeletons {skel_shown} of {skel_total}, bars {bars_shown} of {bars_hit} hits</p>"#
    )
}

fn footer(r: &Report) -> String {
    let methods = r
        .sections
        .first()
        .map_or(r.summary.len(), |s| s.candidates.len())
        .max(1);
    format!(
        r#"<footer><p>Simplified for display only (Ramer–Douglas–Peucker, coordinates rounded to 1/10 000 of each feature's extent): a polygon to at most {} vertices, each skeleton to at most {}, at most {} bars per method (half with the largest z, half evenly spaced). A feature section takes at most {} KB with {} methods. The scores, radii and widths are those of the full geometry, which the GeoPackage holds. Written by skeletonise {}.</p></footer>"#,
        draw::POLYGON_VERTICES,
        draw::SKELETON_VERTICES,
        draw::BARS_PER_METHOD,
        draw::section_bound(methods) / 1000,
        methods,
        env!("CARGO_PKG_VERSION"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_from_the_data_cannot_break_the_markup() {
        assert_eq!(
            esc(r#"<b>"a" & 'b'"#),
            "&lt;b&gt;&quot;a&quot; &amp; &#39;b&#39;"
        );
    }

    #[test]
    fn missing_values_show_as_a_dash_and_keep_no_machine_value() {
        assert_eq!(num(f64::NAN, Num::Z), "–");
        assert_eq!(
            cell("z", f64::NAN, Num::Z, ""),
            r#"<td data-key="z" data-value="">–</td>"#
        );
        assert_eq!(num(0.000031, Num::Z), "0.00003");
        assert_eq!(num(2.94e-12, Num::Z), "2.9e-12");
        assert_eq!(num(2.94e-10, Num::Sig), "2.94e-10");
        assert_eq!(num(48.61, Num::Sig), "48.6");
    }
}
