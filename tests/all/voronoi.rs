//! `VD` and `DVD` on the real training layers and on a long rectangle.
// Without GDAL the training-layer tests are left out, and with them some imports.
#![cfg_attr(not(feature = "gdal"), allow(unused_imports, dead_code))]

#[cfg(feature = "gdal")]
use crate::common::{LAYERS, TRAIN};
use geo::{Coord, LineString, Polygon};
#[cfg(feature = "gdal")]
use rayon::prelude::*;
use skeletonise::geometry::{densify::Density, PreparedPolygon};
use skeletonise::graph::SkeletonGraph;
#[cfg(feature = "gdal")]
use skeletonise::io::read_layer_polygons;
use skeletonise::methods::MethodContext;
use skeletonise::methods::{voronoi::Voronoi, MethodError, SkeletonMethod};
use skeletonise::process::polygon_parts;

#[cfg(feature = "gdal")]
fn parts(layer: &str) -> Vec<PreparedPolygon> {
    read_layer_polygons(TRAIN, layer)
        .unwrap()
        .iter()
        .flat_map(|(_, g)| polygon_parts(Some(g)).unwrap())
        .map(|p| PreparedPolygon::new(&p).unwrap())
        .collect()
}

#[cfg(feature = "gdal")]
fn run_with_threads(
    threads: usize,
    method: &Voronoi,
    parts: &[PreparedPolygon],
) -> Vec<Result<SkeletonGraph, MethodError>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        parts
            .par_iter()
            .map(|p| method.skeletonise(p, &MethodContext::default()))
            .collect()
    })
}

#[cfg(feature = "gdal")]
/// SPEC §3 invariants of a raw skeleton, and radius = distance to ∂P.
fn assert_valid(layer: &str, p: &PreparedPolygon, g: &SkeletonGraph) {
    if let Err(e) = g.check_invariants() {
        panic!("{layer}: {e}");
    }
    let b = p.boundary();
    let tol = 1e-9 * p.extent();
    for n in g.nodes() {
        assert!(
            b.contains_with_tolerance(n.pos, tol),
            "{layer}: node {:?} outside P",
            n.pos
        );
        assert!(
            (n.radius - b.distance(n.pos)).abs() <= tol,
            "{layer}: radius {} at {:?}",
            n.radius,
            n.pos
        );
    }
    for e in g.edges() {
        let (a, c) = (g.node(e.a).pos, g.node(e.b).pos);
        assert!(a != c, "{layer}: zero-length edge at {a:?}");
        assert!(!b.crosses(a, c), "{layer}: edge {a:?}–{c:?} crosses ∂P");
    }
}

#[cfg(feature = "gdal")]
#[test]
fn real_layers_are_valid_and_independent_of_the_thread_count() {
    let methods = [
        Voronoi::plain(),
        Voronoi::densified(Density::Factor(4), 2_000_000),
    ];
    for layer in LAYERS {
        let parts = parts(layer);
        for m in &methods {
            let one = run_with_threads(1, m, &parts);
            let two = run_with_threads(2, m, &parts);
            assert!(one == two, "{layer} {}: 1 and 2 threads differ", m.id());
            let mut edges = 0;
            for (p, g) in parts.iter().zip(&one) {
                let g = g
                    .as_ref()
                    .unwrap_or_else(|e| panic!("{layer} {}: {e}", m.id()));
                assert_valid(layer, p, g);
                edges += g.edges().len();
            }
            assert!(edges > 0, "{layer} {}: no skeleton at all", m.id());
        }
    }
}

#[cfg(feature = "gdal")]
#[test]
fn densified_skeleton_of_a_real_river_is_connected() {
    // The Danube reach is one polygon without holes: DVD at the paper's
    // factor 4 must give one connected skeleton.
    let p = &parts("river_danube")[0];
    let g = Voronoi::densified(Density::Factor(4), 2_000_000)
        .skeletonise(p, &MethodContext::default())
        .unwrap();
    g.check_invariants().unwrap();
    assert_eq!(g.components(), 1);
}

fn seg_dist(p: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> f64 {
    let d = b - a;
    let t = (((p - a).x * d.x + (p - a).y * d.y) / (d.x * d.x + d.y * d.y)).clamp(0.0, 1.0);
    let q = a + d * t;
    (q - p).x.hypot((q - p).y)
}

#[test]
fn dvd_converges_to_the_medial_axis() {
    // A 100 × 10 rectangle with a few irregularly placed vertices on its long
    // sides (with only the four corners the long sides stay sampled more
    // coarsely than the width up to factor 8, and the error stalls there).
    let c = |x: f64, y: f64| Coord { x, y };
    let ring = vec![
        c(0., 0.),
        c(30., 0.),
        c(70., 0.),
        c(100., 0.),
        c(100., 10.),
        c(55., 10.),
        c(15., 10.),
        c(0., 10.),
    ];
    let p = PreparedPolygon::new(&Polygon::new(LineString(ring), vec![])).unwrap();
    // Its exact medial axis: the centre segment and the four corner bisectors.
    let ma = [
        (c(5., 5.), c(95., 5.)),
        (c(0., 0.), c(5., 5.)),
        (c(0., 10.), c(5., 5.)),
        (c(100., 0.), c(95., 5.)),
        (c(100., 10.), c(95., 5.)),
    ];
    let dist = |q: Coord<f64>| {
        ma.iter()
            .map(|&(a, b)| seg_dist(q, a, b))
            .fold(f64::INFINITY, f64::min)
    };
    let mean: Vec<f64> = [2, 4, 8, 16]
        .into_iter()
        .map(|k| {
            let g = Voronoi::densified(Density::Factor(k), 1_000_000)
                .skeletonise(&p, &MethodContext::default())
                .unwrap();
            g.check_invariants().unwrap();
            g.nodes().iter().map(|n| dist(n.pos)).sum::<f64>() / g.nodes().len() as f64
        })
        .collect();
    for w in mean.windows(2) {
        assert!(
            w[1] < w[0],
            "mean distance to the MA did not shrink: {mean:?}"
        );
    }
    assert!(mean[3] < 0.01 * 10.0, "still {} from the MA", mean[3]);
}

#[cfg(feature = "gdal")]
#[test]
fn a_spacing_that_would_create_millions_of_points_is_an_error() {
    let p = &parts("river_danube")[0];
    let e = Voronoi::densified(Density::Spacing(0.01), 2_000_000)
        .skeletonise(p, &MethodContext::default())
        .unwrap_err();
    match e {
        MethodError::TooManyPoints { points, max } => {
            assert_eq!(max, 2_000_000);
            assert!(points > max);
        }
        other => panic!("expected TooManyPoints, got {other:?}"),
    }
}
