//! `VD` and `DVD` — skeletons from the Voronoi diagram of boundary points
//! (SPEC §3; paper sections "Voronoi Diagram for a Set of Points" and
//! "Densified Voronoi Diagram", Fig. 2a–c).
//!
//! **Definition.** `VD` is the Voronoi diagram of all distinct vertices of ∂P
//! (every ring); the skeleton is its *finite* edges lying inside P that do not
//! cross ∂P. `DVD` is the same after inserting pseudo-nodes on every boundary
//! edge (`densify: {factor: k}` → k − 1 equally spaced points per edge,
//! `{spacing: d}` → no piece longer than d). As the density grows, DVD
//! converges to the medial axis.
//!
//! **Algorithm.** The Voronoi diagram is taken as the dual of spade's Delaunay
//! triangulation (bulk loaded, O(n log n)) of the sites, translated by the
//! polygon's bounding-box corner so that huge coordinates keep their
//! precision; duplicate sites (a vertex shared by two rings) become one site.
//! Voronoi vertices are the circumcentres of the inner triangles; a finite
//! Voronoi edge is the dual of a Delaunay edge between two inner triangles and
//! joins their circumcentres (edges of the convex hull give infinite rays,
//! which are never part of the skeleton). An edge is kept when both end points
//! lie in P — inside, or within 1e-9 × extent of ∂P — and the segment does not
//! properly cross ∂P. Edges that cross are *dropped, not clipped*, so the VD of
//! a sparse boundary may fall apart into several components (the paper's
//! Fig. 8b case); that is a valid result, never an error. One nearest-segment
//! query of the boundary's R-tree per Voronoi vertex tells both which side of
//! ∂P the vertex lies on and its distance to ∂P, the node radius.
//!
//! **Degenerate input.** Cocircular sites (a rectangle, any regular grid, every
//! densified straight edge facing another) make several triangles share one
//! circumcircle: the Delaunay triangulation is then not unique, but the
//! Voronoi diagram is — the extra Delaunay edges dual to zero-length Voronoi
//! edges. The circumcentres of those triangles are computed from different
//! triples and agree only up to rounding, so exact equality cannot merge them.
//! Instead every Voronoi edge not longer than the merge tolerance
//! (1e-9 × extent) is contracted: its two triangles are united (union–find)
//! and the class is represented by the circumcentre of its lowest-numbered
//! triangle. This is exact topology, not a grid snap (a grid puts two nearly
//! equal points into different cells when they straddle a cell border), and
//! every node keeps a position computed from real sites.
//!
//! ```
//! use geo::polygon;
//! use skeletonise::geometry::{densify::Density, PreparedPolygon};
//! use skeletonise::methods::{voronoi::Voronoi, MethodContext, SkeletonMethod};
//!
//! let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)];
//! let p = PreparedPolygon::new(&p).unwrap();
//! // Four cocircular corners: the Voronoi diagram is one point, no edge.
//! let no_limit = MethodContext::default();
//! assert!(Voronoi::plain().skeletonise(&p, &no_limit).unwrap().is_empty());
//! // Densified to pieces of at most 0.5: the centre line y = 1 (where the
//! // inscribed disc has the half width as radius) and short legs into the corners.
//! let g = Voronoi::densified(Density::Spacing(0.5), 1_000_000)
//!     .skeletonise(&p, &no_limit)
//!     .unwrap();
//! assert_eq!(g.components(), 1);
//! assert_eq!(g.leg_count(), 4);
//! let on_centre_line = g.nodes().iter().filter(|n| n.pos.y == 1.0 && n.radius == 1.0);
//! assert_eq!(on_centre_line.count(), 18);
//! ```

use super::{MethodContext, MethodError, MethodId, SkeletonMethod};
use crate::geometry::segment::orient;
use crate::geometry::tolerance::{BOUND_MARGIN, SAME_POINT};
use crate::geometry::vector::{hypot, norm, within_hypot};
use crate::geometry::{densify, densify::Density, PreparedPolygon};
use crate::graph::UnionFind;
use crate::graph::{GraphBuilder, SkeletonGraph};
use geo::{Coord, LineString};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use spade::{DelaunayTriangulation, InsertionError, Point2, Triangulation};

/// Densification of the boundary for DVD.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
pub enum DensifyParams {
    /// `k − 1` equally spaced pseudo-nodes on each boundary edge (paper: 2 and 4).
    Factor(u32),
    /// No piece longer than this many CRS units.
    Spacing(f64),
}

impl Default for DensifyParams {
    fn default() -> Self {
        DensifyParams::Factor(4)
    }
}

impl From<DensifyParams> for Density {
    fn from(d: DensifyParams) -> Self {
        match d {
            DensifyParams::Factor(k) => Self::Factor(k),
            DensifyParams::Spacing(s) => Self::Spacing(s),
        }
    }
}

fn default_max_points() -> usize {
    2_000_000
}

/// DVD's options in the `skeleton` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct VoronoiOptions {
    /// Boundary densification for DVD.
    #[serde(default)]
    pub densify: DensifyParams,
    /// Most points a densified polygon may have (DVD); more is an error for that feature.
    #[serde(default = "default_max_points")]
    pub max_points: usize,
}

impl Default for VoronoiOptions {
    fn default() -> Self {
        Self {
            densify: DensifyParams::default(),
            max_points: default_max_points(),
        }
    }
}

impl VoronoiOptions {
    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        match self.densify {
            DensifyParams::Factor(0) => Err((
                "densify.factor".into(),
                "factor must be at least 1 (the paper uses 2 and 4)".into(),
            )),
            DensifyParams::Spacing(d) if !(d > 0.0 && d.is_finite()) => Err((
                "densify.spacing".into(),
                "spacing must be a positive number of CRS units".into(),
            )),
            _ if self.max_points == 0 => {
                Err(("max_points".into(), "max_points must be at least 1".into()))
            }
            _ => Ok(()),
        }
    }
}

/// Voronoi skeleton of the (optionally densified) boundary vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Voronoi {
    density: Option<Density>,
    max_points: usize,
}

impl Voronoi {
    /// `VD`: the boundary vertices as they are.
    pub fn plain() -> Self {
        Self {
            density: None,
            max_points: usize::MAX,
        }
    }

    /// `DVD`: vertices plus pseudo-nodes, at most `max_points` in all.
    pub fn densified(density: Density, max_points: usize) -> Self {
        Self {
            density: Some(density),
            max_points,
        }
    }

    /// The sites of `polygon`'s Voronoi diagram, relative to
    /// `polygon.origin()`: every ring's vertices, densified for DVD.
    ///
    /// Fails with [`MethodError::TooManyPoints`] before allocating anything
    /// when the densified rings would have more than `max_points` points.
    pub fn sites(&self, polygon: &PreparedPolygon) -> Result<Vec<Coord<f64>>, MethodError> {
        let origin = polygon.origin();
        if let Some(density) = self.density {
            let points = densified_count(polygon.rings(), density, self.max_points);
            if points > self.max_points {
                return Err(MethodError::TooManyPoints {
                    points,
                    max: self.max_points,
                });
            }
        }
        let mut sites = Vec::new();
        for ring in polygon.rings() {
            // Translate first, then densify: pseudo-nodes are interpolated in
            // small, well-conditioned coordinates.
            let local = LineString(ring.0.iter().map(|&c| c - origin).collect());
            match self.density {
                None => sites.extend_from_slice(&local.0[..local.0.len() - 1]),
                Some(d) => sites.extend(densify::densify_ring(&local, d)),
            }
        }
        Ok(sites)
    }
}

/// Points all rings have after densifying, counted without overflow and
/// stopping as soon as the count exceeds `cap` (a tiny `spacing` on a long
/// boundary can ask for more points than `usize` holds). Equals the sum of
/// [`densify::densified_len`] over the rings when that is at most `cap`.
fn densified_count<'a>(
    rings: impl Iterator<Item = &'a LineString<f64>>,
    density: Density,
    cap: usize,
) -> usize {
    let mut total = 0usize;
    for ring in rings {
        for l in ring.lines() {
            let d = l.end - l.start;
            total = total.saturating_add(density.pieces(hypot(d)));
            if total > cap {
                return total;
            }
        }
    }
    total
}

impl SkeletonMethod for Voronoi {
    fn id(&self) -> MethodId {
        if self.density.is_some() {
            MethodId::DVD
        } else {
            MethodId::VD
        }
    }

    fn skeletonise(
        &self,
        polygon: &PreparedPolygon,
        _ctx: &MethodContext,
    ) -> Result<SkeletonGraph, MethodError> {
        let sites = self.sites(polygon)?;
        let tol = SAME_POINT * polygon.extent();
        let vd = VoronoiDiagram::new(&sites, tol).map_err(|e| MethodError::Failed {
            method: self.id(),
            reason: format!("the boundary points cannot be triangulated: {e:?}"),
        })?;
        let boundary = polygon.boundary();
        let origin = polygon.origin();
        let locator = Locator::new(polygon);
        let (lo, hi) = (boundary.bbox_min(), boundary.bbox_max());
        let pos: Vec<Coord<f64>> = vd.vertices.iter().map(|&v| v + origin).collect();
        // Distance to ∂P of every vertex in P (within tolerance), `None`
        // outside; beyond the (tolerance-grown) bounding box is a cheap "no"
        // for the many circumcentres outside the convex hull.
        let radius: Vec<Option<f64>> = pos
            .iter()
            .zip(&vd.site_distance)
            .map(|(&p, &to_site)| {
                let in_box = p.x >= lo.x - tol
                    && p.x <= hi.x + tol
                    && p.y >= lo.y - tol
                    && p.y <= hi.y + tol;
                if in_box {
                    locator.locate(p, to_site, tol)
                } else {
                    None
                }
            })
            .collect();
        // The radii are the distances just found, so `finish` need not query
        // the R-tree a second time for every node.
        let inside = radius.iter().filter(|r| r.is_some()).count();
        let mut b = GraphBuilder::with_capacity(inside, vd.edges.len());
        let mut radii = Vec::with_capacity(inside);
        // Each Voronoi vertex's node, looked up by position once (vertices
        // at the same position share a node, as the builder decides).
        let mut node_of: Vec<Option<crate::graph::NodeId>> = vec![None; pos.len()];
        for &[u, v] in &vd.edges {
            let (u, v) = (u as usize, v as usize);
            let (Some(ru), Some(rv)) = (radius[u], radius[v]) else {
                continue;
            };
            if boundary.crosses(pos[u], pos[v]) {
                continue;
            }
            for (k, r) in [(u, ru), (v, rv)] {
                if node_of[k].is_none() {
                    let n = b.node(pos[k]);
                    if n.index() == radii.len() {
                        radii.push(r);
                    }
                    node_of[k] = Some(n);
                }
            }
            if let (Some(a), Some(c)) = (node_of[u], node_of[v]) {
                b.segment_between(a, c);
            }
        }
        let mut g = b.finish_raw();
        for (n, r) in g.nodes_mut().iter_mut().zip(radii) {
            n.radius = r;
        }
        Ok(g)
    }
}

/// Point-in-polygon from the nearest-segment query that also gives the
/// distance to ∂P: cheaper than a ray cast across the R-tree, which on a long
/// river visits hundreds of segments.
///
/// The open disc around `p` whose radius is the distance to ∂P meets no
/// boundary point, so it lies wholly inside or wholly outside P, and when the
/// nearest boundary point is interior to a segment, the side of that
/// segment's line on which `p` lies tells which. When the nearest point is a
/// vertex, where another ring may touch (a hole at a vertex of the exterior),
/// the ray cast decides.
struct Locator<'a> {
    boundary: &'a crate::geometry::Boundary,
}

impl<'a> Locator<'a> {
    fn new(polygon: &'a PreparedPolygon) -> Self {
        Self {
            boundary: polygon.boundary(),
        }
    }

    /// The distance from `p` to ∂P when `p` lies inside P or within `tol`
    /// of ∂P, `None` when it lies outside. `to_site` is the distance from
    /// `p` to a site (a point of ∂P up to rounding): it bounds the search
    /// (the same answer, fewer nodes queued).
    fn locate(&self, p: Coord<f64>, to_site: f64, tol: f64) -> Option<f64> {
        let limit = to_site * (1.0 + BOUND_MARGIN) + tol;
        let (_, k, d) = self
            .boundary
            .nearest_within(p, limit)
            .or_else(|| self.boundary.nearest(p))?;
        let inside = d <= tol || {
            let s = self.boundary.segments()[k];
            match s.closest(p).1 {
                t if t > 0.0 && t < 1.0 => orient(s.a, s.b, p) > 0.0,
                _ => self.boundary.contains(p),
            }
        };
        inside.then_some(d)
    }
}

/// The finite part of the Voronoi diagram of a point set: its vertices and
/// the finite edges between them, with coincident vertices merged.
///
/// Invariant: every edge joins two distinct vertices (`u < v`), no edge
/// appears twice, and the order of both lists depends only on the input.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct VoronoiDiagram {
    /// Voronoi vertices (circumcentres of Delaunay triangles), in the sites'
    /// coordinates.
    pub vertices: Vec<Coord<f64>>,
    /// Finite Voronoi edges as pairs of indices into `vertices`.
    pub edges: Vec<[u32; 2]>,
    /// For every vertex, its distance to a corner of its Delaunay triangle
    /// (a site, the circumradius): the nearest site is no farther.
    pub site_distance: Vec<f64>,
}

impl VoronoiDiagram {
    /// The Voronoi diagram of `sites` (duplicates are one site). Voronoi
    /// vertices closer than `merge_tolerance` along a Voronoi edge are merged
    /// into one, so cocircular sites give one vertex and no zero-length edge.
    pub fn new(sites: &[Coord<f64>], merge_tolerance: f64) -> Result<Self, InsertionError> {
        let dt: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::bulk_load(
            sites.iter().map(|c| Point2::new(c.x, c.y)).collect(),
        )?;
        let n_faces = dt.num_all_faces();
        let mut centre = vec![Coord { x: 0.0, y: 0.0 }; n_faces];
        for f in dt.inner_faces() {
            centre[f.fix().index()] = circumcentre(f.positions());
        }
        // Dual edges between two inner faces; contract the (near) zero-length ones.
        let mut uf = UnionFind::new(n_faces);
        let mut dual = Vec::with_capacity(dt.num_undirected_edges());
        for e in dt.undirected_edges() {
            let d = e.as_directed();
            let (f, g) = (d.face(), d.rev().face());
            if f.is_outer() || g.is_outer() {
                continue;
            }
            let (f, g) = (f.fix().index(), g.fix().index());
            let (cf, cg) = (centre[f], centre[g]);
            if within_hypot(cf - cg, merge_tolerance) {
                uf.union(f, g);
            } else {
                dual.push((f, g));
            }
        }
        // One vertex per class, at its lowest face's circumcentre, numbered in
        // face order.
        let mut id = vec![u32::MAX; n_faces];
        let mut vertices = Vec::new();
        let mut corner = vec![Coord { x: 0.0, y: 0.0 }; n_faces];
        for f in dt.inner_faces() {
            let p = f.positions()[0];
            corner[f.fix().index()] = Coord { x: p.x, y: p.y };
        }
        let mut site_distance = Vec::new();
        for f in dt.inner_faces() {
            let f = f.fix().index();
            let r = uf.find(f);
            if id[r] == u32::MAX {
                id[r] = vertices.len() as u32;
                vertices.push(centre[r]);
                // A bound of the search for the nearest boundary point,
                // which never changes its answer: no need for `hypot`.
                site_distance.push(norm(centre[r] - corner[r]));
            }
            id[f] = id[r];
        }
        let mut edges: Vec<[u32; 2]> = dual
            .into_iter()
            .filter_map(|(f, g)| {
                let (a, b) = (id[f], id[g]);
                (a != b).then(|| [a.min(b), a.max(b)])
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        Ok(Self {
            vertices,
            edges,
            site_distance,
        })
    }
}

/// Circumcentre of a (non-degenerate) triangle, computed relative to its
/// first corner. The denominator is the robust orientation determinant, so
/// it is never zero for a triangle spade accepted as an inner face.
fn circumcentre([a, b, c]: [Point2<f64>; 3]) -> Coord<f64> {
    let (bx, by) = (b.x - a.x, b.y - a.y);
    let (cx, cy) = (c.x - a.x, c.y - a.y);
    let det = orient(
        Coord { x: a.x, y: a.y },
        Coord { x: b.x, y: b.y },
        Coord { x: c.x, y: c.y },
    );
    let d = 2.0 * det;
    let (lb, lc) = (bx * bx + by * by, cx * cx + cy * cy);
    Coord {
        x: a.x + (cy * lb - by * lc) / d,
        y: a.y + (bx * lc - cx * lb) / d,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::{polygon, Polygon};

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// A closed ring through `corners` with a vertex every `step` units.
    fn sampled(corners: &[(f64, f64)], step: f64) -> LineString<f64> {
        let mut out = Vec::new();
        for (i, &a) in corners.iter().enumerate() {
            let b = corners[(i + 1) % corners.len()];
            let n = ((b.0 - a.0).hypot(b.1 - a.1) / step).round() as usize;
            for k in 0..n {
                let t = k as f64 / n as f64;
                out.push(c(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
            }
        }
        LineString(out)
    }

    fn prepared(p: Polygon<f64>) -> PreparedPolygon {
        PreparedPolygon::new(&p).unwrap()
    }

    fn vd(p: &PreparedPolygon) -> SkeletonGraph {
        crate::methods::checked_skeleton(&Voronoi::plain(), p)
    }

    /// Every edge as its two end points, sorted, for comparison with a known answer.
    fn segments(g: &SkeletonGraph) -> Vec<[(f64, f64); 2]> {
        let mut v: Vec<_> = g
            .edges()
            .iter()
            .map(|e| {
                let (a, b) = (g.node(e.a).pos, g.node(e.b).pos);
                let (a, b) = ((a.x, a.y), (b.x, b.y));
                if a <= b {
                    [a, b]
                } else {
                    [b, a]
                }
            })
            .collect();
        v.sort_by(|x, y| x.partial_cmp(y).unwrap());
        v
    }

    /// Raw output invariants: the graph's, points in P, no crossing,
    /// radius = distance to ∂P.
    fn assert_valid(p: &PreparedPolygon, g: &SkeletonGraph) {
        g.check_invariants().unwrap();
        let tol = SAME_POINT * p.extent();
        for n in g.nodes() {
            assert!(
                p.boundary().contains_with_tolerance(n.pos, tol),
                "{:?}",
                n.pos
            );
            assert!((n.radius - p.boundary().distance(n.pos)).abs() <= tol);
        }
        for e in g.edges() {
            assert!(!p.boundary().crosses(g.node(e.a).pos, g.node(e.b).pos));
        }
    }

    #[test]
    fn cocircular_corners_give_one_vertex_and_no_edge() {
        // The two Delaunay triangles of a rectangle share their circumcentre.
        let sites = [c(0., 0.), c(10., 0.), c(10., 2.), c(0., 2.)];
        let d = VoronoiDiagram::new(&sites, 1e-8).unwrap();
        assert_eq!(d.vertices, vec![c(5., 1.)]);
        assert!(d.edges.is_empty());
        let p =
            prepared(polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)]);
        assert!(vd(&p).is_empty());
    }

    #[test]
    fn nearly_cocircular_vertices_merge_into_one_node() {
        // A regular 24-gon: its circumcentres agree only up to rounding, so
        // exact equality would leave a cluster of tiny edges at the centre.
        let ring: Vec<Coord<f64>> = (0..24)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 24.0;
                c(1000.0 + 7.0 * a.cos(), 2000.0 + 7.0 * a.sin())
            })
            .collect();
        let p = prepared(Polygon::new(LineString(ring), vec![]));
        assert!(vd(&p).is_empty());
        let g = Voronoi::densified(Density::Factor(3), usize::MAX)
            .skeletonise(&p, &MethodContext::default())
            .unwrap();
        assert_valid(&p, &g);
        let deg = g.degrees();
        let centre: Vec<_> = g
            .nodes()
            .iter()
            .enumerate()
            .filter(|(_, n)| {
                (n.pos - c(1000., 2000.))
                    .x
                    .hypot((n.pos - c(1000., 2000.)).y)
                    < 1e-6
            })
            .collect();
        assert_eq!(centre.len(), 1, "one node at the centre");
        assert_eq!(
            deg[centre[0].0], 24,
            "reached by the bisector of every edge"
        );
    }

    #[test]
    fn sampled_rectangle_gives_its_medial_axis() {
        let p = prepared(Polygon::new(
            sampled(&[(0., 0.), (10., 0.), (10., 2.), (0., 2.)], 1.0),
            vec![],
        ));
        let g = vd(&p);
        assert_valid(&p, &g);
        let mut want = vec![
            [(0.5, 0.5), (1.0, 1.0)],
            [(0.5, 1.5), (1.0, 1.0)],
            [(1.0, 1.0), (1.5, 1.0)],
            [(8.5, 1.0), (9.0, 1.0)],
            [(9.0, 1.0), (9.5, 0.5)],
            [(9.0, 1.0), (9.5, 1.5)],
        ];
        want.extend((1..8).map(|i| [(i as f64 + 0.5, 1.0), (i as f64 + 1.5, 1.0)]));
        want.sort_by(|x, y| x.partial_cmp(y).unwrap());
        assert_eq!(segments(&g), want);
        assert_eq!(g.components(), 1);
        let mid = g.nodes().iter().find(|n| n.pos == c(5.5, 1.0)).unwrap();
        assert_eq!(mid.radius, 1.0);
    }

    #[test]
    fn l_shape_gives_the_two_centre_lines() {
        let p = prepared(Polygon::new(
            sampled(
                &[(0., 0.), (4., 0.), (4., 1.), (1., 1.), (1., 4.), (0., 4.)],
                1.0,
            ),
            vec![],
        ));
        let g = vd(&p);
        assert_valid(&p, &g);
        let want = vec![
            [(0.5, 0.5), (0.5, 1.5)],
            [(0.5, 0.5), (1.5, 0.5)],
            [(0.5, 1.5), (0.5, 2.5)],
            [(0.5, 2.5), (0.5, 3.5)],
            [(1.5, 0.5), (2.5, 0.5)],
            [(2.5, 0.5), (3.5, 0.5)],
        ];
        assert_eq!(segments(&g), want);
    }

    #[test]
    fn hole_is_surrounded_by_one_cycle() {
        let p = prepared(Polygon::new(
            sampled(&[(0., 0.), (10., 0.), (10., 10.), (0., 10.)], 1.0),
            vec![sampled(&[(3., 3.), (3., 7.), (7., 7.), (7., 3.)], 1.0)],
        ));
        let g = vd(&p);
        assert_valid(&p, &g);
        assert_eq!(g.components(), 1);
        // Cyclomatic number 1: exactly one cycle, and it goes round the hole
        // along the lines half-way between hole and exterior.
        assert_eq!(g.edges().len() + g.components(), g.nodes().len() + 1);
        for x in [1.5, 8.5] {
            for y in 2..8 {
                let y = y as f64 + 0.5;
                assert!(g
                    .nodes()
                    .iter()
                    .any(|n| n.pos == c(x, y) || n.pos == c(y, x)));
            }
        }
        // Four legs to the outer corners.
        assert_eq!(g.leg_count(), 4);
    }

    /// A 20 × 10 block with a thin slot cut from the top. The slot's left wall
    /// has a vertex every unit, its right wall none, and the bottom edge none:
    /// the bisectors of the left-wall vertices run straight through the slot
    /// into the right half, so the diagram's edges cross ∂P with both ends
    /// inside (the paper's Fig. 8b).
    fn slotted() -> PreparedPolygon {
        let mut v = vec![c(0., 0.)];
        v.extend((0..10).map(|i| c(20., i as f64)));
        v.extend((11..=20).rev().map(|i| c(i as f64, 10.)));
        v.extend([c(10.1, 10.), c(10.1, 1.)]);
        v.extend((1..=10).map(|i| c(9.9, i as f64)));
        v.extend((0..10).rev().map(|i| c(i as f64, 10.)));
        v.extend((1..10).rev().map(|i| c(0., i as f64)));
        prepared(Polygon::new(LineString(v), vec![]))
    }

    #[test]
    fn crossing_edges_are_dropped_and_the_skeleton_may_fall_apart() {
        let p = slotted();
        let sites = Voronoi::plain().sites(&p).unwrap();
        let d = VoronoiDiagram::new(&sites, 1e-8).unwrap();
        let at = |i: u32| d.vertices[i as usize] + p.origin();
        let crossing = d
            .edges
            .iter()
            .filter(|&&[u, v]| {
                p.boundary().contains(at(u))
                    && p.boundary().contains(at(v))
                    && p.boundary().crosses(at(u), at(v))
            })
            .count();
        assert!(crossing > 0, "the example must exercise the crossing test");
        let g = vd(&p);
        assert_valid(&p, &g);
        assert!(g.components() >= 2, "{} components", g.components());
    }

    #[test]
    fn nearest_segment_locator_agrees_with_ray_casting() {
        // Convex and reflex corners, a hole, and points on a fine grid whose
        // nearest boundary point is often a vertex.
        let p = prepared(polygon!(
            exterior: [(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 1.), (x: 1., y: 1.), (x: 1., y: 4.), (x: 0., y: 4.)],
            interiors: [[(x: 0.25, y: 0.25), (x: 0.25, y: 0.75), (x: 0.75, y: 0.75), (x: 0.75, y: 0.25)]],
        ));
        let loc = Locator::new(&p);
        let tol = SAME_POINT * p.extent();
        let mut inside = 0;
        for i in -10..=90 {
            for j in -10..=90 {
                let q = c(i as f64 * 0.05 + 0.013, j as f64 * 0.05 + 0.007);
                let want = p.boundary().contains_with_tolerance(q, tol);
                assert_eq!(loc.locate(q, f64::INFINITY, tol).is_some(), want, "{q:?}");
                inside += usize::from(want);
            }
        }
        assert!(inside > 500);
    }

    #[test]
    fn huge_coordinates_keep_their_precision() {
        let (dx, dy) = (512_345.0, 6_123_456.0);
        let shifted = |l: LineString<f64>| LineString(l.0.iter().map(|&q| q + c(dx, dy)).collect());
        let base = sampled(&[(0., 0.), (10., 0.), (10., 2.), (0., 2.)], 1.0);
        let g0 = vd(&prepared(Polygon::new(base.clone(), vec![])));
        let g1 = vd(&prepared(Polygon::new(shifted(base), vec![])));
        assert_eq!(g0.nodes().len(), g1.nodes().len());
        for (a, b) in g0.nodes().iter().zip(g1.nodes()) {
            assert!((b.pos - a.pos - c(dx, dy)).x.abs() < 1e-9);
            assert!((b.pos - a.pos - c(dx, dy)).y.abs() < 1e-9);
        }
    }

    #[test]
    fn a_vertex_shared_by_two_rings_is_one_site() {
        // The hole touches the exterior at (0, 5).
        let p = prepared(polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.), (x: 0., y: 5.)],
            interiors: [[(x: 0., y: 5.), (x: 4., y: 4.), (x: 4., y: 6.)]],
        ));
        let sites = Voronoi::plain().sites(&p).unwrap();
        assert_eq!(sites.len(), 8);
        let mut distinct = sites.clone();
        distinct.sort_by(|a, b| (a.x, a.y).partial_cmp(&(b.x, b.y)).unwrap());
        distinct.dedup();
        assert_eq!(distinct.len(), 7);
        assert_eq!(
            VoronoiDiagram::new(&sites, 1e-8).unwrap().edges.len(),
            VoronoiDiagram::new(&distinct, 1e-8).unwrap().edges.len()
        );
        let g = Voronoi::densified(Density::Factor(8), usize::MAX)
            .skeletonise(&p, &MethodContext::default())
            .unwrap();
        assert_valid(&p, &g);
        assert!(!g.is_empty());
    }

    #[test]
    fn densified_point_count_is_checked_before_densifying() {
        let p = prepared(polygon![(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 1.), (x: 0., y: 1.)]);
        let ok = Voronoi::densified(Density::Factor(4), 16)
            .sites(&p)
            .unwrap();
        assert_eq!(ok.len(), 16);
        assert_eq!(
            Voronoi::densified(Density::Factor(4), 15).skeletonise(&p, &MethodContext::default()),
            Err(MethodError::TooManyPoints {
                points: 16,
                max: 15
            })
        );
        // A spacing so small that the count would overflow `usize`.
        let e = Voronoi::densified(Density::Spacing(1e-300), 2_000_000)
            .skeletonise(&p, &MethodContext::default())
            .unwrap_err();
        assert!(
            matches!(e, MethodError::TooManyPoints { points, max: 2_000_000 } if points > 2_000_000),
            "{e:?}"
        );
        assert!(e.to_string().contains("densify.spacing"));
    }

    #[test]
    fn counting_agrees_with_densified_len() {
        let p = prepared(Polygon::new(
            sampled(&[(0., 0.), (7., 0.), (7., 3.), (0., 3.)], 1.3),
            vec![sampled(&[(1., 1.), (1., 2.), (2., 2.)], 0.4)],
        ));
        for d in [Density::Factor(3), Density::Spacing(0.25)] {
            let want: usize = p.rings().map(|r| densify::densified_len(r, d)).sum();
            assert_eq!(densified_count(p.rings(), d, usize::MAX), want);
            assert_eq!(
                Voronoi::densified(d, usize::MAX).sites(&p).unwrap().len(),
                want
            );
        }
    }
}
