//! The skeleton graph shared by every method and step.
//!
//! Nodes carry a position, the radius r = Euclidean distance to ∂P (the same
//! definition for every method; for MA it is the disc radius) and, for the
//! straight skeleton, the event time. Edges are polylines between two nodes.
//!
//! Handles are typed indices ([`NodeId`], [`EdgeId`]), never pointers.
//! The invariants every operation keeps are written above
//! [`SkeletonGraph`]. Graphs are values: pruning and extension build new
//! graphs.

pub(crate) mod bridge;
pub(crate) mod cut;
pub(crate) mod ends;
pub mod extend;
mod handle;
mod invariants;
pub mod junctions;
pub mod line;
pub mod planar;
pub mod prune;
pub mod roundabouts;
pub(crate) mod structure;
pub mod widths;

pub use handle::{EdgeId, NodeId};

use crate::geometry::Boundary;
use crate::geometry::CoordKey;
use geo::{Coord, LineString, MultiLineString};
use rustc_hash::FxHashMap as HashMap;

/// A skeleton node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Position (CRS units).
    pub pos: Coord<f64>,
    /// Distance to ∂P.
    pub radius: f64,
    /// Straight-skeleton event time (offset distance), when the method has one.
    pub time: Option<f64>,
}

/// A skeleton edge: a polyline between two nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// First end node.
    pub a: NodeId,
    /// Second end node.
    pub b: NodeId,
    /// Interior vertices of the polyline from `a` to `b` (may be empty).
    pub interior: Vec<Coord<f64>>,
}

/// A maximal chain of edges between two nodes of degree ≠ 2 (SPEC §2), or a
/// closed cycle of degree-2 nodes (then `start == end`).
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Node where the chain starts.
    pub start: NodeId,
    /// Node where the chain ends.
    pub end: NodeId,
    /// Edges in chain order.
    pub edges: Vec<EdgeId>,
    /// The chain's polyline from `start` to `end`.
    pub coords: Vec<Coord<f64>>,
}

/// A leg (SPEC §2): a branch with a leaf at one end — the one definition
/// that pruning, counting and the `legs` column share. Pruning judges the
/// legs that end at a junction.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// The branch, oriented from the leaf (`start`) to its other end (`end`).
    pub branch: Branch,
    /// The other end is a junction (degree ≥ 3), not the other leaf of a
    /// simple path.
    pub junction: bool,
}

impl Leg {
    /// The leaf.
    pub fn leaf(&self) -> NodeId {
        self.branch.start
    }

    /// The node at the other end.
    pub fn other(&self) -> NodeId {
        self.branch.end
    }
}

impl Branch {
    /// Length of the chain's polyline.
    pub fn length(&self) -> f64 {
        polyline_length(&self.coords)
    }
}

/// Length of a polyline.
pub fn polyline_length(c: &[Coord<f64>]) -> f64 {
    c.windows(2)
        .map(|w| crate::geometry::norm(w[1] - w[0]))
        .sum()
}

/// The skeleton of one polygon: nodes and polyline edges.
///
/// Invariants, kept by every method and step (and checked by
/// [`SkeletonGraph::check_invariants`] in the tests):
///
/// * each edge's end nodes exist, and its polyline runs from `nodes[a].pos`
///   through `interior` to `nodes[b].pos`;
/// * no edge has zero length: its polyline has two distinct points at least
///   ([`GraphBuilder`] leaves degenerate segments and polylines out);
/// * every position is finite, every radius finite and ≥ 0 (the distance to
///   ∂P once set, 0 before), every event time finite and ≥ 0;
/// * a node's degree ([`SkeletonGraph::degrees`]) is the number of edge ends
///   at it, as [`SkeletonGraph::adjacency`] lists them (a loop twice).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SkeletonGraph {
    nodes: Vec<Node>,
    edges: Vec<Edge>,
}

impl SkeletonGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes room for `nodes` more nodes and `edges` more edges.
    pub fn reserve(&mut self, nodes: usize, edges: usize) {
        self.nodes.reserve(nodes);
        self.edges.reserve(edges);
    }

    /// Adds a node.
    pub fn add_node(&mut self, pos: Coord<f64>, radius: f64, time: Option<f64>) -> NodeId {
        self.nodes.push(Node { pos, radius, time });
        NodeId::from_index(self.nodes.len() - 1)
    }

    /// Adds an edge between existing nodes.
    pub fn add_edge(&mut self, a: NodeId, b: NodeId, interior: Vec<Coord<f64>>) -> EdgeId {
        debug_assert!((a.index()) < self.nodes.len() && (b.index()) < self.nodes.len());
        self.edges.push(Edge { a, b, interior });
        EdgeId::from_index(self.edges.len() - 1)
    }

    /// All nodes.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Mutable nodes (positions must keep the edge invariant).
    pub fn nodes_mut(&mut self) -> &mut [Node] {
        &mut self.nodes
    }

    /// All edges.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// One node.
    pub fn node(&self, n: NodeId) -> &Node {
        &self.nodes[n.index()]
    }

    /// One edge.
    pub fn edge(&self, e: EdgeId) -> &Edge {
        &self.edges[e.index()]
    }

    /// True when the graph has no edge.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// The polyline of an edge from `a` to `b`.
    pub fn edge_coords(&self, e: EdgeId) -> Vec<Coord<f64>> {
        let ed = self.edge(e);
        let mut v = Vec::with_capacity(ed.interior.len() + 2);
        v.push(self.node(ed.a).pos);
        v.extend_from_slice(&ed.interior);
        v.push(self.node(ed.b).pos);
        v
    }

    /// Length of an edge's polyline.
    pub fn edge_length(&self, e: EdgeId) -> f64 {
        // polyline_length of edge_coords, term by term in the same order,
        // without building the polyline.
        let ed = self.edge(e);
        let points = std::iter::once(self.node(ed.a).pos)
            .chain(ed.interior.iter().copied())
            .chain(std::iter::once(self.node(ed.b).pos));
        points
            .clone()
            .zip(points.skip(1))
            .map(|(p, q)| crate::geometry::norm(q - p))
            .sum()
    }

    /// Total length of all edges.
    pub fn total_length(&self) -> f64 {
        (0..self.edges.len())
            .map(|i| self.edge_length(EdgeId::from_index(i)))
            .sum()
    }

    /// Incident edges of every node (a loop edge appears twice).
    pub fn adjacency(&self) -> Adjacency {
        Adjacency::of(self, |_| true)
    }

    /// Degree of every node.
    pub fn degrees(&self) -> Vec<usize> {
        let mut d = vec![0; self.nodes.len()];
        for e in &self.edges {
            d[e.a.index()] += 1;
            d[e.b.index()] += 1;
        }
        d
    }

    /// The other end of edge `e` seen from node `n`.
    pub fn opposite(&self, e: EdgeId, n: NodeId) -> NodeId {
        let ed = self.edge(e);
        if ed.a == n {
            ed.b
        } else {
            ed.a
        }
    }

    /// Number of connected components that have at least one edge.
    pub fn components(&self) -> usize {
        let mut uf = UnionFind::new(self.nodes.len());
        for e in &self.edges {
            uf.union(e.a.index(), e.b.index());
        }
        let mut roots: Vec<usize> = self.edges.iter().map(|e| uf.find(e.a.index())).collect();
        roots.sort_unstable();
        roots.dedup();
        roots.len()
    }

    /// Component label of every node (nodes without edges get their own).
    pub fn component_labels(&self) -> Vec<usize> {
        let mut uf = UnionFind::new(self.nodes.len());
        for e in &self.edges {
            uf.union(e.a.index(), e.b.index());
        }
        (0..self.nodes.len()).map(|i| uf.find(i)).collect()
    }

    /// Branches: maximal chains between nodes of degree ≠ 2, plus closed
    /// cycles made only of degree-2 nodes. Deterministic order (by first edge).
    pub fn branches(&self) -> Vec<Branch> {
        let mut out = Vec::new();
        self.walk_branches(|start, edges, end| {
            let len = 1 + edges
                .iter()
                .map(|&e| self.edge(e).interior.len() + 1)
                .sum::<usize>();
            let mut coords = Vec::with_capacity(len);
            coords.push(self.node(start).pos);
            let mut cur = start;
            for &e in edges {
                self.push_oriented(&mut coords, e, cur);
                cur = self.opposite(e, cur);
            }
            out.push(Branch {
                start,
                end,
                edges: edges.to_vec(),
                coords,
            });
        });
        out
    }

    /// Walks the branches of [`SkeletonGraph::branches`] in its order,
    /// calling `f(start, edges, end)` for each (the edges in walking order,
    /// in a buffer reused from branch to branch).
    fn walk_branches(&self, mut f: impl FnMut(NodeId, &[EdgeId], NodeId)) {
        let adj = Adjacency::of(self, |_| true);
        let mut used = vec![false; self.edges.len()];
        let mut edges = Vec::new();
        let mut walk = |start: NodeId, first: EdgeId, used: &mut Vec<bool>| {
            edges.clear();
            edges.push(first);
            used[first.index()] = true;
            let mut cur = self.opposite(first, start);
            while adj[cur.index()].len() == 2 && cur != start {
                let next = adj[cur.index()].iter().copied().find(|e| !used[e.index()]);
                let Some(next) = next else { break };
                used[next.index()] = true;
                edges.push(next);
                cur = self.opposite(next, cur);
            }
            f(start, &edges, cur);
        };
        for n in 0..self.nodes.len() {
            let a = &adj[n];
            if a.len() == 2 {
                continue;
            }
            for &e in a {
                if !used[e.index()] {
                    walk(NodeId::from_index(n), e, &mut used);
                }
            }
        }
        // Remaining edges lie on cycles of degree-2 nodes.
        for i in 0..self.edges.len() {
            if !used[i] {
                let start = self.edges[i].a;
                walk(start, EdgeId::from_index(i), &mut used);
            }
        }
    }

    /// Appends the polyline of edge `e`, walked from node `from`, to
    /// `coords`, which ends at `from`'s position (so that is not repeated).
    fn push_oriented(&self, coords: &mut Vec<Coord<f64>>, e: EdgeId, from: NodeId) {
        let ed = self.edge(e);
        if ed.a == from {
            coords.extend_from_slice(&ed.interior);
            coords.push(self.node(ed.b).pos);
        } else {
            coords.extend(ed.interior.iter().rev());
            coords.push(self.node(ed.a).pos);
        }
    }

    /// The polyline of edge `e` oriented to start at node `from`.
    pub fn oriented_coords(&self, e: EdgeId, from: NodeId) -> Vec<Coord<f64>> {
        let mut c = self.edge_coords(e);
        if self.edge(e).a != from {
            c.reverse();
        }
        c
    }

    /// A new graph in which every chain through degree-2 nodes is one edge.
    /// Unused nodes are dropped.
    pub fn merged(&self) -> SkeletonGraph {
        let branches = self.branches();
        let mut g = SkeletonGraph::new();
        g.edges.reserve_exact(branches.len());
        let mut ids = NodeMap::new(self);
        for b in branches {
            let s = ids.id(&mut g, b.start);
            let t = ids.id(&mut g, b.end);
            let mut interior = b.coords;
            interior.pop();
            interior.remove(0);
            g.add_edge(s, t, interior);
        }
        g
    }

    /// A copy keeping only the edges for which `keep` is true; unused nodes dropped.
    pub fn filter_edges(&self, mut keep: impl FnMut(EdgeId, &Edge) -> bool) -> SkeletonGraph {
        let mut g = SkeletonGraph::new();
        let mut ids = NodeMap::new(self);
        for (i, e) in self.edges.iter().enumerate() {
            if !keep(EdgeId::from_index(i), e) {
                continue;
            }
            let a = ids.id(&mut g, e.a);
            let b = ids.id(&mut g, e.b);
            g.add_edge(a, b, e.interior.clone());
        }
        g
    }

    /// The skeleton as a multilinestring, one linestring per branch.
    pub fn to_multilinestring(&self) -> MultiLineString<f64> {
        MultiLineString(
            self.branches()
                .into_iter()
                .map(|b| LineString(b.coords))
                .collect(),
        )
    }

    /// The graph of skeleton lines made by any tool: each line one edge,
    /// end points shared bit for bit one node, radii 0 (see
    /// [`GraphBuilder::polyline`] for the lines it leaves out).
    pub fn from_lines(lines: &MultiLineString<f64>) -> SkeletonGraph {
        let mut b = GraphBuilder::new();
        for l in &lines.0 {
            b.polyline(&l.0);
        }
        b.finish_raw()
    }

    /// Recomputes every node's radius as its distance to ∂P.
    pub fn set_radii(&mut self, boundary: &Boundary) {
        for n in &mut self.nodes {
            n.radius = boundary.distance(n.pos);
        }
    }

    /// The polyline from node `n` along its first edge to the first node of
    /// degree ≠ 2 (for a leaf: its whole branch, starting at the leaf);
    /// `adj` is [`SkeletonGraph::adjacency`].
    pub fn line_from(&self, n: NodeId, adj: &Adjacency) -> Vec<Coord<f64>> {
        let deg = |m: NodeId| adj[m.index()].len();
        let mut coords = vec![self.node(n).pos];
        let Some(&first) = adj[n.index()].first() else {
            return coords;
        };
        let (mut at, mut via) = (n, first);
        for _ in 0..self.edges.len() {
            let c = self.oriented_coords(via, at);
            coords.extend_from_slice(&c[1..]);
            at = self.opposite(via, at);
            if deg(at) != 2 || at == n {
                break;
            }
            let Some(&next) = adj[at.index()].iter().find(|&&e| e != via) else {
                break;
            };
            via = next;
        }
        coords
    }

    /// The legs (SPEC §2): branches with a leaf at one end, oriented from
    /// the leaf. A simple path (leaf to leaf) is one leg.
    pub fn legs(&self) -> Vec<Leg> {
        let deg = self.degrees();
        self.branches()
            .into_iter()
            .filter(|b| b.start != b.end)
            .filter_map(|mut b| {
                if deg[b.start.index()] != 1 {
                    if deg[b.end.index()] != 1 {
                        return None;
                    }
                    std::mem::swap(&mut b.start, &mut b.end);
                    b.edges.reverse();
                    b.coords.reverse();
                }
                let junction = deg[b.end.index()] >= 3;
                Some(Leg {
                    branch: b,
                    junction,
                })
            })
            .collect()
    }

    /// Number of legs ([`SkeletonGraph::legs`]): the `legs` column.
    pub fn leg_count(&self) -> usize {
        if self.nodes.len() >= LEGS_IN_PARALLEL {
            return self.leg_count_from_leaves();
        }
        // The legs of `legs()`, counted without building their lines.
        let deg = self.degrees();
        let mut n = 0;
        self.walk_branches(|start, _, end| {
            n += usize::from(start != end && (deg[start.index()] == 1 || deg[end.index()] == 1));
        });
        n
    }

    /// [`SkeletonGraph::leg_count`] walked from every leaf on every core: a
    /// leg is the branch from a leaf through degree-2 nodes to the first
    /// other node, counted once when that is a leaf too (a lone path).
    fn leg_count_from_leaves(&self) -> usize {
        use rayon::prelude::*;
        let adj = Adjacency::of(self, |_| true);
        (0..self.nodes.len())
            .into_par_iter()
            .filter(|&i| {
                let a = &adj[i];
                if a.len() != 1 {
                    return false;
                }
                let (mut e, mut cur) = (a[0], self.opposite(a[0], NodeId::from_index(i)));
                while adj[cur.index()].len() == 2 {
                    let Some(&next) = adj[cur.index()].iter().find(|&&x| x != e) else {
                        break;
                    };
                    e = next;
                    cur = self.opposite(next, cur);
                }
                adj[cur.index()].len() != 1 || i < cur.index()
            })
            .count()
    }

    /// [`SkeletonGraph::leg_count`] from the graph's branches
    /// ([`SkeletonGraph::branches`]) when they are at hand: no second walk.
    pub fn leg_count_in(&self, branches: &[Branch]) -> usize {
        let deg = self.degrees();
        let leaf = |n: NodeId| deg[n.index()] == 1;
        branches
            .iter()
            .filter(|b| b.start != b.end && (leaf(b.start) || leaf(b.end)))
            .count()
    }
}

/// [`SkeletonGraph::leg_count`] walks the legs on every core from this many
/// nodes on (a rough rim's raw medial axis has millions; most skeletons, in
/// a run that has a thread per feature already, are walked on one).
const LEGS_IN_PARALLEL: usize = 1 << 16;

/// The nodes of a graph copied into a new one, numbered in the order they
/// are first met.
struct NodeMap<'a> {
    from: &'a SkeletonGraph,
    /// New handle of every node of `from` (`None`: not copied yet).
    ids: Vec<Option<NodeId>>,
}

impl<'a> NodeMap<'a> {
    fn new(from: &'a SkeletonGraph) -> Self {
        Self {
            from,
            ids: vec![None; from.nodes.len()],
        }
    }

    /// Node `n`'s number in `g`, copied there the first time.
    fn id(&mut self, g: &mut SkeletonGraph, n: NodeId) -> NodeId {
        *self.ids[n.index()].get_or_insert_with(|| {
            let nd = self.from.node(n);
            g.add_node(nd.pos, nd.radius, nd.time)
        })
    }
}

/// The incident edges of every node of a [`SkeletonGraph`] in two flat
/// arrays: `adj[n]` is node `n`'s, in edge order (a loop twice). One
/// allocation for the whole graph instead of one per node — the walks over
/// a skeleton build it several times per polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct Adjacency {
    /// `edges[start[n]..start[n + 1]]` are node `n`'s.
    start: Vec<u32>,
    edges: Vec<EdgeId>,
}

impl Adjacency {
    /// The edges of `g` for which `keep` is true, per node in edge order (a
    /// loop twice at its node).
    pub fn of(g: &SkeletonGraph, keep: impl Fn(EdgeId) -> bool) -> Self {
        let mut start = vec![0u32; g.nodes.len() + 1];
        let mut kept = 0;
        for (i, e) in g.edges.iter().enumerate() {
            if keep(EdgeId::from_index(i)) {
                start[e.a.index() + 1] += 1;
                start[e.b.index() + 1] += 1;
                kept += 2;
            }
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut next = start.clone();
        let mut edges = vec![EdgeId::from_index(0); kept];
        for (i, e) in g.edges.iter().enumerate() {
            if !keep(EdgeId::from_index(i)) {
                continue;
            }
            for n in [e.a, e.b] {
                let at = &mut next[n.index()];
                edges[*at as usize] = EdgeId::from_index(i);
                *at += 1;
            }
        }
        Self { start, edges }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    /// True for a graph without nodes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Each node's edges, in node order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[EdgeId]> + '_ {
        (0..self.len()).map(|n| &self[n])
    }
}

impl std::ops::Index<usize> for Adjacency {
    type Output = [EdgeId];

    fn index(&self, n: usize) -> &[EdgeId] {
        &self.edges[self.start[n] as usize..self.start[n + 1] as usize]
    }
}

/// Builds a graph from segments or polylines, merging end points that are
/// bit-for-bit equal (methods compute shared points from the same inputs, so
/// exact equality is the right test and no tolerance is needed).
#[derive(Debug, Default)]
pub struct GraphBuilder {
    graph: SkeletonGraph,
    index: HashMap<CoordKey, NodeId>,
}

impl GraphBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty builder with room for `nodes` nodes and `edges` edges.
    pub fn with_capacity(nodes: usize, edges: usize) -> Self {
        let mut b = Self::default();
        b.graph.nodes.reserve(nodes);
        b.graph.edges.reserve(edges);
        b.index.reserve(nodes);
        b
    }

    /// The node at `p`, created when absent (radius set by [`GraphBuilder::finish`]).
    pub fn node(&mut self, p: Coord<f64>) -> NodeId {
        // +0.0 normalises −0.0 so both zeros share a node.
        let key = CoordKey::from(Coord {
            x: p.x + 0.0,
            y: p.y + 0.0,
        });
        let g = &mut self.graph;
        *self
            .index
            .entry(key)
            .or_insert_with(|| g.add_node(p, 0.0, None))
    }

    /// Sets the event time of the node at `p` (straight skeleton).
    pub fn set_time(&mut self, n: NodeId, time: f64) {
        self.graph.nodes[n.index()].time = Some(time);
    }

    /// Adds the segment `pq` (ignored when degenerate).
    pub fn segment(&mut self, p: Coord<f64>, q: Coord<f64>) -> Option<EdgeId> {
        if p == q {
            return None;
        }
        let a = self.node(p);
        let b = self.node(q);
        Some(self.graph.add_edge(a, b, Vec::new()))
    }

    /// [`GraphBuilder::segment`] between two nodes it made, without looking
    /// their positions up again (ignored when they are at one position).
    pub fn segment_between(&mut self, a: NodeId, b: NodeId) -> Option<EdgeId> {
        if self.graph.node(a).pos == self.graph.node(b).pos {
            return None;
        }
        Some(self.graph.add_edge(a, b, Vec::new()))
    }

    /// Adds a polyline as one edge (ignored when shorter than two distinct points).
    pub fn polyline(&mut self, pts: &[Coord<f64>]) -> Option<EdgeId> {
        let mut v: Vec<Coord<f64>> = Vec::with_capacity(pts.len());
        for &p in pts {
            if v.last() != Some(&p) {
                v.push(p);
            }
        }
        if v.len() < 2 {
            return None;
        }
        let a = self.node(v[0]);
        let b = self.node(*v.last().unwrap());
        let interior = v[1..v.len() - 1].to_vec();
        Some(self.graph.add_edge(a, b, interior))
    }

    /// Adds a polyline as [`GraphBuilder::polyline`] does, a closed one
    /// (a loop from a node back to it) as two edges through its middle, so
    /// that no edge joins a node to itself.
    pub fn path(&mut self, pts: &[Coord<f64>]) {
        if pts.len() > 2 && pts.first() == pts.last() {
            let mid = pts.len() / 2;
            self.polyline(&pts[..=mid]);
            self.polyline(&pts[mid..]);
        } else {
            self.polyline(pts);
        }
    }

    /// Finishes the graph: node radii set to their distance to ∂P.
    pub fn finish(mut self, boundary: &Boundary) -> SkeletonGraph {
        self.graph.set_radii(boundary);
        self.graph
    }

    /// Finishes the graph without touching radii (they stay as set).
    pub fn finish_raw(self) -> SkeletonGraph {
        self.graph
    }
}

/// Union–find over `0..n` whose class root is always the smallest member
/// (so labels are deterministic).
pub(crate) struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
        }
    }
    pub(crate) fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }
    pub(crate) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
            self.parent[hi] = lo;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn builder_merges_shared_points_and_branches() {
        let mut b = GraphBuilder::new();
        b.segment(c(0., 0.), c(1., 0.));
        b.segment(c(1., 0.), c(2., 0.));
        b.segment(c(2., 0.), c(3., 1.));
        b.segment(c(2., 0.), c(3., -1.));
        let g = b.finish_raw();
        assert_eq!(g.nodes().len(), 5);
        assert_eq!(g.components(), 1);
        let br = g.branches();
        assert_eq!(br.len(), 3);
        assert_eq!(g.leg_count(), 3);
        let m = g.merged();
        assert_eq!(m.edges().len(), 3);
        assert!((m.total_length() - g.total_length()).abs() < 1e-12);
    }

    #[test]
    fn cycle_is_one_branch() {
        let mut b = GraphBuilder::new();
        b.segment(c(0., 0.), c(1., 0.));
        b.segment(c(1., 0.), c(1., 1.));
        b.segment(c(1., 1.), c(0., 0.));
        let g = b.finish_raw();
        let br = g.branches();
        assert_eq!(br.len(), 1);
        assert_eq!(br[0].start, br[0].end);
        assert_eq!(g.leg_count(), 0);
    }

    #[test]
    fn legs_are_counted_as_listed_and_branches_keep_their_lines() {
        // A path on its own (one leg, two leaves), a fork with a lasso (a
        // loop edge at a junction: no leg), a cycle, and an isolated node.
        let mut g = SkeletonGraph::new();
        let n: Vec<NodeId> = (0..10)
            .map(|i| g.add_node(c(i as f64, (i * i) as f64), 1.0, None))
            .collect();
        g.add_edge(n[0], n[1], vec![c(0.5, 0.1)]);
        g.add_edge(n[1], n[2], vec![]);
        g.add_edge(n[3], n[4], vec![]);
        g.add_edge(n[5], n[4], vec![c(4.5, 20.0), c(4.6, 21.0)]);
        g.add_edge(n[4], n[6], vec![]);
        g.add_edge(n[6], n[6], vec![c(7.0, 40.0)]);
        g.add_edge(n[7], n[8], vec![]);
        g.add_edge(n[8], n[7], vec![c(7.5, 60.0)]);
        assert_eq!(g.legs().len(), 3);
        assert_eq!(g.leg_count(), g.legs().len());
        assert_eq!(g.leg_count_in(&g.branches()), g.legs().len());
        assert_eq!(g.leg_count_from_leaves(), g.legs().len());
        // Every branch's line is its edges' lines joined end to end.
        for b in g.branches() {
            let mut at = b.start;
            let mut joined = vec![g.node(at).pos];
            for &e in &b.edges {
                joined.extend_from_slice(&g.oriented_coords(e, at)[1..]);
                at = g.opposite(e, at);
            }
            assert_eq!(at, b.end);
            assert_eq!(joined, b.coords);
        }
        let lengths: f64 = g.branches().iter().map(Branch::length).sum();
        assert!((lengths - g.total_length()).abs() < 1e-9);
    }

    #[test]
    fn a_large_graphs_legs_are_walked_from_its_leaves_as_counted_by_branches() {
        // Combs of several sizes (legs of 1–4 pieces on a spine), lone
        // paths, lassos, cycles and double edges: above the parallel
        // threshold, the leaf walk counts what the branch walk counts.
        let mut g = SkeletonGraph::new();
        let mut rng = 7u64;
        let mut next = |m: u64| {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 33) % m
        };
        while g.nodes().len() < LEGS_IN_PARALLEL + 1000 {
            let spine: Vec<NodeId> = (0..1 + next(8))
                .map(|_| g.add_node(c(0.0, 0.0), 1.0, None))
                .collect();
            for w in spine.windows(2) {
                g.add_edge(w[0], w[1], vec![]);
            }
            for &s in &spine {
                match next(6) {
                    0 => {
                        g.add_edge(s, s, vec![]);
                    }
                    1 => {
                        let t = g.add_node(c(1.0, 0.0), 1.0, None);
                        g.add_edge(s, t, vec![]);
                        g.add_edge(t, s, vec![]);
                    }
                    _ => {
                        let mut at = s;
                        for _ in 0..next(5) {
                            let t = g.add_node(c(1.0, 1.0), 1.0, None);
                            g.add_edge(at, t, vec![]);
                            at = t;
                        }
                    }
                }
            }
        }
        assert!(g.nodes().len() >= LEGS_IN_PARALLEL);
        let by_branches = g.leg_count_in(&g.branches());
        assert!(by_branches > 10_000, "{by_branches}");
        assert_eq!(g.leg_count(), by_branches);
    }
}
