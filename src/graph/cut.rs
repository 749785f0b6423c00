//! Cut ends: where a polygon ends in a straight cut across its width.
//!
//! A river reach clipped from a longer river, a tile edge, a dam or a road
//! polygon's end: the boundary crosses the shape in a straight line. The
//! medial axis (and the straight skeleton) meets such an end with a
//! junction j whose disc touches both banks and the cut, and two short legs
//! from j into the cut's two corners. By the significance rule both legs are
//! insignificant (they protrude ≈ 0.41 r_j beyond the disc), so pruning
//! would drop the end altogether where another arm meets the line near it,
//! and `trunk` runs into one corner. A **cut end** is recognised as
//!
//! * a junction j of degree 3 with exactly two legs that end on ∂P at c₁,
//!   c₂ (leaves at boundary vertices),
//! * the chord |c₁c₂| spans at least [`MIN_SPAN`] of the local width 2 r_j,
//!   and of the width where the line ending there joins the rest of the
//!   skeleton (the end is as wide as the shape, not a flat-topped bump of a
//!   wider river's bank),
//! * ∂P between c₁ and c₂ (the shorter way round the ring) is straight:
//!   every vertex within [`MAX_BOW`] × |c₁c₂| of the chord, and
//! * the line arriving at j is at least [`MIN_LINE`] radii long (else j is
//!   one node of a cluster, e.g. the centre of a square split by rounding),
//!   and
//! * the cut lies across the line: the foot of j on the chord is within
//!   [`MAX_SLANT_DEG`] of the direction in which the line arrives at j over
//!   its last two radii. The line is the third branch, continued through
//!   junctions that only have legs into ∂P hanging from them (a blunt end
//!   often has several such junctions close together). A straight but slanted end side — one bank
//!   running into the tip of a tapering arm — is no cut: the line goes on
//!   into the tip.
//!
//! Pruning keeps a cut end as an end of the skeleton, and the centred
//! extension ends the line with a straight segment from j square to the
//! cut, where j's disc touches it (the middle of a rectangle's end side).

use super::line::point_at;
use super::{Adjacency, EdgeId, NodeId, SkeletonGraph};
use crate::geometry::segment::closest_on_segment;
use crate::geometry::vector::{cross, dot, hypot};
use crate::geometry::Boundary;
use geo::Coord;

/// Smallest span of a cut relative to the local width 2 r_j.
pub const MIN_SPAN: f64 = 0.5;

/// Largest deviation of ∂P from the chord, relative to the chord's length.
pub const MAX_BOW: f64 = 0.05;

/// Largest angle between the line's course and the direction from the
/// junction to the cut.
pub const MAX_SLANT_DEG: f64 = 35.0;

/// Shortest line arriving at a cut's junction, in radii of the junction.
pub const MIN_LINE: f64 = 0.25;

/// Most boundary vertices along a cut.
const MAX_CUT_VERTICES: usize = 256;

/// A cut end: its junction, the two legs into the cut's corners, and where
/// the line ends on the cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutEnd {
    /// The junction whose disc touches the cut.
    pub junction: NodeId,
    /// The legs from the junction into the cut's corners.
    pub legs: [EdgeId; 2],
    /// Where the line ends: the point where the junction's disc touches the
    /// cut (the boundary point nearest to the junction between the two
    /// corners). A segment from the junction to it runs square to the cut,
    /// so bars that hit it find the same distance to either side.
    pub contact: Coord<f64>,
}

/// The cut ends of `m` (a merged graph whose node radii are distances to
/// ∂P); `tol` is the distance within which a leaf lies on ∂P.
pub fn cut_ends(m: &SkeletonGraph, boundary: &Boundary, tol: f64) -> Vec<CutEnd> {
    let adj = m.adjacency();
    let deg: Vec<usize> = adj.iter().map(<[EdgeId]>::len).collect();
    let rings = RingIndex::new(boundary);
    let mut out = Vec::new();
    for (j, edges) in adj.iter().enumerate() {
        if edges.len() != 3 {
            continue;
        }
        let jn = NodeId::from_index(j);
        let legs: Vec<(EdgeId, NodeId)> = edges
            .iter()
            .map(|&e| (e, m.opposite(e, jn)))
            .filter(|&(_, o)| o != jn && deg[o.index()] == 1 && m.node(o).radius <= tol)
            .collect();
        let [(e1, c1), (e2, c2)] = legs[..] else {
            continue;
        };
        let (p1, p2) = (m.node(c1).pos, m.node(c2).pos);
        let span = hypot(p2 - p1);
        let rj = m.node(jn).radius;
        if span < MIN_SPAN * 2.0 * rj {
            continue;
        }
        let Some(&line) = edges.iter().find(|&&e| e != e1 && e != e2) else {
            continue;
        };
        let (c, r_far) = course_line(m, &adj, &deg, jn, line, tol, 2.0 * rj);
        // The cut spans the line it ends, not only a bump's own width: a
        // flat-topped bump of a bank ends in a short straight edge too, but
        // its line joins a much wider one.
        if span < MIN_SPAN * 2.0 * r_far {
            continue;
        }
        // A line shorter than a quarter radius makes j one node of a
        // cluster (a square's centre split by rounding): no single line
        // arrives there, so there is no cut to end on.
        let len = super::polyline_length(&c);
        if len < MIN_LINE * rj {
            continue;
        }
        let course = c[0] - point_at(&c, (2.0 * rj).min(len));
        let foot = closest_on_segment(p1, p2, c[0]).0 - c[0];
        let (lc, lf) = (hypot(course), hypot(foot));
        if lc == 0.0 || lf == 0.0 {
            continue;
        }
        if dot(course, foot) / (lc * lf) < MAX_SLANT_DEG.to_radians().cos() {
            continue;
        }
        if !rings.straight_between(boundary, p1, p2, span) {
            continue;
        }
        let (u1, u2) = (p1 - c[0], p2 - c[0]);
        let (right, left) = if cross(u1, u2) > 0.0 {
            (u1, u2)
        } else {
            (u2, u1)
        };
        if let Some((contact, _)) = boundary.nearest_in_sector(c[0], right, left) {
            out.push(CutEnd {
                junction: jn,
                legs: [e1, e2],
                contact,
            });
        }
    }
    out
}

/// The line arriving at `j` along `first`, from `j` outwards, continued
/// through nodes whose other branches are all legs into ∂P, up to `length`;
/// and the radius of the node where it stops (the junction where it joins
/// the rest of the skeleton, or the node `length` along it).
fn course_line(
    m: &SkeletonGraph,
    adj: &Adjacency,
    deg: &[usize],
    j: NodeId,
    first: EdgeId,
    tol: f64,
    length: f64,
) -> (Vec<Coord<f64>>, f64) {
    let mut coords = vec![m.node(j).pos];
    let (mut at, mut via) = (j, first);
    let mut total = 0.0;
    for _ in 0..m.edges().len() {
        let c = m.oriented_coords(via, at);
        total += super::polyline_length(&c);
        coords.extend_from_slice(&c[1..]);
        at = m.opposite(via, at);
        if total >= length || at == j {
            break;
        }
        let is_leg = |e: EdgeId| {
            let o = m.opposite(e, at);
            deg[o.index()] == 1 && m.node(o).radius <= tol
        };
        let onward: Vec<EdgeId> = adj[at.index()]
            .iter()
            .copied()
            .filter(|&e| e != via && !is_leg(e))
            .collect();
        let [next] = onward[..] else { break };
        via = next;
    }
    (coords, m.node(at).radius)
}

/// Where each ring's segments start in [`Boundary::segments`].
struct RingIndex {
    start: Vec<usize>,
}

impl RingIndex {
    fn new(b: &Boundary) -> Self {
        let mut start = Vec::new();
        for (i, s) in b.segments().iter().enumerate() {
            if s.ring as usize >= start.len() {
                start.resize(s.ring as usize + 1, i);
            }
        }
        start.push(b.segments().len());
        Self { start }
    }

    /// The (ring, position in ring) of the boundary vertex at `p`.
    fn vertex(&self, b: &Boundary, p: Coord<f64>) -> Option<(usize, usize)> {
        let (_, seg, _) = b.nearest(p)?;
        let s = b.segments()[seg];
        let ring = s.ring as usize;
        let at = seg - self.start[ring];
        let n = self.start[ring + 1] - self.start[ring];
        let da = hypot(s.a - p);
        let db = hypot(s.b - p);
        Some((ring, if da <= db { at } else { (at + 1) % n }))
    }

    /// True when ∂P runs straight from `p1` to `p2` (both boundary
    /// vertices of one ring) the shorter way round.
    fn straight_between(&self, b: &Boundary, p1: Coord<f64>, p2: Coord<f64>, span: f64) -> bool {
        let (Some((r1, i1)), Some((r2, i2))) = (self.vertex(b, p1), self.vertex(b, p2)) else {
            return false;
        };
        if r1 != r2 {
            return false;
        }
        let n = self.start[r1 + 1] - self.start[r1];
        let forward = (i2 + n - i1) % n;
        let (from, steps) = if forward <= n - forward {
            (i1, forward)
        } else {
            (i2, n - forward)
        };
        if steps == 0 || steps > MAX_CUT_VERTICES {
            return false;
        }
        let d = p2 - p1;
        (1..steps).all(|k| {
            let v = b.segments()[self.start[r1] + (from + k) % n].a;
            let w = v - p1;
            let off = cross(w, d).abs() / span;
            let t = dot(w, d) / (span * span);
            off <= MAX_BOW * span && (0.0..=1.0).contains(&t)
        })
    }
}
