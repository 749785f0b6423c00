//! Joining a skeleton that fell apart.
//!
//! The Voronoi methods (VD, DVD) drop every Voronoi edge that crosses ∂P, so
//! at a neck narrower than the spacing of the boundary vertices their
//! skeleton falls into pieces (SPEC §3 reports them as `components`). A
//! piece ends there in a leaf a local radius or so from the next piece;
//! [`bridge`] joins such pieces with a straight segment, shortest first
//! (Kruskal over the pieces), when the segment is no longer than
//! [`MAX_GAP`] local radii and stays in P. Pieces farther apart are left as
//! they are, and still counted in `components`.

use super::{NodeId, SkeletonGraph, UnionFind};
use crate::geometry::vector::hypot;
use crate::geometry::PreparedPolygon;
use rstar::{primitives::GeomWithData, RTree};

/// The longest bridge, in local radii (the larger radius of its two ends):
/// a neck is about two radii wide.
pub const MAX_GAP: f64 = 3.0;

/// `graph` with its pieces joined where they come close (see the module
/// documentation); unchanged when it is connected.
pub fn bridge(graph: &SkeletonGraph, polygon: &PreparedPolygon) -> SkeletonGraph {
    if graph.components() <= 1 {
        return graph.clone();
    }
    let labels = graph.component_labels();
    let deg = graph.degrees();
    let b = polygon.boundary();
    let tree: RTree<GeomWithData<[f64; 2], u32>> = RTree::bulk_load(
        graph
            .nodes()
            .iter()
            .enumerate()
            .filter(|(i, _)| deg[*i] > 0)
            .map(|(i, n)| GeomWithData::new([n.pos.x, n.pos.y], i as u32))
            .collect(),
    );
    let mut candidates: Vec<(f64, u32, u32)> = Vec::new();
    for (v, node) in graph.nodes().iter().enumerate() {
        if deg[v] != 1 {
            continue;
        }
        let reach = MAX_GAP * node.radius;
        let mut best: Option<(f64, u32)> = None;
        for item in tree.locate_within_distance([node.pos.x, node.pos.y], reach * reach) {
            let w = item.data as usize;
            if labels[w] == labels[v] {
                continue;
            }
            let other = graph.nodes()[w];
            let d = hypot(other.pos - node.pos);
            if d > MAX_GAP * node.radius.max(other.radius) {
                continue;
            }
            if best.is_none_or(|(bd, bw)| (d, w as u32) < (bd, bw)) {
                best = Some((d, w as u32));
            }
        }
        if let Some((d, w)) = best {
            candidates.push((d, v as u32, w));
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut uf = UnionFind::new(graph.nodes().len());
    for (i, &l) in labels.iter().enumerate() {
        uf.union(i, l);
    }
    let mut out = graph.clone();
    for (_, v, w) in candidates {
        let (pv, pw) = (graph.nodes()[v as usize].pos, graph.nodes()[w as usize].pos);
        if uf.find(v as usize) == uf.find(w as usize) || b.crosses(pv, pw) {
            continue;
        }
        if !b.contains(pv * 0.5 + pw * 0.5) {
            continue;
        }
        uf.union(v as usize, w as usize);
        out.add_edge(
            NodeId::from_index(v as usize),
            NodeId::from_index(w as usize),
            Vec::new(),
        );
    }
    out
}
