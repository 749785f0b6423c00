//! Method MA (medial axis transform): exact shapes, the analytic parabola,
//! the invariants of SPEC §3, robustness cases and every training layer.
// Without GDAL the training-layer tests are left out, and with them some imports.
#![cfg_attr(not(feature = "gdal"), allow(unused_imports, dead_code))]

#[cfg(feature = "gdal")]
use crate::common::{LAYERS, TRAIN};
use geo::{polygon, Coord, LineString, Polygon};
use skeletonise::geometry::PreparedPolygon;
use skeletonise::graph::widths::medial_axis_transform;
use skeletonise::graph::{EdgeId, SkeletonGraph};
use skeletonise::methods::medial_axis::{resolution, ArcTolerance, MedialAxis};
use skeletonise::methods::MethodContext;
use skeletonise::methods::{MethodError, SkeletonMethod};

fn c(x: f64, y: f64) -> Coord<f64> {
    Coord { x, y }
}

fn ma_with(p: &Polygon<f64>, tol: ArcTolerance) -> (PreparedPolygon, SkeletonGraph) {
    let pp = PreparedPolygon::new(p).unwrap();
    let g = MedialAxis::new(tol)
        .skeletonise(&pp, &MethodContext::default())
        .unwrap();
    g.check_invariants().unwrap();
    (pp, g)
}

fn ma(p: &Polygon<f64>) -> (PreparedPolygon, SkeletonGraph) {
    ma_with(p, ArcTolerance::default())
}

fn dist(a: Coord<f64>, b: Coord<f64>) -> f64 {
    (a - b).x.hypot((a - b).y)
}

/// The graph's invariants ([`SkeletonGraph::check_invariants`]) and SPEC
/// §3's: radius = distance to ∂P, every point in P, no edge crossing ∂P.
/// Tolerance: a few grid spacings (MA quantises ∂P).
fn check_invariants(pp: &PreparedPolygon, g: &SkeletonGraph) {
    g.check_invariants().unwrap();
    let b = pp.boundary();
    let res = resolution(pp);
    assert!(res > 0.0 && res < 1.5e-8 * pp.extent());
    let tol = 4.0 * res;
    for n in g.nodes() {
        let d = b.distance(n.pos);
        assert!(
            (n.radius - d).abs() <= tol,
            "node {:?}: radius {} but distance to ∂P {d}",
            n.pos,
            n.radius
        );
        assert!(
            b.contains(n.pos) || d <= tol,
            "node {:?} outside P (distance {d})",
            n.pos
        );
    }
    for i in 0..g.edges().len() {
        let pts = g.edge_coords(EdgeId::from_index(i));
        for w in pts.windows(2) {
            assert!(
                !b.crosses(w[0], w[1]),
                "edge piece {:?}–{:?} crosses ∂P",
                w[0],
                w[1]
            );
            let m = (w[0] + w[1]) * 0.5;
            assert!(
                b.contains(m) || b.distance(m) <= tol,
                "edge piece midpoint {m:?} outside P"
            );
        }
    }
}

/// Undirected straight edges of the degree-2-merged graph, end points rounded.
fn branch_ends(g: &SkeletonGraph) -> Vec<[(i64, i64); 2]> {
    let r = |p: Coord<f64>| ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64);
    let mut v: Vec<[(i64, i64); 2]> = g
        .branches()
        .iter()
        .map(|b| {
            let (a, z) = (r(b.coords[0]), r(*b.coords.last().unwrap()));
            if a <= z {
                [a, z]
            } else {
                [z, a]
            }
        })
        .collect();
    v.sort();
    v
}

#[test]
fn rectangle_is_centre_segment_plus_four_corner_legs() {
    let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 4.), (x: 0., y: 4.)];
    let (pp, g) = ma(&p);
    check_invariants(&pp, &g);
    let r = |x: f64, y: f64| ((x * 1e6) as i64, (y * 1e6) as i64);
    let mut want = vec![
        [r(0., 0.), r(2., 2.)],
        [r(0., 4.), r(2., 2.)],
        [r(2., 2.), r(8., 2.)],
        [r(8., 2.), r(10., 0.)],
        [r(8., 2.), r(10., 4.)],
    ];
    want.sort();
    assert_eq!(branch_ends(&g), want);
    assert_eq!(g.edges().len(), 5, "all edges straight, no subdivision");
    assert_eq!(g.leg_count(), 4);
    // Legs are at 45°.
    for b in g.branches() {
        let (a, z) = (b.coords[0], *b.coords.last().unwrap());
        let d = z - a;
        assert!(d.y == 0.0 || (d.x.abs() - d.y.abs()).abs() < 1e-9, "{d:?}");
    }
}

#[test]
fn square_is_an_x() {
    let p = polygon![(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 4.), (x: 0., y: 4.)];
    let (pp, g) = ma(&p);
    check_invariants(&pp, &g);
    assert_eq!(g.edges().len(), 4);
    let deg = g.degrees();
    let centre = deg
        .iter()
        .position(|&d| d == 4)
        .expect("one junction of degree 4");
    assert!(dist(g.nodes()[centre].pos, c(2., 2.)) < 1e-8);
    assert!((g.nodes()[centre].radius - 2.0).abs() < 1e-8);
}

#[test]
fn regular_polygon_is_a_star_to_the_centre() {
    for n in [5usize, 7, 12, 31, 64] {
        let ring: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / n as f64 + 0.1;
                (100.0 + 5.0 * a.cos(), -30.0 + 5.0 * a.sin())
            })
            .collect();
        let p = Polygon::new(LineString::from(ring.clone()), vec![]);
        let (pp, g) = ma(&p);
        check_invariants(&pp, &g);
        let inradius = 5.0 * (std::f64::consts::PI / n as f64).cos();
        // Every edge is a leg from a vertex (exactly) to the centre. With many
        // sides the centre splits into a few junctions: a near-regular
        // polygon's junctions move by many times the input's rounding, so
        // for large n they are only required to lie within 1e-6 × extent.
        let res = resolution(&pp);
        let spread = if n <= 12 {
            4.0 * res
        } else {
            1e-6 * pp.extent()
        };
        assert!(
            n > 12 || g.edges().len() == n,
            "{n}-gon: {} edges",
            g.edges().len()
        );
        let mut legs = 0;
        for e in g.edges() {
            let (a, b) = (g.node(e.a), g.node(e.b));
            let (vertex, centre) = if a.radius < b.radius { (a, b) } else { (b, a) };
            assert!(
                dist(centre.pos, c(100.0, -30.0)) <= spread,
                "{n}-gon: junction at {:?}",
                centre.pos
            );
            assert!((centre.radius - inradius).abs() <= spread);
            if vertex.radius == 0.0 {
                assert!(
                    ring.iter().any(|&(x, y)| vertex.pos == c(x, y)),
                    "leaf {:?} not a vertex",
                    vertex.pos
                );
                legs += 1;
            } else {
                assert!(
                    dist(vertex.pos, c(100.0, -30.0)) <= spread,
                    "{n}-gon: inner edge far from the centre"
                );
            }
        }
        assert_eq!(legs, n);
        assert_eq!(g.leg_count(), n);
        assert_eq!(g.components(), 1);
        if n <= 12 {
            assert_eq!(
                g.degrees().iter().filter(|&&d| d == n).count(),
                1,
                "{n}-gon: one junction of degree {n}"
            );
        }
    }
}

/// The analytic medial axis of the L-shape near its reflex vertex (1, 1):
/// the parabola of points equidistant from (1, 1) and the bottom edge y = 0,
/// `y = ((x − 1)² + 1) / 2` for x ∈ [2 − √2, 1] (and its mirror image).
fn l_shape() -> Polygon<f64> {
    polygon![(x: 0., y: 0.), (x: 2., y: 0.), (x: 2., y: 1.), (x: 1., y: 1.), (x: 1., y: 2.), (x: 0., y: 2.)]
}

fn parabola(x: f64) -> f64 {
    ((x - 1.0) * (x - 1.0) + 1.0) / 2.0
}

/// Distance from q to the curve y = parabola(x), x ∈ [lo, hi] (golden-section).
fn distance_to_parabola(q: Coord<f64>, lo: f64, hi: f64) -> f64 {
    let d = |x: f64| dist(q, c(x, parabola(x)));
    // Coarse scan, then refine around the best sample.
    let steps = 2000;
    let mut best = (lo, d(lo));
    for k in 0..=steps {
        let x = lo + (hi - lo) * k as f64 / steps as f64;
        let v = d(x);
        if v < best.1 {
            best = (x, v);
        }
    }
    let h = (hi - lo) / steps as f64;
    let (mut a, mut b) = ((best.0 - h).max(lo), (best.0 + h).min(hi));
    for _ in 0..100 {
        let m1 = a + (b - a) / 3.0;
        let m2 = b - (b - a) / 3.0;
        if d(m1) < d(m2) {
            b = m2;
        } else {
            a = m1;
        }
    }
    d(0.5 * (a + b)).min(best.1)
}

#[test]
fn l_shape_has_the_analytic_parabola_within_tolerance() {
    let x_junction = 2.0 - std::f64::consts::SQRT_2;
    for tol in [
        ArcTolerance::Relative(0.01),
        ArcTolerance::Relative(0.001),
        ArcTolerance::Absolute(0.002),
    ] {
        let (pp, g) = ma_with(&l_shape(), tol);
        check_invariants(&pp, &g);
        // Topology: 5 legs (convex corners), junctions at the diagonal's end
        // and at the two arm ends.
        let m = g.merged();
        assert_eq!(m.leg_count(), 5);
        assert_eq!(m.edges().len(), 7);
        let junction = c(x_junction, x_junction);
        assert!(
            m.nodes()
                .iter()
                .any(|n| dist(n.pos, junction) < 1e-8 && (n.radius - x_junction).abs() < 1e-8),
            "no junction at ({x_junction}, {x_junction})"
        );
        // The lower arc: nodes with x ∈ [2 − √2, 1], y < x (below the diagonal).
        let on_arc = |p: Coord<f64>| {
            p.x >= x_junction - 1e-9 && p.x <= 1.0 + 1e-9 && p.y <= p.x + 1e-9 && p.y >= 0.5 - 1e-9
        };
        // Every straight piece of every edge (an arc's samples are its
        // edge's interior vertices), with the exact radius at its ends.
        let mut pieces = 0;
        let mut worst: f64 = 0.0;
        let mat = medial_axis_transform(&g, Some(pp.boundary()));
        for s in &mat {
            let (a, b) = (s.line.start, s.line.end);
            if !(on_arc(a) && on_arc(b)) || (a.y - 0.5).abs() < 1e-9 && (b.y - 0.5).abs() < 1e-9 {
                continue;
            }
            pieces += 1;
            for (q, r) in [(a, s.r_start), (b, s.r_end)] {
                // Points lie on the parabola, and their radius is the parabola's height.
                assert!((q.y - parabola(q.x)).abs() < 1e-8, "{q:?} off the parabola");
                assert!((r - q.y).abs() < 1e-8);
            }
            let (x0, x1) = (a.x.min(b.x), a.x.max(b.x));
            let r_min = parabola(x0.max(1.0).min(x1))
                .min(parabola(x0))
                .min(parabola(x1));
            let allowed = match tol {
                ArcTolerance::Relative(f) => f * r_min,
                ArcTolerance::Absolute(d) => d,
            };
            for k in 0..=40 {
                let t = k as f64 / 40.0;
                let q = a + (b - a) * t;
                let dev = distance_to_parabola(q, x0 - 0.01, x1 + 0.01);
                assert!(
                    dev <= allowed * (1.0 + 1e-6) + 1e-12,
                    "{tol:?}: deviation {dev} > {allowed}"
                );
                worst = worst.max(dev / allowed);
            }
        }
        assert!(pieces >= 2, "{tol:?}: the arc has {pieces} pieces");
        assert!(
            worst > 0.2,
            "{tol:?}: arc needlessly fine (worst use {worst})"
        );
        // Mirror symmetry: the upper arc is the same set of points, transposed.
        let points = points_of(&g);
        let key = |x: f64, y: f64| ((x * 1e7).round() as i64, (y * 1e7).round() as i64);
        let mut lower: Vec<(i64, i64)> = points
            .iter()
            .filter(|p| on_arc(**p))
            .map(|p| key(p.x, p.y))
            .collect();
        let mut upper: Vec<(i64, i64)> = points
            .iter()
            .filter(|p| on_arc(c(p.y, p.x)))
            .map(|p| key(p.y, p.x))
            .collect();
        lower.sort();
        upper.sort();
        lower.dedup();
        upper.dedup();
        assert_eq!(lower, upper);
    }
}

/// Every node and interior vertex of `g`.
fn points_of(g: &SkeletonGraph) -> Vec<Coord<f64>> {
    (0..g.edges().len())
        .flat_map(|i| g.edge_coords(EdgeId::from_index(i)))
        .collect()
}

/// The number of straight pieces of `g`'s edges.
fn pieces_of(g: &SkeletonGraph) -> usize {
    (0..g.edges().len())
        .map(|i| g.edge_coords(EdgeId::from_index(i)).len() - 1)
        .sum()
}

#[test]
fn finer_tolerance_gives_more_pieces() {
    let n = |t| pieces_of(&ma_with(&l_shape(), ArcTolerance::Relative(t)).1);
    assert!(n(0.0001) > n(0.01));
    assert!(n(0.01) > n(0.3));
}

/// A finer tolerance adds vertices inside an arc's edge, not edges and
/// nodes: the raw graph of a rough rim stays a few nodes per boundary
/// vertex however finely its arcs are drawn.
#[test]
fn an_arc_is_one_edge_whatever_the_tolerance() {
    let g = |t| ma_with(&l_shape(), ArcTolerance::Relative(t)).1;
    let (fine, coarse) = (g(0.0001), g(0.3));
    assert!(pieces_of(&fine) > pieces_of(&coarse));
    assert_eq!(fine.edges().len(), coarse.edges().len());
    assert_eq!(fine.nodes().len(), coarse.nodes().len());
}

#[test]
fn relative_tolerance_is_scale_free() {
    let (_, g1) = ma(&l_shape());
    let big = geo::MapCoords::map_coords(&l_shape(), |p| c(p.x * 1000.0 + 3e5, p.y * 1000.0 + 6e6));
    let (_, g2) = ma(&big);
    assert_eq!(g1.edges().len(), g2.edges().len());
    assert_eq!(g1.nodes().len(), g2.nodes().len());
}

#[test]
fn polygon_with_holes_has_a_cycle_around_each_hole() {
    let p = polygon!(
        exterior: [(x: 0., y: 0.), (x: 20., y: 0.), (x: 20., y: 10.), (x: 0., y: 10.)],
        interiors: [
            [(x: 4., y: 4.), (x: 6., y: 4.), (x: 6., y: 6.), (x: 4., y: 6.)],
            [(x: 14., y: 3.), (x: 16., y: 5.), (x: 14., y: 7.), (x: 12., y: 5.)],
        ],
    );
    let (pp, g) = ma(&p);
    check_invariants(&pp, &g);
    assert_eq!(g.components(), 1);
    // Cycles = E − V + C (V counting only nodes with edges).
    let used = g.degrees().iter().filter(|&&d| d > 0).count();
    assert_eq!(
        g.edges().len() + 1 - used,
        2,
        "one independent cycle per hole"
    );
    // Only the exterior's four convex corners give legs: hole corners are reflex.
    assert_eq!(g.leg_count(), 4);
    for (i, d) in g.degrees().iter().enumerate() {
        if *d == 1 {
            let q = g.nodes()[i].pos;
            assert!(q.x == 0.0 || q.x == 20.0, "leg to {q:?}");
        }
    }
}

#[test]
fn touching_rings_work() {
    // A hole touching the exterior at a point inside an exterior edge, and a
    // second hole touching the first at a shared vertex.
    let p = polygon!(
        exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)],
        interiors: [
            [(x: 5., y: 0.), (x: 3., y: 3.), (x: 7., y: 3.)],
            [(x: 7., y: 3.), (x: 6., y: 6.), (x: 8., y: 6.)],
        ],
    );
    let (pp, g) = ma(&p);
    check_invariants(&pp, &g);
    assert!(!g.is_empty());
    assert_eq!(g.components(), 1);
    // The convex corners on both sides of the hole's touch at (5, 0) send
    // their legs to the one touching point, where they meet.
    let deg = g.degrees();
    let touch = g
        .nodes()
        .iter()
        .position(|n| n.pos == c(5., 0.))
        .expect("a node at the touch");
    assert_eq!(deg[touch], 2);
    // Nothing passes through the touching points except legs ending there.
    for n in g.nodes() {
        if dist(n.pos, c(5., 0.)) < 1e-9 || dist(n.pos, c(7., 3.)) < 1e-9 {
            assert!(n.radius < 1e-9);
        }
    }
}

#[test]
fn nearly_collinear_and_nearly_coincident_vertices_work() {
    let e = 1e-11;
    let p = polygon![
        (x: 0., y: 0.), (x: 3., y: e), (x: 6., y: 0.), (x: 6. + e, y: 0.), (x: 10., y: 0.),
        (x: 10., y: 4.), (x: 10., y: 4. + e), (x: 7., y: 4. - e), (x: 5., y: 4.), (x: 3., y: 4.),
        (x: 0., y: 4.)
    ];
    let (pp, g) = ma(&p);
    check_invariants(&pp, &g);
    let m = g.merged();
    // Still a rectangle's axis: no spurious legs at the (nearly) straight vertices.
    assert_eq!(m.leg_count(), 4, "{:?}", branch_ends(&m));
    // A jagged boundary with tiny zig-zags must not fail either.
    let mut ring = Vec::new();
    for i in 0..200 {
        let x = i as f64 * 0.05;
        ring.push((x, if i % 2 == 0 { 0.0 } else { 1e-9 }));
    }
    ring.push((10.0, 3.0));
    ring.push((0.0, 3.0));
    let (pp, g) = ma(&Polygon::new(LineString::from(ring), vec![]));
    check_invariants(&pp, &g);
}

#[test]
fn exact_straight_angle_vertices_give_no_legs() {
    let p = polygon![(x: 0., y: 0.), (x: 3., y: 0.), (x: 7., y: 0.), (x: 10., y: 0.), (x: 10., y: 4.), (x: 5., y: 4.), (x: 0., y: 4.)];
    let (pp, g) = ma(&p);
    check_invariants(&pp, &g);
    assert_eq!(g.leg_count(), 4);
    assert_eq!(g.merged().edges().len(), 5);
}

#[test]
fn huge_coordinates_give_the_translated_result() {
    let base = polygon!(
        exterior: [(x: 0., y: 0.), (x: 30., y: 2.), (x: 40., y: 15.), (x: 20., y: 12.), (x: 8., y: 20.), (x: -5., y: 9.)],
        interiors: [[(x: 10., y: 5.), (x: 14., y: 6.), (x: 12., y: 9.)]],
    );
    let (_, g0) = ma(&base);
    for shift in [1e7, 4e7] {
        let moved = geo::MapCoords::map_coords(&base, |p| c(p.x + shift, p.y - shift / 2.0));
        let (pp, g1) = ma(&moved);
        check_invariants(&pp, &g1);
        assert_eq!(g0.edges().len(), g1.edges().len());
        assert_eq!(g0.nodes().len(), g1.nodes().len());
        // Same nodes, up to a grid spacing or two: the shifted input's own
        // rounding (ulp(4e7) ≈ 7e-9) can move a vertex to the next grid point.
        let tol = 2.0 * resolution(&pp);
        for (a, b) in g0.nodes().iter().zip(g1.nodes()) {
            let back = c(b.pos.x - shift, b.pos.y + shift / 2.0);
            assert!(dist(a.pos, back) < tol, "{:?} vs {back:?}", a.pos);
            assert!((a.radius - b.radius).abs() < tol);
        }
    }
}

#[test]
fn mat_gives_width_per_segment() {
    let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 4.), (x: 0., y: 4.)];
    let (pp, g) = ma(&p);
    let mat = medial_axis_transform(&g, None);
    assert_eq!(mat.len(), 5);
    for s in &mat {
        for (q, r) in [(s.line.start, s.r_start), (s.line.end, s.r_end)] {
            assert!((pp.boundary().distance(q) - r).abs() < 1e-8);
        }
        if s.line.start.y == 2.0 && s.line.end.y == 2.0 {
            assert!((s.mean_width() - 4.0).abs() < 1e-8);
        }
    }
    // After merging degree-2 chains, interior vertices get their radius from ∂P.
    let (pp, g) = ma(&l_shape());
    let merged = g.merged();
    for b in [None, Some(pp.boundary())] {
        let mat = medial_axis_transform(&merged, b);
        assert_eq!(mat.len(), pieces_of(&g));
        for s in &mat {
            let d = pp.boundary().distance(s.line.start);
            let allowed = if b.is_some() { 1e-8 } else { 0.1 };
            assert!((d - s.r_start).abs() < allowed, "{} vs {d}", s.r_start);
        }
    }
}

#[test]
fn same_input_same_output() {
    let (_, a) = ma(&l_shape());
    let (_, b) = ma(&l_shape());
    assert_eq!(a, b);
}

#[test]
fn invalid_tolerance_is_an_error_not_a_hang() {
    let pp = PreparedPolygon::new(&l_shape()).unwrap();
    for t in [
        ArcTolerance::Relative(0.0),
        ArcTolerance::Absolute(-1.0),
        ArcTolerance::Relative(f64::NAN),
    ] {
        let r = MedialAxis::new(t).skeletonise(&pp, &MethodContext::default());
        assert!(
            matches!(r, Err(MethodError::Failed { ref reason, .. }) if reason.contains("arc_tolerance")),
            "{r:?}"
        );
    }
}

#[test]
fn self_intersecting_boundary_is_rejected_with_a_reason() {
    let bow = polygon![(x: 0., y: 0.), (x: 4., y: 4.), (x: 4., y: 0.), (x: 0., y: 6.)];
    let pp = PreparedPolygon::new(&bow).unwrap();
    let r = MedialAxis::default().skeletonise(&pp, &MethodContext::default());
    assert!(
        matches!(r, Err(MethodError::Failed { ref reason, .. }) if reason.contains("intersects")),
        "{r:?}"
    );
}

#[test]
fn arc_tolerance_serde() {
    let t: ArcTolerance = serde_json::from_str(r#"{"relative": 0.05}"#).unwrap();
    assert_eq!(t, ArcTolerance::Relative(0.05));
    let t: ArcTolerance = serde_json::from_str(r#"{"absolute": 2.5}"#).unwrap();
    assert_eq!(t, ArcTolerance::Absolute(2.5));
    assert_eq!(ArcTolerance::default(), ArcTolerance::Relative(0.001));
}

#[cfg(feature = "gdal")]
#[test]
fn every_training_layer_runs_with_no_rejected_feature() {
    for layer in LAYERS {
        let feats = skeletonise::io::read_layer_polygons(TRAIN, layer).unwrap();
        assert!(!feats.is_empty());
        let mut checked = 0;
        for (fid, geom) in &feats {
            let parts = skeletonise::process::polygon_parts(Some(geom)).unwrap();
            for part in parts {
                let pp = PreparedPolygon::new(&part).unwrap();
                let g = MedialAxis::default()
                    .skeletonise(&pp, &MethodContext::default())
                    .unwrap_or_else(|e| panic!("{layer} fid {fid:?}: {e}"));
                assert!(!g.is_empty(), "{layer} fid {fid:?}: empty medial axis");
                assert_eq!(
                    g.components(),
                    1,
                    "{layer} fid {fid:?}: MA of a polygon is connected"
                );
                // Invariants on every feature of the small layers, a sample of the islands.
                if layer != "islands_hebrides" || checked % 25 == 0 {
                    check_invariants(&pp, &g);
                }
                checked += 1;
            }
        }
    }
}

mod random {
    use super::*;
    use geo::algorithm::Validation;
    use proptest::prelude::*;

    /// A star-shaped ring around (cx, cy), vertices rounded to `grid` (0 = no
    /// rounding): coarse grids make collinear runs, repeated and touching vertices.
    fn star(angles: &[f64], radii: &[f64], cx: f64, cy: f64, r: f64, grid: f64) -> LineString<f64> {
        let mut a = angles.to_vec();
        a.sort_by(f64::total_cmp);
        LineString::from(
            a.iter()
                .zip(radii)
                .map(|(t, k)| {
                    let (x, y) = (cx + r * k * t.cos(), cy + r * k * t.sin());
                    if grid > 0.0 {
                        ((x / grid).round() * grid, (y / grid).round() * grid)
                    } else {
                        (x, y)
                    }
                })
                .collect::<Vec<_>>(),
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        #[test]
        fn random_valid_polygons_satisfy_the_invariants(
            ext in (3usize..60).prop_flat_map(|n| (
                proptest::collection::vec(0.0..std::f64::consts::TAU, n),
                proptest::collection::vec(0.3..1.0f64, n))),
            hole in (3usize..12).prop_flat_map(|n| (
                proptest::collection::vec(0.0..std::f64::consts::TAU, n),
                proptest::collection::vec(0.3..1.0f64, n))),
            with_hole in any::<bool>(),
            grid in prop::sample::select(vec![0.0, 1.0, 0.25, 1e-3]),
            shift in prop::sample::select(vec![0.0, 5e5, 1e7]),
        ) {
            let exterior = star(&ext.0, &ext.1, shift, shift, 100.0, grid);
            let holes = if with_hole {
                vec![star(&hole.0, &hole.1, shift + 10.0, shift - 5.0, 8.0, grid)]
            } else {
                vec![]
            };
            let p = Polygon::new(exterior, holes);
            prop_assume!(p.is_valid());
            let Ok(pp) = PreparedPolygon::new(&p) else { return Ok(()) };
            let g = MedialAxis::default().skeletonise(&pp, &MethodContext::default()).unwrap();
            check_invariants(&pp, &g);
            prop_assert_eq!(g.components(), 1);
            let used = g.degrees().iter().filter(|&&d| d > 0).count();
            prop_assert_eq!(g.edges().len() + 1 - used, pp.polygon().interiors().len());
        }
    }
}
