//! Straight skeleton (StSk): known answers, validity invariants, property
//! tests on random star-shaped polygons, and every training layer.
// Without GDAL the training-layer tests are left out, and with them some imports.
#![cfg_attr(not(feature = "gdal"), allow(unused_imports, dead_code))]

use geo::{Coord, LineString, Polygon};
use proptest::prelude::*;
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::SkeletonGraph;
use skeletonise::methods::straight_skeleton::{straight_skeleton_with_stats, StraightSkeleton};
use skeletonise::methods::MethodContext;
use skeletonise::methods::SkeletonMethod;

fn poly(ext: &[(f64, f64)], holes: &[Vec<(f64, f64)>]) -> Polygon<f64> {
    let ring = |v: &[(f64, f64)]| LineString::from(v.to_vec());
    Polygon::new(ring(ext), holes.iter().map(|h| ring(h)).collect())
}

/// Signed distances of `p` to the supporting lines of every boundary edge
/// (positive on the interior side).
fn line_distances(pp: &PreparedPolygon, p: Coord<f64>) -> Vec<f64> {
    pp.boundary()
        .segments()
        .iter()
        .map(|s| {
            let d = s.b - s.a;
            let len = d.x.hypot(d.y);
            ((p - s.a).y * d.x - (p - s.a).x * d.y) / len
        })
        .collect()
}

/// Checks the invariants that hold for every polygon and returns the graph.
///
/// * every node lies in P and no edge crosses ∂P;
/// * every node has an event time, and time ≤ radius (the mitred wavefront
///   at time t lies in the Euclidean offset at distance t);
/// * every node's time equals its distance to the supporting lines of at
///   least two edges, which it reaches from their interior side;
/// * the skeleton is connected when P has no hole (one wavefront).
fn check(p: &Polygon<f64>) -> (SkeletonGraph, PreparedPolygon) {
    check_with(p, 0.0)
}

/// [`check`], with each edge shortened by `end_tol · extent` at both ends
/// before it is tested for crossing ∂P (a ring with two vertices 1e-15
/// apart has a vertex that far outside the next edge, so an arc from it
/// crosses that edge at its start).
fn check_with(p: &Polygon<f64>, end_tol: f64) -> (SkeletonGraph, PreparedPolygon) {
    let pp = PreparedPolygon::new(p).unwrap();
    let (g, stats) = straight_skeleton_with_stats(&pp, &MethodContext::default()).unwrap();
    g.check_invariants().unwrap();
    // Positions and times: 1e-7 of the extent; the line-support check
    // allows 1e-5, since near-simultaneous events (many vertices on one
    // circle) are resolved one after another with rounding in between.
    let tol = 1e-7 * pp.extent();
    let support_tol = 1e-5 * pp.extent();
    assert!(stats.pops <= 1000 * stats.input_vertices + 10_000);
    assert!(!g.is_empty());
    for n in g.nodes() {
        assert!(
            pp.boundary().contains_with_tolerance(n.pos, tol),
            "node {:?} outside",
            n.pos
        );
        let t = n.time.expect("every node has an event time");
        assert!(
            t >= -tol && t <= n.radius + tol,
            "time {t} radius {}",
            n.radius
        );
        let support = line_distances(&pp, n.pos)
            .into_iter()
            .filter(|d| (d - t).abs() <= support_tol)
            .count();
        assert!(
            support >= 2,
            "node {:?} at time {t} lies on {support} offset lines",
            n.pos
        );
    }
    for e in g.edges() {
        let (a, b) = (g.node(e.a).pos, g.node(e.b).pos);
        let len = (b - a).x.hypot((b - a).y);
        let cut = (end_tol * pp.extent() / len.max(f64::MIN_POSITIVE)).min(0.5);
        let (a, b) = (a + (b - a) * cut, b - (b - a) * cut);
        assert!(!pp.boundary().crosses(a, b), "edge {a:?}–{b:?} crosses ∂P");
    }
    if p.interiors().is_empty() {
        assert_eq!(g.components(), 1);
    }
    (g, pp)
}

/// For a convex polygon StSk equals MA: every node and every edge midpoint
/// is as far from ∂P as its (linearly interpolated) event time.
fn check_convex_equals_medial_axis(g: &SkeletonGraph, pp: &PreparedPolygon) {
    let tol = 1e-7 * pp.extent();
    for n in g.nodes() {
        assert!((n.time.unwrap() - n.radius).abs() <= tol);
    }
    for e in g.edges() {
        let (a, b) = (g.node(e.a), g.node(e.b));
        let m = (a.pos + b.pos) * 0.5;
        let t = 0.5 * (a.time.unwrap() + b.time.unwrap());
        assert!((pp.boundary().distance(m) - t).abs() <= tol);
    }
}

fn regular(n: usize, r: f64) -> Polygon<f64> {
    let v: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            (r * a.cos(), r * a.sin())
        })
        .collect();
    poly(&v, &[])
}

#[test]
fn square_is_an_x_with_the_medial_axis() {
    let (g, pp) = check(&poly(&[(0., 0.), (6., 0.), (6., 6.), (0., 6.)], &[]));
    let g = g.merged();
    assert_eq!(g.leg_count(), 4);
    assert!((g.total_length() - 4.0 * 18f64.sqrt()).abs() < 1e-9);
    check_convex_equals_medial_axis(&g, &pp);
}

#[test]
fn rectangle_is_a_segment_and_four_legs() {
    let (g, pp) = check(&poly(&[(0., 0.), (10., 0.), (10., 4.), (0., 4.)], &[]));
    assert_eq!(g.leg_count(), 4);
    let g = g.merged();
    assert_eq!(g.branches().len(), 5);
    assert!((g.total_length() - (6.0 + 4.0 * 8f64.sqrt())).abs() < 1e-9);
    check_convex_equals_medial_axis(&g, &pp);
}

#[test]
fn regular_polygons_are_stars_to_the_centre() {
    for n in [3, 5, 6, 8, 17, 64] {
        let (g, pp) = check(&regular(n, 10.0));
        assert_eq!(g.leg_count(), n, "{n}-gon");
        let r_in = 10.0 * (std::f64::consts::PI / n as f64).cos();
        let tmax = g
            .nodes()
            .iter()
            .map(|x| x.time.unwrap())
            .fold(0.0, f64::max);
        assert!((tmax - r_in).abs() < 1e-9, "{n}-gon: {tmax} vs {r_in}");
        check_convex_equals_medial_axis(&g, &pp);
    }
}

#[test]
fn l_shape() {
    let (g, _) = check(&poly(
        &[
            (0., 0.),
            (10., 0.),
            (10., 2.),
            (2., 2.),
            (2., 10.),
            (0., 10.),
        ],
        &[],
    ));
    // The raw skeleton has an arc from every vertex, the reflex one included.
    assert_eq!(g.leg_count(), 6);
    assert_eq!(g.merged().branches().len(), 6 + 2);
}

#[test]
fn t_shape() {
    let (g, _) = check(&poly(
        &[
            (0., 8.),
            (4., 8.),
            (4., 0.),
            (6., 0.),
            (6., 8.),
            (10., 8.),
            (10., 10.),
            (0., 10.),
        ],
        &[],
    ));
    assert_eq!(g.leg_count(), 8);
}

#[test]
fn one_hole_gives_a_cycle_around_it() {
    let p = poly(
        &[(0., 0.), (10., 0.), (10., 10.), (0., 10.)],
        &[vec![(3., 3.), (3., 7.), (7., 7.), (7., 3.)]],
    );
    let (g, _) = check(&p);
    assert_eq!(g.components(), 1);
    assert!(
        g.edges().len() >= g.nodes().len(),
        "no cycle round the hole"
    );
}

#[test]
fn many_holes() {
    let mut holes = Vec::new();
    for i in 0..5 {
        for j in 0..4 {
            let (x, y) = (2.0 + 4.0 * i as f64, 2.0 + 4.0 * j as f64 + 0.3 * i as f64);
            holes.push(vec![(x, y), (x + 1.0, y + 1.3), (x + 2.0, y + 0.2)]);
        }
    }
    let (g, _) = check(&poly(
        &[(0., 0.), (22., 0.), (23., 19.), (-1., 18.)],
        &holes,
    ));
    assert_eq!(g.components(), 1);
    // One independent cycle per hole.
    assert_eq!(g.edges().len() + 1, g.nodes().len() + holes.len());
}

#[test]
fn comb_with_parallel_teeth() {
    let mut v = vec![(0., 0.), (20., 0.), (20., 3.)];
    for k in (0..5).rev() {
        let x = 4.0 * k as f64;
        v.push((x + 3.0, 3.0));
        v.push((x + 3.0, 12.0));
        v.push((x + 1.0, 12.0));
        v.push((x + 1.0, 3.0));
    }
    v.push((0., 3.));
    let (g, _) = check(&poly(&v, &[]));
    assert!(g.leg_count() >= 12);
}

#[test]
fn spiral() {
    // A square spiral corridor of width 1.
    let outer = [
        (0., 0.),
        (10., 0.),
        (10., 10.),
        (2., 10.),
        (2., 4.),
        (6., 4.),
        (6., 6.),
        (4., 6.),
        (4., 7.),
        (7., 7.),
        (7., 3.),
        (1., 3.),
        (1., 11.),
        (11., 11.),
        (11., -1.),
        (-1., -1.),
    ];
    // Make it simple: a corridor outline, checked for validity below.
    let p = poly(&outer, &[]);
    if geo::Validation::is_valid(&p) {
        check(&p);
    }
    let spiral = poly(
        &[
            (0., 0.),
            (9., 0.),
            (9., 9.),
            (2., 9.),
            (2., 4.),
            (5., 4.),
            (5., 5.),
            (3., 5.),
            (3., 8.),
            (8., 8.),
            (8., 1.),
            (1., 1.),
            (1., 9.),
            (0., 9.),
        ],
        &[],
    );
    assert!(geo::Validation::is_valid(&spiral));
    check(&spiral);
}

#[test]
fn collinear_edges_and_a_vertex_event() {
    // Collinear vertices on the bottom; two reflex vertices meeting.
    check(&poly(
        &[(0., 0.), (3., 0.), (6., 0.), (6., 6.), (0., 6.)],
        &[],
    ));
    check(&poly(
        &[(0., 0.), (4., 2.), (8., 0.), (8., 8.), (4., 6.), (0., 8.)],
        &[],
    ));
}

#[test]
fn time_is_the_distance_to_the_boundary_for_convex_polygons() {
    let p = poly(&[(0., 0.), (7., 1.), (9., 5.), (3., 8.), (-1., 4.)], &[]);
    let (g, pp) = check(&p);
    check_convex_equals_medial_axis(&g, &pp);
}

fn star(radii: &[f64], hole: bool) -> Polygon<f64> {
    let n = radii.len();
    let v: Vec<(f64, f64)> = radii
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            (r * a.cos(), r * a.sin())
        })
        .collect();
    let min = radii.iter().copied().fold(f64::INFINITY, f64::min);
    let holes = if hole {
        let h = 0.3 * min;
        vec![vec![(-h, -h), (h * 0.2, h), (h, -h * 0.5)]]
    } else {
        Vec::new()
    };
    poly(&v, &holes)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    // Random star polygons, many with several vertices on one circle
    // (simultaneous events), with and without a hole: every one gives a
    // skeleton that passes the invariants, with no panic and no hang.
    // Saved case radii = [1, 9.2, 6.67, 4.64, 9.22, 1, 1] with a hole: a
    // hole edge nearly antiparallel to an outer edge (formerly zipped up as
    // a fold, leaving a node on one offset line only).
    #[test]
    fn random_star_polygons(radii in prop::collection::vec(1.0f64..10.0, 3..60), hole in any::<bool>()) {
        check(&star(&radii, hole));
    }

    // Stars whose radii take only three values put many vertices on one
    // circle at once, so many events fall at one time.
    // The events at one time and point are handled as one vertex event.
    #[test]
    fn stars_with_vertices_on_common_circles(
        picks in prop::collection::vec(0usize..3, 3..60),
        hole in any::<bool>(),
    ) {
        let radii: Vec<f64> = picks.iter().map(|&k| [4.0, 7.0, 9.0][k]).collect();
        check(&star(&radii, hole));
    }
}

/// The directions in which two arcs leave one node the same way (within
/// 1e-6 rad): two wavefront vertices that travel as one. Arcs shorter than
/// `1e-6 · extent` are left out (no one sees them).
fn arcs_leaving_together(g: &SkeletonGraph, extent: f64) -> Vec<Coord<f64>> {
    let mut rays: Vec<((i64, i64), f64, Coord<f64>)> = Vec::new();
    let key = |c: Coord<f64>| {
        let q = 1e-9 * extent;
        ((c.x / q).round() as i64, (c.y / q).round() as i64)
    };
    for e in 0..g.edges().len() {
        let c = g.edge_coords(skeletonise::graph::EdgeId::from_index(e));
        let (a, b) = (c[0], c[c.len() - 1]);
        if (b - a).x.hypot((b - a).y) <= 1e-6 * extent {
            continue;
        }
        for (p, q) in [(c[0], c[1]), (c[c.len() - 1], c[c.len() - 2])] {
            rays.push((key(p), (q - p).y.atan2((q - p).x), p));
        }
    }
    rays.sort_by(|r, s| r.0.cmp(&s.0).then(r.1.total_cmp(&s.1)));
    rays.windows(2)
        .filter(|w| w[0].0 == w[1].0 && w[1].1 - w[0].1 < 1e-6)
        .map(|w| w[0].2)
        .collect()
}

/// Buffered lines (`tests/data/buffered-lines.gpkg`, made by
/// `scripts/make_buffered_lines.py`: the 115 of 6 000 generated buffers on
/// which the straight skeleton had two arcs leaving a node the same way).
/// Their antiparallel sides and common circles put many events at one time
/// and point. Each must give a valid skeleton whose arcs never run on top of
/// each other: a reflex vertex that reaches a wavefront vertex exactly is a
/// vertex event (it was a split that left a zero-length edge between two
/// vertices moving as one), and rays of one direction around an event are
/// a tie.
#[cfg(feature = "gdal")]
#[test]
fn buffered_lines_give_no_arcs_on_top_of_each_other() {
    let feats =
        skeletonise::io::read_layer_polygons("tests/data/buffered-lines.gpkg", "buffers").unwrap();
    assert_eq!(feats.len(), 115);
    let mut bad = Vec::new();
    for (i, (_, g)) in feats.into_iter().enumerate() {
        let geo::Geometry::Polygon(p) = g else {
            panic!("feature {i} is not a polygon")
        };
        // GEOS leaves vertices 1e-15 apart: see `check_with`.
        let (g, pp) = check_with(&p, 1e-9);
        let together = arcs_leaving_together(&g, pp.extent());
        if !together.is_empty() {
            bad.push((i, together));
        }
    }
    assert!(
        bad.is_empty(),
        "arcs on top of each other (feature, nodes): {bad:?}"
    );
}

/// A segment buffered 40 m with square caps: a rectangle 80 m wide whose
/// long sides carry a vertex 40 m before each far corner (collinear with its
/// side). Everything collapses at t = 40: the skeleton is the centre segment
/// (the long side less 80 m), four corner legs of 40√2 and the collinear
/// vertices' arcs, perpendicular to their sides and 40 long. CGAL 5.5's
/// `create_interior_straight_skeleton_2` (Epick) draws those two arcs
/// skewed, 564.271 in all; the exact answer is 557.568.
#[test]
fn a_square_capped_buffer_with_collinear_vertices() {
    let v = [
        (-185.0053399948134, 184.78349432021506),
        (-217.35085154897564, 208.3157675274417),
        (-170.28630513452237, 273.00679063576615),
        (65.26480546129463, 101.6367048813754),
        (97.61031701545687, 78.10443167414876),
        (50.54577060100361, 13.413408565824273),
    ];
    let (g, _) = check(&poly(&v, &[]));
    let side = (v[4].0 - v[2].0).hypot(v[4].1 - v[2].1);
    let exact = 4.0 * 40.0 * 2f64.sqrt() + 2.0 * 40.0 + (side - 80.0);
    assert!(
        (g.total_length() - exact).abs() < 1e-6,
        "{} against {exact}",
        g.total_length()
    );
    // The collinear vertices' arcs: 40 long, perpendicular to their sides.
    for (p, q) in [(v[0], v[1]), (v[3], v[4])] {
        let n = g
            .nodes()
            .iter()
            .position(|n| (n.pos.x - p.0).hypot(n.pos.y - p.1) < 1e-9)
            .expect("a node at the collinear vertex");
        let e = g
            .edges()
            .iter()
            .find(|e| e.a.index() == n || e.b.index() == n)
            .unwrap();
        let (a, b) = (g.node(e.a).pos, g.node(e.b).pos);
        let d = b - a;
        let len = d.x.hypot(d.y);
        assert!((len - 40.0).abs() < 1e-6, "arc {len} long");
        let side_dir = ((q.0 - p.0) / 40.0, (q.1 - p.1) / 40.0);
        assert!((d.x * side_dir.0 + d.y * side_dir.1).abs() / len < 1e-9);
    }
}

/// A known failure: a polyline that doubles back on itself, buffered 10 m
/// by geo's `Buffer` (i_overlay; butt caps, round joins). Its round joins'
/// vertices are snapped to a grid, so their events fall up to 2e-6 apart in
/// time at one point — more than the tolerance — and every search pass ends
/// with a loop of four reflex vertices ("did not collapse"). 66 of 3 000
/// random polylines buffered so fail (69 before the fixes of 2026-12-06);
/// GEOS's buffers of the same kind do not. In a run StSk fails for such a
/// polygon with the reason in `candidates.error`, and the other methods go
/// on. Run with `--ignored` to work on it.
#[test]
#[ignore = "known failure: near-simultaneous events of a buffer from geo (see the comment)"]
fn a_doubled_back_polyline_buffered_by_geo() {
    use geo::algorithm::buffer::{BufferStyle, LineCap, LineJoin};
    use geo::Buffer;
    let steps = [
        (-98.13527902608205, 0.0),
        (-81.46734493436833, 0.0),
        (-4.431547394960876, -57.89874930093889),
        (-64.92195118644766, 61.396675550308025),
        (-35.62592431998498, -52.14681253556502),
        (-84.60659810899709, 0.0),
        (0.9685529304641459, 0.0),
        (-42.24640632165111, 0.0),
    ];
    let mut at = (0.0, 0.0);
    let mut pts = vec![at];
    for (dx, dy) in steps {
        at = (at.0 + dx, at.1 + dy);
        pts.push(at);
    }
    let style = BufferStyle::new(10.0)
        .line_cap(LineCap::Butt)
        .line_join(LineJoin::Round(0.3));
    for p in LineString::from(pts).buffer_with_style(style) {
        let (g, pp) = check_with(&p, 1e-9);
        assert!(arcs_leaving_together(&g, pp.extent()).is_empty());
    }
}

/// A buffer whose ring holds two vertices 3e-15 m apart (GEOS's output): the
/// edge between them had no direction, its vertices' velocities came out
/// NaN and the wavefront never collapsed. Vertices within the tolerance of
/// the one before are one vertex now.
#[test]
fn a_ring_with_two_vertices_3e_15_apart() {
    let ext = [
        (-48.78893002206842, -187.99266743586756),
        (-133.87432536617007, -151.52749800268114),
        (-97.63912803067778, -18.66510777254263),
        (-32.8036879932896, 35.364425591947516),
        (-23.654747052650514, 38.21497928889369),
        (-19.877674693472375, 72.20863052149693),
        (-12.49390095108848, 85.61737618886062),
        (2.208630521496937, 89.87767469347239),
        (15.61737618886061, 82.49390095108848),
        (19.877674693472375, 67.79136947850307),
        (13.690111010294462, 12.103296329901847),
        (38.973665961010276, 3.675444679663241),
        (-27.899857903904373, -196.94512691508072),
        (-27.899857903904376, -196.94512691508072),
        (-32.156046749966826, -209.71369345326806),
        (-50.74864192144724, -205.6300745302769),
    ];
    let hole = vec![
        (-39.643691593230116, -105.68552157632276),
        (-29.445943063155568, -13.905784805651821),
        (-62.360871969322226, -41.33489222745737),
        (-86.1256746338299, -128.4725019973189),
        (-52.100142096095624, -143.05487308491928),
    ];
    let (g, pp) = check_with(&poly(&ext, &[hole]), 1e-9);
    assert!(arcs_leaving_together(&g, pp.extent()).is_empty());
    // One cycle around the hole.
    assert_eq!(g.components(), 1);
}

#[cfg(feature = "gdal")]
#[test]
fn every_training_layer() {
    use rayon::prelude::*;
    let mut failures = Vec::new();
    for layer in [
        "islands_hebrides",
        "lakes_scotland",
        "river_st_lawrence",
        "river_danube",
        "river_lena",
    ] {
        let feats = skeletonise::io::read_layer_polygons(crate::common::TRAIN, layer).unwrap();
        let polys: Vec<Polygon<f64>> = feats
            .into_iter()
            .flat_map(|(_, g)| match g {
                geo::Geometry::Polygon(p) => vec![p],
                geo::Geometry::MultiPolygon(m) => m.0,
                _ => Vec::new(),
            })
            .collect();
        let bad: Vec<String> = polys
            .par_iter()
            .filter_map(|p| {
                let pp = PreparedPolygon::new(p).ok()?;
                match StraightSkeleton.skeletonise(&pp, &MethodContext::default()) {
                    Ok(g) => {
                        if let Err(e) = g.check_invariants() {
                            return Some(format!("{layer}: {e}"));
                        }
                        let crossing = g
                            .edges()
                            .iter()
                            .any(|e| pp.boundary().crosses(g.node(e.a).pos, g.node(e.b).pos));
                        crossing.then(|| format!("{layer}: edge crosses ∂P"))
                    }
                    Err(e) => Some(format!("{layer}: {e}")),
                }
            })
            .collect();
        failures.extend(bad);
    }
    for f in &failures {
        eprintln!("{f}");
    }
    assert!(
        failures.is_empty(),
        "{} failures: {:?}",
        failures.len(),
        &failures[..failures.len().min(10)]
    );
}

/// The largest river_lena reach (about 11 000 vertices, nearly parallel
/// banks whose fast reflex vertices split faces far from their own ray)
/// yields a skeleton whose nodes lie in P, whose edges do not cross ∂P and
/// whose node times never exceed the radius.
#[cfg(feature = "gdal")]
#[test]
fn largest_lena_reach() {
    let feats = skeletonise::io::read_layer_polygons(crate::common::TRAIN, "river_lena").unwrap();
    let p = feats
        .into_iter()
        .flat_map(|(_, g)| match g {
            geo::Geometry::Polygon(p) => vec![p],
            geo::Geometry::MultiPolygon(m) => m.0,
            _ => Vec::new(),
        })
        .max_by_key(|p| {
            p.exterior().0.len() + p.interiors().iter().map(|r| r.0.len()).sum::<usize>()
        })
        .unwrap();
    let pp = PreparedPolygon::new(&p).unwrap();
    assert!(pp.vertex_count() > 10_000);
    let (g, stats) = straight_skeleton_with_stats(&pp, &MethodContext::default()).unwrap();
    g.check_invariants().unwrap();
    assert!(stats.pops <= 1000 * stats.input_vertices + 10_000);
    let tol = 1e-6 * pp.extent();
    for n in g.nodes() {
        assert!(pp.boundary().contains_with_tolerance(n.pos, tol));
        let t = n.time.unwrap();
        assert!(
            t >= -tol && t <= n.radius + tol,
            "time {t} radius {}",
            n.radius
        );
    }
    for e in g.edges() {
        assert!(!pp.boundary().crosses(g.node(e.a).pos, g.node(e.b).pos));
    }
}

/// A circle of radius 10 000 with `n` vertices, each moved radially by a
/// deterministic pseudo-random amount up to a quarter of the vertex
/// spacing: rough at every scale, so nearly half the vertices are reflex
/// and every reflex vertex's ray sees a large part of the boundary.
fn noisy_circle(n: usize) -> Polygon<f64> {
    let spacing = std::f64::consts::TAU * 10_000.0 / n as f64;
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let pts: Vec<Coord<f64>> = (0..n)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 10_000.0 * (1.0 + 0.05 * (7.0 * t).sin()) + 0.5 * u * spacing;
            Coord {
                x: 5e5 + r * t.cos(),
                y: 6e6 + r * t.sin(),
            }
        })
        .collect();
    Polygon::new(LineString(pts), vec![])
}

#[test]
fn a_polygon_beyond_the_budget_is_declined_up_front_with_the_reason() {
    use skeletonise::methods::budget::{with_budget, Budget};
    use skeletonise::methods::{MethodError, MethodId};
    use std::time::Duration;
    let pp = PreparedPolygon::new(&noisy_circle(50_000)).unwrap();
    // A second is far less than the quadratic split-event search needs here:
    // the method predicts that from a sample and declines before it starts.
    let one_second = Budget {
        time: Some(Duration::from_secs(1)),
        memory: None,
    };
    match with_budget(MethodId::STSK, one_second, |ctx| {
        StraightSkeleton.skeletonise(&pp, ctx)
    }) {
        Err(MethodError::OverBudget { method, reason }) => {
            assert_eq!(method, MethodId::STSK);
            assert!(reason.contains("would need about"), "{reason}");
            assert!(reason.contains("skeleton.timeout_s"), "{reason}");
        }
        other => panic!(
            "expected OverBudget, got {:?}",
            other.map(|g| g.edges().len())
        ),
    }
    // Memory: one megabyte cannot hold this polygon's split events either.
    let one_megabyte = Budget {
        time: None,
        memory: Some(1_000_000),
    };
    match with_budget(MethodId::STSK, one_megabyte, |ctx| {
        StraightSkeleton.skeletonise(&pp, ctx)
    }) {
        Err(MethodError::OverBudget { reason, .. }) => {
            assert!(reason.contains("skeleton.max_memory_mb"), "{reason}");
        }
        other => panic!(
            "expected OverBudget, got {:?}",
            other.map(|g| g.edges().len())
        ),
    }
    // The same budgets leave a small polygon alone.
    let small = PreparedPolygon::new(&noisy_circle(400)).unwrap();
    for b in [one_second, one_megabyte] {
        let g = with_budget(MethodId::STSK, b, |ctx| {
            StraightSkeleton.skeletonise(&small, ctx)
        })
        .unwrap();
        g.check_invariants().unwrap();
        assert!(g.edges().len() > 400);
    }
}

/// A meandering river as a raster vectorises it: columns of 10 m pixels,
/// each from `floor(60 sin(x / 40))` up, 14 pixels deep, traced along the
/// pixel edges (every vertex a right angle, half of them reflex), with two
/// square islands of 3 × 3 pixels.
fn pixel_river(columns: usize) -> Polygon<f64> {
    let px = 10.0;
    let low = |i: usize| (6.0 * (i as f64 / 4.0).sin()).floor() * px;
    let depth = 14.0 * px;
    let mut ring: Vec<(f64, f64)> = Vec::new();
    for i in 0..columns {
        let (x0, x1) = (i as f64 * px, (i + 1) as f64 * px);
        ring.push((x0, low(i)));
        ring.push((x1, low(i)));
    }
    for i in (0..columns).rev() {
        let (x0, x1) = (i as f64 * px, (i + 1) as f64 * px);
        ring.push((x1, low(i) + depth));
        ring.push((x0, low(i) + depth));
    }
    ring.dedup();
    ring.push(ring[0]);
    let island = |i: usize| {
        let (x, y) = (i as f64 * px, low(i) + 5.0 * px);
        vec![
            (x, y),
            (x, y + 3.0 * px),
            (x + 3.0 * px, y + 3.0 * px),
            (x + 3.0 * px, y),
            (x, y),
        ]
    };
    poly(&ring, &[island(columns / 3), island(2 * columns / 3)])
}

/// A raster staircase puts thousands of split candidates at each multiple
/// of half a pixel, nearly all of them on pixel edges elsewhere; they are
/// passed over as they come up, and the skeleton still satisfies every
/// invariant in the first, local search pass (a real split passed over as
/// a miss leaves a trace that crosses another, and a later pass would be
/// needed).
#[test]
fn a_pixel_staircase_is_skeletonised_in_the_first_pass() {
    let p = pixel_river(600);
    let (g, pp) = check(&p);
    let (_, stats) = straight_skeleton_with_stats(&pp, &MethodContext::default()).unwrap();
    assert_eq!(stats.passes, 1, "{stats:?}");
    assert!(
        stats.missed > stats.input_vertices,
        "a staircase misses many candidates: {stats:?}"
    );
    assert_eq!(g.components(), 1, "the islands' rings join the river's");
}

/// Found by `stars_with_vertices_on_common_circles`: 36 vertices on
/// circles of radius 4, 7 and 9, with runs of up to ten consecutive
/// vertices on the inner circle. The edges between the inner and the middle
/// circle are all tangent to one small circle about the centre, so at time
/// 1.549 seven wavefront vertices and four splits meet at the centre — and
/// two of those edges, on opposite sides of the star, are antiparallel:
/// they meet along a segment from the centre to a reflex vertex. Around the
/// centre the arriving ray of one and the leaving ray of the other point
/// the same way, but their rounded angles differed in the last bits, so the
/// rays did not alternate, the group was handled one event at a time, and
/// every search pass ended with a loop of four reflex vertices outside P
/// ("did not collapse"). The rays of one direction are a tie now, and the
/// two lines join into a fold that zips to the reflex vertex. The skeleton
/// is CGAL's: SFCGAL's `ST_StraightSkeleton` (PostGIS 3, SFCGAL 1.4) gives
/// the same 62 edges, 123.392656112076 long in all.
#[test]
fn a_star_with_runs_of_vertices_on_its_inner_circle() {
    let picks = [
        0, 0, 0, 0, 0, 2, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 1, 0, 1, 1, 1, 2, 1,
        1, 0, 0, 0, 0, 0,
    ];
    let radii: Vec<f64> = picks.iter().map(|&k| [4.0, 7.0, 9.0][k]).collect();
    let (g, _) = check(&star(&radii, false));
    assert_eq!(g.edges().len(), 62);
    assert!(
        (g.total_length() - 123.392656112076).abs() < 1e-9,
        "{}",
        g.total_length()
    );
}
