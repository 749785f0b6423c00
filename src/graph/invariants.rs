//! [`SkeletonGraph::check_invariants`]: the invariants written above
//! [`SkeletonGraph`], checked.

use super::{EdgeId, SkeletonGraph};
use geo::Coord;

fn finite(c: Coord<f64>) -> bool {
    c.x.is_finite() && c.y.is_finite()
}

impl SkeletonGraph {
    /// Checks the invariants written above [`SkeletonGraph`]: the first
    /// that is broken, and where, or `Ok`.
    ///
    /// Public (not `#[cfg(test)]`) because the integration tests in
    /// `tests/` and the author of a new method (see `tests/all/registry.rs`)
    /// call it on graphs the library made, and they cannot see the
    /// library's test-only items; hidden from the documentation because it
    /// is a check for tests, not part of the graph's interface. It costs
    /// nothing unless called: no step calls it.
    #[doc(hidden)]
    pub fn check_invariants(&self) -> Result<(), String> {
        for (i, n) in self.nodes.iter().enumerate() {
            if !finite(n.pos) {
                return Err(format!("node {i} lies at {:?}", n.pos));
            }
            if !(n.radius.is_finite() && n.radius >= 0.0) {
                return Err(format!("node {i} has radius {}", n.radius));
            }
            if let Some(t) = n.time.filter(|t| !(t.is_finite() && *t >= 0.0)) {
                return Err(format!("node {i} has event time {t}"));
            }
        }
        for (i, e) in self.edges.iter().enumerate() {
            for end in [e.a, e.b] {
                if end.index() >= self.nodes.len() {
                    return Err(format!(
                        "edge {i} ends at node {} of {}",
                        end.index(),
                        self.nodes.len()
                    ));
                }
            }
            if let Some(c) = e.interior.iter().find(|c| !finite(**c)) {
                return Err(format!("edge {i} runs through {c:?}"));
            }
            let coords = self.edge_coords(EdgeId::from_index(i));
            if coords.iter().all(|&c| c == coords[0]) {
                return Err(format!("edge {i} has zero length at {:?}", coords[0]));
            }
        }
        let adjacency = self.adjacency();
        for (n, d) in self.degrees().into_iter().enumerate() {
            let incident = &adjacency[n];
            let ends = incident
                .iter()
                .filter(|&&e| {
                    let ed = self.edge(e);
                    ed.a.index() == n || ed.b.index() == n
                })
                .count();
            if incident.len() != d || ends != d {
                return Err(format!(
                    "node {n} has degree {d} but {} incident edge ends ({ends} at it)",
                    incident.len()
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::GraphBuilder;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn a_built_graph_keeps_them_and_each_break_is_named() {
        let mut b = GraphBuilder::new();
        b.segment(c(0., 0.), c(1., 0.));
        b.polyline(&[c(1., 0.), c(2., 1.), c(3., 0.)]);
        b.segment(c(1., 0.), c(1., 1.));
        let g = b.finish_raw();
        assert_eq!(g.check_invariants(), Ok(()));
        let broken = |f: &dyn Fn(&mut SkeletonGraph)| {
            let mut h = g.clone();
            f(&mut h);
            h.check_invariants().unwrap_err()
        };
        let e = broken(&|h| h.nodes_mut()[1].radius = f64::NAN);
        assert!(e.contains("node 1 has radius NaN"), "{e}");
        let e = broken(&|h| h.nodes_mut()[0].pos.x = f64::INFINITY);
        assert!(e.contains("node 0 lies at"), "{e}");
        let e = broken(&|h| h.nodes_mut()[2].time = Some(-1.0));
        assert!(e.contains("event time -1"), "{e}");
        let e = broken(&|h| h.edges[1].interior[0].y = f64::NAN);
        assert!(e.contains("edge 1 runs through"), "{e}");
        let e = broken(&|h| h.edges[0].b = crate::graph::NodeId::from_index(9));
        assert!(e.contains("edge 0 ends at node 9 of"), "{e}");
        let e = broken(&|h| {
            let a = h.edges[2].a;
            h.add_edge(a, a, Vec::new());
        });
        assert!(e.contains("edge 3 has zero length"), "{e}");
    }
}
