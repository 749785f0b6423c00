//! Defects a cartographer sees that the paper's metrics can hide: hooks at
//! line ends, crossing pieces and zig-zags.
//!
//! * **Hook**: a line end that turns sideways onto the bank instead of
//!   running on into the polygon's end. Walking back from the end e, w is
//!   the arc length of the first point whose distance to ∂P is half the
//!   arc length walked (one local width back,
//!   [`crate::graph::structure::end_width_point`]); the end's turn is the
//!   angle between the line's course entering that stretch (from 1.5 w to
//!   w back) and its last segment. A turn above [`HOOK_DEG`] is a hook.
//! * **Crossing**: two segments of the skeleton that cross without a node
//!   ([`crate::graph::planar::crossings`]).
//! * **Sharp turns**: vertices of the skeleton where the line turns by
//!   more than [`SHARP_DEG`], per kilometre of line: the saw-tooth of CDT and
//!   VD lines (a cartographic line turns gently).

use crate::geometry::PreparedPolygon;
use crate::graph::prune::legs::point_at;
use crate::graph::structure::end_width_point;
use crate::graph::{polyline_length, GraphBuilder, NodeId, SkeletonGraph};
use geo::{Coord, MultiLineString};

/// A line end that turns by more than this (degrees) within its last local
/// width is a hook.
pub const HOOK_DEG: f64 = 60.0;

/// A vertex where the line turns by more than this (degrees) is a sharp turn.
pub const SHARP_DEG: f64 = 45.0;

fn angle_deg(a: Coord<f64>, b: Coord<f64>) -> Option<f64> {
    let (la, lb) = (a.x.hypot(a.y), b.x.hypot(b.y));
    if la == 0.0 || lb == 0.0 {
        return None;
    }
    let c = ((a.x * b.x + a.y * b.y) / (la * lb)).clamp(-1.0, 1.0);
    Some(c.acos().to_degrees())
}

/// The graph of skeleton lines made by any tool (end points shared bit for
/// bit become nodes).
pub fn graph_of(lines: &MultiLineString<f64>) -> SkeletonGraph {
    let mut b = GraphBuilder::new();
    for l in &lines.0 {
        b.polyline(&l.0);
    }
    b.finish_raw()
}

/// The turn (degrees) of every line end of `g`, a skeleton of `polygon`, in
/// node order (see the module documentation).
pub fn end_turns(g: &SkeletonGraph, polygon: &PreparedPolygon) -> Vec<f64> {
    let adj = g.adjacency();
    let mut out = Vec::new();
    for n in 0..g.nodes().len() {
        if adj[n].len() != 1 {
            continue;
        }
        let coords = g.line_from(NodeId(n as u32), &adj);
        if let Some(t) = end_turn(&coords, polygon) {
            out.push(t);
        }
    }
    out
}

/// The turn of the line `coords` at its first point (see the module docs).
pub fn end_turn(coords: &[Coord<f64>], polygon: &PreparedPolygon) -> Option<f64> {
    let total = polyline_length(coords);
    if total <= 0.0 {
        return None;
    }
    let (w, _) = end_width_point(coords, polygon);
    let e = coords[0];
    let last = coords.iter().copied().find(|&c| c != e)?;
    let before = point_at(coords, w.min(total));
    let start = point_at(coords, (1.5 * w).min(total));
    if before == start {
        return Some(0.0);
    }
    angle_deg(before - start, e - last)
}

/// Vertices where the lines of `g` turn by more than [`SHARP_DEG`], and the
/// total length of the lines.
pub fn sharp_turns(g: &SkeletonGraph) -> (usize, f64) {
    let mut n = 0;
    let mut length = 0.0;
    for b in g.branches() {
        length += b.length();
        let c: Vec<Coord<f64>> = b
            .coords
            .windows(2)
            .filter(|w| w[0] != w[1])
            .map(|w| w[0])
            .chain(b.coords.last().copied())
            .collect();
        n += c
            .windows(3)
            .filter(|w| angle_deg(w[1] - w[0], w[2] - w[1]).is_some_and(|a| a > SHARP_DEG))
            .count();
    }
    (n, length)
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn a_straight_end_does_not_turn_and_a_sideways_stub_is_a_hook() {
        let p = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 100., y: 0.),
            (x: 100., y: 10.), (x: 0., y: 10.)])
        .unwrap();
        // The centre line to the short side's midpoint.
        let t = end_turn(&[c(100., 5.), c(60., 5.), c(0., 5.)], &p).unwrap();
        assert!(t < 1e-9, "{t}");
        // The same line turning onto the bank for its last 5 units.
        let t = end_turn(&[c(95., 0.), c(95., 5.), c(0., 5.)], &p).unwrap();
        assert!((t - 90.0).abs() < 1e-9, "{t}");
    }

    #[test]
    fn saw_tooth_counts_sharp_turns() {
        let mut b = GraphBuilder::new();
        b.polyline(&[c(0., 0.), c(1., 1.), c(2., 0.), c(3., 1.), c(4., 0.)]);
        let (n, len) = sharp_turns(&b.finish_raw());
        assert_eq!(n, 3);
        assert!((len - 4.0 * 2f64.sqrt()).abs() < 1e-12);
    }
}
