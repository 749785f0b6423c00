//! Planarity of a finished skeleton: pieces never cross without a node.
//!
//! Every method's raw skeleton is planar, but the segments added afterwards
//! (end segments, bridges across necks, straight rays) can cross a line of
//! the skeleton. [`crossings`] finds every proper crossing of two segments
//! (a packed R-tree over the segments' boxes, O(n log n) on real data), and
//! `node_crossings` splits both edges there, so the written skeleton is a
//! planar graph: two lines meet only at a node.

use super::{Edge, SkeletonGraph};
use crate::geometry::packed::{Bbox, PackedTree};
use crate::geometry::segment::{crossing_point, properly_cross};
use crate::geometry::vector::dot;
use crate::geometry::Boundary;
use geo::Coord;
use std::ops::ControlFlow;

/// One segment of an edge's polyline: edge index, segment index, ends.
#[derive(Debug, Clone, Copy)]
struct Seg {
    edge: usize,
    index: usize,
    a: Coord<f64>,
    b: Coord<f64>,
}

fn segments(g: &SkeletonGraph) -> Vec<Seg> {
    let mut out = Vec::with_capacity(g.edges().len());
    for (i, e) in g.edges().iter().enumerate() {
        // The polyline node a, interior…, node b, without collecting it.
        let mut a = g.node(e.a).pos;
        let rest = e.interior.iter().copied().chain([g.node(e.b).pos]);
        for (k, b) in rest.enumerate() {
            if a != b {
                out.push(Seg {
                    edge: i,
                    index: k,
                    a,
                    b,
                });
            }
            a = b;
        }
    }
    out
}

/// Every proper crossing of two segments of `g`: (segment i, segment j,
/// point), i < j, as indices into the segments in edge order.
fn find(segs: &[Seg]) -> Vec<(usize, usize, Coord<f64>)> {
    let boxes: Vec<Bbox> = segs
        .iter()
        .map(|s| {
            [
                s.a.x.min(s.b.x),
                s.a.y.min(s.b.y),
                s.a.x.max(s.b.x),
                s.a.y.max(s.b.y),
            ]
        })
        .collect();
    let mut out = Vec::new();
    PackedTree::pairs_of(&boxes, |i, j| {
        let (s, t) = (&segs[i as usize], &segs[j as usize]);
        if properly_cross(s.a, s.b, t.a, t.b) {
            out.push((i as usize, j as usize, crossing_point(s.a, s.b, t.a, t.b)));
        }
        ControlFlow::<()>::Continue(())
    });
    out.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.cmp(&y.1)));
    out
}

/// Number of proper crossings between segments of `g` (0 for a planar
/// skeleton).
pub fn crossings(g: &SkeletonGraph) -> usize {
    find(&segments(g)).len()
}

/// `g` with a node at every proper crossing (both edges split there; the new
/// node's radius is its distance to ∂P). Returns the graph and the number of
/// crossings noded.
pub(crate) fn node_crossings(g: SkeletonGraph, boundary: &Boundary) -> (SkeletonGraph, usize) {
    let segs = segments(&g);
    let found = find(&segs);
    if found.is_empty() {
        return (g, 0);
    }
    // Crossing points per (edge, segment), with their parameter along it.
    let mut cuts: std::collections::BTreeMap<(usize, usize), Vec<(f64, usize)>> =
        Default::default();
    let mut out = SkeletonGraph::new();
    for n in g.nodes() {
        out.add_node(n.pos, n.radius, n.time);
    }
    let mut cut_nodes = Vec::with_capacity(found.len());
    for &(i, j, p) in &found {
        let id = out.add_node(p, boundary.distance(p), None);
        cut_nodes.push(id);
        for s in [&segs[i], &segs[j]] {
            let d = s.b - s.a;
            let t = dot(p - s.a, d) / dot(d, d);
            cuts.entry((s.edge, s.index))
                .or_default()
                .push((t, cut_nodes.len() - 1));
        }
    }
    for (ei, e) in g.edges().iter().enumerate() {
        let coords = g.edge_coords(super::EdgeId::from_index(ei));
        let mut from = e.a;
        let mut interior: Vec<Coord<f64>> = Vec::new();
        // Walk the polyline segment by segment; the k-th segment runs from
        // coords[k] to coords[k + 1] (degenerate ones were skipped above but
        // keep their index here).
        for (k, &c) in coords.iter().enumerate().take(coords.len() - 1) {
            if k > 0 {
                interior.push(c);
            }
            if let Some(list) = cuts.get_mut(&(ei, k)) {
                list.sort_by(|a, b| a.0.total_cmp(&b.0));
                for &(_, c) in list.iter() {
                    let to = cut_nodes[c];
                    out.add_edge(from, to, std::mem::take(&mut interior));
                    from = to;
                }
            }
        }
        out.add_edge(from, e.b, interior);
    }
    (drop_empty(out), found.len())
}

/// Removes zero-length edges (a crossing computed exactly at a segment's
/// end would leave one).
fn drop_empty(g: SkeletonGraph) -> SkeletonGraph {
    g.filter_edges(|_, e: &Edge| {
        !(e.interior.is_empty() && e.a != e.b && g.node(e.a).pos == g.node(e.b).pos)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PreparedPolygon;
    use crate::graph::NodeId;
    use geo::polygon;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn a_crossing_is_found_and_noded_and_touches_are_not_crossings() {
        let p = PreparedPolygon::new(&polygon![
            (x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)
        ])
        .unwrap();
        let mut g = SkeletonGraph::new();
        let n: Vec<NodeId> = [c(1., 1.), c(9., 9.), c(1., 9.), c(9., 1.), c(6., 6.)]
            .into_iter()
            .map(|q| g.add_node(q, 1.0, None))
            .collect();
        // Two diagonals cross at (5, 5) (the second with an interior vertex
        // at (3, 7)). A third edge starts on the first diagonal's interior
        // and ends at the second's end: touches, not crossings.
        g.add_edge(n[0], n[1], vec![]);
        g.add_edge(n[2], n[3], vec![c(3., 7.)]);
        g.add_edge(n[4], n[3], vec![]);
        assert_eq!(crossings(&g), 1);
        let (noded, count) = node_crossings(g.clone(), p.boundary());
        assert_eq!(count, 1);
        assert_eq!(crossings(&noded), 0);
        let centre = noded
            .nodes()
            .iter()
            .position(|q| (q.pos - c(5., 5.)).x.hypot((q.pos - c(5., 5.)).y) < 1e-9)
            .expect("a node at the crossing");
        assert_eq!(noded.degrees()[centre], 4);
        assert!((noded.nodes()[centre].radius - 5.0).abs() < 1e-9);
        assert_eq!(noded.edges().len(), 5);
        assert!((noded.total_length() - g.total_length()).abs() < 1e-9);
    }
}
