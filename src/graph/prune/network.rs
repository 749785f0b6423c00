//! `network` pruning: the through-lines of a line network.
//!
//! A lake or river inside a line network needs the lines from every point
//! where a network line meets it to every other — its inflows, outflows and
//! tributaries — and nothing else: not every bay's arm. Given the graph's
//! *terminals* (its nodes at the connection points), the kept graph is the
//! **union of the shortest paths between every pair of terminals**, lengths
//! measured along the skeleton:
//!
//! * on a tree that is exactly the smallest subtree joining the terminals,
//!   whose leaves are the terminals;
//! * around an island, a channel is kept when it is the shorter way between
//!   some two connections: a lake with an island between its inflow and its
//!   outflow keeps the shorter side only, while a river whose lines meet both
//!   channels (a tributary on each bank) keeps both, each serving its own
//!   connections. One rule, no threshold, the same for every method;
//! * with one terminal (a spring or a terminal lake), the path from it to the
//!   leaf farthest along the skeleton — the far tip of the axis.
//!
//! The cost is near-linear in the graph and the connection points: a
//! shortest path between two terminals crosses the graph's *blocks* (its
//! biconnected components) through their cut vertices, and within a block it
//! is a shortest path between two of the block's *portals* — its terminals and
//! the cut vertices with a terminal behind them. So a bridge (every edge of a
//! tree) is kept exactly when both its sides hold a terminal, and a Dijkstra
//! runs only inside a block with cycles (around islands), once per portal of
//! it: O(n + Σ p_B · b_B log b_B) for blocks of b_B edges and p_B portals,
//! instead of one Dijkstra of the whole graph per terminal and a walk per
//! pair of terminals (seconds at 2 000 connection points, minutes at
//! 10 000). The walk can be stopped: `expired` is asked between and during
//! the Dijkstras (a feature's time budget).

use super::trunk::Sweep;
use crate::graph::{EdgeId, NodeId, SkeletonGraph};

/// The kept edges of `m` (a merged graph): every shortest path between two
/// of `terminals`, or with one terminal the path to its farthest leaf.
/// Terminals in another component than all others keep nothing. `None`
/// when `expired()` said the time is up before the walk was done.
pub(crate) fn mask(
    m: &SkeletonGraph,
    terminals: &[NodeId],
    expired: &dyn Fn() -> bool,
) -> Option<Vec<bool>> {
    let mut keep = vec![false; m.edges().len()];
    match terminals {
        [] => {}
        [t] => {
            let adj = m.adjacency();
            let deg = m.degrees();
            let len: Vec<f64> = (0..m.edges().len())
                .map(|i| m.edge_length(EdgeId::from_index(i)))
                .collect();
            let mut sweep = Sweep::new(m.nodes().len());
            let (far, _) = sweep.run(m, &adj, &len, &deg, *t);
            let mut n = far;
            while n != *t {
                let e = sweep.pred[n.index()]?;
                keep[e.index()] = true;
                n = m.opposite(e, n);
            }
        }
        _ => between(m, terminals, &mut keep, expired)?,
    }
    Some(keep)
}

/// No block: a loop edge (never on a simple path).
const LOOP: u32 = u32::MAX;

/// The biconnected components of `m`: each edge's block (`LOOP` for a loop
/// edge) and the number of blocks (Tarjan's, without recursion).
fn blocks(m: &SkeletonGraph, adj: &crate::graph::Adjacency) -> (Vec<u32>, usize) {
    let n = m.nodes().len();
    let mut block = vec![LOOP; m.edges().len()];
    let mut disc = vec![u32::MAX; n];
    let mut low = vec![0u32; n];
    let mut time = 0u32;
    let mut count = 0usize;
    let mut edge_stack: Vec<EdgeId> = Vec::new();
    // (node, the edge it was entered by, next incident edge to look at)
    let mut stack: Vec<(NodeId, Option<EdgeId>, usize)> = Vec::new();
    for root in 0..n {
        if disc[root] != u32::MAX || adj[root].is_empty() {
            continue;
        }
        disc[root] = time;
        low[root] = time;
        time += 1;
        stack.push((NodeId::from_index(root), None, 0));
        while let Some(top) = stack.last_mut() {
            let (u, via, next) = *top;
            if let Some(&e) = adj[u.index()].get(next) {
                top.2 += 1;
                if Some(e) == via {
                    continue;
                }
                let v = m.opposite(e, u);
                if v == u {
                    continue; // a loop edge stays LOOP
                }
                if disc[v.index()] == u32::MAX {
                    disc[v.index()] = time;
                    low[v.index()] = time;
                    time += 1;
                    edge_stack.push(e);
                    stack.push((v, Some(e), 0));
                } else if disc[v.index()] < disc[u.index()] {
                    // A back edge (to an ancestor), seen once from below.
                    low[u.index()] = low[u.index()].min(disc[v.index()]);
                    edge_stack.push(e);
                }
                continue;
            }
            stack.pop();
            let (Some(e), Some(&(p, _, _))) = (via, stack.last()) else {
                continue;
            };
            low[p.index()] = low[p.index()].min(low[u.index()]);
            if low[u.index()] >= disc[p.index()] {
                // p separates u's subtree: the edges down to e are a block.
                while let Some(f) = edge_stack.pop() {
                    block[f.index()] = count as u32;
                    if f == e {
                        break;
                    }
                }
                count += 1;
            }
        }
    }
    (block, count)
}

/// `mask` for two or more terminals: the blocks' portals and the shortest
/// paths between them.
fn between(
    m: &SkeletonGraph,
    terminals: &[NodeId],
    keep: &mut [bool],
    expired: &dyn Fn() -> bool,
) -> Option<()> {
    let adj = m.adjacency();
    let tree = BlockTree::of(m, &adj, terminals);
    // Each block's portals; a block with two or more keeps the shortest
    // paths between them.
    let len: Vec<f64> = (0..m.edges().len())
        .map(|i| m.edge_length(EdgeId::from_index(i)))
        .collect();
    let mut search = BlockSearch::new(m.nodes().len(), m.edges().len());
    for b in 0..tree.members.len() {
        let portals = tree.portals(b);
        if portals.len() < 2 {
            continue;
        }
        if let [e] = tree.edges_of[b][..] {
            keep[e.index()] = true; // a bridge between two terminals' sides
            continue;
        }
        if expired() {
            return None;
        }
        let block = &tree.block;
        search.keep_between(m, &adj, &len, block, b as u32, &portals, keep, expired)?;
    }
    Some(())
}

/// The block–cut tree of a merged graph (tree nodes: its blocks, then its
/// cut vertices), rooted per component, with the terminals below each
/// tree node.
struct BlockTree {
    /// The block of each edge (`LOOP` for a loop).
    block: Vec<u32>,
    /// Each block's edges.
    edges_of: Vec<Vec<EdgeId>>,
    /// Each block's vertices.
    members: Vec<Vec<NodeId>>,
    /// How many blocks each vertex lies in (two or more: a cut vertex).
    in_blocks: Vec<u32>,
    is_terminal: Vec<bool>,
    /// Each cut vertex's tree node.
    tree_id: Vec<u32>,
    /// Each tree node's parent (`u32::MAX` at a root).
    parent: Vec<u32>,
    /// The terminals in each tree node's subtree.
    below: Vec<usize>,
    /// Each tree node's root.
    root_of: Vec<u32>,
}

impl BlockTree {
    fn of(m: &SkeletonGraph, adj: &crate::graph::Adjacency, terminals: &[NodeId]) -> Self {
        let n = m.nodes().len();
        let (block, count) = blocks(m, adj);
        let (edges_of, members, in_blocks) = block_members(m, &block, count);
        let mut is_terminal = vec![false; n];
        terminals.iter().for_each(|v| is_terminal[v.index()] = true);
        let mut tree = Self {
            block,
            edges_of,
            members,
            in_blocks,
            is_terminal,
            tree_id: vec![u32::MAX; n],
            parent: Vec::new(),
            below: Vec::new(),
            root_of: Vec::new(),
        };
        let mut cuts: Vec<NodeId> = Vec::new();
        for v in (0..n).map(NodeId::from_index) {
            if tree.is_cut(v) {
                tree.tree_id[v.index()] = (count + cuts.len()) as u32;
                cuts.push(v);
            }
        }
        let size = count + cuts.len();
        let mut tree_adj: Vec<Vec<u32>> = vec![Vec::new(); size];
        let mut weight = vec![0usize; size];
        for (b, vs) in tree.members.iter().enumerate() {
            for &v in vs {
                if tree.is_cut(v) {
                    let c = tree.tree_id[v.index()];
                    tree_adj[b].push(c);
                    tree_adj[c as usize].push(b as u32);
                } else if tree.is_terminal[v.index()] {
                    weight[b] += 1;
                }
            }
        }
        for (k, v) in cuts.iter().enumerate() {
            weight[count + k] = usize::from(tree.is_terminal[v.index()]);
        }
        let (parent, root_of, order) = rooted(&tree_adj);
        let mut below = weight;
        for &x in order.iter().rev() {
            let p = parent[x as usize];
            if p != u32::MAX {
                below[p as usize] += below[x as usize];
            }
        }
        (tree.parent, tree.below, tree.root_of) = (parent, below, root_of);
        tree
    }

    fn is_cut(&self, v: NodeId) -> bool {
        self.in_blocks[v.index()] >= 2
    }

    /// Block `b`'s portals: its terminals, and its cut vertices with a
    /// terminal behind them.
    fn portals(&self, b: usize) -> Vec<NodeId> {
        let total = self.below[self.root_of[b] as usize];
        self.members[b]
            .iter()
            .copied()
            .filter(|v| {
                if !self.is_cut(*v) {
                    return self.is_terminal[v.index()];
                }
                let c = self.tree_id[v.index()] as usize;
                let behind = if self.parent[b] == c as u32 {
                    total - self.below[b]
                } else {
                    self.below[c]
                };
                behind > 0
            })
            .collect()
    }
}

/// Each block's edges and vertices (in the order its edges meet them), and
/// how many blocks each vertex lies in.
fn block_members(
    m: &SkeletonGraph,
    block: &[u32],
    count: usize,
) -> (Vec<Vec<EdgeId>>, Vec<Vec<NodeId>>, Vec<u32>) {
    let n = m.nodes().len();
    let mut edges_of: Vec<Vec<EdgeId>> = vec![Vec::new(); count];
    for (i, &k) in block.iter().enumerate() {
        if k != LOOP {
            edges_of[k as usize].push(EdgeId::from_index(i));
        }
    }
    let mut last = vec![u32::MAX; n];
    let mut in_blocks = vec![0u32; n];
    let members = edges_of
        .iter()
        .enumerate()
        .map(|(b, es)| {
            let mut vs = Vec::new();
            for &e in es {
                let ed = m.edge(e);
                for v in [ed.a, ed.b] {
                    if last[v.index()] != b as u32 {
                        last[v.index()] = b as u32;
                        in_blocks[v.index()] += 1;
                        vs.push(v);
                    }
                }
            }
            vs
        })
        .collect();
    (edges_of, members, in_blocks)
}

/// A forest given by adjacency lists, rooted at the lowest node of each
/// tree: each node's parent (`u32::MAX` at a root) and root, and the nodes
/// in breadth-first order.
fn rooted(tree_adj: &[Vec<u32>]) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let size = tree_adj.len();
    let mut parent = vec![u32::MAX; size];
    let mut root_of = vec![0u32; size];
    let mut order: Vec<u32> = Vec::with_capacity(size);
    let mut seen = vec![false; size];
    for r in 0..size {
        if seen[r] {
            continue;
        }
        seen[r] = true;
        let start = order.len();
        order.push(r as u32);
        let mut i = start;
        while i < order.len() {
            let x = order[i] as usize;
            root_of[x] = r as u32;
            for &y in &tree_adj[x] {
                if !seen[y as usize] {
                    seen[y as usize] = true;
                    parent[y as usize] = x as u32;
                    order.push(y);
                }
            }
            i += 1;
        }
    }
    (parent, root_of, order)
}

/// Searches inside one block, with buffers reused across blocks.
struct BlockSearch {
    sweep: Sweep,
    /// The search that last walked each edge back (walks of one search
    /// stop where another of the same search went before: its tree).
    walked: Vec<u32>,
    searches: u32,
}

impl BlockSearch {
    fn new(nodes: usize, edges: usize) -> Self {
        Self {
            sweep: Sweep::new(nodes),
            walked: vec![u32::MAX; edges],
            searches: 0,
        }
    }

    /// Keeps the shortest paths inside block `b` between every two of
    /// `portals`.
    #[allow(clippy::too_many_arguments)]
    fn keep_between(
        &mut self,
        m: &SkeletonGraph,
        adj: &crate::graph::Adjacency,
        len: &[f64],
        block: &[u32],
        b: u32,
        portals: &[NodeId],
        keep: &mut [bool],
        expired: &dyn Fn() -> bool,
    ) -> Option<()> {
        for (i, &s) in portals[..portals.len() - 1].iter().enumerate() {
            let inside = |e: EdgeId| block[e.index()] == b;
            self.sweep
                .search(m, adj, len, s, inside, expired, |_, _| {})?;
            self.searches += 1;
            for &t in &portals[i + 1..] {
                let mut v = t;
                while v != s {
                    let Some(e) = self.sweep.pred[v.index()] else {
                        break;
                    };
                    if self.walked[e.index()] == self.searches {
                        break;
                    }
                    self.walked[e.index()] = self.searches;
                    keep[e.index()] = true;
                    v = m.opposite(e, v);
                }
            }
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PreparedPolygon;
    use crate::graph::GraphBuilder;
    use geo::{polygon, Coord};

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    fn node_at(g: &SkeletonGraph, p: Coord<f64>) -> NodeId {
        NodeId::from_index(g.nodes().iter().position(|n| n.pos == p).unwrap())
    }

    /// A 100 × 40 box with a ring around an island (x 40–60) on its axis,
    /// bays off the axis at x = 20 (north) and x = 80 (south, shorter than the axis beyond it).
    fn river_with_island() -> SkeletonGraph {
        let p = PreparedPolygon::new(
            &polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 40.), (x: 0., y: 40.)],
        )
        .unwrap();
        let mut b = GraphBuilder::new();
        b.polyline(&[c(0., 20.), c(20., 20.)]);
        b.polyline(&[c(20., 20.), c(40., 20.)]);
        b.polyline(&[c(40., 20.), c(50., 30.)]);
        b.polyline(&[c(50., 30.), c(60., 20.)]);
        b.polyline(&[c(40., 20.), c(50., 12.), c(60., 20.)]);
        b.polyline(&[c(60., 20.), c(80., 20.)]);
        b.polyline(&[c(80., 20.), c(100., 20.)]);
        b.polyline(&[c(20., 20.), c(20., 40.)]);
        b.polyline(&[c(80., 20.), c(85., 5.)]);
        b.polyline(&[c(50., 30.), c(50., 40.)]);
        b.finish(p.boundary()).merged()
    }

    /// Every vertex of the graph's lines.
    fn vertices(g: &SkeletonGraph) -> Vec<Coord<f64>> {
        (0..g.edges().len())
            .flat_map(|e| g.edge_coords(EdgeId::from_index(e)))
            .collect()
    }

    fn leaves(g: &SkeletonGraph) -> Vec<Coord<f64>> {
        g.degrees()
            .iter()
            .enumerate()
            .filter(|(_, &d)| d == 1)
            .map(|(n, _)| g.nodes()[n].pos)
            .collect()
    }

    fn mask_all(m: &SkeletonGraph, t: &[NodeId]) -> Vec<bool> {
        mask(m, t, &|| false).unwrap()
    }

    fn kept(m: &SkeletonGraph, keep: &[bool]) -> SkeletonGraph {
        m.filter_edges(|e, _| keep[e.index()]).merged()
    }

    #[test]
    fn two_ends_keep_the_shorter_channel_and_no_bay() {
        let m = river_with_island();
        let keep = mask_all(&m, &[node_at(&m, c(0., 20.)), node_at(&m, c(100., 20.))]);
        let g = kept(&m, &keep);
        assert_eq!(
            leaves(&g),
            vec![c(0., 20.), c(100., 20.)],
            "only the two ends are leaves"
        );
        let v = vertices(&g);
        assert!(
            !v.contains(&c(20., 40.)) && !v.contains(&c(85., 5.)),
            "no bay"
        );
        assert!(
            v.contains(&c(50., 12.)) && !v.contains(&c(50., 30.)),
            "the south channel only"
        );
        // The south channel (two legs of √164 ≈ 12.8) is shorter than the
        // north one (two of √200 ≈ 14.1).
        assert!((g.total_length() - (80.0 + 2.0 * 164f64.sqrt())).abs() < 1e-9);
    }

    #[test]
    fn a_connection_on_each_channel_keeps_both_channels() {
        let m = river_with_island();
        let ends = [c(0., 20.), c(100., 20.), c(50., 40.), c(85., 5.)];
        let keep = mask_all(&m, &ends.map(|p| node_at(&m, p)));
        let g = kept(&m, &keep);
        let leaves = leaves(&g);
        assert_eq!(leaves.len(), 4, "{leaves:?}");
        assert!(ends.iter().all(|e| leaves.contains(e)));
        let v = vertices(&g);
        assert!(v.contains(&c(50., 12.)), "the south channel stays");
        assert!(!v.contains(&c(20., 40.)), "the bay goes");
    }

    #[test]
    fn one_connection_runs_to_the_farthest_tip() {
        let m = river_with_island();
        let keep = mask_all(&m, &[node_at(&m, c(20., 40.))]);
        let g = kept(&m, &keep);
        let leaves = leaves(&g);
        assert_eq!(leaves.len(), 2);
        assert!(
            leaves.contains(&c(20., 40.)) && leaves.contains(&c(100., 20.)),
            "{leaves:?}"
        );
    }

    /// The union of the shortest paths between every pair of terminals,
    /// one Dijkstra of the whole graph per terminal (the definition).
    fn by_pairs(m: &SkeletonGraph, terminals: &[NodeId]) -> Vec<bool> {
        let adj = m.adjacency();
        let deg = m.degrees();
        let len: Vec<f64> = (0..m.edges().len())
            .map(|i| m.edge_length(EdgeId::from_index(i)))
            .collect();
        let mut keep = vec![false; m.edges().len()];
        let mut sweep = Sweep::new(m.nodes().len());
        for (i, &t) in terminals.iter().enumerate() {
            sweep.run(m, &adj, &len, &deg, t);
            for &u in &terminals[i + 1..] {
                let mut n = u;
                while n != t {
                    let Some(e) = sweep.pred[n.index()] else {
                        break;
                    };
                    keep[e.index()] = true;
                    n = m.opposite(e, n);
                }
            }
        }
        keep
    }

    proptest::proptest! {
        /// Through blocks and portals, the kept edges are those of every
        /// pairwise shortest path: random jittered grids (a tree with
        /// extra edges making cycles, and leaves), random terminals.
        #[test]
        fn the_blocks_keep_what_every_pair_of_terminals_keeps(
            seed in 0u64..1_000_000,
            extra in 0usize..12,
            terminals in 2usize..9,
        ) {
            let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let mut next = move |n: usize| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((state >> 33) as usize) % n
            };
            let side = 6;
            let mut b = GraphBuilder::new();
            // A random spanning tree of the grid, then extra grid edges.
            let mut inside = vec![false; side * side];
            inside[0] = true;
            let mut edges = Vec::new();
            let nb = |v: usize| {
                let (i, j) = (v % side, v / side);
                let mut out = Vec::new();
                if i > 0 { out.push(v - 1) }
                if i + 1 < side { out.push(v + 1) }
                if j > 0 { out.push(v - side) }
                if j + 1 < side { out.push(v + side) }
                out
            };
            for _ in 0..side * side * 8 {
                let v = next(side * side);
                if !inside[v] { continue; }
                let ns = nb(v);
                let w = ns[next(ns.len())];
                if !inside[w] {
                    inside[w] = true;
                    edges.push((v, w));
                }
            }
            for _ in 0..extra {
                let v = next(side * side);
                let ns = nb(v);
                let w = ns[next(ns.len())];
                if inside[v] && inside[w] && !edges.contains(&(v, w)) && !edges.contains(&(w, v)) {
                    edges.push((v, w));
                }
            }
            // Jittered, so that no two paths tie.
            let pos: Vec<Coord<f64>> = (0..side * side)
                .map(|v| {
                    let (dx, dy) = (next(1000) as f64 * 3e-3, next(1000) as f64 * 3e-3);
                    c((v % side) as f64 * 10.0 + dx, (v / side) as f64 * 10.0 + dy)
                })
                .collect();
            for &(v, w) in &edges {
                b.segment(pos[v], pos[w]);
            }
            let g = b.finish_raw();
            // A tree that never grew from its first vertex has no node.
            proptest::prop_assume!(g.nodes().len() >= 2);
            let mut ts: Vec<NodeId> = (0..terminals)
                .map(|_| NodeId::from_index(next(g.nodes().len())))
                .collect();
            ts.sort();
            ts.dedup();
            proptest::prop_assume!(ts.len() >= 2);
            proptest::prop_assert_eq!(mask_all(&g, &ts), by_pairs(&g, &ts));
        }
    }
}
