//! The default output's quality (the issue on centred ends and like-for-like
//! selection): known answers on constructed shapes, and the defect counts a
//! cartographer sees on every training layer.
// Without GDAL the training-layer tests are left out, and with them some imports.
#![cfg_attr(not(feature = "gdal"), allow(unused_imports, dead_code))]

#[cfg(feature = "gdal")]
use crate::common::{LAYERS, TRAIN};
use geo::{Coord, Geometry, LineString, MultiLineString, Polygon};
#[cfg(feature = "gdal")]
use rayon::prelude::*;
use skeletonise::geometry::segment::closest_on_segment;
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::planar::crossings;
use skeletonise::graph::prune::{PruneMode, PruneParams};
use skeletonise::graph::SkeletonGraph;
#[cfg(feature = "gdal")]
use skeletonise::io::read_layer_polygons;
use skeletonise::methods::MethodContext;
use skeletonise::methods::{build, MethodId, SkeletonParams};
use skeletonise::process::{polygon_parts, process, FeatureOutcome, ProcessParams, Processed};
use skeletonise::score::defects::{end_turns, HOOK_DEG};

fn c(x: f64, y: f64) -> Coord<f64> {
    Coord { x, y }
}

fn polygon(v: &[(f64, f64)]) -> Polygon<f64> {
    Polygon::new(LineString::from(v.to_vec()), vec![])
}

/// `polygon` with a vertex every `step` along its edges, as digitised
/// outlines have (VD needs more than the corners to have a skeleton at all).
fn digitised(v: &[(f64, f64)], step: f64) -> Polygon<f64> {
    let mut out = Vec::new();
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        let n = (((b.0 - a.0).hypot(b.1 - a.1)) / step).ceil().max(1.0) as usize;
        for k in 0..n {
            let t = k as f64 / n as f64;
            out.push((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
        }
    }
    polygon(&out)
}

/// The default pipeline's steps (as `pipelines/demo.yaml` runs them).
fn defaults() -> ProcessParams {
    ProcessParams::all_steps()
}

fn run(p: &Polygon<f64>, params: &ProcessParams) -> FeatureOutcome {
    match process(Some(&Geometry::Polygon(p.clone())), params) {
        Processed::Done(o) => o,
        other => panic!("not processed: {other:?}"),
    }
}

/// The line ends (degree-1 nodes) of a skeleton, sorted.
fn ends(lines: &MultiLineString<f64>) -> Vec<Coord<f64>> {
    let g = SkeletonGraph::from_lines(lines);
    let deg = g.degrees();
    let mut v: Vec<Coord<f64>> = g
        .nodes()
        .iter()
        .zip(&deg)
        .filter(|(_, &d)| d == 1)
        .map(|(n, _)| n.pos)
        .collect();
    v.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    v
}

fn near(a: Coord<f64>, b: Coord<f64>, tol: f64) -> bool {
    (a - b).x.hypot((a - b).y) <= tol
}

fn candidate_lines(o: &FeatureOutcome, m: MethodId) -> &MultiLineString<f64> {
    let c = o
        .candidates
        .iter()
        .find(|c| c.method == m)
        .expect("method ran");
    &c.result.as_ref().expect("method succeeded").geometry
}

#[test]
fn rectangle_pruned_medial_axis_ends_on_the_short_sides_midpoints() {
    let rect = digitised(&[(0., 0.), (100., 0.), (100., 20.), (0., 20.)], 5.0);
    let o = run(&rect, &defaults());
    assert_eq!(o.chosen().0, &MethodId::MA);
    let e = ends(candidate_lines(&o, MethodId::MA));
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(
        near(e[0], c(0., 10.), 1e-6) && near(e[1], c(100., 10.), 1e-6),
        "{e:?}"
    );
    // The same cut ends for every method (like-for-like structure).
    for m in MethodId::builtin() {
        let e = ends(candidate_lines(&o, m));
        assert_eq!(e.len(), 2, "{m}: {e:?}");
        assert!(
            near(e[0], c(0., 10.), 1e-6) && near(e[1], c(100., 10.), 1e-6),
            "{m}: {e:?}"
        );
    }
}

/// A 400 × 60 strip ending in a tip at (560, 30), with small bumps on both
/// banks near the tip (their medial-axis legs are whiskers).
fn tapering_tip() -> Polygon<f64> {
    polygon(&[
        (0., 0.),
        (400., 0.),
        (460., 8.),
        (470., 4.),
        (480., 11.),
        (560., 30.),
        (485., 47.),
        (472., 55.),
        (462., 52.),
        (400., 60.),
        (0., 60.),
    ])
}

#[test]
fn a_tapering_tip_is_reached_along_the_medial_axis_own_leg() {
    let p = tapering_tip();
    let o = run(&p, &defaults());
    let lines = candidate_lines(&o, MethodId::MA);
    let e = ends(lines);
    assert!(e.iter().any(|&x| near(x, c(560., 30.), 1e-6)), "{e:?}");
    // Every point of the end near the tip lies on the raw medial axis.
    let pp = PreparedPolygon::new(&p).unwrap();
    let raw = build(MethodId::MA, &SkeletonParams::default())
        .skeletonise(&pp, &MethodContext::default())
        .unwrap();
    let raw_lines = raw.to_multilinestring();
    let dist = |q: Coord<f64>| {
        raw_lines
            .0
            .iter()
            .flat_map(|l| l.0.windows(2))
            .map(|w| {
                let (p, _) = closest_on_segment(w[0], w[1], q);
                (p - q).x.hypot((p - q).y)
            })
            .fold(f64::INFINITY, f64::min)
    };
    for l in &lines.0 {
        for &q in &l.0 {
            if q.x > 420.0 {
                assert!(
                    dist(q) < 1e-6,
                    "{q:?} is {} off the raw medial axis",
                    dist(q)
                );
            }
        }
    }
}

/// A broad basin (1000 × 800) with a bay 120 wide and 300 long off its
/// top, ending in a point.
fn lake_with_bay() -> Polygon<f64> {
    polygon(&[
        (0., 0.),
        (1000., 0.),
        (1000., 800.),
        (560., 800.),
        (560., 1040.),
        (500., 1100.),
        (440., 1040.),
        (440., 800.),
        (0., 800.),
    ])
}

#[test]
fn a_long_bay_of_a_broad_lake_keeps_its_arm() {
    let p = lake_with_bay();
    let o = run(&p, &defaults());
    let e = ends(candidate_lines(&o, MethodId::MA));
    // One end in the bay's tip.
    assert!(
        e.iter().any(|&q| near(q, c(500., 1100.), 1e-6)),
        "no end in the bay: {e:?}"
    );
    // Measured against the basin's radius alone (arm rule off), the bay
    // goes: it protrudes less than one basin radius beyond its junction.
    let mut off = defaults();
    off.prune = Some(PruneParams {
        arm_ratio: 0.0,
        ..PruneParams::default()
    });
    let e = ends(candidate_lines(&run(&p, &off), MethodId::MA));
    assert!(e.iter().all(|q| q.y < 1000.0), "{e:?}");
}

#[test]
fn a_bump_of_the_bank_is_no_arm() {
    // A 1000 × 100 strip with a pointed bump 30 high and 60 wide on one
    // bank and a flat-topped one (a short straight edge across it) on the
    // other: neither gets a leg.
    let p = polygon(&[
        (0., 0.),
        (270., 0.),
        (300., -30.),
        (330., 0.),
        (1000., 0.),
        (1000., 100.),
        (720., 100.),
        (710., 125.),
        (670., 125.),
        (660., 100.),
        (0., 100.),
    ]);
    let o = run(&p, &defaults());
    let e = ends(candidate_lines(&o, MethodId::MA));
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(
        near(e[0], c(0., 50.), 1e-6) && near(e[1], c(1000., 50.), 1e-6),
        "{e:?}"
    );
}

/// A T: bar [0, 300] × [200, 300] on a stem [100, 200] × [0, 200].
fn t_shape() -> Polygon<f64> {
    digitised(
        &[
            (0., 200.),
            (100., 200.),
            (100., 0.),
            (200., 0.),
            (200., 200.),
            (300., 200.),
            (300., 300.),
            (0., 300.),
        ],
        10.0,
    )
}

#[test]
fn every_method_has_the_same_contacts_on_a_t_shape() {
    let o = run(&t_shape(), &defaults());
    let reference = ends(candidate_lines(&o, MethodId::MA));
    // The three arms end on their end sides' midpoints.
    assert_eq!(reference.len(), 3, "{reference:?}");
    for (got, want) in reference
        .iter()
        .zip([c(0., 250.), c(150., 0.), c(300., 250.)])
    {
        assert!(near(*got, want, 1e-6), "{reference:?}");
    }
    for m in MethodId::builtin() {
        let e = ends(candidate_lines(&o, m));
        assert_eq!(e.len(), reference.len(), "{m}: {e:?}");
        for (a, b) in e.iter().zip(&reference) {
            // Within the local radius (50) of the reference's contact.
            assert!(near(*a, *b, 50.0), "{m}: {e:?} against {reference:?}");
        }
    }
}

#[test]
fn independent_structure_prunes_every_method_on_its_own() {
    let mut p = defaults();
    p.prune = Some(PruneParams {
        structure: skeletonise::graph::prune::Structure::Independent,
        ..PruneParams::default()
    });
    let o = run(&t_shape(), &p);
    assert!(o.candidates.iter().all(|c| c.result.is_ok()));
}

#[cfg(feature = "gdal")]
/// Counts on one training layer: hooked ends and ends of the chosen
/// skeletons, skeletons with a crossing, and with `trunk`, polygon parts
/// whose chosen skeleton is not one line and rivers not won by MA.
fn layer_defects(layer: &str, params: &ProcessParams) -> (usize, usize, usize, usize, usize) {
    let feats = read_layer_polygons(TRAIN, layer).unwrap();
    feats
        .par_iter()
        .map(|(_, g)| {
            let parts: Vec<PreparedPolygon> = polygon_parts(Some(g))
                .unwrap()
                .iter()
                .map(|p| PreparedPolygon::new(p).unwrap())
                .collect();
            let Processed::Done(o) = process(Some(g), params) else {
                panic!("{layer}: a feature was not processed");
            };
            let (method, chosen) = o.chosen();
            let lines = &chosen.geometry;
            let all = SkeletonGraph::from_lines(lines);
            let (mut hooks, mut n_ends, mut not_one_line) = (0, 0, 0);
            for p in &parts {
                let g = all.filter_edges(|e, _| {
                    let c = all.edge_coords(e);
                    p.boundary()
                        .contains_with_tolerance(c[c.len() / 2], 1e-6 * p.extent())
                });
                let turns = end_turns(&g, p);
                n_ends += turns.len();
                hooks += turns.iter().filter(|&&t| t > HOOK_DEG).count();
                let deg = g.degrees();
                let one_line = g.components() == 1
                    && deg.iter().all(|&d| d <= 2)
                    && deg.iter().filter(|&&d| d == 1).count() == 2;
                not_one_line += usize::from(!one_line);
            }
            let crossing = usize::from(crossings(&all) > 0);
            let not_ma = usize::from(*method != MethodId::MA);
            (hooks, n_ends, crossing, not_one_line, not_ma)
        })
        .reduce(
            || (0, 0, 0, 0, 0),
            |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3, a.4 + b.4),
        )
}

#[cfg(feature = "gdal")]
#[test]
fn default_output_on_every_training_layer_has_no_hooks_or_crossings() {
    for layer in LAYERS {
        let (hooks, n_ends, crossing, _, _) = layer_defects(layer, &defaults());
        println!("{layer}: {hooks} hooks of {n_ends} ends, {crossing} crossing skeletons");
        // Below half a percent of the ends on every layer (the issue on
        // rough boundaries; 11 of 2 392 on the islands, none elsewhere).
        assert!(
            (hooks as f64) < 0.005 * n_ends as f64,
            "{layer}: {hooks} of {n_ends} ends hook"
        );
        assert_eq!(crossing, 0, "{layer}: skeletons cross themselves");
    }
}

#[cfg(feature = "gdal")]
#[test]
fn trunk_gives_one_line_per_polygon_part_and_ma_wins_every_river() {
    let mut params = defaults();
    params.prune = Some(PruneParams {
        mode: PruneMode::Trunk,
        ..PruneParams::default()
    });
    for layer in LAYERS {
        let (hooks, n_ends, crossing, not_one_line, not_ma) = layer_defects(layer, &params);
        println!("{layer}: trunk: {not_one_line} parts not one line, {not_ma} not MA, {hooks}/{n_ends} hooks");
        assert_eq!(not_one_line, 0, "{layer}");
        assert_eq!(crossing, 0, "{layer}");
        if layer.starts_with("river") {
            assert_eq!(not_ma, 0, "{layer}: another method beat MA");
        }
    }
}
