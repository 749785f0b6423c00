//! River networks through lakes: `prune: {mode: network}` keeps the
//! through-lines between the points where a line network meets each polygon,
//! and the `network` layer is the lines and the skeletons as one noded
//! network. Run with the shipped `pipelines/lakes-network.yaml` on the
//! training lakes and rivers with the generated network of
//! `tests/data/network-train.gpkg` (`scripts/make_network.py`) and on its
//! constructed cases.
#![cfg(all(feature = "cli", feature = "gdal"))]

use crate::common::*;
use gdal::vector::LayerAccess;
use geo::{Coord, Geometry, Intersects, LineString, MultiLineString, Polygon};
use skeletonise::graph::SkeletonGraph;
use std::collections::HashMap;
use std::path::Path;

const NETWORK: &str = "tests/data/network-train.gpkg";
const TRAIN: &str = "tests/data/gshhg-train.gpkg";

fn geometry(w: &str) -> Geometry<f64> {
    wkt::TryFromWkt::try_from_wkt_str(w).unwrap()
}

fn lines_of(w: &str) -> MultiLineString<f64> {
    match geometry(w) {
        Geometry::MultiLineString(m) => m,
        Geometry::LineString(l) => MultiLineString(vec![l]),
        other => panic!("not lines: {other:?}"),
    }
}

/// Runs `pipelines/lakes-network.yaml` on `layer` of `source` with the lines
/// of `lines` (and `--set` overrides); returns the output's path.
fn run(dir: &Path, source: &str, layer: &str, lines: &str, sets: &[&str]) -> std::path::PathBuf {
    let out = dir.join(format!("{layer}.gpkg"));
    let mut args = vec![
        "run".to_string(),
        root("pipelines/lakes-network.yaml"),
        "--set".into(),
        format!("input.source={}", root(source)),
        "--set".into(),
        format!("input.layer={layer}"),
        "--set".into(),
        format!("input.connect.source={}", root(NETWORK)),
        "--set".into(),
        format!("input.connect.layer={lines}"),
        "--set".into(),
        format!("output.path={}", out.display()),
    ];
    for s in sets {
        args.extend(["--set".to_string(), s.to_string()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = skeletonise(&args);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    out
}

fn polygons(source: &str, layer: &str) -> Vec<(i64, Polygon<f64>)> {
    let ds = open(Path::new(&root(source)));
    let mut l = ds.layer_by_name(layer).unwrap();
    l.features()
        .map(|f| {
            let w = f.geometry().unwrap().wkt().unwrap();
            let p = match geometry(&w) {
                Geometry::Polygon(p) => p,
                Geometry::MultiPolygon(m) => m.0.into_iter().next().unwrap(),
                other => panic!("not a polygon: {other:?}"),
            };
            (f.fid().unwrap() as i64, p)
        })
        .collect()
}

fn network_lines(layer: &str) -> Vec<LineString<f64>> {
    let ds = open(Path::new(&root(NETWORK)));
    wkts(&ds, layer)
        .into_iter()
        .map(|w| lines_of(&w.unwrap()).0.remove(0))
        .collect()
}

fn dist(a: Coord<f64>, b: Coord<f64>) -> f64 {
    (a.x - b.x).hypot(a.y - b.y)
}

/// The points where the lines end on polygon `p`'s boundary (the generator
/// ends every line on a boundary vertex).
fn meeting_points(p: &Polygon<f64>, lines: &[LineString<f64>]) -> Vec<Coord<f64>> {
    let ring = |r: &LineString<f64>| r.0.clone();
    let vertices: Vec<Coord<f64>> = std::iter::once(p.exterior())
        .chain(p.interiors())
        .flat_map(ring)
        .collect();
    let mut out: Vec<Coord<f64>> = Vec::new();
    for l in lines {
        for end in [l.0[0], l.0[l.0.len() - 1]] {
            if vertices.iter().any(|v| dist(*v, end) < 1e-6)
                && !out.iter().any(|o| dist(*o, end) < 1e-6)
            {
                out.push(end);
            }
        }
    }
    out
}

/// Skeleton rows by source FID: (lines, distortion).
fn skeletons(out: &Path) -> HashMap<i64, (MultiLineString<f64>, f64)> {
    let ds = open(out);
    let fids = ints(&ds, "skeletons", "src_fid");
    let z = reals(&ds, "skeletons", "distortion");
    fids.into_iter()
        .zip(z)
        .zip(wkts(&ds, "skeletons"))
        .map(|((f, z), w)| (f.unwrap(), (lines_of(&w.unwrap()), z.unwrap_or(f64::NAN))))
        .collect()
}

/// Connected components of a set of lines joined where they share an end
/// point bit for bit (how a routing tool reads a noded network).
fn noded_components(lines: &[LineString<f64>]) -> usize {
    let mut id: HashMap<(u64, u64), usize> = HashMap::new();
    let mut parent: Vec<usize> = Vec::new();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            p[a] = p[p[a]];
            a = p[a];
        }
        a
    }
    let mut key = |c: Coord<f64>, parent: &mut Vec<usize>| {
        let k = (c.x.to_bits(), c.y.to_bits());
        *id.entry(k).or_insert_with(|| {
            parent.push(parent.len());
            parent.len() - 1
        })
    };
    for l in lines {
        let a = key(l.0[0], &mut parent);
        let b = key(l.0[l.0.len() - 1], &mut parent);
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        parent[ra] = rb;
    }
    (0..parent.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count()
}

/// Components of the input: lines and polygons, a line joined to every
/// polygon and line it meets.
fn input_components(polys: &[(i64, Polygon<f64>)], lines: &[LineString<f64>]) -> usize {
    let n = polys.len() + lines.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            a = p[a];
        }
        a
    }
    let join = |a: usize, b: usize, parent: &mut Vec<usize>| {
        let (ra, rb) = (find(parent, a), find(parent, b));
        parent[ra] = rb;
    };
    for (i, l) in lines.iter().enumerate() {
        for (k, (_, p)) in polys.iter().enumerate() {
            if l.intersects(p) {
                join(polys.len() + i, k, &mut parent);
            }
        }
        for (j, m) in lines.iter().enumerate().skip(i + 1) {
            if l.intersects(m) {
                join(polys.len() + i, polys.len() + j, &mut parent);
            }
        }
    }
    (0..n).filter(|&i| find(&mut parent, i) == i).count()
}

fn network_rows(out: &Path) -> Vec<(String, LineString<f64>)> {
    let ds = open(out);
    strings(&ds, "network", "kind")
        .into_iter()
        .zip(wkts(&ds, "network"))
        .map(|(k, w)| (k.unwrap(), lines_of(&w.unwrap()).0.remove(0)))
        .collect()
}

/// On the training lakes and rivers with the generated network: every
/// polygon's through-line is one connected piece whose leaves are exactly
/// its connection points, centred (Z ≤ 0.0002), and the `network` layer is
/// connected wherever the input is.
#[test]
fn training_lakes_and_rivers_keep_exactly_their_through_lines() {
    let dir = tmp();
    for layer in [
        "lakes_scotland",
        "river_st_lawrence",
        "river_danube",
        "river_lena",
    ] {
        let lines_layer = format!("lines_{layer}");
        let out = run(
            dir.path(),
            TRAIN,
            layer,
            &lines_layer,
            &["output.candidates=true"],
        );
        let polys = polygons(TRAIN, layer);
        let lines = network_lines(&lines_layer);
        let sk = skeletons(&out);
        assert_eq!(sk.len(), polys.len(), "{layer}: one row per polygon");
        for (fid, p) in &polys {
            let (lines_out, z) = &sk[fid];
            let want = meeting_points(p, &lines);
            assert!(
                !want.is_empty(),
                "{layer} {fid}: the generator gave it lines"
            );
            let got = leaves(lines_out);
            let g = SkeletonGraph::from_lines(lines_out);
            assert_eq!(
                g.components(),
                1,
                "{layer} {fid}: one connected through-line"
            );
            if want.len() >= 2 {
                assert_eq!(
                    got.len(),
                    want.len(),
                    "{layer} {fid}: leaves {got:?}, connections {want:?}"
                );
                for w in &want {
                    assert!(
                        got.iter().any(|g| dist(*g, *w) < 1e-6),
                        "{layer} {fid}: no leaf at {w:?}"
                    );
                }
            } else {
                assert_eq!(
                    got.len(),
                    2,
                    "{layer} {fid}: one connection and the far tip"
                );
                assert!(got.iter().any(|g| dist(*g, want[0]) < 1e-6));
            }
            assert!(*z <= 0.0002, "{layer} {fid}: Z = {z}");
        }
        // Every method is pruned to the same connections: MA, StSk, DVD
        // and CDT reach each (VD, whose lines on a coarse polygon stop far
        // from its ends, may stop short where no straight leg joins them).
        let ds = open(&out);
        let cands = ints(&ds, "candidates", "src_fid")
            .into_iter()
            .zip(strings(&ds, "candidates", "method"))
            .zip(wkts(&ds, "candidates"));
        let mut checked = 0;
        for ((fid, method), w) in cands {
            let (fid, method) = (fid.unwrap(), method.unwrap());
            if method == "VD" {
                continue;
            }
            let p = &polys.iter().find(|(f, _)| *f == fid).unwrap().1;
            let got = leaves(&lines_of(&w.unwrap()));
            for w in meeting_points(p, &lines) {
                assert!(
                    got.iter().any(|g| dist(*g, w) < 1e-6),
                    "{layer} {fid} {method}: no leaf at {w:?}"
                );
            }
            checked += 1;
        }
        assert_eq!(
            checked,
            4 * polys.len(),
            "{layer}: four methods' candidates"
        );
        let rows = network_rows(&out);
        let pieces: Vec<LineString<f64>> = rows.iter().map(|(_, l)| l.clone()).collect();
        assert_eq!(
            noded_components(&pieces),
            input_components(&polys, &lines),
            "{layer}: the network layer is connected wherever lines and polygons are"
        );
        let lines_written = rows.iter().filter(|(k, _)| k == "line").count();
        assert!(
            lines_written >= lines.len(),
            "{layer}: every input line is written"
        );
    }
}

/// The constructed cases: a lake with three bays keeps only its line from
/// inflow to outflow; a Y keeps three arms; a river whose lines meet both
/// channels beside an island keeps both; a lake no line meets follows
/// `prune.fallback`; a lake with one line runs from it to its far tip.
#[test]
fn constructed_cases_keep_the_channels_their_connections_need() {
    let dir = tmp();
    let out = run(dir.path(), NETWORK, "cases", "cases_lines", &[]);
    let polys = polygons(NETWORK, "cases");
    let lines = network_lines("cases_lines");
    let sk = skeletons(&out);
    let (x0, y0) = (500_000.0, 6_000_000.0);
    // bays_lake: two leaves (in and out), no line into a bay.
    let (bays, _) = &sk[&polys[0].0];
    assert_eq!(leaves(bays).len(), 2);
    assert!(
        bays.0
            .iter()
            .flat_map(|l| l.0.iter())
            .all(|c| (c.y - y0).abs() < 700.0),
        "no line runs into a bay"
    );
    // y_lake: three leaves, one per arm.
    let (y, _) = &sk[&polys[1].0];
    assert_eq!(leaves(y).len(), 3);
    // island_river: four leaves; both channels beside the island are kept.
    let (river, _) = &sk[&polys[2].0];
    let got = leaves(river);
    assert_eq!(got.len(), 4, "{got:?}");
    let ry = y0 + 30_000.0;
    let passes = |x: f64, y: f64| {
        river.0.iter().flat_map(|l| l.0.windows(2)).any(|w| {
            (w[0].x - x) * (w[1].x - x) <= 0.0 && ((w[0].y + w[1].y) / 2.0 - y).abs() < 120.0
        })
    };
    assert!(passes(x0 + 6000.0, ry + 325.0), "the north channel stays");
    assert!(passes(x0 + 6000.0, ry - 325.0), "the south channel stays");
    for w in meeting_points(&polys[2].1, &lines) {
        assert!(got.iter().any(|g| dist(*g, w) < 1e-6), "no leaf at {w:?}");
    }
    // lonely_lake: the fallback (significance) gives it a line.
    let (lonely, _) = &sk[&polys[3].0];
    assert!(!lonely.0.is_empty());
    // spring_lake: one connection (its west end): the line runs from it to
    // the far (east) tip.
    let (spring, _) = &sk[&polys[4].0];
    let got = leaves(spring);
    let tip = Coord {
        x: x0 + 24_000.0,
        y: y0 + 15_000.0,
    };
    assert_eq!(got.len(), 2, "{got:?}");
    assert!(got
        .iter()
        .any(|g| dist(*g, meeting_points(&polys[4].1, &lines)[0]) < 1e-6));
    assert!(
        got.iter().any(|g| dist(*g, tip) < 1.0),
        "the far tip: {got:?}"
    );

    // fallback trunk: one line; fallback drop: rejected with the reason.
    let dir2 = tmp();
    let out = run(
        dir2.path(),
        NETWORK,
        "cases",
        "cases_lines",
        &["steps.prune.fallback=trunk"],
    );
    assert_eq!(leaves(&skeletons(&out)[&polys[3].0].0).len(), 2);
    let dir3 = tmp();
    let out = run(
        dir3.path(),
        NETWORK,
        "cases",
        "cases_lines",
        &["steps.prune.fallback=drop"],
    );
    assert!(!skeletons(&out).contains_key(&polys[3].0));
    let ds = open(&out);
    let reasons = strings(&ds, "rejected", "reason");
    assert_eq!(reasons.len(), 1);
    assert!(
        reasons[0].as_deref().unwrap().contains("fallback"),
        "{reasons:?}"
    );
}

/// The network mode without a network is a configuration error that says
/// what to add.
#[test]
fn network_mode_without_lines_is_an_error_naming_input_connect() {
    let dir = tmp();
    let out = dir.path().join("o.gpkg");
    let text = basic_pipeline(
        &root(TRAIN),
        "lakes_scotland",
        &out,
        "  - prune: { mode: network }\n",
    );
    let p = pipeline(dir.path(), "p.yaml", &text);
    let o = skeletonise(&["run", p.to_str().unwrap()]);
    let (code, err) = code_and_err(&o);
    assert_ne!(code, 0);
    assert!(
        err.contains("input.connect") && err.contains("prune.mode"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
}

/// Network pruning keeps the feature's time budget: a lake crossed 20 000
/// times by one line (which took minutes, past any `timeout_s`, when every
/// connection point ran a search of the whole skeleton) is rejected for its
/// budget soon after it runs out, the reason naming `skeleton.timeout_s`,
/// and the summary does not claim that no line meets a polygon. With the
/// budget it needs, the same lake gets one through-line per crossing pair.
#[test]
fn a_lake_crossed_twenty_thousand_times_keeps_its_time_budget() {
    let dir = tmp();
    let src = dir.path().join("zz.gpkg");
    let (lake, line) = shapes::zig_zag_lake(20_000);
    make_layer(&src, "lake", 32633, &[Some(&lake)]);
    make_layer(&src, "lines", 32633, &[Some(&line)]);
    let run = |timeout: &str, out: &Path| {
        let text = format!(
            "input:\n  source: {src}\n  layer: lake\n  connect:\n    source: {src}\n    layer: lines\n\
             steps:\n  - skeleton:\n      methods: [MA]\n      timeout_s: {timeout}\n\
             \x20 - prune: {{ mode: network }}\n  - score: {{}}\n  - select: {{ by: distortion }}\n\
             output:\n  path: {out}\non_error: reject\n",
            src = src.display(),
            out = out.display()
        );
        let p = pipeline(dir.path(), "p.yaml", &text);
        let started = std::time::Instant::now();
        let o = skeletonise(&["run", p.to_str().unwrap()]);
        (o, started.elapsed().as_secs_f64())
    };
    let out = dir.path().join("short.gpkg");
    let (o, seconds) = run("0.05", &out);
    let (_, err) = code_and_err(&o);
    let ds = open(&out);
    assert_eq!(count(&ds, "skeletons"), 0, "{err}");
    let reasons: Vec<String> = strings(&ds, "rejected", "reason")
        .into_iter()
        .flatten()
        .collect();
    assert!(
        reasons.len() == 1 && reasons[0].contains("skeleton.timeout_s"),
        "{reasons:?}"
    );
    assert!(seconds < 60.0, "the run took {seconds} s");
    assert!(!err.contains("no line of the network touches"), "{err}");
    let out = dir.path().join("long.gpkg");
    let (o, _) = run("600", &out);
    assert!(o.status.success(), "{}", code_and_err(&o).1);
    let ds = open(&out);
    let connections = count(&ds, "connections");
    assert_eq!(connections, 20_000);
}
