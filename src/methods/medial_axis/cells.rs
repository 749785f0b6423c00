//! The cells of the segment Voronoi diagram of ∂P inside P: every edge of
//! the diagram that lies in P — the medial axis, the edges MA leaves out
//! (between a segment and its own endpoint, the normal at a straight-angle
//! vertex) — with the two sites whose cells it separates. Each point of P
//! lies in the cell of the boundary site nearest to it, so the union of the
//! cells of the sites owned by one neighbour is the part of P nearest to
//! that neighbour's bank: the `partition` step is made of these edges.

use super::{fail, fpt, quantised, ArcTolerance, Extractor, Site as GridSite};
use crate::geometry::PreparedPolygon;
use crate::methods::MethodError;
use geo::Coord;

/// A site of the diagram: a boundary segment or a boundary vertex, in the
/// input's coordinates (its vertices bit for bit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CellSite {
    /// The segment from `.0` to `.1` (P on its left).
    Segment(Coord<f64>, Coord<f64>),
    /// A vertex (its cell lies in P when it is a reflex vertex).
    Vertex(Coord<f64>),
}

/// One edge of the diagram inside P.
#[derive(Debug, Clone, PartialEq)]
pub struct CellEdge {
    /// The sites whose cells it separates: `[left, right]` walking `line`
    /// from its first point to its last.
    pub sites: [CellSite; 2],
    /// The edge (a parabolic one as a polyline within the tolerance); its
    /// end points are shared exactly with the edges that meet there.
    pub line: Vec<Coord<f64>>,
}

/// The cells of a polygon's diagram as a method made them beside its
/// skeleton ([`crate::methods::SkeletonMethod::skeletonise_with_cells`]),
/// and the thread CPU time they took: the step that reads them counts it
/// as its own.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagramCells {
    /// Every inside edge with its sites (see [`cell_edges`]).
    pub edges: Vec<CellEdge>,
    /// The time making them took.
    pub time: std::time::Duration,
}

/// Every edge of the segment Voronoi diagram of `polygon`'s boundary that
/// lies inside it (arcs within `tolerance`).
pub fn cell_edges(
    polygon: &PreparedPolygon,
    tolerance: ArcTolerance,
) -> Result<Vec<CellEdge>, MethodError> {
    tolerance.validate().map_err(fail)?;
    let Some((grid, segs, diagram)) = quantised(polygon)? else {
        return Ok(Vec::new());
    };
    Extractor::new(&diagram, &segs, &grid, tolerance).cell_edges()
}

/// The input vertex each grid point was rounded from (the first segment
/// that starts there gives it).
type Vertices = rustc_hash::FxHashMap<super::Pt, Coord<f64>>;

impl Extractor<'_> {
    /// The site in world coordinates: a vertex site the input vertex it was
    /// rounded from.
    fn world_site(&self, vertices: &Vertices, s: GridSite) -> CellSite {
        match s {
            GridSite::Segment(i) => CellSite::Segment(self.segs[i].wa, self.segs[i].wb),
            GridSite::Point(p) => CellSite::Vertex(
                vertices
                    .get(&p)
                    .copied()
                    .unwrap_or_else(|| self.grid.world(p[0] as f64, p[1] as f64)),
            ),
        }
    }

    /// Every inside edge with its sites (see [`cell_edges`]).
    pub(super) fn cell_edges(mut self) -> Result<Vec<CellEdge>, MethodError> {
        let mut vertices = Vertices::default();
        for s in self.segs {
            vertices.entry(s.a).or_insert(s.wa);
        }
        let kept = self.inside_edges(true)?;
        let mut rep = self.representatives(&kept);
        let mut out = Vec::with_capacity(kept.len());
        for k in &kept {
            let (r0, r1) = (
                super::find(&mut rep, k.v0.usize()),
                super::find(&mut rep, k.v1.usize()),
            );
            if r0 == r1 {
                continue;
            }
            let (s0, s1) = self.sites(k);
            let (w0, _) = self.position(r0, s0);
            let (w1, _) = self.position(r1, s0);
            if let Some(line) = self.through_vertex(&vertices, s0, s1, r0, r1, w0, w1) {
                out.push(CellEdge {
                    sites: [
                        self.world_site(&vertices, s0),
                        self.world_site(&vertices, s1),
                    ],
                    line,
                });
                continue;
            }
            let mut line = vec![w0];
            if k.curved {
                let (p0, p1) = (self.vertex_at(r0), self.vertex_at(r1));
                line.extend(self.arc_points(p0, p1, s0, s1));
            }
            line.push(w1);
            out.push(CellEdge {
                sites: [
                    self.world_site(&vertices, s0),
                    self.world_site(&vertices, s1),
                ],
                line,
            });
        }
        out.extend(self.normals_through_vertices(&mut rep, &vertices));
        Ok(out)
    }

    /// A secondary edge (between a segment and its own end point) that
    /// runs through that point — the normal at a straight-angle vertex,
    /// between Voronoi vertices on both sides of ∂P — cut there: its part
    /// on P's side, from or to the vertex (the same direction). `None` for
    /// any other edge.
    #[allow(clippy::too_many_arguments)]
    fn through_vertex(
        &self,
        vertices: &Vertices,
        s0: GridSite,
        s1: GridSite,
        r0: usize,
        r1: usize,
        w0: Coord<f64>,
        w1: Coord<f64>,
    ) -> Option<Vec<Coord<f64>>> {
        let (q, seg) = match (s0, s1) {
            (GridSite::Point(q), GridSite::Segment(s))
            | (GridSite::Segment(s), GridSite::Point(q)) => (q, s),
            _ => return None,
        };
        let sg = &self.segs[seg];
        if sg.a != q && sg.b != q {
            return None;
        }
        // A secondary edge is the normal to the segment at q: it crosses ∂P
        // (at q) when its ends lie on both sides of the segment's line.
        let (p0, p1) = (self.vertex_at(r0), self.vertex_at(r1));
        if super::side(sg, p0) * super::side(sg, p1) >= 0.0 {
            return None;
        }
        let CellSite::Vertex(wq) = self.world_site(vertices, GridSite::Point(q)) else {
            return None;
        };
        Some(if super::side(sg, p1) > 0.0 {
            vec![wq, w1]
        } else {
            vec![w0, wq]
        })
    }

    /// The secondary edges that pass through their vertex site (the normal
    /// at a straight-angle vertex, where the vertex's own cell has no area):
    /// the diagram holds them as rays from infinity through the vertex to a
    /// Voronoi vertex; their part in P runs from the vertex to that Voronoi
    /// vertex.
    fn normals_through_vertices(&self, rep: &mut [usize], vertices: &Vertices) -> Vec<CellEdge> {
        let d = self.diagram;
        let edges = d.edges();
        let mut out = Vec::new();
        for e in edges.iter() {
            let Ok(twin) = e.twin() else { continue };
            let t = &edges[twin.usize()];
            // One half-edge of each pair: the one that starts at infinity.
            let (None, Some(v)) = (e.vertex0(), t.vertex0()) else {
                continue;
            };
            if e.is_primary() {
                continue;
            }
            let (Ok(c0), Ok(c1)) = (e.cell(), t.cell()) else {
                continue;
            };
            let (s0, s1) = (
                self.site(&d.cells()[c0.usize()]),
                self.site(&d.cells()[c1.usize()]),
            );
            let (q, seg) = match (s0, s1) {
                (GridSite::Point(q), GridSite::Segment(s))
                | (GridSite::Segment(s), GridSite::Point(q)) => (q, s),
                _ => continue,
            };
            let pv = self.vertex(v);
            let mid = [0.5 * (pv[0] + q[0] as f64), 0.5 * (pv[1] + q[1] as f64)];
            if fpt(q) == pv || super::side(&self.segs[seg], mid) <= 0.0 {
                continue;
            }
            let r = super::find(rep, v.usize());
            let (w, _) = self.position(r, s0);
            let CellSite::Vertex(wq) = self.world_site(vertices, GridSite::Point(q)) else {
                continue;
            };
            out.push(CellEdge {
                sites: [self.world_site(vertices, s0), self.world_site(vertices, s1)],
                line: vec![wq, w],
            });
        }
        out
    }

    /// The inner points of a parabolic edge from `p0` to `p1` (grid
    /// coordinates) between a point and a segment site, in world
    /// coordinates.
    fn arc_points(
        &self,
        p0: [f64; 2],
        p1: [f64; 2],
        s0: GridSite,
        s1: GridSite,
    ) -> Vec<Coord<f64>> {
        let (point, seg) = match (s0, s1) {
            (GridSite::Point(p), GridSite::Segment(s))
            | (GridSite::Segment(s), GridSite::Point(p)) => (p, s),
            _ => return Vec::new(),
        };
        let s = self.segs[seg];
        let Some(par) = super::arc::Parabola::new(fpt(point), fpt(s.a), fpt(s.b)) else {
            return Vec::new();
        };
        let (grid, tol) = (*self.grid, self.tolerance);
        par.samples(par.abscissa(p0), par.abscissa(p1), |r| tol.at(r, &grid))
            .into_iter()
            .map(|smp| grid.world(smp.x, smp.y))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    #[test]
    fn a_rectangles_cells_meet_on_its_medial_axis_and_its_corner_bisectors() {
        let r = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 4.), (x: 0., y: 4.)];
        let p = PreparedPolygon::new(&r).unwrap();
        let edges = cell_edges(&p, ArcTolerance::default()).unwrap();
        // The medial axis (5 edges): no reflex vertex, no straight angle.
        assert_eq!(edges.len(), 5, "{edges:#?}");
        // The centre line separates the bottom from the top side, the
        // bottom (P on its left, walking east) on the right of a line
        // walked east, or on its left walked west.
        let centre = edges
            .iter()
            .find(|e| e.line.iter().all(|c| (c.y - 2.0).abs() < 1e-9))
            .expect("the centre line");
        let bottom = CellSite::Segment(Coord { x: 0., y: 0. }, Coord { x: 10., y: 0. });
        let east = centre.line[centre.line.len() - 1].x > centre.line[0].x;
        assert_eq!(centre.sites[usize::from(east)], bottom, "{centre:?}");
    }

    #[test]
    fn a_straight_angle_vertex_and_a_reflex_vertex_bound_cells() {
        // An L with a vertex in the middle of its bottom side.
        let l = polygon![
            (x: 0., y: 0.), (x: 20., y: 0.), (x: 40., y: 0.), (x: 40., y: 6.), (x: 6., y: 6.),
            (x: 6., y: 30.), (x: 0., y: 30.)
        ];
        let p = PreparedPolygon::new(&l).unwrap();
        let edges = cell_edges(&p, ArcTolerance::default()).unwrap();
        let normal_at_20 = edges.iter().any(|e| {
            e.line.contains(&Coord { x: 20., y: 0. })
                && e.line.iter().all(|c| (c.x - 20.0).abs() < 1e-6)
        });
        assert!(
            normal_at_20,
            "the normal at the straight-angle vertex bounds two cells"
        );
        let reflex = Coord { x: 6., y: 6. };
        let at_reflex = edges
            .iter()
            .filter(|e| e.sites.contains(&CellSite::Vertex(reflex)))
            .count();
        assert!(
            at_reflex >= 3,
            "the reflex vertex's cell: its two normals and the arc"
        );
    }
}
