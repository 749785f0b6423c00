//! `trunk` pruning: the longest leaf-to-leaf path of each component, one
//! centreline per part.
//!
//! The two end leaves are found by repeated farthest-leaf sweeps (Dijkstra
//! over branch lengths): exact on trees (the tree diameter), a heuristic for
//! components with cycles, where the result is the shortest path between the
//! leaf pair found, so a river with islands stays one connected line from end
//! to end. A component with one leaf keeps its cycles without the leg; a
//! component without leaves (a ring) is kept.

use crate::graph::{Adjacency, EdgeId, NodeId, SkeletonGraph};
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// Shortest-path distances from one source, reusing buffers across calls so
/// that many components cost O(total size), not O(components × size).
pub(super) struct Sweep {
    pub(super) dist: Vec<f64>,
    pub(super) pred: Vec<Option<EdgeId>>,
    touched: Vec<NodeId>,
}

impl Sweep {
    pub(super) fn new(n: usize) -> Self {
        Self {
            dist: vec![f64::INFINITY; n],
            pred: vec![None; n],
            touched: Vec::new(),
        }
    }

    /// Dijkstra from `s`; returns the farthest leaf (ties: smaller node id).
    pub(super) fn run(
        &mut self,
        g: &SkeletonGraph,
        adj: &Adjacency,
        len: &[f64],
        deg: &[usize],
        s: NodeId,
    ) -> (NodeId, f64) {
        let mut best = (s, 0.0);
        self.search(
            g,
            adj,
            len,
            s,
            |_| true,
            &|| false,
            |n, d| {
                if deg[n.index()] == 1 && (d > best.1 || (d == best.1 && n < best.0 && d > 0.0)) {
                    best = (n, d);
                }
            },
        );
        best
    }

    /// Dijkstra from `s` over the edges `usable` accepts, telling `settled`
    /// each node with its distance as it is settled; `None` when `expired()`
    /// (asked every 4 096 nodes taken from the queue) said to stop.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn search(
        &mut self,
        g: &SkeletonGraph,
        adj: &Adjacency,
        len: &[f64],
        s: NodeId,
        usable: impl Fn(EdgeId) -> bool,
        expired: &dyn Fn() -> bool,
        mut settled: impl FnMut(NodeId, f64),
    ) -> Option<()> {
        for &t in &self.touched {
            self.dist[t.index()] = f64::INFINITY;
            self.pred[t.index()] = None;
        }
        self.touched.clear();
        let mut heap = BinaryHeap::new();
        self.dist[s.index()] = 0.0;
        self.touched.push(s);
        heap.push(Reverse((OrdF(0.0), s)));
        let mut pops = 0u32;
        while let Some(Reverse((OrdF(d), n))) = heap.pop() {
            pops = pops.wrapping_add(1);
            if pops.is_multiple_of(4096) && expired() {
                return None;
            }
            if d > self.dist[n.index()] {
                continue;
            }
            settled(n, d);
            for &e in &adj[n.index()] {
                if !usable(e) {
                    continue;
                }
                let o = g.opposite(e, n);
                let nd = d + len[e.index()];
                if nd < self.dist[o.index()] {
                    if self.dist[o.index()].is_infinite() {
                        self.touched.push(o);
                    }
                    self.dist[o.index()] = nd;
                    self.pred[o.index()] = Some(e);
                    heap.push(Reverse((OrdF(nd), o)));
                }
            }
        }
        Some(())
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

/// The kept edges of `m` (a merged graph): the trunk of every component.
pub fn mask(m: &SkeletonGraph) -> Vec<bool> {
    let adj = m.adjacency();
    let deg = m.degrees();
    let len: Vec<f64> = (0..m.edges().len())
        .map(|i| m.edge_length(EdgeId::from_index(i)))
        .collect();
    let labels = m.component_labels();
    let mut leaves_of: Vec<Vec<NodeId>> = vec![Vec::new(); m.nodes().len()];
    for (n, &d) in deg.iter().enumerate() {
        if d == 1 {
            leaves_of[labels[n]].push(NodeId::from_index(n));
        }
    }
    let mut keep = vec![false; m.edges().len()];
    let mut sweep = Sweep::new(m.nodes().len());
    let mut done = vec![false; m.nodes().len()];
    for e in m.edges() {
        let c = labels[e.a.index()];
        if done[c] {
            continue;
        }
        done[c] = true;
        let leaves = &leaves_of[c];
        match leaves.len() {
            0 => {
                // A ring: keep the whole component.
                for (k, f) in m.edges().iter().enumerate() {
                    if labels[f.a.index()] == c {
                        keep[k] = true;
                    }
                }
            }
            1 => {
                // Cycles and one leg: keep the cycles.
                let leg = adj[leaves[0].index()][0];
                for (k, f) in m.edges().iter().enumerate() {
                    if labels[f.a.index()] == c && EdgeId::from_index(k) != leg {
                        keep[k] = true;
                    }
                }
            }
            _ => {
                let (mut a, _) = sweep.run(m, &adj, &len, &deg, leaves[0]);
                let (mut b, mut d) = sweep.run(m, &adj, &len, &deg, a);
                for _ in 2..MAX_SWEEPS {
                    let (c2, d2) = sweep.run(m, &adj, &len, &deg, b);
                    if d2 <= d {
                        // Restore the predecessors of the sweep from a.
                        sweep.run(m, &adj, &len, &deg, a);
                        break;
                    }
                    (a, b, d) = (b, c2, d2);
                }
                // Walk back from b to a along the predecessors of the sweep from a.
                let mut n = b;
                while n != a {
                    let e = sweep.pred[n.index()].expect("b is reachable from a");
                    keep[e.index()] = true;
                    n = m.opposite(e, n);
                }
            }
        }
    }
    keep
}

/// The edges of a shortest path from `from` to `to` in `g` over the edges for
/// which `usable` is true (lengths = edge lengths), or `None` when `to` is
/// not reachable.
pub(crate) fn shortest_path(
    g: &SkeletonGraph,
    usable: &[bool],
    from: NodeId,
    to: NodeId,
) -> Option<Vec<EdgeId>> {
    let adj = Adjacency::of(g, |e| usable[e.index()]);
    let len: Vec<f64> = (0..g.edges().len())
        .map(|i| g.edge_length(EdgeId::from_index(i)))
        .collect();
    let deg: Vec<usize> = adj.iter().map(<[EdgeId]>::len).collect();
    let mut sweep = Sweep::new(g.nodes().len());
    sweep.run(g, &adj, &len, &deg, from);
    if from != to && sweep.pred[to.index()].is_none() {
        return None;
    }
    let mut path = Vec::new();
    let mut n = to;
    while n != from {
        let e = sweep.pred[n.index()]?;
        path.push(e);
        n = g.opposite(e, n);
    }
    Some(path)
}
