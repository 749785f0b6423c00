//! The `collapse` step through the real binary, on constructed shapes and on
//! the training layers: lines where the polygon is narrow, areas where it is
//! wide, cut across the polygon where they meet, and the bounds —
//! kept areas wider than width·(1 − tol) and collapsed lines narrower than
//! width·(1 + tol) (except within one width of a cut or a line's end), no
//! stretch shorter than `min_length`, every line end on a cut, on ∂P or on
//! another line.

use crate::common::{
    code_and_err, count, make_layer, open, pipeline, root, skeletonise, strings, tmp, wkts, TRAIN,
};
use gdal::vector::LayerAccess;
use geo::{Area, Coord, Geometry, LineString, MultiPolygon, Polygon};
use skeletonise::geometry::PreparedPolygon;
use std::path::Path;

const TOL: f64 = 0.2;

/// One row of `skeletons` or `areas`: src_fid, the `collapsed` flag (areas:
/// None) and the geometry.
struct Row {
    src_fid: i64,
    collapsed: Option<bool>,
    geometry: Geometry<f64>,
    id: Option<i64>,
}

fn rows(path: &Path, layer: &str) -> Vec<Row> {
    let ds = open(path);
    let mut l = ds.layer_by_name(layer).unwrap();
    let defn = l.defn();
    let idx = |n: &str| defn.field_index(n).ok();
    let (fid, col, id) = (idx("src_fid").unwrap(), idx("collapsed"), idx("id"));
    l.features()
        .map(|f| Row {
            src_fid: f.field_as_integer64(fid).unwrap().unwrap(),
            collapsed: col.and_then(|c| f.field_as_integer(c).unwrap().map(|v| v == 1)),
            geometry: f.geometry().unwrap().to_geo().unwrap(),
            id: id.and_then(|c| f.field_as_integer64(c).unwrap()),
        })
        .collect()
}

fn lines(g: &Geometry<f64>) -> Vec<LineString<f64>> {
    match g {
        Geometry::MultiLineString(m) => m.0.clone(),
        Geometry::LineString(l) => vec![l.clone()],
        other => panic!("not lines: {other:?}"),
    }
}

fn polygons(g: &Geometry<f64>) -> Vec<Polygon<f64>> {
    match g {
        Geometry::Polygon(p) => vec![p.clone()],
        Geometry::MultiPolygon(m) => m.0.clone(),
        other => panic!("not a polygon: {other:?}"),
    }
}

/// The polygons of a layer by FID.
fn sources(path: &str, layer: &str) -> std::collections::BTreeMap<i64, Vec<Polygon<f64>>> {
    let ds = gdal::Dataset::open(path).unwrap();
    let mut l = ds.layer_by_name(layer).unwrap();
    l.features()
        .map(|f| {
            (
                f.fid().unwrap() as i64,
                polygons(&f.geometry().unwrap().to_geo().unwrap()),
            )
        })
        .collect()
}

fn collapse_pipeline(dir: &Path, source: &str, layer: &str, collapse: &str) -> std::path::PathBuf {
    let out = dir.join(format!("{layer}.gpkg"));
    let text = format!(
        "input: {{ source: {source}, layer: {layer} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - prune: {{}}\n  - extend: {{}}\n  - collapse: {collapse}\n  - score: {{}}\n  - select: {{}}\noutput: {{ path: {}, overwrite: true }}\n",
        out.display()
    );
    let p = pipeline(dir, &format!("{layer}.yaml"), &text);
    let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    out
}

fn dist(a: Coord<f64>, b: Coord<f64>) -> f64 {
    (a - b).x.hypot((a - b).y)
}

/// Distance from `c` to the boundary of any of `areas`.
fn to_areas(c: Coord<f64>, areas: &[Polygon<f64>]) -> f64 {
    use geo::{Distance, Euclidean};
    areas
        .iter()
        .flat_map(|a| std::iter::once(a.exterior()).chain(a.interiors()))
        .map(|r| Euclidean.distance(&geo::Point(c), r))
        .fold(f64::INFINITY, f64::min)
}

/// Points along a line at most `step` apart, with their distance along it.
fn samples(l: &LineString<f64>, step: f64) -> Vec<Coord<f64>> {
    let mut out = vec![l.0[0]];
    for w in l.0.windows(2) {
        let n = (dist(w[0], w[1]) / step).ceil().max(1.0) as usize;
        for k in 1..=n {
            out.push(w[0] + (w[1] - w[0]) * (k as f64 / n as f64));
        }
    }
    out
}

/// What the checks found on one layer.
#[derive(Debug, Default)]
struct Measured {
    collapsed_max_width: f64,
    kept_min_width: f64,
    shortest_collapsed: f64,
    shortest_kept: f64,
    loose_ends: usize,
    ends: usize,
    areas: usize,
    cuts: usize,
}

/// Checks one output against its polygons (see the module documentation).
fn measure(
    out: &Path,
    polys: &std::collections::BTreeMap<i64, Vec<Polygon<f64>>>,
    w: f64,
) -> Measured {
    let skel = rows(out, "skeletons");
    let areas = rows(out, "areas");
    let mut m = Measured {
        collapsed_max_width: 0.0,
        kept_min_width: f64::INFINITY,
        shortest_collapsed: f64::INFINITY,
        shortest_kept: f64::INFINITY,
        ..Measured::default()
    };
    for (fid, parts) in polys {
        let prepared: Vec<PreparedPolygon> = parts
            .iter()
            .map(|p| PreparedPolygon::new(p).unwrap())
            .collect();
        let r = |c: Coord<f64>| {
            prepared
                .iter()
                .map(|p| p.boundary().distance(c))
                .fold(f64::INFINITY, f64::min)
        };
        let area_polys: Vec<Polygon<f64>> = areas
            .iter()
            .filter(|a| a.src_fid == *fid)
            .flat_map(|a| polygons(&a.geometry))
            .collect();
        m.areas += area_polys.len();
        let area_sum: f64 = area_polys.iter().map(|a| a.unsigned_area()).sum();
        let total: f64 = parts.iter().map(|p| p.unsigned_area()).sum();
        assert!(
            area_sum <= total * (1.0 + 1e-9),
            "fid {fid}: areas exceed the polygon"
        );
        let of = |c: bool| -> Vec<LineString<f64>> {
            skel.iter()
                .filter(|s| s.src_fid == *fid && s.collapsed == Some(c))
                .flat_map(|s| lines(&s.geometry))
                .collect()
        };
        let (collapsed, kept) = (of(true), of(false));
        let extent = parts
            .iter()
            .map(|p| PreparedPolygon::new(p).unwrap().extent())
            .fold(0.0, f64::max);
        let tol = 1e-6 * extent;
        let all_ends: Vec<Coord<f64>> = collapsed
            .iter()
            .chain(&kept)
            .flat_map(|l| [l.0[0], *l.0.last().unwrap()])
            .collect();
        // Cut points: line ends on an area's boundary, not on ∂P.
        let cut_points: Vec<Coord<f64>> = all_ends
            .iter()
            .copied()
            .filter(|&c| r(c) > tol && to_areas(c, &area_polys) <= tol)
            .collect();
        m.cuts += cut_points.len();
        let on_bp = |c: Coord<f64>| r(c) <= tol;
        for l in &collapsed {
            for end in [l.0[0], *l.0.last().unwrap()] {
                m.ends += 1;
                let shared = all_ends.iter().filter(|&&e| dist(e, end) <= tol).count() > 1;
                if !(on_bp(end) || to_areas(end, &area_polys) <= tol || shared) {
                    m.loose_ends += 1;
                }
            }
        }
        // Widths, away from the cuts and from the lines' own ends on ∂P.
        let near_end = |c: Coord<f64>| {
            cut_points.iter().any(|&p| dist(p, c) < w)
                || all_ends.iter().any(|&e| on_bp(e) && dist(e, c) < w)
        };
        for l in &collapsed {
            for c in samples(l, w / 8.0).into_iter().filter(|&c| !near_end(c)) {
                m.collapsed_max_width = m.collapsed_max_width.max(2.0 * r(c));
            }
        }
        for l in &kept {
            for c in samples(l, w / 8.0).into_iter().filter(|&c| !near_end(c)) {
                m.kept_min_width = m.kept_min_width.min(2.0 * r(c));
            }
        }
        // Stretch lengths: connected lines of one kind between changes.
        for (lines, shortest) in [
            (&collapsed, &mut m.shortest_collapsed),
            (&kept, &mut m.shortest_kept),
        ] {
            for (len, meets_other) in stretches(lines, &cut_points, tol) {
                if meets_other {
                    *shortest = shortest.min(len);
                }
            }
        }
    }
    m
}

/// Connected groups of `lines` (joined where ends coincide): total length
/// and whether the group ends on a cut (meets the other kind).
fn stretches(lines: &[LineString<f64>], cuts: &[Coord<f64>], tol: f64) -> Vec<(f64, bool)> {
    use geo::{Euclidean, Length};
    let n = lines.len();
    let mut group: Vec<usize> = (0..n).collect();
    fn find(g: &mut [usize], i: usize) -> usize {
        if g[i] != i {
            let r = find(g, g[i]);
            g[i] = r;
        }
        g[i]
    }
    let ends = |l: &LineString<f64>| [l.0[0], *l.0.last().unwrap()];
    for i in 0..n {
        for j in i + 1..n {
            if ends(&lines[i])
                .iter()
                .any(|a| ends(&lines[j]).iter().any(|b| dist(*a, *b) <= tol))
            {
                let (a, b) = (find(&mut group, i), find(&mut group, j));
                group[a.max(b)] = a.min(b);
            }
        }
    }
    let mut out: std::collections::BTreeMap<usize, (f64, bool)> = Default::default();
    for (i, line) in lines.iter().enumerate() {
        let g = find(&mut group, i);
        let e = out.entry(g).or_default();
        e.0 += Euclidean.length(line);
        e.1 |= ends(line)
            .iter()
            .any(|c| cuts.iter().any(|p| dist(*p, *c) <= tol));
    }
    out.into_values().collect()
}

fn wkt_layer(dir: &Path, wkts: &[&str]) -> String {
    let src = dir.join("polygons.gpkg");
    let w: Vec<Option<&str>> = wkts.iter().map(|w| Some(*w)).collect();
    make_layer(&src, "shapes", 3857, &w);
    src.display().to_string()
}

/// Two 1 km lakes joined by a 2 km channel 100 m wide.
const DUMBBELL: &str = "POLYGON ((0 0, 1000 0, 1000 450, 3000 450, 3000 0, 4000 0, 4000 1000, 3000 1000, 3000 550, 1000 550, 1000 1000, 0 1000, 0 0))";

#[test]
fn a_dumbbell_gives_two_areas_joined_by_one_line_ending_on_their_cuts() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[DUMBBELL]);
    let out = collapse_pipeline(dir.path(), &src, "shapes", "{ width: 300 }");
    let areas: Vec<Polygon<f64>> = rows(&out, "areas")
        .iter()
        .flat_map(|a| polygons(&a.geometry))
        .collect();
    assert_eq!(areas.len(), 2, "two lakes");
    for a in &areas {
        assert!(
            a.unsigned_area() > 0.95e6 && a.unsigned_area() < 1.1e6,
            "{}",
            a.unsigned_area()
        );
    }
    let skel = rows(&out, "skeletons");
    let collapsed: Vec<LineString<f64>> = skel
        .iter()
        .filter(|s| s.collapsed == Some(true))
        .flat_map(|s| lines(&s.geometry))
        .collect();
    assert_eq!(collapsed.len(), 1, "one line: {collapsed:?}");
    let line = &collapsed[0];
    let (a, b) = (line.0[0], *line.0.last().unwrap());
    assert!(
        to_areas(a, &areas) < 1e-3 && to_areas(b, &areas) < 1e-3,
        "ends on the cuts: {a:?} {b:?}"
    );
    // The ends lie within one width of the channel's mouths (the line runs
    // on into a lake until the lake is wider than the width).
    assert!((a.x.min(b.x) - 1000.0).abs() < 300.0, "{a:?} {b:?}");
    assert!((a.x.max(b.x) - 3000.0).abs() < 300.0, "{a:?} {b:?}");
    assert!((a.y - 500.0).abs() < 1.0 && (b.y - 500.0).abs() < 1.0);
    // The lake's centreline ends on the same points: lines and areas connect.
    let kept_ends: Vec<Coord<f64>> = skel
        .iter()
        .filter(|s| s.collapsed == Some(false))
        .flat_map(|s| lines(&s.geometry))
        .flat_map(|l| [l.0[0], *l.0.last().unwrap()])
        .collect();
    for e in [a, b] {
        assert!(
            kept_ends.iter().any(|k| dist(*k, e) < 1e-9),
            "{e:?} continues into the lake"
        );
    }
    // Every source field is carried to both layers.
    assert!(rows(&out, "areas").iter().all(|r| r.id == Some(0)));
    assert!(skel.iter().all(|r| r.id == Some(0)));
    let m = measure(&out, &sources(&src, "shapes"), 300.0);
    assert_eq!(m.loose_ends, 0, "{m:?}");
    assert!(m.collapsed_max_width < 300.0 * (1.0 + TOL), "{m:?}");
}

/// A 200 m wide river that widens around an island: the channels around it
/// (800 m beside it, 700 m at its ends) are wider than the collapse width,
/// the river above and below is not.
const ISLAND_RIVER: &str = "POLYGON ((0 -100, 4000 -100, 4000 -1200, 6000 -1200, 6000 -100, 10000 -100, 10000 100, 6000 100, 6000 1200, 4000 1200, 4000 100, 0 100, 0 -100), (4700 -400, 4700 400, 5300 400, 5300 -400, 4700 -400))";

#[test]
fn a_river_with_an_island_wider_than_the_width_keeps_the_island_in_one_area() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[ISLAND_RIVER]);
    let out = collapse_pipeline(dir.path(), &src, "shapes", "{ width: 500 }");
    let areas: Vec<Polygon<f64>> = rows(&out, "areas")
        .iter()
        .flat_map(|a| polygons(&a.geometry))
        .collect();
    assert_eq!(areas.len(), 1, "{areas:?}");
    assert_eq!(
        areas[0].interiors().len(),
        1,
        "the island is a hole of the area"
    );
    let collapsed: Vec<LineString<f64>> = rows(&out, "skeletons")
        .iter()
        .filter(|s| s.collapsed == Some(true))
        .flat_map(|s| lines(&s.geometry))
        .collect();
    assert_eq!(collapsed.len(), 2, "upstream and downstream: {collapsed:?}");
    for l in &collapsed {
        let (a, b) = (l.0[0], *l.0.last().unwrap());
        let (outer, inner) = if a.x < 1.0 || a.x > 9999.0 {
            (a, b)
        } else {
            (b, a)
        };
        assert!(
            outer.x < 1.0 || outer.x > 9999.0,
            "one end on the river's cut end: {l:?}"
        );
        assert!(
            to_areas(inner, &areas) < 1e-3,
            "the other on the area's cut: {l:?}"
        );
    }
    let m = measure(&out, &sources(&src, "shapes"), 500.0);
    assert_eq!(m.loose_ends, 0, "{m:?}");
    assert!(m.kept_min_width > 500.0 * (1.0 - TOL), "{m:?}");

    // Narrower than the width all round: two lines around the island, no area.
    let out = collapse_pipeline(dir.path(), &src, "shapes", "{ width: 2000 }");
    assert_eq!(rows(&out, "areas").len(), 0);
    let collapsed: Vec<LineString<f64>> = rows(&out, "skeletons")
        .iter()
        .flat_map(|s| lines(&s.geometry))
        .collect();
    let poly = &sources(&src, "shapes")[&1][0];
    let island = Polygon::new(poly.interiors()[0].clone(), vec![]);
    use geo::Intersects;
    assert!(
        collapsed.iter().all(|l| !l.intersects(&island)),
        "no line crosses the island"
    );
    let ys: Vec<f64> = collapsed
        .iter()
        .flat_map(|l| l.0.iter().map(|c| c.y))
        .collect();
    assert!(
        ys.iter().any(|&y| y > 700.0) && ys.iter().any(|&y| y < -700.0),
        "a line in each channel"
    );
}

#[test]
fn whole_mode_collapses_a_polygon_entirely_or_keeps_it() {
    let dir = tmp();
    let src = wkt_layer(
        dir.path(),
        &[
            DUMBBELL,
            "POLYGON ((0 2000, 5000 2000, 5000 2100, 0 2100, 0 2000))",
        ],
    );
    let out = collapse_pipeline(dir.path(), &src, "shapes", "{ width: 300, mode: whole }");
    let areas = rows(&out, "areas");
    assert_eq!(areas.len(), 1, "the dumbbell is mostly lake: kept");
    assert_eq!(areas[0].src_fid, 1);
    let a: MultiPolygon<f64> = MultiPolygon(polygons(&areas[0].geometry));
    assert!(
        (a.unsigned_area() - 2.2e6).abs() < 1.0,
        "kept whole: {}",
        a.unsigned_area()
    );
    let skel = rows(&out, "skeletons");
    let collapsed: Vec<i64> = skel
        .iter()
        .filter(|s| s.collapsed == Some(true))
        .map(|s| s.src_fid)
        .collect();
    assert_eq!(collapsed, vec![2], "the thin strip collapses");
}

/// `pipelines/collapse-rivers.yaml`, as shipped, on a training layer at
/// `width`.
fn real_layer(layer: &str, width: f64) -> Measured {
    let dir = tmp();
    let out = dir.path().join(format!("{layer}.gpkg"));
    let o = skeletonise(&[
        "run",
        "pipelines/collapse-rivers.yaml",
        "--set",
        &format!("input.layer={layer}"),
        "--set",
        &format!("steps.collapse.width={width}"),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    assert!(
        crate::common::count(&open(&out), "widths") > 0,
        "the pipeline writes widths"
    );
    let m = measure(&out, &sources(TRAIN, layer), width);
    eprintln!("{layer} width {width}: {m:?}");
    m
}

/// The bounds on a real layer at a width that collapses part of it.
fn assert_bounds(layer: &str, width: f64) {
    let m = real_layer(layer, width);
    assert!(
        m.areas > 0 && m.cuts > 0,
        "{layer}: something is kept and cut: {m:?}"
    );
    assert_eq!(
        m.loose_ends, 0,
        "{layer}: every line end on a cut, ∂P or a line: {m:?}"
    );
    assert!(
        m.collapsed_max_width < width * (1.0 + TOL),
        "{layer}: {m:?}"
    );
    assert!(m.kept_min_width > width * (1.0 - TOL), "{layer}: {m:?}");
    assert!(
        m.shortest_collapsed >= width,
        "{layer}: min_length = width: {m:?}"
    );
    assert!(
        m.shortest_kept >= width,
        "{layer}: min_length = width: {m:?}"
    );
}

#[test]
fn river_lena_collapses_within_the_bounds() {
    assert_bounds("river_lena", 1500.0);
}

#[test]
fn river_st_lawrence_collapses_within_the_bounds() {
    assert_bounds("river_st_lawrence", 1500.0);
}

#[test]
fn lakes_scotland_collapse_within_the_bounds() {
    assert_bounds("lakes_scotland", 1000.0);
}

/// Kept areas with a cut whose area is below `limit`: beads on a
/// collapsed river (every kept area the step writes with a cut meets a
/// collapsed line there).
fn beads(out: &Path, limit: f64) -> usize {
    use geo::Area;
    let ds = open(out);
    let cuts = crate::common::ints(&ds, "areas", "cuts");
    rows(out, "areas")
        .iter()
        .zip(cuts)
        .filter(|(r, c)| c.unwrap_or(0) > 0 && r.geometry.unsigned_area() < limit)
        .count()
}

/// The length-weighted median of the local width 2r along a layer's
/// collapsed and kept lines (the `widths` layer of a run).
fn median_width(out: &Path) -> f64 {
    use geo::{Euclidean, Length};
    let ds = open(out);
    let (a, b) = (
        crate::common::reals(&ds, "widths", "width_start"),
        crate::common::reals(&ds, "widths", "width_end"),
    );
    let mut w: Vec<(f64, f64)> = rows(out, "widths")
        .iter()
        .zip(a.iter().zip(&b))
        .map(|(r, (a, b))| {
            let len: f64 = lines(&r.geometry).iter().map(|l| Euclidean.length(l)).sum();
            ((a.unwrap() + b.unwrap()) / 2.0, len)
        })
        .collect();
    w.sort_by(|x, y| x.0.total_cmp(&y.0));
    let half = w.iter().map(|x| x.1).sum::<f64>() / 2.0;
    let mut acc = 0.0;
    w.into_iter()
        .find(|x| {
            acc += x.1;
            acc >= half
        })
        .unwrap()
        .0
}

/// `collapse.min_area` on the training rivers at their median width: the
/// isolated kept areas below 4 width² with collapsed lines on all their cuts
/// (there are some without it) are collapsed, and every line still ends on
/// a cut, on ∂P or on another line.
#[test]
fn min_area_collapses_the_beads_on_the_training_rivers() {
    for layer in ["river_lena", "river_st_lawrence"] {
        let dir = tmp();
        let probe = dir.path().join("probe.gpkg");
        let run = |out: &Path, sets: &[String]| {
            let mut args = vec![
                "run".to_string(),
                "pipelines/collapse-rivers.yaml".into(),
                "--set".into(),
                format!("input.layer={layer}"),
                "-o".into(),
                out.display().to_string(),
                "-q".into(),
            ];
            for s in sets {
                args.extend(["--set".to_string(), s.clone()]);
            }
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = skeletonise(&args);
            assert!(o.status.success(), "{}", code_and_err(&o).1);
        };
        run(&probe, &[]);
        let w = median_width(&probe);
        let limit = 4.0 * w * w;
        let (before, after) = (
            dir.path().join("before.gpkg"),
            dir.path().join("after.gpkg"),
        );
        run(&before, &[format!("steps.collapse.width={w}")]);
        run(
            &after,
            &[
                format!("steps.collapse.width={w}"),
                format!("steps.collapse.min_area={limit}"),
            ],
        );
        let n = beads(&before, limit);
        assert!(n > 0, "{layer} at {w:.0} m has beads without min_area");
        assert_eq!(
            beads(&after, limit),
            0,
            "{layer}: no bead below {limit:.0} m² is left"
        );
        let m = measure(&after, &sources(TRAIN, layer), w);
        assert_eq!(m.loose_ends, 0, "{layer}: {m:?}");
        let kept = |p: &Path| rows(p, "areas").len();
        assert_eq!(
            kept(&after),
            kept(&before) - n,
            "{layer}: only the beads go"
        );
        eprintln!("{layer}: median width {w:.0} m, {n} beads below 4 w² collapsed");
    }
}

#[test]
fn bad_collapse_options_name_the_key_and_the_fix() {
    let dir = tmp();
    for (collapse, key, words) in [
        ("{ width: -5 }", "collapse.width", "positive"),
        (
            "{ width: 100, tolerance: 1.5 }",
            "collapse.tolerance",
            "below 1",
        ),
        ("{ tolerance: 0.1 }", "collapse", "width"),
        ("{ width: 100, mode: partly }", "collapse.mode", "partial"),
        ("{ width: 100, min_area: -1 }", "collapse.min_area", "≥ 0"),
    ] {
        let text = format!(
            "input: {{ source: {TRAIN} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - collapse: {collapse}\noutput: {{ path: {}/o.gpkg }}\n",
            dir.path().display()
        );
        let p = pipeline(dir.path(), "bad.yaml", &text);
        let (code, err) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
        assert_eq!(code, 78, "{collapse}: {err}");
        assert!(
            err.contains(key) && err.contains(words),
            "{collapse}: {err}"
        );
    }
    // After `score` is the wrong place.
    let text = format!(
        "input: {{ source: {TRAIN} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - score: {{}}\n  - collapse: {{ width: 100 }}\noutput: {{ path: {}/o.gpkg }}\n",
        dir.path().display()
    );
    let p = pipeline(dir.path(), "order.yaml", &text);
    let (code, err) = code_and_err(&skeletonise(&["validate", p.to_str().unwrap()]));
    assert_eq!(code, 78, "{err}");
    assert!(err.contains("collapse"), "{err}");
}

#[test]
fn methods_lists_the_collapse_options() {
    let o = skeletonise(&["methods"]);
    let text = String::from_utf8_lossy(&o.stdout);
    for k in ["collapse", "width", "tolerance", "min_length", "mode"] {
        assert!(text.contains(k), "{k} missing from:\n{text}");
    }
}

#[test]
fn without_collapse_there_is_no_areas_layer_and_no_collapsed_column() {
    let dir = tmp();
    let out = dir.path().join("plain.gpkg");
    let text = crate::common::basic_pipeline(TRAIN, "lakes_scotland", &out, "");
    let p = pipeline(dir.path(), "plain.yaml", &text);
    assert!(skeletonise(&["run", p.to_str().unwrap(), "-q"])
        .status
        .success());
    let ds = open(&out);
    assert!(ds.layer_by_name("areas").is_err());
    let l = ds.layer_by_name("skeletons").unwrap();
    assert!(l.defn().field_index("collapsed").is_err());
}

/// A river bend (an annulus sector 1 km wide, vertices every degree) cut
/// into three reaches at 60° and 120°: the reaches share their seams'
/// vertices.
fn three_reaches() -> Vec<String> {
    let at = |r: f64, deg: i32| {
        let a = f64::from(deg).to_radians();
        format!("{} {}", r * a.cos(), r * a.sin())
    };
    [(0, 60), (60, 120), (120, 180)]
        .iter()
        .map(|&(a0, a1)| {
            let mut v: Vec<String> = (a0..=a1).map(|d| at(10_000.0, d)).collect();
            v.extend((a0..=a1).rev().map(|d| at(9_000.0, d)));
            v.push(v[0].clone());
            format!("POLYGON (({}))", v.join(", "))
        })
        .collect()
}

/// Largest turn (degrees) between successive segments of `lines` at
/// vertices within `radius` of `p`.
fn max_turn_near(lines: &[LineString<f64>], p: Coord<f64>, radius: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for l in lines {
        for w in l.0.windows(3) {
            if dist(w[1], p) > radius {
                continue;
            }
            let (u, v) = (w[1] - w[0], w[2] - w[1]);
            let turn = (u.x * v.y - u.y * v.x).atan2(u.x * v.x + u.y * v.y).abs();
            worst = worst.max(turn.to_degrees());
        }
    }
    worst
}

#[test]
fn a_river_in_three_adjacent_reaches_gives_one_line_without_gap_or_kink_at_the_seams() {
    let dir = tmp();
    let reaches = three_reaches();
    let wkts: Vec<&str> = reaches.iter().map(String::as_str).collect();
    let src = wkt_layer(dir.path(), &wkts);
    let out = dir.path().join("merged.gpkg");
    let run = |extra: &str| {
        let text = format!(
            "input: {{ source: {src}, layer: shapes{extra} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - prune: {{}}\n  - extend: {{}}\noutput: {{ path: {}, overwrite: true }}\n",
            out.display()
        );
        let p = pipeline(dir.path(), "merge.yaml", &text);
        let o = skeletonise(&["run", p.to_str().unwrap()]);
        let (code, err) = code_and_err(&o);
        assert_eq!(code, 0, "{err}");
        err
    };
    let log = run(", merge_adjacent: true");
    assert!(log.contains("3 read, 3 written"), "{log}");
    let ds = open(&out);
    assert_eq!(
        crate::common::strings(&ds, "skeletons", "members"),
        vec![Some("1,2,3".to_string())]
    );
    assert_eq!(
        crate::common::ints(&ds, "skeletons", "components"),
        vec![Some(1)]
    );
    let rows = rows(&out, "skeletons");
    let lines = lines(&rows[0].geometry);
    // One line from one cut end to the other, through both seams.
    let ends: Vec<Coord<f64>> = lines
        .iter()
        .flat_map(|l| [l.0[0], *l.0.last().unwrap()])
        .collect();
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(
        ends.iter()
            .any(|e| dist(*e, Coord { x: 9500.0, y: 0.0 }) < 20.0),
        "{ends:?}"
    );
    assert!(
        ends.iter()
            .any(|e| dist(*e, Coord { x: -9500.0, y: 0.0 }) < 20.0),
        "{ends:?}"
    );
    for deg in [60.0_f64, 120.0] {
        let seam = Coord {
            x: 9500.0 * deg.to_radians().cos(),
            y: 9500.0 * deg.to_radians().sin(),
        };
        let near = lines
            .iter()
            .flat_map(|l| l.0.windows(2).map(|w| geo::Line::new(w[0], w[1])))
            .map(|s| {
                use geo::{Distance, Euclidean};
                Euclidean.distance(&s, &geo::Point(seam))
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            near < 5.0,
            "the line passes the seam at {deg}° in its middle: {near}"
        );
        let turn = max_turn_near(&lines, seam, 1500.0);
        eprintln!("seam at {deg}°: {near:.3} m from the line's middle, largest turn {turn:.2}°");
        assert!(turn < 3.0, "no kink at the seam at {deg}°: {turn}°");
    }
    // Only within the same value of a field: every reach has its own `id`.
    run(", merge_adjacent: true, merge_by: id");
    assert_eq!(crate::common::count(&open(&out), "skeletons"), 3);
    // Without merging, three reaches give three lines.
    run("");
    let ds = open(&out);
    assert_eq!(crate::common::count(&ds, "skeletons"), 3);
    assert!(ds
        .layer_by_name("skeletons")
        .unwrap()
        .defn()
        .field_index("members")
        .is_err());
}

#[test]
fn a_line_network_touching_a_polygon_at_three_places_gets_three_legs_ending_there() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[DUMBBELL]);
    // Ends on the left lake's shore; crosses the right lake's shore; ends
    // 4 m short of the channel's bank (within snap); far away.
    make_layer(
        Path::new(&src),
        "rivers",
        3857,
        &[
            Some("LINESTRING (-500 800, 0 800)"),
            Some("LINESTRING (3500 1500, 3500 700)"),
            Some("LINESTRING (2000 -300, 2000 446)"),
            Some("LINESTRING (5000 0, 6000 0)"),
        ],
    );
    let out = dir.path().join("connected.gpkg");
    let text = format!(
        "input: {{ source: {src}, layer: shapes, connect: {{ source: {src}, layer: rivers, snap: 10 }} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - prune: {{}}\n  - extend: {{}}\n  - collapse: {{ width: 300 }}\noutput: {{ path: {} }}\n",
        out.display()
    );
    let p = pipeline(dir.path(), "connect.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    let ds = open(&out);
    let mut l = ds.layer_by_name("connections").unwrap();
    let legs: Vec<(i64, LineString<f64>)> = l
        .features()
        .map(|f| {
            let fid = f
                .field_as_integer64(f.field_index("line_fid").unwrap())
                .unwrap()
                .unwrap();
            let Geometry::LineString(g) = f.geometry().unwrap().to_geo().unwrap() else {
                panic!("a leg is a line")
            };
            (fid, g)
        })
        .collect();
    let mut served: Vec<i64> = legs.iter().map(|(f, _)| *f).collect();
    served.sort_unstable();
    assert_eq!(
        served,
        vec![1, 2, 3],
        "exactly three legs, one per touching line"
    );
    let want = [
        (1, Coord { x: 0.0, y: 800.0 }),
        (
            2,
            Coord {
                x: 3500.0,
                y: 1000.0,
            },
        ),
        (
            3,
            Coord {
                x: 2000.0,
                y: 450.0,
            },
        ),
    ];
    let skel: Vec<LineString<f64>> = rows(&out, "skeletons")
        .iter()
        .flat_map(|r| lines(&r.geometry))
        .collect();
    for (fid, point) in want {
        let (_, leg) = legs.iter().find(|(f, _)| *f == fid).unwrap();
        let end = *leg.0.last().unwrap();
        assert!(
            dist(end, point) < 1e-6,
            "line {fid}: leg ends at {end:?}, not {point:?}"
        );
        // It leaves the shore inwards (within 60° of the normal), never along it.
        let start = leg.0[0];
        let mid = start + (end - start) * 0.5;
        let poly = PreparedPolygon::new(&sources(&src, "shapes")[&1][0]).unwrap();
        assert!(
            poly.boundary().distance(mid) >= 0.24 * dist(start, end),
            "line {fid}: the leg {leg:?} runs along the boundary"
        );
        // The leg is part of the written skeleton, ending on the same point.
        let skel_ends: Vec<Coord<f64>> = skel
            .iter()
            .flat_map(|l| [l.0[0], *l.0.last().unwrap()])
            .collect();
        assert!(
            skel_ends.iter().any(|e| dist(*e, point) < 1e-6),
            "line {fid}: the skeleton reaches {point:?}"
        );
    }
    let m = measure(&out, &sources(&src, "shapes"), 300.0);
    assert_eq!(m.loose_ends, 0, "{m:?}");
}

#[test]
fn measures_width_gives_every_skeleton_vertex_its_local_width_as_m() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[DUMBBELL]);
    let out = dir.path().join("measured.gpkg");
    for collapse in ["", "  - collapse: { width: 300 }\n"] {
        let text = format!(
            "input: {{ source: {src}, layer: shapes }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - prune: {{}}\n  - extend: {{}}\n{collapse}output: {{ path: {}, overwrite: true, measures: width }}\n",
            out.display()
        );
        let p = pipeline(dir.path(), "measures.yaml", &text);
        let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
        assert!(o.status.success(), "{}", code_and_err(&o).1);
        let poly = &sources(&src, "shapes")[&1][0];
        let boundary = PreparedPolygon::new(poly).unwrap();
        let ds = open(&out);
        let mut l = ds.layer_by_name("skeletons").unwrap();
        let mut vertices = 0;
        for f in l.features() {
            let g = f.geometry().unwrap();
            assert!(
                gdal::vector::geometry_type_has_m(g.geometry_type()),
                "XYM lines"
            );
            for i in 0..g.geometry_count() {
                let mut pts = Vec::new();
                g.get_geometry(i).get_points_zm(&mut pts);
                for (x, y, _, m) in pts {
                    let want = 2.0 * boundary.boundary().distance(Coord { x, y });
                    assert!((m - want).abs() < 1e-6, "M {m} at ({x}, {y}), width {want}");
                    vertices += 1;
                }
            }
        }
        assert!(vertices > 3, "{vertices} vertices");
    }
}

#[test]
fn bad_merge_and_connect_inputs_are_errors_before_any_work() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[DUMBBELL]);
    let out = dir.path().join("o.gpkg");
    for (input, code, words) in [
        (
            ", merge_by: id",
            78,
            "merge_by only applies with `merge_adjacent: true`",
        ),
        (
            ", merge_adjacent: true, merge_by: river",
            1,
            "no field `river`; its fields are id",
        ),
        (
            ", connect: { source: /nonexistent/net.gpkg }",
            1,
            "/nonexistent/net.gpkg",
        ),
        (
            ", connect: { source: SRC, snap: -1 }",
            78,
            "snap must be ≥ 0",
        ),
    ] {
        let input = input.replace("SRC", &src);
        let text = format!(
            "input: {{ source: {src}, layer: shapes{input} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\noutput: {{ path: {} }}\n",
            out.display()
        );
        let p = pipeline(dir.path(), "bad.yaml", &text);
        for cmd in ["validate", "run"] {
            let (c, err) = code_and_err(&skeletonise(&[cmd, p.to_str().unwrap()]));
            assert_eq!(c, code, "{cmd} {input}: {err}");
            assert!(err.contains(words), "{cmd} {input}: {err}");
            assert!(!out.exists(), "{cmd} {input}: nothing written");
        }
    }
}

#[test]
fn the_report_of_a_collapse_run_draws_each_feature_once_with_all_its_lines() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[DUMBBELL]);
    let page = |collapse: &str| {
        let out = collapse_pipeline(dir.path(), &src, "shapes", collapse);
        let html = dir.path().join("r.html");
        let o = skeletonise(&[
            "report",
            out.to_str().unwrap(),
            "-o",
            html.to_str().unwrap(),
            "--overwrite",
            "-q",
        ]);
        assert!(o.status.success(), "{}", code_and_err(&o).1);
        (
            crate::common::count(&open(&out), "skeletons"),
            std::fs::read_to_string(&html).unwrap(),
        )
    };
    // Width 1: nothing collapses, one row; width 300: two rows.
    let (rows_plain, plain) = page("{ width: 1 }");
    let (rows_collapsed, collapsed) = page("{ width: 300 }");
    assert_eq!((rows_plain, rows_collapsed), (1, 2));
    assert_eq!(
        collapsed.matches("<path").count(),
        plain.matches("<path").count(),
        "the collapsed and kept rows are drawn as one skeleton"
    );
}

/// A 3 km lake with a 200 m river arm to the east; one island touches the
/// shore at a vertex, a second touches the first at a vertex, and a third
/// leaves a 100 m channel along the south shore (OGC-valid, all of it).
const TOUCHING: &str = "POLYGON((0 0,3000 0,3000 1400,8000 1400,8000 1600,3000 1600,3000 3000,0 3000,0 1500,0 0),(0 1500,800 1700,800 1300,0 1500),(800 1700,1100 2300,1400 1900,800 1700),(1000 100,1500 500,2000 100,1000 100))";

/// GEOS (through GDAL) on a polygon: valid or the reason.
fn geos_valid(p: &Polygon<f64>) -> bool {
    use gdal::vector::ToGdal;
    p.to_gdal().unwrap().is_valid()
}

/// Length of `lines` inside the polygons `areas` shrunk by 1 cm (a line
/// on a cut does not count), by GEOS.
fn length_inside(lines: &[LineString<f64>], areas: &[Polygon<f64>]) -> f64 {
    use gdal::vector::ToGdal;
    let mut total = 0.0;
    for a in areas {
        let shrunk = a.to_gdal().unwrap().buffer(-0.01, 8).unwrap();
        for l in lines {
            let g = l.to_gdal().unwrap().intersection(&shrunk);
            total += g.map_or(0.0, |g| g.length());
        }
    }
    total
}

/// Every vertex of every area either is one of `source`'s vertices bit for
/// bit, or lies on its boundary (a cut's end, inserted into an edge), or
/// lies farther than `far` from it (a cut's change point).
fn vertices_exact(areas: &[Polygon<f64>], source: &[Polygon<f64>], far: f64) -> Result<(), String> {
    let mut vertices = std::collections::HashSet::new();
    for p in source {
        for r in std::iter::once(p.exterior()).chain(p.interiors()) {
            vertices.extend(r.0.iter().map(|c| (c.x.to_bits(), c.y.to_bits())));
        }
    }
    let prepared: Vec<PreparedPolygon> = source
        .iter()
        .map(|p| PreparedPolygon::new(p).unwrap())
        .collect();
    for a in areas {
        for r in std::iter::once(a.exterior()).chain(a.interiors()) {
            for c in &r.0 {
                if vertices.contains(&(c.x.to_bits(), c.y.to_bits())) {
                    continue;
                }
                let d = prepared
                    .iter()
                    .map(|p| p.boundary().distance(*c))
                    .fold(f64::INFINITY, f64::min);
                let extent = prepared.iter().map(|p| p.extent()).fold(0.0, f64::max);
                if d > 1e-9 * extent && d < far {
                    return Err(format!(
                        "area vertex {c:?} lies {d:e} from the source boundary: moved"
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Checks a collapse output against its source polygons: valid areas,
/// exact vertices, no sliver, no collapsed line inside an area, every kept
/// line inside one. Returns (areas, collapsed length).
fn check_areas(
    out: &Path,
    source: &std::collections::BTreeMap<i64, Vec<Polygon<f64>>>,
) -> (usize, f64) {
    let (areas, skel) = (rows(out, "areas"), rows(out, "skeletons"));
    let mut n = 0;
    let mut collapsed_length = 0.0;
    for (fid, parts) in source {
        let a: Vec<Polygon<f64>> = areas
            .iter()
            .filter(|r| r.src_fid == *fid)
            .flat_map(|r| polygons(&r.geometry))
            .collect();
        n += a.len();
        for p in &a {
            assert!(geos_valid(p), "fid {fid}: an invalid area {p:?}");
            assert!(
                p.unsigned_area() > 1.0,
                "fid {fid}: a sliver of {} m²",
                p.unsigned_area()
            );
        }
        vertices_exact(&a, parts, 1.0).unwrap_or_else(|e| panic!("fid {fid}: {e}"));
        let of = |c: bool| -> Vec<LineString<f64>> {
            skel.iter()
                .filter(|s| s.src_fid == *fid && s.collapsed == Some(c))
                .flat_map(|s| lines(&s.geometry))
                .collect()
        };
        let (collapsed, kept) = (of(true), of(false));
        use geo::{Euclidean, Length};
        collapsed_length += collapsed.iter().map(|l| Euclidean.length(l)).sum::<f64>();
        let inside = length_inside(&collapsed, &a);
        assert!(
            inside < 1e-6,
            "fid {fid}: {inside} m of collapsed line inside the kept areas"
        );
        let kept_len: f64 = kept.iter().map(|l| Euclidean.length(l)).sum();
        let grown: Vec<Polygon<f64>> = a
            .iter()
            .map(|p| {
                use gdal::vector::ToGdal;
                let g = p
                    .to_gdal()
                    .unwrap()
                    .buffer(0.02, 8)
                    .unwrap()
                    .to_geo()
                    .unwrap();
                polygons(&g).remove(0)
            })
            .collect();
        let kept_inside = length_inside(&kept, &grown);
        assert!(
            (kept_len - kept_inside).abs() < 1e-6 * kept_len.max(1.0),
            "fid {fid}: kept lines outside the areas: {kept_len} vs {kept_inside}"
        );
    }
    (n, collapsed_length)
}

#[test]
fn holes_touching_the_shore_and_each_other_give_valid_exact_areas_and_no_collapsed_line_in_them() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[TOUCHING]);
    let source = sources(&src, "shapes");
    for width in [300, 500] {
        let out = collapse_pipeline(dir.path(), &src, "shapes", &format!("{{ width: {width} }}"));
        let (areas, collapsed) = check_areas(&out, &source);
        assert_eq!(areas, 1, "width {width}: one lake");
        // The arm (5 km) and the south channel collapse at least.
        assert!(
            collapsed > 5000.0 + 1000.0,
            "width {width}: {collapsed} m collapsed"
        );
    }
}

#[test]
fn real_collapsed_areas_keep_the_source_vertices_and_hold_no_collapsed_line() {
    let dir = tmp();
    for (layer, width) in [
        ("river_lena", 1000),
        ("river_st_lawrence", 1500),
        ("lakes_scotland", 1500),
        ("islands_hebrides", 300),
    ] {
        let out = collapse_pipeline(dir.path(), TRAIN, layer, &format!("{{ width: {width} }}"));
        let (areas, collapsed) = check_areas(&out, &sources(TRAIN, layer));
        assert!(
            areas > 0 && collapsed > 0.0,
            "{layer}: {areas} areas, {collapsed} m collapsed"
        );
    }
}

#[test]
fn a_connection_leg_in_a_kept_lake_is_kept_and_cuts_no_notch() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[TOUCHING]);
    let net = dir.path().join("net.gpkg");
    make_layer(
        &net,
        "net",
        3857,
        &[
            Some("LINESTRING(1500 4000,1500 3000)"),
            Some("LINESTRING(-1000 500,0 500)"),
        ],
    );
    let plain = collapse_pipeline(dir.path(), &src, "shapes", "{ width: 300 }");
    let area = |out: &Path| -> f64 {
        rows(out, "areas")
            .iter()
            .flat_map(|r| polygons(&r.geometry))
            .map(|p| p.unsigned_area())
            .sum()
    };
    let before = area(&plain);
    let out = dir.path().join("connected.gpkg");
    let text = format!(
        "input: {{ source: {src}, layer: shapes, connect: {{ source: {}, layer: net }} }}\nsteps:\n  - skeleton: {{ methods: [MA] }}\n  - prune: {{}}\n  - extend: {{}}\n  - collapse: {{ width: 300 }}\noutput: {{ path: {} }}\n",
        net.display(),
        out.display()
    );
    let p = pipeline(dir.path(), "connected.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    check_areas(&out, &sources(&src, "shapes"));
    // Both legs reach the shore as kept lines, and the lake loses nothing.
    let skel = rows(&out, "skeletons");
    for end in [
        Coord {
            x: 1500.0,
            y: 3000.0,
        },
        Coord { x: 0.0, y: 500.0 },
    ] {
        let holder = skel.iter().find(|s| {
            lines(&s.geometry)
                .iter()
                .any(|l| l.0.iter().any(|c| dist(*c, end) < 1e-6))
        });
        assert_eq!(
            holder.and_then(|s| s.collapsed),
            Some(false),
            "the leg to {end:?}"
        );
    }
    assert!(
        (area(&out) - before).abs() < 1e-6 * before,
        "{} vs {before}",
        area(&out)
    );
}

#[test]
fn collapse_without_ma_is_refused_with_the_reason() {
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[TOUCHING]);
    let out = dir.path().join("o.gpkg");
    for methods in ["[CDT]", "[StSk, VD]", "[DVD]"] {
        let text = format!(
            "input: {{ source: {src}, layer: shapes }}\nsteps:\n  - skeleton: {{ methods: {methods} }}\n  - collapse: {{ width: 300 }}\noutput: {{ path: {} }}\n",
            out.display()
        );
        let p = pipeline(dir.path(), "p.yaml", &text);
        for cmd in ["validate", "run"] {
            let (code, err) = code_and_err(&skeletonise(&[cmd, p.to_str().unwrap()]));
            assert_eq!(code, 78, "{cmd} {methods}: {err}");
            assert!(
                err.contains("`steps[0].skeleton.methods`") && err.contains("add MA to the list"),
                "{err}"
            );
            assert!(!out.exists());
        }
    }
}

/// `collapse` with the skeleton step's default methods runs MA alone (the
/// collapse draws the medial axis; the others would only be scored and
/// dropped), and with MA among other listed methods the skeleton layer is
/// MA's collapsed lines (the others are scored as candidates): the same
/// layers as with MA alone.
#[test]
fn collapse_with_the_default_methods_runs_ma() {
    let dir = tmp();
    let run = |skeleton: &str, name: &str| {
        let out = dir.path().join(format!("{name}.gpkg"));
        let text = format!(
            "input: {{ source: {}, layer: river_lena }}\nsteps:\n  - skeleton: {skeleton}\n  - prune: {{}}\n  - extend: {{}}\n  - collapse: {{ width: 1500 }}\n  - score: {{}}\n  - select: {{}}\noutput: {{ path: {} }}\n",
            root(TRAIN),
            out.display()
        );
        let p = pipeline(dir.path(), &format!("{name}.yaml"), &text);
        let o = skeletonise(&["run", p.to_str().unwrap(), "-q"]);
        assert!(o.status.success(), "{name}: {}", code_and_err(&o).1);
        out
    };
    let ma = run("{ methods: [MA] }", "ma");
    let default = run("{}", "default");
    let bare = run("", "bare");
    let both = run("{ methods: [CDT, MA] }", "both");
    let collapsed = |out: &Path| {
        let ds = open(out);
        (count(&ds, "areas"), wkts(&ds, "skeletons"))
    };
    let (ma_areas, ma_lines) = collapsed(&ma);
    assert!(ma_areas > 0);
    for (name, out) in [("default", &default), ("bare", &bare), ("both", &both)] {
        assert_eq!(collapsed(out), (ma_areas, ma_lines.clone()), "{name}");
        let methods = strings(&open(out), "skeletons", "method");
        assert!(
            methods.iter().all(|m| m.as_deref() == Some("MA")),
            "{methods:?}"
        );
    }
}

#[test]
fn a_star_of_a_hundred_spikes_gets_a_hundred_cuts() {
    // Spikes 2 km long on a 1 km disc, 63 m wide at their base: each is
    // collapsed and cut off at its base, the cuts of neighbours meeting on
    // the reflex vertex between them.
    let n = 100;
    let mut pts: Vec<String> = (0..2 * n)
        .map(|i| {
            let r = if i % 2 == 0 { 3000.0 } else { 1000.0 };
            let a = std::f64::consts::PI * f64::from(i) / f64::from(n);
            format!("{:.3} {:.3}", r * a.cos(), r * a.sin())
        })
        .collect();
    pts.push(pts[0].clone());
    let star = format!("POLYGON(({}))", pts.join(","));
    let dir = tmp();
    let src = wkt_layer(dir.path(), &[&star]);
    let out = collapse_pipeline(dir.path(), &src, "shapes", "{ width: 100 }");
    let areas = rows(&out, "areas");
    assert_eq!(areas.len(), 1, "the disc");
    let ds = open(&out);
    assert_eq!(crate::common::ints(&ds, "areas", "cuts"), [Some(100)]);
    check_areas(&out, &sources(&src, "shapes"));
}
