//! The visual report, end to end: written by the pipeline option and by
//! `skeletonise report`, checked as a file (self-contained, bounded size,
//! selection, errors) and in a real headless Chromium (no console error,
//! one skeleton per method in every section, the summary equal to the
//! GeoPackage's numbers, pan, zoom, bars and the radius on click).

use crate::common::browser::{base64, find_chromium, Browser};
use crate::common::*;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Runs the demo pipeline into `dir`; returns the GeoPackage and the report.
fn demo_run(dir: &Path, extra: &[&str]) -> (PathBuf, PathBuf) {
    let out = dir.join("demo.gpkg");
    let mut args = vec![
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ];
    args.extend_from_slice(extra);
    let o = skeletonise(&args);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    (out, dir.join("demo.html"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The values of attribute `name` in every tag of the page that has it.
fn attr_values(html: &str, tag: &str, name: &str) -> Vec<String> {
    html.split(&format!("<{tag} "))
        .skip(1)
        .filter_map(|t| {
            let t = &t[..t.find('>').unwrap_or(t.len())];
            let rest = &t[t.find(&format!("{name}=\""))? + name.len() + 2..];
            Some(rest[..rest.find('"')?].to_string())
        })
        .collect()
}

/// Per method from the GeoPackage's candidates, as the summary defines
/// them: features won, mean Z / s / S over the candidates with hits, mean
/// coverage over the scored ones, mean legs over those that succeeded.
fn expected_summary(gpkg: &Path) -> BTreeMap<String, BTreeMap<&'static str, f64>> {
    let ds = open(gpkg);
    let method = strings(&ds, "candidates", "method");
    let chosen = ints(&ds, "candidates", "chosen");
    let hits = ints(&ds, "candidates", "hits");
    let legs = ints(&ds, "candidates", "legs");
    let error = strings(&ds, "candidates", "error");
    let cols = ["distortion", "deviation", "deviation_parts", "coverage"];
    let vals: Vec<Vec<Option<f64>>> = cols.iter().map(|c| reals(&ds, "candidates", c)).collect();
    let mut sums: BTreeMap<String, BTreeMap<&str, (f64, f64)>> = BTreeMap::new();
    for i in 0..method.len() {
        let m = sums.entry(method[i].clone().unwrap()).or_default();
        let mut add = |k, v: f64| {
            let e = m.entry(k).or_insert((0.0, 0.0));
            *e = (e.0 + v, e.1 + 1.0);
        };
        add("won", f64::from(u8::from(chosen[i] == Some(1))));
        if error[i].is_some() {
            continue;
        }
        add("legs", legs[i].unwrap() as f64);
        add("coverage", vals[3][i].unwrap());
        if hits[i].unwrap_or(0) > 0 {
            for (k, col) in cols[..3].iter().enumerate() {
                add(col, vals[k][i].unwrap());
            }
        }
    }
    sums.into_iter()
        .map(|(m, cols)| {
            let v = cols
                .into_iter()
                .map(|(k, (sum, n))| (k, if k == "won" { sum } else { sum / n }))
                .collect();
            (m, v)
        })
        .collect()
}

#[test]
fn compare_methods_pipeline_writes_the_geopackage_and_a_self_contained_report() {
    let d = tmp();
    let out = d.path().join("lakes.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "-o",
        out.to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    let html_path = d.path().join("lakes.html");
    assert!(out.exists() && html_path.exists(), "{err}");
    assert!(err.contains("report: 18 features"), "{err}");
    let html = read(&html_path);
    // Nothing is fetched: no URL, no external script, style sheet or image.
    for needle in [
        "http://",
        "https://",
        "<script src",
        "<link",
        "<img",
        "url(",
    ] {
        assert!(!html.contains(needle), "the report holds `{needle}`");
    }
    // 18 lakes, each with one panel per method and one chosen.
    assert_eq!(attr_values(&html, "section", "data-fid").len(), 18);
    let methods = attr_values(&html, "figure", "data-method");
    assert_eq!(methods.len(), 18 * 5);
    assert_eq!(
        attr_values(&html, "figure", "data-chosen")
            .iter()
            .filter(|c| *c == "1")
            .count(),
        18
    );
}

#[test]
fn a_big_layer_gives_a_report_within_its_stated_bound() {
    let d = tmp();
    let out = d.path().join("islands.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "--set",
        "input.layer=islands_hebrides",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let html = read(&d.path().join("islands.html"));
    // 1192 islands, the default 20 shown.
    assert_eq!(attr_values(&html, "section", "data-fid").len(), 20);
    assert!(html.contains("20 of 1192 features shown"));
    let bound = 20 * skeletonise::report::section_bound(5) + 200_000;
    assert!(html.len() < bound, "{} bytes > {bound}", html.len());
    // The largest river is simplified for display within the polygon budget.
    let lena = d.path().join("lena.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/compare-methods.yaml",
        "--set",
        "input.layer=river_lena",
        "--set",
        "output.report.features={top: 1}",
        "-o",
        lena.to_str().unwrap(),
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let html = read(&d.path().join("lena.html"));
    let drawn = html.split("drawn: polygon ").nth(1).expect("drawn note");
    let nums: Vec<usize> = drawn
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .take(2)
        .map(|s| s.parse().unwrap())
        .collect();
    assert!(
        nums[0] <= skeletonise::report::POLYGON_VERTICES && nums[1] > 10_000,
        "{nums:?}"
    );
    assert!(
        html.len() < skeletonise::report::section_bound(5) + 100_000,
        "{}",
        html.len()
    );
}

#[test]
fn features_are_chosen_by_fid_or_by_where_and_a_bad_filter_names_itself() {
    let d = tmp();
    let (gpkg, _) = demo_run(d.path(), &[]);
    let g = gpkg.to_str().unwrap();
    let by_fid = d.path().join("fids.html");
    let o = skeletonise(&[
        "report",
        g,
        "--fid",
        "25,1,999",
        "-o",
        by_fid.to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("source FID 999 is not in"), "{err}");
    let html = read(&by_fid);
    assert_eq!(attr_values(&html, "section", "data-fid"), ["25", "1"]);
    assert!(html.contains("Source FID 999 is not in the file."));
    let lakes = d.path().join("lakes.html");
    let o = skeletonise(&[
        "report",
        g,
        "--where",
        "kind = 'lake'",
        "-o",
        lakes.to_str().unwrap(),
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let want: Vec<String> = {
        let ds = open(&gpkg);
        let kinds = strings(&ds, "skeletons", "kind");
        let fids = ints(&ds, "skeletons", "src_fid");
        kinds
            .iter()
            .zip(fids)
            .filter(|(k, _)| k.as_deref() == Some("lake"))
            .map(|(_, f)| f.unwrap().to_string())
            .collect()
    };
    assert_eq!(want.len(), 4);
    assert_eq!(attr_values(&read(&lakes), "section", "data-fid"), want);
    let o = skeletonise(&["report", g, "--where", "kind = = 'lake'", "--overwrite"]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1);
    assert!(
        err.contains("invalid filter `kind = = 'lake'` on layer `skeletons`"),
        "{err}"
    );
}

#[test]
fn a_candidate_without_lines_is_drawn_as_none_not_a_failed_report() {
    // A method can end with no lines on a polygon (on a very rough rim,
    // StSk conformed to the medial axis' structure kept nothing): the run
    // writes its candidate row with a NULL geometry. The report shows the
    // feature with the other methods' lines instead of failing.
    let d = tmp();
    let (gpkg, _) = demo_run(d.path(), &[]);
    let g = gpkg.to_str().unwrap();
    let o = std::process::Command::new("ogrinfo")
        .args([
            g,
            "-sql",
            "UPDATE candidates SET geom = NULL WHERE method = 'VD' AND src_fid = 1",
        ])
        .output()
        .expect("ogrinfo (GDAL) runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = d.path().join("one.html");
    let o = skeletonise(&["report", g, "--fid", "1", "-o", html.to_str().unwrap()]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    assert_eq!(attr_values(&read(&html), "section", "data-fid"), ["1"]);
}

#[test]
fn polygons_that_cannot_be_reopened_name_the_fix_and_can_be_given() {
    let d = tmp();
    let src = d.path().join("moved.gpkg");
    std::fs::copy(root(DEMO), &src).unwrap();
    let out = d.path().join("out.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-i",
        src.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.report=null",
        "-q",
    ]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    assert!(!d.path().join("out.html").exists());
    std::fs::remove_file(&src).unwrap();
    let o = skeletonise(&["report", out.to_str().unwrap()]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1);
    assert!(err.contains("cannot open the polygons of"), "{err}");
    assert!(
        err.contains("--polygons SRC [--polygons-layer LAYER]"),
        "{err}"
    );
    let o = skeletonise(&["report", out.to_str().unwrap(), "--polygons", DEMO]);
    assert_eq!(code_and_err(&o).0, 0, "{}", code_and_err(&o).1);
    let html = read(&d.path().join("out.html"));
    assert!(!html.contains("have no polygon"), "every polygon found");
    assert_eq!(attr_values(&html, "section", "data-fid").len(), 17);
}

#[test]
fn bars_computed_for_the_report_are_the_bars_the_run_writes() {
    let d = tmp();
    let (_, without) = demo_run(d.path(), &[]);
    let computed = read(&without);
    let e = tmp();
    let (_, with) = demo_run(e.path(), &["--set", "output.bars=true"]);
    let stored = read(&with);
    assert!(computed.contains("The file has no bars layer"));
    assert!(!stored.contains("The file has no bars layer"));
    let bars = |html: &str| -> Vec<String> {
        html.split("<g class=\"bars\">")
            .skip(1)
            .map(|s| s[..s.find("</g>").unwrap()].to_string())
            .collect()
    };
    let (c, s) = (bars(&computed), bars(&stored));
    assert_eq!(c.len(), 17 * 5);
    assert!(
        c.iter().all(|b| b.contains("class=\"z")),
        "every method has bars"
    );
    assert_eq!(c, s);
}

#[test]
fn a_report_option_that_cannot_work_stops_the_run_before_it_starts() {
    let d = tmp();
    let out = d.path().join("o.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--set",
        "output.report.features={top: 0}",
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 78, "{err}");
    assert!(err.contains("`output.report.features.top`"), "{err}");
    let o = skeletonise(&[
        "run",
        "pipelines/demo.yaml",
        "-o",
        out.to_str().unwrap(),
        "--set",
        &format!(
            "output.report.path={}/no/such/dir/r.html",
            d.path().display()
        ),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("does not exist"), "{err}");
    assert!(!out.exists(), "nothing was run");
}

#[test]
fn base64_decodes_padded_and_unpadded_text() {
    assert_eq!(base64("aGVsbG8="), b"hello");
    assert_eq!(base64("aGk"), b"hi");
    assert_eq!(base64("YWJj"), b"abc");
}

/// The page's sections: for each, its FID and per panel `[method, chosen,
/// vertices of its skeleton path, has an error caption]`.
const SECTIONS_JS: &str = r#"Array.from(document.querySelectorAll('section.feature')).map(s => ({
  fid: s.dataset.fid,
  panels: Array.from(s.querySelectorAll('figure.panel')).map(f => {
    const p = f.querySelector('path.skel');
    return [f.dataset.method, f.dataset.chosen === '1',
            p ? (p.getAttribute('d').match(/-?\d+/g) || []).length / 2 : 0,
            !!f.querySelector('.error')];
  })
}))"#;

const SUMMARY_JS: &str = r#"Object.fromEntries(Array.from(document.querySelectorAll('#summary-table tbody tr')).map(r =>
  [r.dataset.method, Object.fromEntries(Array.from(r.querySelectorAll('td[data-key]')).map(c => [c.dataset.key, c.dataset.value]))]))"#;

/// Where the middle vertex of the first section's chosen skeleton is on
/// screen (after scrolling it into view), from the path's relative moves.
const VERTEX_JS: &str = r#"(() => {
  const f = document.querySelector('section.feature figure.panel.chosen');
  f.scrollIntoView({block: 'center'});
  const svg = f.querySelector('svg'), d = f.querySelector('path.skel').getAttribute('d');
  const pts = []; let x = 0, y = 0, mode = '';
  const t = d.match(/[Mlz]|-?\d+/g);
  for (let i = 0; i < t.length;) {
    if (/[Mlz]/.test(t[i])) { mode = t[i]; i += 1; continue; }
    const a = Number(t[i]), b = Number(t[i + 1]); i += 2;
    if (mode === 'M') { x = a; y = b; mode = 'l'; } else { x += a; y += b; }
    pts.push([x, y]);
  }
  const m = pts[Math.floor(pts.length / 2)];
  const p = new DOMPoint(m[0], m[1]).matrixTransform(svg.getScreenCTM());
  return [p.x, p.y];
})()"#;

fn check_sections(b: &mut Browser, gpkg: &Path) {
    let ds = open(gpkg);
    let methods = strings(&ds, "candidates", "method");
    let fids = ints(&ds, "candidates", "src_fid");
    let chosen = ints(&ds, "candidates", "chosen");
    let sections = b.eval(SECTIONS_JS);
    let sections = sections.as_array().expect("sections");
    assert_eq!(sections.len(), 17);
    for s in sections {
        let fid: i64 = s["fid"].as_str().unwrap().parse().unwrap();
        let want: Vec<(String, bool)> = (0..methods.len())
            .filter(|&i| fids[i] == Some(fid))
            .map(|i| (methods[i].clone().unwrap(), chosen[i] == Some(1)))
            .collect();
        let panels = s["panels"].as_array().unwrap();
        let got: Vec<(String, bool)> = panels
            .iter()
            .map(|p| (p[0].as_str().unwrap().to_string(), p[1].as_bool().unwrap()))
            .collect();
        assert_eq!(
            got, want,
            "fid {fid}: one panel per method, the chosen marked"
        );
        for p in panels {
            assert!(
                p[2].as_f64().unwrap() >= 2.0 || p[3] == Value::Bool(true),
                "fid {fid}: {p}"
            );
        }
    }
}

fn check_summary(b: &mut Browser, gpkg: &Path) {
    let shown = b.eval(SUMMARY_JS);
    let want = expected_summary(gpkg);
    assert_eq!(shown.as_object().unwrap().len(), want.len(), "{shown}");
    for (method, cols) in &want {
        for (key, v) in cols {
            let got: f64 = shown[method][key]
                .as_str()
                .unwrap_or_default()
                .parse()
                .unwrap_or(f64::NAN);
            assert!(
                (got - v).abs() <= 1e-9 * v.abs().max(1.0),
                "{method} {key}: page {got}, file {v}"
            );
        }
    }
}

/// The width the `widths` layer holds at the vertex the page names
/// (`… at x = X, y = Y`, to within `resolution`).
fn width_in_file(gpkg: &Path, info: &str, resolution: f64) -> Option<f64> {
    let at = info.split(" at x = ").nth(1)?;
    let (x, y) = at.split_once(", y = ")?;
    let (x, y): (f64, f64) = (x.parse().ok()?, y.trim().parse().ok()?);
    let ds = open(gpkg);
    let lines = wkts(&ds, "widths");
    let (starts, ends) = (
        reals(&ds, "widths", "width_start"),
        reals(&ds, "widths", "width_end"),
    );
    lines.iter().enumerate().find_map(|(i, w)| {
        let w = w
            .as_deref()?
            .strip_prefix("LINESTRING (")?
            .strip_suffix(')')?;
        w.split(',').enumerate().find_map(|(k, pt)| {
            let mut c = pt.split_whitespace().map(|v| v.parse::<f64>().unwrap());
            let (px, py) = (c.next()?, c.next()?);
            let near = (px - x).hypot(py - y) <= resolution;
            near.then(|| if k == 0 { starts[i] } else { ends[i] })
                .flatten()
        })
    })
}

/// The number after `label` in `text`.
fn number_after(text: &str, label: &str) -> f64 {
    text.split(label)
        .nth(1)
        .and_then(|v| v.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no number after `{label}` in {text}"))
}

fn check_interaction(b: &mut Browser, gpkg: &Path) {
    let p = b.eval(VERTEX_JS);
    let (x, y) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
    b.click(x, y);
    let info = b.eval("document.querySelector('section.feature p.info').textContent");
    let info = info.as_str().unwrap();
    assert!(
        info.contains("node radius r = ") && info.contains("width 2r = "),
        "{info}"
    );
    // Inside the polygon the radius at a vertex of the skeleton is positive,
    // and the width shown is the one the `widths` layer holds there.
    assert!(number_after(info, "node radius r = ") > 0.0, "{info}");
    let shown = number_after(info, "width 2r = ");
    let scale: f64 = b
        .eval("document.querySelector('section.feature').dataset.scale")
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    let file = width_in_file(gpkg, info, 1.5 / scale).unwrap_or_else(|| panic!("{info}"));
    assert!(
        (shown - file).abs() <= 0.005 * file,
        "{info}: the file says {file}"
    );
    assert_eq!(
        b.eval("document.querySelectorAll('section.feature g.pick circle').length"),
        2
    );
    let boxes = "Array.from(document.querySelector('section.feature').querySelectorAll('svg.map')).map(s => s.getAttribute('viewBox'))";
    let before = b.eval(boxes);
    b.wheel(x, y, -400.0);
    let after = b.eval(boxes);
    let after = after.as_array().unwrap();
    assert_ne!(after[0], before[0], "the wheel zooms");
    assert!(
        after.iter().all(|v| *v == after[0]),
        "the panels zoom together: {after:?}"
    );
    let bars_shown = "getComputedStyle(document.querySelector('g.bars')).display !== 'none'";
    assert_eq!(
        b.eval(bars_shown),
        Value::Bool(false),
        "bars hidden until asked for"
    );
    b.eval("document.getElementById('show-bars').click()");
    assert_eq!(b.eval(bars_shown), Value::Bool(true));
}

#[test]
fn the_demo_report_works_in_a_real_browser() {
    let Some(chromium) = find_chromium() else {
        if std::env::var_os("SKELETONISE_REQUIRE_BROWSER").is_some() {
            panic!("chromium not found and SKELETONISE_REQUIRE_BROWSER is set");
        }
        eprintln!("SKIPPED the_demo_report_works_in_a_real_browser: chromium not found (install the Debian package `chromium`; .ci/run does)");
        return;
    };
    let d = tmp();
    let (gpkg, html) = demo_run(d.path(), &[]);
    let url = format!("file://{}", html.canonicalize().unwrap().display());
    let mut b = Browser::launch(&chromium, 1400, 1000);
    b.open(&url);
    assert_eq!(b.errors(), Vec::<String>::new(), "console errors");
    let requests = b.requests();
    assert!(
        requests.iter().all(|r| *r == url),
        "the page fetched {requests:?}"
    );
    check_sections(&mut b, &gpkg);
    check_summary(&mut b, &gpkg);
    b.eval("window.scrollTo(0, 0)");
    let shot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-demo.png");
    b.screenshot(&shot);
    check_interaction(&mut b, &gpkg);
    assert_eq!(
        b.errors(),
        Vec::<String>::new(),
        "console errors after interaction"
    );
    let png = std::fs::read(&shot).unwrap();
    assert!(
        png.starts_with(b"\x89PNG") && png.len() > 10_000,
        "screenshot"
    );
    eprintln!("screenshot: {}", shot.display());
}

#[test]
fn without_candidates_the_chosen_skeleton_is_shown_alone_and_a_non_output_is_named() {
    let d = tmp();
    let (_, html) = demo_run(d.path(), &["--set", "output.candidates=false"]);
    let html = read(&html);
    assert!(html.contains("The file has no candidates layer"));
    assert_eq!(attr_values(&html, "section", "data-fid").len(), 17);
    assert_eq!(attr_values(&html, "figure", "data-method").len(), 17);
    let o = skeletonise(&[
        "report",
        TRAIN,
        "-o",
        d.path().join("t.html").to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1);
    assert!(
        err.contains("as the output of `skeletonise run`: it has no skeleton layer `skeletons`"),
        "{err}"
    );
}
