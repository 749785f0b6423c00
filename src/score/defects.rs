//! Defects a cartographer sees that the paper's metrics can hide: hooks at
//! line ends, crossing pieces and zig-zags.
//!
//! * **Hook**: a line end that turns sideways onto the bank instead of
//!   running on into the polygon's end. Walking back from the end e, w is
//!   the arc length of the first point whose distance to ∂P is half the
//!   arc length walked (one local width back,
//!   `crate::graph::line::end_width_point`); the end's turn is the
//!   angle between the line's course entering that stretch (from 1.5 w to
//!   w back) and its last segment, or — whichever is larger — between the
//!   last segment (length l) and the stretch of half its length before it
//!   (from 1.5 l to l back), which catches a short sideways stub the width's
//!   stretch passes over. A turn above [`HOOK_DEG`] is a hook.
//! * **Crossing**: two segments of the skeleton that cross without a node
//!   ([`crate::graph::planar::crossings`]).
//! * **Sharp turns**: vertices of the skeleton where the line turns by
//!   more than [`SHARP_DEG`], per kilometre of line: the saw-tooth of CDT and
//!   VD lines (a cartographic line turns gently).

use crate::graph::line::angle_deg;
pub use crate::graph::line::{end_turn, end_turns, HOOK_DEG};
use crate::graph::SkeletonGraph;
use geo::Coord;

/// A vertex where the line turns by more than this (degrees) is a sharp turn.
pub const SHARP_DEG: f64 = 45.0;

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

    use crate::geometry::PreparedPolygon;
    use crate::graph::GraphBuilder;

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
        // A spur into a slot 0.2 wide: the last local width lies inside the
        // slot on a straight segment, but the segment turned 90° off the
        // line's course where it left it.
        let slot = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 100., y: 0.),
            (x: 100., y: 20.), (x: 50.1, y: 20.), (x: 50.1, y: 45.), (x: 49.9, y: 45.),
            (x: 49.9, y: 20.), (x: 0., y: 20.)])
        .unwrap();
        let t = end_turn(&[c(50., 44.95), c(50., 10.), c(0., 10.)], &slot).unwrap();
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
