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
//!
//! **Rough cuts** (only with `prune: {junctions: merge}`, a network of
//! corridors, so rivers, lakes and islands keep the rule above): street
//! space cut by a digitised or rasterised edge is not cut straight. Every
//! vertex of the cut that stands out gives the medial axis a leg, so the
//! line forks into the teeth. Then a cut end is also
//!
//! * a junction j of any degree with one branch that goes on (the line) and
//!   the others small trees of legs ending on ∂P, every node within
//!   [`MAX_REACH`] radii of j; the corners are the two leaves farthest
//!   apart;
//! * with the span, slant and line-length tests above, the line reaching
//!   [`MIN_ROUGH_LINE`] radii before another junction (a bend's rounded
//!   outer corner gives a fan of legs just as rough, but its line meets
//!   the bend's junction within a radius), and
//! * ∂P between the corners within [`MAX_ROUGH`] of the local width 2 r_j of
//!   the line that fits its vertices best (the corners are as rough as the
//!   rest; a cut with exactly two legs keeps the chord test).
//!
//! The line ends on the first point of ∂P on the way from j square to that
//! line, and the whole tree of legs goes, as a straight cut's two legs do.
//! A junction inside another cut's tree is no cut of its own.

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

/// Largest deviation of a rough cut (one whose vertices give more than two
/// legs) from the chord between its corners, relative to the local width
/// 2 r_j.
pub const MAX_ROUGH: f64 = 0.2;

/// Farthest a node of a cut's tree of legs lies from its junction, in radii
/// of the junction (a square cut's corners lie at √2).
pub const MAX_REACH: f64 = 2.0;

/// Shortest line arriving at a rough cut's junction before another
/// junction, in radii of the junction.
pub const MIN_ROUGH_LINE: f64 = 2.0;

/// Most edges in a cut's tree of legs.
const MAX_TREE: usize = 64;

/// Most boundary vertices along a cut.
const MAX_CUT_VERTICES: usize = 256;

/// A cut end: its junction, the legs into the cut, and where the line ends
/// on the cut.
#[derive(Debug, Clone, PartialEq)]
pub struct CutEnd {
    /// The junction whose disc touches the cut.
    pub junction: NodeId,
    /// The edges at the junction into the cut: the two legs into its
    /// corners, or on a rough cut the first edges of the small tree of legs
    /// its vertices give.
    pub legs: Vec<EdgeId>,
    /// Every edge beyond the junction into the cut (`legs` and the edges
    /// beyond them).
    pub tree: Vec<EdgeId>,
    /// Where the line ends: the point where the junction's disc touches the
    /// cut (the boundary point nearest to the junction between the two
    /// corners). A segment from the junction to it runs square to the cut,
    /// so bars that hit it find the same distance to either side.
    pub contact: Coord<f64>,
}

/// The branches at `j` that end on ∂P (without `rough` two legs; with it
/// small trees of legs within [`MAX_REACH`] radii of `j`), and the one
/// branch that does not (the line): `(line, legs, tree edges, leaves)`, or
/// `None` when not exactly one branch goes on.
#[allow(clippy::type_complexity)]
fn branches(
    m: &SkeletonGraph,
    adj: &Adjacency,
    deg: &[usize],
    j: NodeId,
    tol: f64,
    rough: bool,
) -> Option<(EdgeId, Vec<EdgeId>, Vec<EdgeId>, Vec<NodeId>)> {
    if !rough {
        return straight_branches(m, adj, deg, j, tol);
    }
    let mut line = None;
    let (mut legs, mut tree, mut leaves) = (Vec::new(), Vec::new(), Vec::new());
    for &first in &adj[j.index()] {
        match small_branch(m, adj, deg, (j, first), tol) {
            Some((edges, ends)) => {
                legs.push(first);
                tree.extend(edges);
                leaves.extend(ends);
            }
            None if line.is_none() => line = Some(first),
            None => return None,
        }
    }
    Some((line?, legs, tree, leaves))
}

/// Where the line from `j` ends on the cut from `p1` to `p2`: where `j`'s
/// disc touches it (the boundary point nearest to `j` between the corners);
/// on a rough cut (`line`: a point of its best-fitting line and its
/// direction) the first boundary point on the way from `j` square to that
/// line, so that the end runs square to the cut, not sideways into the
/// notch nearest to `j`.
fn contact(
    boundary: &Boundary,
    j: Coord<f64>,
    (p1, p2): (Coord<f64>, Coord<f64>),
    line: Option<(Coord<f64>, Coord<f64>)>,
) -> Option<Coord<f64>> {
    if let Some((origin, dir)) = line {
        let foot = origin + dir * dot(j - origin, dir);
        let reach = hypot(foot - j);
        if let Some(hit) = boundary.first_hit(j, (foot - j) / reach, 0.0, 2.0 * reach) {
            return Some(hit.point);
        }
    }
    let (u1, u2) = (p1 - j, p2 - j);
    let (right, left) = if cross(u1, u2) > 0.0 {
        (u1, u2)
    } else {
        (u2, u1)
    };
    boundary.nearest_in_sector(j, right, left).map(|(q, _)| q)
}

/// [`branches`] of the straight rule: exactly two legs, each one edge to a
/// leaf on ∂P, and the line. The legs are counted before anything is
/// collected: most junctions are no cut's, and on many small islands
/// collecting every junction's branches cost more than the rest of the
/// search.
#[allow(clippy::type_complexity)]
fn straight_branches(
    m: &SkeletonGraph,
    adj: &Adjacency,
    deg: &[usize],
    j: NodeId,
    tol: f64,
) -> Option<(EdgeId, Vec<EdgeId>, Vec<EdgeId>, Vec<NodeId>)> {
    let leaf = |e: EdgeId| {
        let o = m.opposite(e, j);
        (o != j && deg[o.index()] == 1 && m.node(o).radius <= tol).then_some(o)
    };
    let edges = &adj[j.index()];
    if edges.len() != 3 || edges.iter().filter(|&&e| leaf(e).is_some()).count() != 2 {
        return None;
    }
    let line = *edges.iter().find(|&&e| leaf(e).is_none())?;
    let legs: Vec<EdgeId> = edges.iter().copied().filter(|&e| e != line).collect();
    let leaves = legs.iter().filter_map(|&e| leaf(e)).collect();
    Some((line, legs.clone(), legs, leaves))
}

/// The branch at `j` through `first`, walked away from `j`, when it is a
/// small tree of legs: its nodes within [`MAX_REACH`] radii of `j`, every
/// leaf on ∂P, no way back to `j` and at most [`MAX_TREE`] edges. Its edges
/// and leaves.
fn small_branch(
    m: &SkeletonGraph,
    adj: &Adjacency,
    deg: &[usize],
    (j, first): (NodeId, EdgeId),
    tol: f64,
) -> Option<(Vec<EdgeId>, Vec<NodeId>)> {
    let pj = m.node(j).pos;
    let (reach, most) = (MAX_REACH * m.node(j).radius, MAX_TREE);
    let (mut edges, mut leaves) = (Vec::new(), Vec::new());
    let mut stack = vec![(first, j)];
    while let Some((e, from)) = stack.pop() {
        let o = m.opposite(e, from);
        edges.push(e);
        let node = m.node(o);
        if o == j || edges.len() > most || hypot(node.pos - pj) > reach {
            return None;
        }
        if deg[o.index()] == 1 {
            if node.radius > tol {
                return None;
            }
            leaves.push(o);
        }
        stack.extend(adj[o.index()].iter().filter(|&&x| x != e).map(|&x| (x, o)));
    }
    Some((edges, leaves))
}

/// The two leaves farthest apart: the cut's corners.
fn corners(m: &SkeletonGraph, leaves: &[NodeId]) -> Option<(Coord<f64>, Coord<f64>)> {
    let mut best: Option<(f64, Coord<f64>, Coord<f64>)> = None;
    for (i, &a) in leaves.iter().enumerate() {
        for &b in &leaves[i + 1..] {
            let (pa, pb) = (m.node(a).pos, m.node(b).pos);
            let d = hypot(pb - pa);
            if best.is_none_or(|(bd, _, _)| d > bd) {
                best = Some((d, pa, pb));
            }
        }
    }
    best.map(|(_, a, b)| (a, b))
}

/// The cut ends of `m` (a merged graph whose node radii are distances to
/// ∂P); `tol` is the distance within which a leaf lies on ∂P. With `rough`
/// (a network of corridors, `prune: {junctions: merge}`) a cut may also be
/// rough: a junction of any degree whose branches but the line are small
/// trees of legs into a cut within [`MAX_ROUGH`] of the local width of a
/// straight line.
pub fn cut_ends(m: &SkeletonGraph, boundary: &Boundary, tol: f64, rough: bool) -> Vec<CutEnd> {
    let adj = m.adjacency();
    let deg: Vec<usize> = adj.iter().map(<[EdgeId]>::len).collect();
    let rings = RingIndex::new(boundary);
    let graph = Around {
        m,
        adj: &adj,
        deg: &deg,
        boundary,
        rings: &rings,
    };
    let out: Vec<CutEnd> = (0..adj.len())
        .filter(|&j| adj[j].len() == 3 || (rough && adj[j].len() > 3))
        .filter_map(|j| graph.cut_at(NodeId::from_index(j), tol, rough))
        .collect();
    outermost(m, out)
}

/// A graph with what finding its cut ends reads around each junction.
struct Around<'a> {
    m: &'a SkeletonGraph,
    adj: &'a Adjacency,
    deg: &'a [usize],
    boundary: &'a Boundary,
    rings: &'a RingIndex,
}

impl Around<'_> {
    /// The cut end at junction `jn`, if the line through it ends on a cut.
    fn cut_at(&self, jn: NodeId, tol: f64, rough: bool) -> Option<CutEnd> {
        let Self {
            m,
            adj,
            deg,
            boundary,
            rings,
        } = *self;
        let (line, legs, tree, leaves) = branches(m, adj, deg, jn, tol, rough)?;
        if !rough && leaves.len() != 2 {
            return None;
        }
        let (p1, p2) = corners(m, &leaves)?;
        let span = hypot(p2 - p1);
        let rj = m.node(jn).radius;
        if span < MIN_SPAN * 2.0 * rj {
            return None;
        }
        let (c, r_far) = course_line(m, adj, deg, jn, line, tol, 2.0 * rj);
        // The cut spans the line it ends, not only a bump's own width: a
        // flat-topped bump of a bank ends in a short straight edge too, but
        // its line joins a much wider one.
        if span < MIN_SPAN * 2.0 * r_far {
            return None;
        }
        // A line shorter than a quarter radius makes j one node of a
        // cluster (a square's centre split by rounding): no single line
        // arrives there, so there is no cut to end on.
        let len = super::polyline_length(&c);
        if len < MIN_LINE * rj {
            return None;
        }
        // A rough cut ends a corridor: its line runs on at least
        // MIN_ROUGH_LINE radii before another junction. The fan of legs
        // into a bend's rounded outer corner is as rough, but its line
        // meets the bend's junction within a radius.
        if rough && len < MIN_ROUGH_LINE * rj {
            return None;
        }
        let course = c[0] - point_at(&c, (2.0 * rj).min(len));
        let foot = closest_on_segment(p1, p2, c[0]).0 - c[0];
        let (lc, lf) = (hypot(course), hypot(foot));
        if lc == 0.0 || lf == 0.0 {
            return None;
        }
        if dot(course, foot) / (lc * lf) < MAX_SLANT_DEG.to_radians().cos() {
            return None;
        }
        // Two legs: ∂P between the corners has no convex vertex, and must
        // not bow. More: the cut is rough, and must stay within a band of
        // the local width about its chord.
        let band = if leaves.len() == 2 {
            MAX_BOW * span
        } else {
            MAX_ROUGH * 2.0 * rj
        };
        let toothed = leaves.len() > 2;
        let cut = rings.straight_between(boundary, (p1, p2), toothed, band)?;
        let contact = contact(boundary, c[0], (p1, p2), toothed.then_some(cut))?;
        Some(CutEnd {
            junction: jn,
            legs,
            tree,
            contact,
        })
    }
}

/// `out` without the cut ends nested in another's tree.
fn outermost(m: &SkeletonGraph, mut out: Vec<CutEnd>) -> Vec<CutEnd> {
    // A rough cut's legs may hang from junctions nested in one tree: the
    // end is the outermost one, whose tree holds the others.
    let inner: std::collections::HashSet<NodeId> = out
        .iter()
        .flat_map(|c| {
            c.tree
                .iter()
                .flat_map(|&e| [m.edge(e).a, m.edge(e).b])
                .filter(move |&n| n != c.junction)
        })
        .collect();
    out.retain(|c| !inner.contains(&c.junction));
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

    /// The cut's line (a point on it and its unit direction) when ∂P runs
    /// straight from `p1` to `p2` (both boundary vertices of one ring) the
    /// shorter way round: every vertex between them within `band` of the
    /// chord `p1 p2`, or with `rough` of the line that fits them all best
    /// (a rough cut's corners are as rough as the rest), and none beyond
    /// the chord's ends.
    fn straight_between(
        &self,
        b: &Boundary,
        (p1, p2): (Coord<f64>, Coord<f64>),
        rough: bool,
        band: f64,
    ) -> Option<(Coord<f64>, Coord<f64>)> {
        let (Some((r1, i1)), Some((r2, i2))) = (self.vertex(b, p1), self.vertex(b, p2)) else {
            return None;
        };
        if r1 != r2 {
            return None;
        }
        let n = self.start[r1 + 1] - self.start[r1];
        let forward = (i2 + n - i1) % n;
        let (from, steps) = if forward <= n - forward {
            (i1, forward)
        } else {
            (i2, n - forward)
        };
        if steps == 0 || steps > MAX_CUT_VERTICES {
            return None;
        }
        let between: Vec<Coord<f64>> = (0..=steps)
            .map(|k| b.segments()[self.start[r1] + (from + k) % n].a)
            .collect();
        let d = p2 - p1;
        let span = hypot(d);
        let slack = if rough { band / span } else { 0.0 };
        let (origin, dir) = if rough {
            best_line(&between)
        } else {
            (p1, d / span)
        };
        let within = between[1..steps].iter().all(|&v| {
            let t = dot(v - p1, d) / (span * span);
            (-slack..=1.0 + slack).contains(&t)
        });
        let near = between[usize::from(!rough)..=steps - usize::from(!rough)]
            .iter()
            .all(|&v| cross(v - origin, dir).abs() <= band);
        (within && near).then_some((origin, dir))
    }
}

/// The line that fits `points` best (least squares across it): a point on
/// it and its unit direction.
fn best_line(points: &[Coord<f64>]) -> (Coord<f64>, Coord<f64>) {
    let n = points.len() as f64;
    let c = points.iter().fold(Coord { x: 0.0, y: 0.0 }, |a, &p| a + p) / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &p in points {
        let q = p - c;
        (sxx, sxy, syy) = (sxx + q.x * q.x, sxy + q.x * q.y, syy + q.y * q.y);
    }
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    (
        c,
        Coord {
            x: angle.cos(),
            y: angle.sin(),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PreparedPolygon;
    use crate::graph::GraphBuilder;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// A street 10 wide, its banks with a vertex every 10, cut at x = 100
    /// by an edge whose teeth stand `out` beyond it (a notch between them).
    fn street(out: f64) -> PreparedPolygon {
        let mut ring: Vec<Coord<f64>> = (0..10).map(|i| c(10. * f64::from(i), -5.)).collect();
        ring.extend([
            c(100., -5.),
            c(100. + out, -2.5),
            c(99.5, 0.),
            c(100. + out, 2.5),
        ]);
        ring.extend((0..=10).rev().map(|i| c(10. * f64::from(i), 5.)));
        PreparedPolygon::new(&geo::Polygon::new(geo::LineString(ring), vec![])).unwrap()
    }

    /// The street with teeth `out`, with a medial axis as MA gives it: the
    /// line to a junction one radius before the cut, legs into the corners
    /// and a small tree into the teeth.
    fn toothed(out: f64) -> (PreparedPolygon, SkeletonGraph) {
        let p = street(out);
        let mut b = GraphBuilder::new();
        b.polyline(&[c(5., 0.), c(95., 0.)]);
        b.segment(c(95., 0.), c(100., 5.));
        b.segment(c(95., 0.), c(100., -5.));
        b.segment(c(95., 0.), c(97.5, 0.));
        b.segment(c(97.5, 0.), c(100. + out, 2.5));
        b.segment(c(97.5, 0.), c(100. + out, -2.5));
        let g = b.finish(p.boundary());
        (p, g.merged())
    }

    #[test]
    fn a_rough_cut_is_a_cut_end_only_where_asked() {
        let (p, m) = toothed(1.0);
        let tol = 1e-9 * p.extent().max(1.0);
        let cuts = cut_ends(&m, p.boundary(), tol, true);
        assert_eq!(cuts.len(), 1, "{cuts:?}");
        let cut = &cuts[0];
        assert_eq!(m.node(cut.junction).pos, c(95., 0.));
        // Three edges at the junction, five into the cut in all.
        assert_eq!((cut.legs.len(), cut.tree.len()), (3, 5));
        // The end goes on square to the cut's line, into the notch.
        assert!(hypot(cut.contact - c(99.5, 0.)) < 1e-9, "{:?}", cut.contact);
        // The straight rule (rivers, lakes, islands) sees no cut: four
        // legs, not two.
        assert!(cut_ends(&m, p.boundary(), tol, false).is_empty());
    }

    #[test]
    fn a_cut_rougher_than_a_fifth_of_the_width_is_no_cut() {
        // The same street with its teeth 3 out of the cut's line (0.3 of
        // the width): a ragged end, not a cut.
        let (p, m) = toothed(3.0);
        let tol = 1e-9 * p.extent().max(1.0);
        assert!(cut_ends(&m, p.boundary(), tol, true).is_empty());
    }
}
