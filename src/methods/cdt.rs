//! `CDT` — skeleton from the constrained Delaunay triangulation (SPEC §3,
//! paper Fig. 3, De Lucia & Black 1987).
//!
//! The boundary ∂P (every ring) is triangulated with spade's constrained
//! Delaunay triangulation; only triangles inside P are kept (found by flood
//! fill from the outer face, flipping inside/outside at every constraint
//! edge, so holes are excluded). Each triangle adds skeleton segments by the
//! number of its edges on ∂P:
//!
//! * 2 → from the midpoint of the inner edge to the opposite vertex;
//! * 1 → joining the midpoints of the two inner edges;
//! * 0 → from the centroid to the midpoints of all three edges;
//! * 3 (P is a triangle) → from the centroid to the three vertices.
//!
//! Coordinates are triangulated relative to the polygon's bounding-box corner
//! so that huge coordinates keep full precision; shared midpoints are computed
//! from the same two vertices in both triangles and so coincide exactly.
//!
//! ```
//! use skeletonise::geometry::PreparedPolygon;
//! use skeletonise::methods::{cdt::Cdt, MethodContext, SkeletonMethod};
//! use geo::polygon;
//! let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)];
//! let p = PreparedPolygon::new(&p).unwrap();
//! let g = Cdt.skeletonise(&p, &MethodContext::default()).unwrap();
//! assert!(g.edges().len() >= 2);
//! ```

use super::{MethodContext, MethodError, MethodId, SkeletonMethod};
use crate::geometry::vector::dot;
use crate::geometry::PreparedPolygon;
use crate::graph::{GraphBuilder, SkeletonGraph};
use geo::Coord;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::VecDeque;

/// The constrained-Delaunay skeleton method.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Cdt;

fn fail(reason: impl Into<String>) -> MethodError {
    MethodError::Failed {
        method: MethodId::CDT,
        reason: reason.into(),
    }
}

/// A triangle of the CDT that lies inside P: its corners and, per edge
/// `i` (from corner `i` to corner `i+1`), whether the edge lies on ∂P.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InsideTriangle {
    /// Corners (counter-clockwise), in polygon coordinates.
    pub corners: [Coord<f64>; 3],
    /// `on_boundary[i]`: the edge `corners[i]` → `corners[(i + 1) % 3]` lies on ∂P.
    pub on_boundary: [bool; 3],
}

/// The triangles of the constrained Delaunay triangulation of ∂P that lie
/// inside P (holes excluded).
pub(crate) fn inside_triangles(
    polygon: &PreparedPolygon,
) -> Result<Vec<InsideTriangle>, MethodError> {
    let origin = polygon.origin();
    // Bulk loading is several times faster than inserting vertex by vertex;
    // duplicate vertices (rings touching at a point) are merged by spade.
    let mut vertices = Vec::with_capacity(polygon.vertex_count());
    let mut edges = Vec::with_capacity(polygon.vertex_count());
    for ring in polygon.rings() {
        let pts = &ring.0[..ring.0.len() - 1];
        let first = vertices.len();
        for p in pts {
            vertices.push(Point2::new(p.x - origin.x, p.y - origin.y));
        }
        for i in 0..pts.len() {
            edges.push([first + i, first + (i + 1) % pts.len()]);
        }
    }
    let mut conflict: Option<[usize; 2]> = None;
    let cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::try_bulk_load_cdt(vertices, edges, |e| {
            conflict.get_or_insert(e);
        })
        .map_err(|e| fail(format!("the boundary cannot be triangulated: {e:?}")))?;
    if let Some([a, _]) = conflict {
        let p = cdt
            .vertices()
            .nth(a)
            .map(|v| v.position())
            .map(|p| (p.x + origin.x, p.y + origin.y))
            .unwrap_or((origin.x, origin.y));
        return Err(fail(format!(
            "the boundary intersects itself near ({}, {}); enable `prepare: {{ make_valid: true }}`",
            p.0, p.1
        )));
    }
    let depth = crossing_depths(&cdt);
    let mut out = Vec::new();
    for face in cdt.inner_faces() {
        if depth[face.fix().index()].unwrap_or(0).is_multiple_of(2) {
            continue;
        }
        let edges = face.adjacent_edges();
        let mut corners = [Coord { x: 0.0, y: 0.0 }; 3];
        let mut on_boundary = [false; 3];
        for (i, e) in edges.iter().enumerate() {
            let p = e.from().position();
            corners[i] = Coord {
                x: p.x + origin.x,
                y: p.y + origin.y,
            };
            on_boundary[i] = cdt.is_constraint_edge(e.as_undirected().fix());
        }
        out.push(InsideTriangle {
            corners,
            on_boundary,
        });
    }
    Ok(out)
}

/// Flood fill from the outer face: per face, the number of constraint edges
/// (boundary edges) crossed to reach it — odd inside P.
fn crossing_depths(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<Option<u32>> {
    let mut depth: Vec<Option<u32>> = vec![None; cdt.num_all_faces()];
    let outer = cdt.outer_face();
    depth[outer.fix().index()] = Some(0);
    let mut queue = VecDeque::from([outer.fix()]);
    while let Some(f) = queue.pop_front() {
        let d = depth[f.index()].unwrap_or(0);
        let face = cdt.face(f);
        // Directed edges whose face is `f`: their reverse's face is a neighbour.
        let edges: Vec<_> = match face.as_inner() {
            Some(inner) => inner.adjacent_edges().to_vec(),
            None => cdt
                .convex_hull()
                .map(|e| if e.face().fix() == f { e } else { e.rev() })
                .collect(),
        };
        for e in edges {
            let nb = e.rev().face().fix();
            if depth[nb.index()].is_none() {
                let crosses = cdt.is_constraint_edge(e.as_undirected().fix());
                depth[nb.index()] = Some(d + u32::from(crosses));
                queue.push_back(nb);
            }
        }
    }
    depth
}

fn mid(a: Coord<f64>, b: Coord<f64>) -> Coord<f64> {
    // Symmetric in a and b so both triangles sharing an edge agree bit for bit.
    Coord {
        x: (a.x + b.x) * 0.5,
        y: (a.y + b.y) * 0.5,
    }
}

fn centroid(c: &[Coord<f64>; 3]) -> Coord<f64> {
    Coord {
        x: (c[0].x + c[1].x + c[2].x) / 3.0,
        y: (c[0].y + c[1].y + c[2].y) / 3.0,
    }
}

impl SkeletonMethod for Cdt {
    fn id(&self) -> MethodId {
        MethodId::CDT
    }

    fn skeletonise(
        &self,
        polygon: &PreparedPolygon,
        _ctx: &MethodContext,
    ) -> Result<SkeletonGraph, MethodError> {
        let triangles = inside_triangles(polygon)?;
        let mut b = Nodes::default();
        for t in &triangles {
            let c = t.corners;
            let m = |i: usize| mid(c[i], c[(i + 1) % 3]);
            // The triangle's edges inside P (not on ∂P), in order.
            let mut inner = [0usize; 3];
            let mut count = 0;
            for i in (0..3).filter(|&i| !t.on_boundary[i]) {
                inner[count] = i;
                count += 1;
            }
            match count {
                1 => {
                    // Opposite vertex of inner edge i is corner i+2.
                    let i = inner[0];
                    b.segment(m(i), c[(i + 2) % 3], &c);
                }
                2 => {
                    b.segment(m(inner[0]), m(inner[1]), &c);
                }
                3 => {
                    let g = centroid(&c);
                    for i in 0..3 {
                        b.segment(g, m(i), &c);
                    }
                }
                _ => {
                    let g = centroid(&c);
                    for corner in c {
                        b.segment(g, corner, &c);
                    }
                }
            }
        }
        Ok(b.finish(polygon.boundary()))
    }
}

/// The graph being built, with an upper bound of every node's distance to
/// ∂P: its distance to the nearest corner of a triangle it lies in (the
/// corners are vertices of ∂P). The bound keeps each radius search short
/// and never changes the radius.
#[derive(Default)]
struct Nodes {
    graph: GraphBuilder,
    bound: Vec<f64>,
}

impl Nodes {
    fn segment(&mut self, p: Coord<f64>, q: Coord<f64>, corners: &[Coord<f64>; 3]) {
        for x in [p, q] {
            let id = self.graph.node(x).index();
            if self.bound.len() <= id {
                self.bound.resize(id + 1, f64::INFINITY);
            }
            let d2 = corners
                .iter()
                .map(|&c| {
                    let d = x - c;
                    dot(d, d)
                })
                .fold(f64::INFINITY, f64::min);
            self.bound[id] = self.bound[id].min(d2.sqrt());
        }
        self.graph.segment(p, q);
    }

    fn finish(self, boundary: &crate::geometry::Boundary) -> SkeletonGraph {
        let mut g = self.graph.finish_raw();
        for (n, &bound) in g.nodes_mut().iter_mut().zip(&self.bound) {
            n.radius = boundary.distance_within(n.pos, bound);
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    fn run(p: geo::Polygon<f64>) -> SkeletonGraph {
        crate::methods::checked_skeleton(&Cdt, &PreparedPolygon::new(&p).unwrap())
    }

    #[test]
    fn rectangle_gives_a_connected_path_inside() {
        let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)];
        let g = run(p.clone());
        assert_eq!(g.components(), 1);
        let pp = PreparedPolygon::new(&p).unwrap();
        for n in g.nodes() {
            assert!(pp.boundary().contains_with_tolerance(n.pos, 1e-9));
            assert!((n.radius - pp.boundary().distance(n.pos)).abs() < 1e-12);
        }
    }

    #[test]
    fn hole_is_excluded_and_skeleton_surrounds_it() {
        let p = polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)],
            interiors: [[(x: 3., y: 3.), (x: 7., y: 3.), (x: 7., y: 7.), (x: 3., y: 7.)]],
        );
        let g = run(p.clone());
        let pp = PreparedPolygon::new(&p).unwrap();
        for n in g.nodes() {
            assert!(
                pp.boundary().contains_with_tolerance(n.pos, 1e-9),
                "{:?}",
                n.pos
            );
        }
        for e in g.edges() {
            assert!(!pp.boundary().crosses(g.node(e.a).pos, g.node(e.b).pos));
        }
        // The skeleton goes round the hole: it has a cycle.
        assert!(g.edges().len() >= g.nodes().len());
    }

    #[test]
    fn triangle_polygon_joins_centroid_to_corners() {
        let g = run(polygon![(x: 0., y: 0.), (x: 4., y: 0.), (x: 0., y: 3.)]);
        assert_eq!(g.edges().len(), 3);
        assert_eq!(g.components(), 1);
    }

    #[test]
    fn self_intersecting_boundary_is_an_error_not_a_panic() {
        let p = polygon![(x: 0., y: 0.), (x: 4., y: 4.), (x: 4., y: 0.), (x: 0., y: 6.)];
        let r = Cdt.skeletonise(
            &PreparedPolygon::new(&p).unwrap(),
            &MethodContext::default(),
        );
        assert!(r.is_err());
    }
}
