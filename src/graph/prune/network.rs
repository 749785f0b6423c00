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
//! The cost is one Dijkstra per terminal on the merged graph (its branches),
//! O(k · b log b) for k terminals and b branches.

use super::trunk::Sweep;
use crate::graph::{EdgeId, NodeId, SkeletonGraph};

/// The kept edges of `m` (a merged graph): every shortest path between two
/// of `terminals`, or with one terminal the path to its farthest leaf.
/// Terminals in another component than all others keep nothing.
pub(crate) fn mask(m: &SkeletonGraph, terminals: &[NodeId]) -> Vec<bool> {
    let adj = m.adjacency();
    let deg = m.degrees();
    let len: Vec<f64> = (0..m.edges().len())
        .map(|i| m.edge_length(EdgeId::from_index(i)))
        .collect();
    let mut keep = vec![false; m.edges().len()];
    let mut sweep = Sweep::new(m.nodes().len());
    let mut walk_back = |sweep: &Sweep, from: NodeId, to: NodeId| {
        if sweep.dist[to.index()].is_infinite() {
            return;
        }
        let mut n = to;
        while n != from {
            let Some(e) = sweep.pred[n.index()] else {
                return;
            };
            keep[e.index()] = true;
            n = m.opposite(e, n);
        }
    };
    match terminals {
        [] => {}
        [t] => {
            let (far, _) = sweep.run(m, &adj, &len, &deg, *t);
            walk_back(&sweep, *t, far);
        }
        _ => {
            for (i, &t) in terminals[..terminals.len() - 1].iter().enumerate() {
                sweep.run(m, &adj, &len, &deg, t);
                for &u in &terminals[i + 1..] {
                    walk_back(&sweep, t, u);
                }
            }
        }
    }
    keep
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

    fn kept(m: &SkeletonGraph, keep: &[bool]) -> SkeletonGraph {
        m.filter_edges(|e, _| keep[e.index()]).merged()
    }

    #[test]
    fn two_ends_keep_the_shorter_channel_and_no_bay() {
        let m = river_with_island();
        let keep = mask(&m, &[node_at(&m, c(0., 20.)), node_at(&m, c(100., 20.))]);
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
        let keep = mask(&m, &ends.map(|p| node_at(&m, p)));
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
        let keep = mask(&m, &[node_at(&m, c(20., 40.))]);
        let g = kept(&m, &keep);
        let leaves = leaves(&g);
        assert_eq!(leaves.len(), 2);
        assert!(
            leaves.contains(&c(20., 40.)) && leaves.contains(&c(100., 20.)),
            "{leaves:?}"
        );
    }
}
