//! The working graph of leg pruning: a multigraph over *pieces* (original
//! edges of the merged graph, or two pieces joined at a former degree-2
//! node), with what both `significance`/`length` pruning (`legs`) and side
//! pruning (`sides`) do to it — remove a piece, join at a node, walk along
//! a piece.

use crate::geometry::Boundary;
use crate::graph::line::point_at;
use crate::graph::{EdgeId, NodeId, SkeletonGraph};
use geo::Coord;
use smallvec::SmallVec;

/// A branch of the working graph: an original edge of the merged graph, or
/// two pieces joined at a former degree-2 node (a binary tree, so joining is
/// O(1) however long the chain).
#[derive(Debug, Clone, Copy)]
pub(super) struct Piece {
    pub(super) u: NodeId,
    pub(super) v: NodeId,
    pub(super) len: f64,
    pub(super) kind: Kind,
}

#[derive(Debug, Clone, Copy)]
pub(super) enum Kind {
    Orig(EdgeId),
    /// Pieces `a` (from `u`) and `b` (to `v`) joined at node `at`.
    Join {
        a: u32,
        b: u32,
        at: NodeId,
    },
}

/// Mutable multigraph over pieces (numbered in the order made; piece `i`
/// of the first `edges().len()` is edge `i`). Invariant: `adj[n]` lists the
/// alive pieces incident to node n (a loop twice), and an alive piece's
/// originals are kept.
pub(super) struct Work<'a> {
    pub(super) graph: &'a SkeletonGraph,
    pub(super) boundary: &'a Boundary,
    pub(super) pieces: Vec<Piece>,
    pub(super) alive: Vec<bool>,
    /// The pieces at each node, inline up to three (a skeleton's nodes have
    /// one to three: no allocation per node, 16 bytes less each than a
    /// `Vec` and its block — 30 MB at a million boundary vertices).
    pub(super) adj: Vec<SmallVec<[u32; 3]>>,
    pub(super) keep: Vec<bool>,
    /// How far the skeleton (with its discs) reached beyond each leaf before
    /// pruning: r_ℓ for an original leaf, the extent of the legs removed
    /// behind a junction that became a leaf.
    pub(super) reach: Vec<f64>,
}

impl<'a> Work<'a> {
    pub(super) fn new(graph: &'a SkeletonGraph, boundary: &'a Boundary) -> Self {
        let mut w = Work {
            graph,
            boundary,
            pieces: Vec::with_capacity(graph.edges().len() * 2),
            alive: Vec::new(),
            adj: vec![SmallVec::new(); graph.nodes().len()],
            keep: vec![true; graph.edges().len()],
            reach: graph.nodes().iter().map(|n| n.radius.max(0.0)).collect(),
        };
        for (i, e) in graph.edges().iter().enumerate() {
            let len = graph.edge_length(EdgeId::from_index(i));
            w.push_piece(e.a, e.b, len, Kind::Orig(EdgeId::from_index(i)));
        }
        w
    }

    pub(super) fn push_piece(&mut self, u: NodeId, v: NodeId, len: f64, kind: Kind) -> u32 {
        let id = self.pieces.len() as u32;
        self.pieces.push(Piece { u, v, len, kind });
        self.alive.push(true);
        self.adj[u.index()].push(id);
        self.adj[v.index()].push(id);
        id
    }

    pub(super) fn deg(&self, n: NodeId) -> usize {
        self.adj[n.index()].len()
    }

    pub(super) fn other(&self, p: u32, n: NodeId) -> NodeId {
        let pc = &self.pieces[p as usize];
        if pc.u == n {
            pc.v
        } else {
            pc.u
        }
    }

    /// `(leaf, junction)` when piece `p` is a leg at a junction of degree ≥ 3.
    pub(super) fn leg(&self, p: u32) -> Option<(NodeId, NodeId)> {
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
    pub(super) fn remove(&mut self, p: u32) {
        self.alive[p as usize] = false;
        let Piece { u, v, .. } = self.pieces[p as usize];
        self.adj[u.index()].retain(|q| *q != p);
        self.adj[v.index()].retain(|q| *q != p);
        let mut stack = vec![p];
        while let Some(q) = stack.pop() {
            match self.pieces[q as usize].kind {
                Kind::Orig(e) => self.keep[e.index()] = false,
                Kind::Join { a, b, .. } => stack.extend([a, b]),
            }
        }
    }

    /// Joins the two distinct pieces at degree-2 node `j` into one.
    pub(super) fn join(&mut self, j: NodeId) -> Option<u32> {
        let (p1, p2) = (self.adj[j.index()][0], self.adj[j.index()][1]);
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
            kind: Kind::Join {
                a: p1,
                b: p2,
                at: j,
            },
        });
        self.alive.push(true);
        self.alive[p1 as usize] = false;
        self.alive[p2 as usize] = false;
        self.adj[j.index()].clear();
        for (n, old) in [(u, p1), (v, p2)] {
            let slot = self.adj[n.index()]
                .iter_mut()
                .find(|q| **q == old)
                .expect("adjacency lists every alive piece");
            *slot = id;
        }
        Some(id)
    }

    /// Extent of leg `p` seen from its junction: its length plus the reach
    /// of its leaf.
    pub(super) fn extent(&self, p: u32, leaf: NodeId) -> f64 {
        self.pieces[p as usize].len + self.reach[leaf.index()]
    }

    /// The interior points of piece `p` (every original edge it joins, with
    /// the nodes where they were joined).
    pub(super) fn piece_coords(&self, p: u32) -> Vec<Coord<f64>> {
        let mut out = Vec::new();
        let mut stack = vec![p];
        while let Some(q) = stack.pop() {
            match self.pieces[q as usize].kind {
                Kind::Orig(e) => out.extend(self.graph.edge(e).interior.iter().copied()),
                Kind::Join { a, b, at } => {
                    out.push(self.graph.node(at).pos);
                    stack.extend([a, b]);
                }
            }
        }
        out
    }

    /// The point at arc length `s` along piece `p` walked from its end `from`.
    pub(super) fn point_at(&self, p: u32, from: NodeId, s: f64) -> Coord<f64> {
        let (mut p, mut from, mut s) = (p, from, s);
        loop {
            let pc = self.pieces[p as usize];
            match pc.kind {
                Kind::Orig(e) => {
                    let coords = self.graph.oriented_coords(e, from);
                    return point_at(&coords, s);
                }
                Kind::Join { a, b, at } => {
                    // `a` runs from `u` to `at`, `b` from `at` to `v`.
                    let (first, second) = if from == pc.u { (a, b) } else { (b, a) };
                    let l1 = self.pieces[first as usize].len;
                    if s <= l1 {
                        p = first;
                    } else {
                        p = second;
                        from = at;
                        s -= l1;
                    }
                }
            }
        }
    }

    pub(super) fn radius(&self, n: NodeId) -> f64 {
        self.graph.node(n).radius
    }
}
