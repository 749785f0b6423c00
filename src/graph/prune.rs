//! Pruning of insignificant legs (SPEC §4).
//!
//! A **leg** is a branch with a leaf ℓ at one end and a junction j (degree ≥ 3)
//! at the other; r_j is the junction's radius (its distance to ∂P, set by
//! every method). With `ratio` = ρ and `min_length` = m:
//!
//! ```text
//!   leg is insignificant  ⇔  length(leg) − r_j < ρ · r_j   or   length(leg) < m
//!   significance(leg)     =  (length(leg) − r_j) / r_j     (+∞ when r_j = 0)
//! ```
//!
//! i.e. an insignificant leg does not protrude `ratio` local radii beyond the
//! inscribed disc at its junction: it is a "whisker" caused by a boundary
//! vertex or a small bump, not an arm of the shape.
//!
//! Modes:
//!
//! * `significance` (default): remove the least significant leg first (ties
//!   broken by the leaf's coordinates, then by branch order), merge degree-2
//!   nodes, re-evaluate, repeat until no leg is insignificant. A priority queue
//!   with lazy invalidation makes this O(n log n) in the number of branches.
//!   When removing a leg leaves its junction j with two branches, one of which
//!   is itself a leg insignificant at j while the other is not, that sibling
//!   leg goes too (j becomes a leaf): a leg is judged at the junction where
//!   it met the rest of the skeleton, so losing a sibling does not rescue it.
//!   This is what turns the medial axis of a rectangle (a centre segment and
//!   four corner legs) into its centre segment. A junction that becomes a
//!   leaf this way keeps the *reach* of what was cut behind it (the larger
//!   extent of the two legs), and a leg's length is always counted with the
//!   reach of its leaf (`length(leg) + reach(ℓ)`, reach = r_ℓ for an original
//!   leaf, 0 on ∂P): without it a long arm whose junctions are closer than two
//!   radii apart would be eroded junction by junction down to a stub. When both remaining branches
//!   are insignificant legs they are merged instead, so a component is never
//!   reduced below a simple path (two leaves); a component that already is a
//!   path keeps both ends, and legs of a component with cycles (a polygon with
//!   holes) are removed down to the cycles.
//! * `length`: the same procedure with only the `length(leg) < m` rule
//!   (least significant = shortest).
//! * `trunk`: keep only the longest leaf-to-leaf path of each component, one
//!   centreline per part. The two end leaves are found by repeated farthest-leaf
//!   sweeps (Dijkstra over branch lengths): exact on trees (the tree diameter),
//!   a heuristic for components with cycles, where the result is the shortest
//!   path between the leaf pair found, so a river with islands stays one
//!   connected line from end to end. A component with one leaf keeps its
//!   cycles without the leg; a component without leaves (a ring) is kept.
//! * `none`: the graph unchanged.
//!
//! The result of every mode but `none` has its degree-2 chains merged (one
//! edge per branch). Everything is sequential and ordered by node and edge
//! indices and coordinates, so the output is the same for any thread count.
//!
//! ```
//! use skeletonise::graph::{GraphBuilder, prune::{prune, PruneParams}};
//! use geo::Coord;
//! let c = |x, y| Coord { x, y };
//! // The medial axis of the rectangle [0, 10] × [0, 4].
//! let mut b = GraphBuilder::new();
//! b.segment(c(2., 2.), c(8., 2.));
//! for (p, q) in [(c(0., 0.), c(2., 2.)), (c(0., 4.), c(2., 2.)),
//!                (c(10., 0.), c(8., 2.)), (c(10., 4.), c(8., 2.))] {
//!     b.segment(p, q);
//! }
//! let mut g = b.finish_raw();
//! for n in g.nodes_mut() {
//!     n.radius = n.pos.x.min(10. - n.pos.x).min(n.pos.y).min(4. - n.pos.y);
//! }
//! let p = prune(&g, &PruneParams::default());
//! assert_eq!(p.edges().len(), 1);
//! assert_eq!(p.total_length(), 6.0);
//! ```

use super::{EdgeId, NodeId, SkeletonGraph};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// How legs are pruned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PruneMode {
    /// Remove legs that do not protrude `ratio` local radii beyond the
    /// inscribed disc at their junction (and legs shorter than `min_length`).
    #[default]
    Significance,
    /// Remove legs shorter than `min_length` only.
    Length,
    /// Keep only the longest leaf-to-leaf path of each component.
    Trunk,
    /// Keep every leg.
    None,
}

/// Options of the `prune` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PruneParams {
    /// Pruning mode.
    pub mode: PruneMode,
    /// A leg is insignificant when `length − r_j < ratio · r_j`.
    pub ratio: f64,
    /// Legs shorter than this (CRS units) are insignificant.
    pub min_length: f64,
}

impl Default for PruneParams {
    fn default() -> Self {
        Self {
            mode: PruneMode::Significance,
            ratio: 1.0,
            min_length: 0.0,
        }
    }
}

impl PruneParams {
    /// True when a leg of `length` ending at a junction of radius `r_j` is
    /// insignificant under this mode (always false for `trunk` and `none`).
    pub fn is_insignificant(&self, length: f64, r_j: f64) -> bool {
        match self.mode {
            PruneMode::Significance => length - r_j < self.ratio * r_j || length < self.min_length,
            PruneMode::Length => length < self.min_length,
            PruneMode::Trunk | PruneMode::None => false,
        }
    }

    /// Removal priority of a leg: smaller is removed first.
    fn key(&self, length: f64, r_j: f64) -> f64 {
        match self.mode {
            PruneMode::Significance => significance(length, r_j),
            _ => length,
        }
    }
}

/// Significance of a leg, `(length − r_j) / r_j`: how many local radii it
/// protrudes beyond the inscribed disc at its junction (+∞ when `r_j ≤ 0`).
pub fn significance(length: f64, r_j: f64) -> f64 {
    if r_j > 0.0 {
        (length - r_j) / r_j
    } else {
        f64::INFINITY
    }
}

/// Prunes `graph` per `params` (see the module documentation).
pub fn prune(graph: &SkeletonGraph, params: &PruneParams) -> SkeletonGraph {
    match params.mode {
        PruneMode::None => graph.clone(),
        PruneMode::Significance | PruneMode::Length => prune_legs(graph, params),
        PruneMode::Trunk => trunk(graph),
    }
}

/// Legs of `graph` that are insignificant under `params` at a junction of
/// degree ≥ 3, as `(leaf, junction, length)`. Empty after [`prune`] with the
/// same parameters; legs of components that are simple paths never count.
pub fn insignificant_legs(
    graph: &SkeletonGraph,
    params: &PruneParams,
) -> Vec<(NodeId, NodeId, f64)> {
    let deg = graph.degrees();
    let mut out = Vec::new();
    for b in graph.branches() {
        if b.start == b.end {
            continue;
        }
        let (ds, de) = (deg[b.start.0 as usize], deg[b.end.0 as usize]);
        for (leaf, j, dl, dj) in [(b.start, b.end, ds, de), (b.end, b.start, de, ds)] {
            if dl == 1 && dj >= 3 {
                let len = b.length();
                if params.is_insignificant(len, graph.node(j).radius) {
                    out.push((leaf, j, len));
                }
            }
        }
    }
    out
}

/// A branch of the working graph: an original edge of the merged graph, or
/// two pieces joined at a former degree-2 node (a binary tree, so joining is
/// O(1) however long the chain).
#[derive(Debug, Clone, Copy)]
struct Piece {
    u: u32,
    v: u32,
    len: f64,
    kind: Kind,
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Orig(u32),
    Join(u32, u32),
}

/// Mutable multigraph over pieces. Invariant: `adj[n]` lists the alive pieces
/// incident to n (a loop twice), and an alive piece's originals are kept.
struct Work<'a> {
    graph: &'a SkeletonGraph,
    pieces: Vec<Piece>,
    alive: Vec<bool>,
    adj: Vec<Vec<u32>>,
    keep: Vec<bool>,
    /// How far the skeleton (with its discs) reached beyond each leaf before
    /// pruning: r_ℓ for an original leaf, the extent of the legs removed
    /// behind a junction that became a leaf.
    reach: Vec<f64>,
}

/// Heap entry; ordered by (key, leaf x, leaf y, piece id).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    key: f64,
    leaf: (f64, f64),
    piece: u32,
}

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        self.key
            .total_cmp(&o.key)
            .then(self.leaf.0.total_cmp(&o.leaf.0))
            .then(self.leaf.1.total_cmp(&o.leaf.1))
            .then(self.piece.cmp(&o.piece))
    }
}

impl<'a> Work<'a> {
    fn new(graph: &'a SkeletonGraph) -> Self {
        let mut w = Work {
            graph,
            pieces: Vec::with_capacity(graph.edges().len() * 2),
            alive: Vec::new(),
            adj: vec![Vec::new(); graph.nodes().len()],
            keep: vec![true; graph.edges().len()],
            reach: graph.nodes().iter().map(|n| n.radius.max(0.0)).collect(),
        };
        for (i, e) in graph.edges().iter().enumerate() {
            let len = graph.edge_length(EdgeId(i as u32));
            w.push_piece(e.a.0, e.b.0, len, Kind::Orig(i as u32));
        }
        w
    }

    fn push_piece(&mut self, u: u32, v: u32, len: f64, kind: Kind) -> u32 {
        let id = self.pieces.len() as u32;
        self.pieces.push(Piece { u, v, len, kind });
        self.alive.push(true);
        self.adj[u as usize].push(id);
        self.adj[v as usize].push(id);
        id
    }

    fn deg(&self, n: u32) -> usize {
        self.adj[n as usize].len()
    }

    fn other(&self, p: u32, n: u32) -> u32 {
        let pc = &self.pieces[p as usize];
        if pc.u == n {
            pc.v
        } else {
            pc.u
        }
    }

    /// `(leaf, junction)` when piece `p` is a leg at a junction of degree ≥ 3.
    fn leg(&self, p: u32) -> Option<(u32, u32)> {
        let pc = &self.pieces[p as usize];
        if pc.u == pc.v {
            return None;
        }
        match (self.deg(pc.u), self.deg(pc.v)) {
            (1, d) if d >= 3 => Some((pc.u, pc.v)),
            (d, 1) if d >= 3 => Some((pc.v, pc.u)),
            _ => None,
        }
    }

    /// Removes piece `p` and drops its originals from the result.
    fn remove(&mut self, p: u32) {
        self.alive[p as usize] = false;
        let Piece { u, v, .. } = self.pieces[p as usize];
        self.adj[u as usize].retain(|&q| q != p);
        self.adj[v as usize].retain(|&q| q != p);
        let mut stack = vec![p];
        while let Some(q) = stack.pop() {
            match self.pieces[q as usize].kind {
                Kind::Orig(e) => self.keep[e as usize] = false,
                Kind::Join(a, b) => stack.extend([a, b]),
            }
        }
    }

    /// Joins the two distinct pieces at degree-2 node `j` into one.
    fn join(&mut self, j: u32) -> Option<u32> {
        let (p1, p2) = (self.adj[j as usize][0], self.adj[j as usize][1]);
        if p1 == p2 {
            return None; // a loop: j anchors a pure cycle
        }
        let (u, v) = (self.other(p1, j), self.other(p2, j));
        let len = self.pieces[p1 as usize].len + self.pieces[p2 as usize].len;
        let id = self.pieces.len() as u32;
        self.pieces.push(Piece {
            u,
            v,
            len,
            kind: Kind::Join(p1, p2),
        });
        self.alive.push(true);
        self.alive[p1 as usize] = false;
        self.alive[p2 as usize] = false;
        self.adj[j as usize].clear();
        for (n, old) in [(u, p1), (v, p2)] {
            let slot = self.adj[n as usize]
                .iter_mut()
                .find(|q| **q == old)
                .expect("adjacency lists every alive piece");
            *slot = id;
        }
        Some(id)
    }

    /// Extent of leg `p` seen from its junction: its length plus the reach
    /// of its leaf.
    fn extent(&self, p: u32, leaf: u32) -> f64 {
        self.pieces[p as usize].len + self.reach[leaf as usize]
    }

    /// Piece `p` is a leg whose leaf is not `j` and which is insignificant
    /// when judged at `j` (radius r_j).
    fn insignificant_at(&self, p: u32, j: u32, params: &PruneParams) -> bool {
        let o = self.other(p, j);
        o != j && self.deg(o) == 1 && params.is_insignificant(self.extent(p, o), self.radius(j))
    }

    fn radius(&self, n: u32) -> f64 {
        self.graph.nodes()[n as usize].radius
    }

    fn entry(&self, p: u32, params: &PruneParams) -> Option<Entry> {
        let (leaf, j) = self.leg(p)?;
        let len = self.extent(p, leaf);
        let rj = self.radius(j);
        if !params.is_insignificant(len, rj) {
            return None;
        }
        let pos = self.graph.nodes()[leaf as usize].pos;
        Some(Entry {
            key: params.key(len, rj),
            leaf: (pos.x, pos.y),
            piece: p,
        })
    }
}

fn prune_legs(graph: &SkeletonGraph, params: &PruneParams) -> SkeletonGraph {
    let m = graph.merged();
    let mut w = Work::new(&m);
    let mut heap: BinaryHeap<Reverse<Entry>> = (0..w.pieces.len() as u32)
        .filter_map(|p| w.entry(p, params).map(Reverse))
        .collect();
    while let Some(Reverse(e)) = heap.pop() {
        // Lazy invalidation: a piece that was joined or removed is dead, and
        // an alive piece keeps its leaf, length and junction radius.
        if !w.alive[e.piece as usize] {
            continue;
        }
        let Some((leaf, j)) = w.leg(e.piece) else {
            continue;
        };
        let removed_extent = w.extent(e.piece, leaf);
        w.remove(e.piece);
        if w.deg(j) != 2 {
            continue;
        }
        let (a, b) = (w.adj[j as usize][0], w.adj[j as usize][1]);
        let (ia, ib) = (
            w.insignificant_at(a, j, params),
            w.insignificant_at(b, j, params),
        );
        let next = if ia != ib {
            // The sibling leg insignificant at j goes too; j becomes a leaf
            // of the other branch, which may now be an insignificant leg.
            let (gone, stays) = if ia { (a, b) } else { (b, a) };
            let gone_leaf = w.other(gone, j);
            // j keeps the reach of what was cut behind it, so that a long
            // arm is not eroded junction by junction.
            w.reach[j as usize] = removed_extent.max(w.extent(gone, gone_leaf));
            w.remove(gone);
            Some(stays)
        } else {
            w.join(j)
        };
        if let Some(entry) = next.and_then(|p| w.entry(p, params)) {
            heap.push(Reverse(entry));
        }
    }
    m.filter_edges(|e, _| w.keep[e.0 as usize]).merged()
}

/// Shortest-path distances from one source, reusing buffers across calls so
/// that many components cost O(total size), not O(components × size).
struct Sweep {
    dist: Vec<f64>,
    pred: Vec<Option<EdgeId>>,
    touched: Vec<u32>,
}

impl Sweep {
    fn new(n: usize) -> Self {
        Self {
            dist: vec![f64::INFINITY; n],
            pred: vec![None; n],
            touched: Vec::new(),
        }
    }

    /// Dijkstra from `s`; returns the farthest leaf (ties: smaller node id).
    fn run(
        &mut self,
        g: &SkeletonGraph,
        adj: &[Vec<EdgeId>],
        len: &[f64],
        deg: &[usize],
        s: NodeId,
    ) -> (NodeId, f64) {
        for &t in &self.touched {
            self.dist[t as usize] = f64::INFINITY;
            self.pred[t as usize] = None;
        }
        self.touched.clear();
        let mut heap = BinaryHeap::new();
        self.dist[s.0 as usize] = 0.0;
        self.touched.push(s.0);
        heap.push(Reverse((OrdF(0.0), s.0)));
        let mut best = (s, 0.0);
        while let Some(Reverse((OrdF(d), n))) = heap.pop() {
            if d > self.dist[n as usize] {
                continue;
            }
            if deg[n as usize] == 1 && (d > best.1 || (d == best.1 && n < best.0 .0 && d > 0.0)) {
                best = (NodeId(n), d);
            }
            for &e in &adj[n as usize] {
                let o = g.opposite(e, NodeId(n));
                let nd = d + len[e.0 as usize];
                if nd < self.dist[o.0 as usize] {
                    if self.dist[o.0 as usize].is_infinite() {
                        self.touched.push(o.0);
                    }
                    self.dist[o.0 as usize] = nd;
                    self.pred[o.0 as usize] = Some(e);
                    heap.push(Reverse((OrdF(nd), o.0)));
                }
            }
        }
        best
    }
}

/// Total order on distances (never NaN: lengths are finite sums).
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrdF(f64);
impl Eq for OrdF {}
impl PartialOrd for OrdF {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for OrdF {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0)
    }
}

/// Farthest-leaf sweeps beyond the classic two; each can only lengthen the
/// path, and on trees the second sweep is already exact.
const MAX_SWEEPS: usize = 4;

fn trunk(graph: &SkeletonGraph) -> SkeletonGraph {
    let m = graph.merged();
    let adj = m.adjacency();
    let deg = m.degrees();
    let len: Vec<f64> = (0..m.edges().len())
        .map(|i| m.edge_length(EdgeId(i as u32)))
        .collect();
    let labels = m.component_labels();
    let mut leaves_of: Vec<Vec<NodeId>> = vec![Vec::new(); m.nodes().len()];
    for (n, &d) in deg.iter().enumerate() {
        if d == 1 {
            leaves_of[labels[n]].push(NodeId(n as u32));
        }
    }
    let mut keep = vec![false; m.edges().len()];
    let mut sweep = Sweep::new(m.nodes().len());
    let mut done = vec![false; m.nodes().len()];
    for e in m.edges() {
        let c = labels[e.a.0 as usize];
        if done[c] {
            continue;
        }
        done[c] = true;
        let leaves = &leaves_of[c];
        match leaves.len() {
            0 => {
                // A ring: keep the whole component.
                for (k, f) in m.edges().iter().enumerate() {
                    if labels[f.a.0 as usize] == c {
                        keep[k] = true;
                    }
                }
            }
            1 => {
                // Cycles and one leg: keep the cycles.
                let leg = adj[leaves[0].0 as usize][0];
                for (k, f) in m.edges().iter().enumerate() {
                    if labels[f.a.0 as usize] == c && EdgeId(k as u32) != leg {
                        keep[k] = true;
                    }
                }
            }
            _ => {
                let (mut a, _) = sweep.run(&m, &adj, &len, &deg, leaves[0]);
                let (mut b, mut d) = sweep.run(&m, &adj, &len, &deg, a);
                for _ in 2..MAX_SWEEPS {
                    let (c2, d2) = sweep.run(&m, &adj, &len, &deg, b);
                    if d2 <= d {
                        // Restore the predecessors of the sweep from a.
                        sweep.run(&m, &adj, &len, &deg, a);
                        break;
                    }
                    (a, b, d) = (b, c2, d2);
                }
                // Walk back from b to a along the predecessors of the sweep from a.
                let mut n = b;
                while n != a {
                    let e = sweep.pred[n.0 as usize].expect("b is reachable from a");
                    keep[e.0 as usize] = true;
                    n = m.opposite(e, n);
                }
            }
        }
    }
    m.filter_edges(|e, _| keep[e.0 as usize]).merged()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::GraphBuilder;
    use geo::Coord;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// A star: junction at the origin (radius r) with legs to the given ends.
    fn star(r: f64, ends: &[(f64, f64)]) -> SkeletonGraph {
        let mut b = GraphBuilder::new();
        for &(x, y) in ends {
            b.segment(c(0., 0.), c(x, y));
        }
        let mut g = b.finish_raw();
        g.nodes_mut()[0].radius = r;
        g
    }

    #[test]
    fn significance_rule_matches_spec() {
        let p = PruneParams::default();
        assert!(p.is_insignificant(1.9, 1.0));
        assert!(!p.is_insignificant(2.0, 1.0));
        let q = PruneParams {
            ratio: 0.5,
            min_length: 3.0,
            ..p
        };
        assert!(!q.is_insignificant(3.0, 2.0));
        assert!(q.is_insignificant(2.9, 1.0));
        assert!(significance(1.0, 0.0).is_infinite());
    }

    #[test]
    fn star_of_whiskers_keeps_the_two_most_significant_legs() {
        let g = star(1.0, &[(1.5, 0.), (-1.2, 0.), (0., 1.8)]);
        let p = prune(&g, &PruneParams::default());
        assert_eq!(p.edges().len(), 1);
        assert!((p.total_length() - 3.3).abs() < 1e-12);
        assert_eq!(p.leg_count(), 1);
    }

    #[test]
    fn significant_legs_survive_and_whiskers_go() {
        let g = star(1.0, &[(5., 0.), (-5., 0.), (0., 5.), (0., -1.5)]);
        let p = prune(&g, &PruneParams::default());
        assert_eq!(p.leg_count(), 3);
        assert!((p.total_length() - 15.0).abs() < 1e-12);
        assert!(insignificant_legs(&p, &PruneParams::default()).is_empty());
        assert_eq!(insignificant_legs(&g, &PruneParams::default()).len(), 1);
    }

    #[test]
    fn length_mode_uses_min_length_only() {
        let g = star(10.0, &[(5., 0.), (-5., 0.), (0., 5.), (0., -1.5)]);
        let params = PruneParams {
            mode: PruneMode::Length,
            min_length: 2.0,
            ..Default::default()
        };
        let p = prune(&g, &params);
        assert_eq!(p.leg_count(), 3);
        assert_eq!(prune(&g, &PruneParams::default()).leg_count(), 1);
    }

    #[test]
    fn cycle_keeps_its_ring_and_loses_whiskers() {
        // A square ring with one short whisker at each corner (r = 1).
        let mut b = GraphBuilder::new();
        let sq = [c(0., 0.), c(10., 0.), c(10., 10.), c(0., 10.)];
        for i in 0..4 {
            b.segment(sq[i], sq[(i + 1) % 4]);
            b.segment(sq[i], sq[i] + (sq[i] - c(5., 5.)) * 0.1);
        }
        let mut g = b.finish_raw();
        for n in g.nodes_mut() {
            n.radius = 1.0;
        }
        let p = prune(&g, &PruneParams::default());
        assert_eq!(p.leg_count(), 0);
        assert!((p.total_length() - 40.0).abs() < 1e-9);
        let t = prune(
            &g,
            &PruneParams {
                mode: PruneMode::Trunk,
                ..Default::default()
            },
        );
        let deg = t.degrees();
        assert_eq!(deg.iter().filter(|&&d| d == 1).count(), 2);
        assert!(deg.iter().all(|&d| d <= 2));
        assert_eq!(t.components(), 1);
    }

    #[test]
    fn trunk_is_the_tree_diameter() {
        let g = star(1.0, &[(5., 0.), (-7., 0.), (0., 6.), (0., -1.5)]);
        let t = prune(
            &g,
            &PruneParams {
                mode: PruneMode::Trunk,
                ..Default::default()
            },
        );
        assert_eq!(t.edges().len(), 1);
        assert!((t.total_length() - 13.0).abs() < 1e-12);
    }

    #[test]
    fn pruning_is_deterministic_and_idempotent() {
        let g = star(1.0, &[(1.5, 0.), (-1.5, 0.), (0., 1.5), (0., -1.5)]);
        let a = prune(&g, &PruneParams::default());
        assert_eq!(a, prune(&g, &PruneParams::default()));
        assert_eq!(a, prune(&a, &PruneParams::default()));
        assert_eq!(a.edges().len(), 1);
    }
}
