//! Centred ends: extension of a pruned skeleton to ∂P along the method's own
//! skeleton (the `centred` mode of the `extend` step, the default).
//!
//! Pruning turns junctions into leaves that stop inside P. A straight ray
//! from such a leaf is not medial: bars that hit it score a large z, and on
//! a bend it turns sideways onto the bank (a *hook*). The method's own
//! skeleton already continues to ∂P — the legs pruning removed behind the
//! leaf — so the centred extension keeps the right one of them:
//!
//! * From a leaf ℓ that pruning made, descend into the removed subtree,
//!   coming in along the direction d the kept line had over its last two
//!   local radii. At each node v (radius r_v) with removed children c
//!   (each with its departure direction u_c over the first r_v and its
//!   *protrusion* p_c = depth_c − r_v beyond the disc at v, depth capped at
//!   3 r_v), the children with p_c ≥ p_max / 2 are the substantial ones:
//!   - if the substantial child most aligned with d is within 30° of it, the
//!     line continues along that child (a tapering tip: the medial axis runs
//!     on into the tip vertex, and the whiskers beside it protrude little);
//!   - else if substantial children lie on both sides of d and the two most
//!     aligned do not both protrude [`HORN_PROTRUSION`] radii or more (horns:
//!     the line follows the more aligned one, below), the removed legs
//!     fork around the line (the corners of a rectangle's or a river reach's
//!     cut end, at ±45° for right-angled corners): the line ends with a
//!     straight segment from v to where v's inscribed disc touches ∂P
//!     between the two most aligned of them (the nearest boundary point in
//!     the sector between their directions) — the end side's midpoint at a
//!     rectangle's end, the foot on the far side of a square block;
//!   - else the line follows the most aligned substantial child (the end
//!     bends to one side; the medial line bends with it).
//!
//!   The end zone is the last two local radii of the line: the descent
//!   starts where the line, walked back from its leaf, first lies two
//!   radii from it (never past a kept junction), and within the zone d
//!   stays the line's course, so that small turns at successive junctions
//!   cannot add up to a hook. An end that still turns by more than
//!   [`HOOK_DEG`] over its last local width (on a compact island the
//!   medial axis reaches ∂P only in corners) ends earlier instead: at the
//!   last node of the descent from which a straight segment to where its
//!   disc touches ∂P ahead (the nearest boundary point within 45° of the
//!   course) makes no hook — a segment square to the end side, so bars that
//!   hit it still find the same distance to either side.
//!   The descent stops on ∂P, or at a leaf inside P (VD and DVD legs stop
//!   short of ∂P), from which a straight ray continues the last direction.
//! * A leaf that already lies on ∂P (a kept leg, or a `trunk` end) is
//!   checked once at the last junction u before it, when the leg is short
//!   (at most 2 r_u): the same rule decides between the kept leg and the
//!   removed ones at u, so a trunk that ran into one corner of a cut end
//!   ends at the cut's midpoint instead.
//!
//! * At a cut end ([`crate::graph::cut`]) the line always ends on the cut,
//!   where the disc at its junction touches it.
//!
//! The 30° threshold sits between a continuing leg (0° on a straight tip)
//! and the ±45° legs of a square cut end; the half-protrusion threshold
//! keeps whiskers (protrusion ≈ 0) from steering the end.
//! Every ray is checked against ∂P (no crossing, inside P); a ray that fails
//! falls back to following the skeleton, then to the nearest point of ∂P.

use super::cut::{cut_ends, CutEnd};
use super::line::{end_turn, point_at, HOOK_DEG};
use super::{Adjacency, EdgeId, NodeId, SkeletonGraph};
use crate::geometry::tolerance::ON_BOUNDARY_END;
use crate::geometry::vector::{cross, dot, hypot};
use crate::geometry::{Boundary, PreparedPolygon};
use geo::Coord;

/// Largest angle between the line's course and a removed leg that the line
/// follows.
const FOLLOW_ANGLE_DEG: f64 = 30.0;

/// Depth of a removed subtree is explored up to this many radii of the node
/// it hangs from (enough to tell a whisker from a continuing leg).
const DEPTH_CAP: f64 = 3.0;

/// Legs protruding at least this many radii beyond the disc at their node
/// on both sides of the line are horns, not the corners of an end side: the
/// line follows the more aligned one into its tip instead of ending between
/// them. The corner legs of a square end protrude √2 − 1 = 0.41 radii, of
/// a 70° corner 1/sin 35° − 1 = 0.74; the two horns of a notched end or two
/// lobes of a star more.
const HORN_PROTRUSION: f64 = 0.75;

/// Largest angle between the line's course and its last segment at a fork
/// (beyond it the end would turn onto the bank: a hook).
const FORK_ANGLE_DEG: f64 = 45.0;

/// Length of a line's end zone, in radii.
const ZONE: f64 = 2.0;

/// A fork's ray must meet ∂P within this many radii of the fork node (its
/// inscribed disc touches ∂P at one radius).
const FORK_REACH: f64 = 3.0;

/// The centred extension of a pruned skeleton.
///
/// `m` is the merged raw graph and `keep` the pruning's kept edges of it
/// ([`crate::graph::prune::prune_mask`]); the result is the kept graph with
/// the followed legs and the end segments, merged.
pub fn centred(m: &SkeletonGraph, keep: Vec<bool>, polygon: &PreparedPolygon) -> SkeletonGraph {
    let e = Extender::new(m, polygon);
    let mut st = State::new(m, keep);
    let leaves: Vec<NodeId> = (0..m.nodes().len())
        .filter(|&n| st.kdeg[n] == 1)
        .map(NodeId::from_index)
        .collect();
    for leaf in leaves {
        let (start, tail) = e.end_zone(leaf, &st);
        if tail.is_empty() && e.on_boundary(leaf) {
            continue;
        }
        for &t in &tail {
            st.release(m, t);
        }
        let Some(behind) = e.adj[start.index()]
            .iter()
            .copied()
            .find(|x| st.keep[x.index()])
        else {
            continue;
        };
        let d = e.arrival(behind, start);
        let rec = e.descend(start, d, &mut st);
        if e.hooks(start, &rec, &st, polygon) {
            e.unhook(start, d, rec, &mut st, polygon);
        }
    }
    assemble(m, &st.keep, &st.segments)
}

/// The growing result of the extension.
struct State {
    /// Edges of the merged graph in the result.
    keep: Vec<bool>,
    /// Kept edges at every node.
    kdeg: Vec<usize>,
    /// Edges that no descent may take again (kept, or used).
    taken: Vec<bool>,
    /// End segments: from a node to a point on ∂P.
    segments: Vec<(NodeId, Coord<f64>)>,
}

impl State {
    fn new(m: &SkeletonGraph, keep: Vec<bool>) -> Self {
        let mut kdeg = vec![0usize; m.nodes().len()];
        for (i, ed) in m.edges().iter().enumerate() {
            if keep[i] {
                kdeg[ed.a.index()] += 1;
                kdeg[ed.b.index()] += 1;
            }
        }
        Self {
            taken: keep.clone(),
            keep,
            kdeg,
            segments: Vec::new(),
        }
    }

    /// Takes a kept edge out of the result and frees it for a descent.
    fn release(&mut self, m: &SkeletonGraph, e: EdgeId) {
        self.set(m, e, false);
        self.taken[e.index()] = false;
    }

    fn set(&mut self, m: &SkeletonGraph, e: EdgeId, on: bool) {
        if self.keep[e.index()] == on {
            return;
        }
        self.keep[e.index()] = on;
        let ed = m.edge(e);
        for n in [ed.a, ed.b] {
            if on {
                self.kdeg[n.index()] += 1;
            } else {
                self.kdeg[n.index()] -= 1;
            }
        }
        if on {
            self.taken[e.index()] = true;
        }
    }
}

/// The kept edges of `m` plus one straight segment per `(node, point)`,
/// merged into one edge per branch.
pub fn assemble(
    m: &SkeletonGraph,
    keep: &[bool],
    segments: &[(NodeId, Coord<f64>)],
) -> SkeletonGraph {
    let mut g = SkeletonGraph::new();
    let mut map: Vec<Option<NodeId>> = vec![None; m.nodes().len()];
    let mut id = |g: &mut SkeletonGraph, n: NodeId| -> NodeId {
        *map[n.index()].get_or_insert_with(|| {
            let nd = m.node(n);
            g.add_node(nd.pos, nd.radius, nd.time)
        })
    };
    for (i, ed) in m.edges().iter().enumerate() {
        if keep[i] {
            let a = id(&mut g, ed.a);
            let b = id(&mut g, ed.b);
            g.add_edge(a, b, ed.interior.clone());
        }
    }
    for &(n, p) in segments {
        let a = id(&mut g, n);
        if g.node(a).pos != p {
            let b = g.add_node(p, 0.0, None);
            g.add_edge(a, b, Vec::new());
        }
    }
    g.merged()
}

/// What a descent added: the edges it followed (from its start) and its
/// end segment's point on ∂P.
struct Descent {
    edges: Vec<EdgeId>,
    segment: Option<Coord<f64>>,
}

/// What to do at a node of the descent.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Decision {
    /// Continue along this edge.
    Follow(EdgeId),
    /// End with a straight segment to ∂P between the departure directions
    /// of two legs: clockwise-most `right`, counter-clockwise-most `left`.
    Fork { right: Coord<f64>, left: Coord<f64> },
    /// End with a straight segment to this point of ∂P (on a cut).
    End(Coord<f64>),
}

struct Extender<'a> {
    m: &'a SkeletonGraph,
    boundary: &'a Boundary,
    /// Every cut end, by junction.
    cuts: std::collections::HashMap<NodeId, CutEnd>,
    adj: Adjacency,
    len: Vec<f64>,
    tol: f64,
    max_t: f64,
    /// `m` has no cycle: the subtree beyond an edge is the same for every
    /// walk that reaches it, so its depth can be remembered.
    forest: bool,
    /// Depths of subtrees found during the current descent.
    heights: std::cell::RefCell<Heights>,
}

/// Remembered subtree depths, by directed edge (`2·edge + 0` from its
/// `a` end, `+ 1` from `b`), valid while `stamp` equals `generation`.
struct Heights {
    generation: u32,
    stamp: Vec<u32>,
    value: Vec<f64>,
}

impl Heights {
    fn get(&self, k: usize) -> Option<f64> {
        (self.stamp[k] == self.generation).then(|| self.value[k])
    }

    fn set(&mut self, k: usize, v: f64) {
        self.stamp[k] = self.generation;
        self.value[k] = v;
    }
}

fn unit(v: Coord<f64>) -> Option<Coord<f64>> {
    let n = hypot(v);
    (n > 0.0 && n.is_finite()).then(|| v / n)
}

impl<'a> Extender<'a> {
    fn new(m: &'a SkeletonGraph, polygon: &'a PreparedPolygon) -> Self {
        let boundary = polygon.boundary();
        let span = boundary.bbox_max() - boundary.bbox_min();
        let tol = ON_BOUNDARY_END * polygon.extent();
        Self {
            m,
            boundary,
            cuts: cut_ends(m, boundary, tol)
                .into_iter()
                .map(|c| (c.junction, c))
                .collect(),
            adj: m.adjacency(),
            len: (0..m.edges().len())
                .map(|i| m.edge_length(EdgeId::from_index(i)))
                .collect(),
            tol,
            max_t: 2.0 * hypot(span) + 1.0,
            forest: m.edges().iter().all(|e| e.a != e.b)
                && m.edges().len() + m.components() == m.nodes().len(),
            heights: std::cell::RefCell::new(Heights {
                generation: 1,
                stamp: vec![0; 2 * m.edges().len()],
                value: vec![0.0; 2 * m.edges().len()],
            }),
        }
    }

    fn radius(&self, n: NodeId) -> f64 {
        self.m.node(n).radius
    }

    fn pos(&self, n: NodeId) -> Coord<f64> {
        self.m.node(n).pos
    }

    fn on_boundary(&self, n: NodeId) -> bool {
        self.radius(n) <= self.tol
    }

    /// Unit direction in which edge `e` arrives at node `at`, measured over
    /// its last two local radii (the whole edge when `at` lies on ∂P).
    fn arrival(&self, e: EdgeId, at: NodeId) -> Coord<f64> {
        let c = self.m.oriented_coords(e, at);
        let r = self.radius(at);
        let l = self.len[e.index()];
        let s = if r > self.tol { (2.0 * r).min(l) } else { l };
        unit(c[0] - point_at(&c, s)).unwrap_or(Coord { x: 1.0, y: 0.0 })
    }

    /// Unit direction in which edge `e` leaves node `from`, over the first
    /// radius of `from` (the whole edge when it is shorter).
    fn departure(&self, e: EdgeId, from: NodeId) -> Option<Coord<f64>> {
        let c = self.m.oriented_coords(e, from);
        let r = self.radius(from);
        let l = self.len[e.index()];
        let s = if r > self.tol { r.min(l) } else { l };
        unit(point_at(&c, s) - c[0])
    }

    /// The removed edges at `v` that a descent may take: not kept, not yet
    /// used, not a loop, not leading back into the result.
    fn children(&self, v: NodeId, st: &State) -> Vec<EdgeId> {
        self.adj[v.index()]
            .iter()
            .copied()
            .filter(|e| {
                let ed = self.m.edge(*e);
                let o = self.m.opposite(*e, v);
                !st.taken[e.index()] && ed.a != ed.b && st.kdeg[o.index()] == 0
            })
            .collect()
    }

    /// Depth of the subtree entered by edge `e` from `v`: the longest path
    /// through untaken edges plus the reach (radius) of its last node,
    /// explored up to `cap`.
    fn depth(&self, v: NodeId, e: EdgeId, taken: &[bool], cap: f64) -> f64 {
        if self.forest {
            return self.height(v, e, taken).min(cap);
        }
        let mut best = 0.0f64;
        let mut stack = vec![(self.m.opposite(e, v), e, self.len[e.index()])];
        let mut seen = std::collections::HashSet::new();
        seen.insert(v);
        while let Some((n, via, d)) = stack.pop() {
            if d >= cap {
                return cap;
            }
            if !seen.insert(n) {
                continue;
            }
            let mut leaf = true;
            for &f in &self.adj[n.index()] {
                if f != via && !taken[f.index()] {
                    let o = self.m.opposite(f, n);
                    if !seen.contains(&o) {
                        leaf = false;
                        stack.push((o, f, d + self.len[f.index()]));
                    }
                }
            }
            let reach = if leaf { self.radius(n) } else { 0.0 };
            best = best.max(d + reach);
        }
        best.min(cap)
    }

    /// [`Self::depth`] without the cap, in a forest: the longest path from
    /// `v` through `e` and untaken edges beyond it, plus the radius of its
    /// last node. Every subtree is measured once per descent (the edges a
    /// descent takes lie behind it, so the subtrees ahead stay the same);
    /// the walk with a cap would measure the same subtree again at every
    /// step, quadratic on a long descent.
    fn height(&self, v: NodeId, e: EdgeId, taken: &[bool]) -> f64 {
        let key = |from: NodeId, e: EdgeId| 2 * e.index() + usize::from(self.m.edge(e).a != from);
        let mut h = self.heights.borrow_mut();
        let mut stack = vec![(v, e, false)];
        while let Some((from, e, ready)) = stack.pop() {
            let k = key(from, e);
            if h.get(k).is_some() {
                continue;
            }
            let b = self.m.opposite(e, from);
            let ahead = self.adj[b.index()]
                .iter()
                .copied()
                .filter(|&f| f != e && !taken[f.index()]);
            if ready {
                let deepest = ahead
                    .map(|f| h.get(key(b, f)).expect("measured before"))
                    .reduce(f64::max);
                h.set(
                    k,
                    self.len[e.index()] + deepest.unwrap_or_else(|| self.radius(b)),
                );
            } else {
                stack.push((from, e, true));
                stack.extend(
                    ahead
                        .filter(|&f| h.get(key(b, f)).is_none())
                        .map(|f| (b, f, false)),
                );
            }
        }
        h.get(key(v, e)).expect("measured")
    }

    /// The centred-end rule at node `v` (see the module documentation).
    fn decide(
        &self,
        v: NodeId,
        d: Coord<f64>,
        children: &[EdgeId],
        taken: &[bool],
    ) -> Option<Decision> {
        if let Some(cut) = self.cuts.get(&v) {
            if cut.legs.iter().all(|l| children.contains(l)) {
                return Some(Decision::End(cut.contact));
            }
        }
        let rv = self.radius(v);
        let cap = DEPTH_CAP * rv.max(self.tol);
        let cands: Vec<(EdgeId, Coord<f64>, f64)> = children
            .iter()
            .filter_map(|&c| {
                let u = self.departure(c, v)?;
                Some((c, u, self.depth(v, c, taken, cap) - rv))
            })
            .collect();
        let p_max = cands.iter().map(|c| c.2).fold(f64::NEG_INFINITY, f64::max);
        let substantial: Vec<&(EdgeId, Coord<f64>, f64)> = cands
            .iter()
            .filter(|c| p_max <= 0.0 || c.2 >= 0.5 * p_max)
            .collect();
        // Most aligned first; ties by edge index (deterministic).
        let aligned = |side: f64| {
            substantial
                .iter()
                .filter(move |c| side == 0.0 || cross(d, c.1) * side > 0.0)
                .max_by(|a, b| dot(a.1, d).total_cmp(&dot(b.1, d)).then(b.0.cmp(&a.0)))
                .copied()
        };
        let best = aligned(0.0)?;
        if dot(best.1, d) >= FOLLOW_ANGLE_DEG.to_radians().cos() {
            return Some(Decision::Follow(best.0));
        }
        if let (Some(l), Some(r)) = (aligned(1.0), aligned(-1.0)) {
            if l.2.min(r.2) < HORN_PROTRUSION * rv {
                return Some(Decision::Fork {
                    right: r.1,
                    left: l.1,
                });
            }
        }
        Some(Decision::Follow(best.0))
    }

    /// Where the end at a fork at `v` meets ∂P: the point where the disc at
    /// `v` touches ∂P between the two legs (the nearest boundary point in the
    /// sector between their directions), if it lies within
    /// [`FORK_REACH`] radii.
    fn fork_contact(
        &self,
        v: NodeId,
        d: Coord<f64>,
        right: Coord<f64>,
        left: Coord<f64>,
    ) -> Option<Coord<f64>> {
        let p = self.pos(v);
        let (q, dist) = self.boundary.nearest_in_sector(p, right, left)?;
        let ahead = unit(q - p).is_some_and(|u| dot(u, d) >= FORK_ANGLE_DEG.to_radians().cos());
        (dist > 0.0 && dist <= FORK_REACH * self.radius(v) && ahead).then_some(q)
    }

    /// The point where the ray from `p` along `dir` meets ∂P, if the segment
    /// to it stays in P and is no longer than `max_len`.
    fn ray(&self, p: Coord<f64>, dir: Coord<f64>, max_len: f64) -> Option<Coord<f64>> {
        let hit = self.boundary.first_hit(p, dir, 0.0, self.max_t)?;
        if hit.t > max_len || hit.t <= 0.0 {
            return None;
        }
        let mid = (p + hit.point) * 0.5;
        if !self.boundary.reaches(p, hit.point)
            || !self.boundary.contains_with_tolerance(mid, self.tol)
        {
            return None;
        }
        Some(hit.point)
    }

    /// A straight end from `v` along `dir`, or to the nearest point of ∂P.
    fn straight_end(&self, v: NodeId, dir: Coord<f64>) -> Option<Coord<f64>> {
        let p = self.pos(v);
        self.ray(p, dir, self.max_t)
            .or_else(|| self.boundary.nearest(p).map(|(q, _, _)| q))
    }

    /// Descends from the leaf `start` (course `d`) into the removed subtree,
    /// keeping the followed edges; records the end segment if the descent
    /// stops inside P.
    fn descend(&self, start: NodeId, mut d: Coord<f64>, st: &mut State) -> Descent {
        self.heights.borrow_mut().generation += 1;
        let mut rec = Descent {
            edges: Vec::new(),
            segment: None,
        };
        let mut v = start;
        // Within the end zone (two radii of the start) the course stays the
        // line's: following it leg by leg would let the end drift sideways.
        let zone = ZONE * self.radius(start);
        let mut walked = 0.0;
        for _ in 0..=self.m.edges().len() {
            let children = self.children(v, st);
            if children.is_empty() {
                if !self.on_boundary(v) {
                    if let Some(q) = self.straight_end(v, d) {
                        st.segments.push((v, q));
                        rec.segment = Some(q);
                    }
                }
                return rec;
            }
            let next = match self.decide(v, d, &children, &st.taken) {
                Some(Decision::Fork { right, left }) => {
                    if let Some(q) = self.fork_contact(v, d, right, left) {
                        st.segments.push((v, q));
                        rec.segment = Some(q);
                        return rec;
                    }
                    // The fork's ray fails: follow the most aligned leg.
                    self.most_aligned(v, d, &children)
                }
                Some(Decision::End(q)) => {
                    st.segments.push((v, q));
                    rec.segment = Some(q);
                    return rec;
                }
                Some(Decision::Follow(c)) => Some(c),
                None => None,
            };
            let Some(c) = next else {
                if let Some(q) = self.straight_end(v, d) {
                    st.segments.push((v, q));
                    rec.segment = Some(q);
                }
                return rec;
            };
            st.set(self.m, c, true);
            rec.edges.push(c);
            let o = self.m.opposite(c, v);
            walked += self.len[c.index()];
            if walked > zone {
                d = self.arrival(c, o);
            }
            v = o;
        }
        rec
    }

    fn hooks(&self, start: NodeId, rec: &Descent, st: &State, polygon: &PreparedPolygon) -> bool {
        end_turn(&self.end_line(start, rec, st), polygon).is_some_and(|t| t > HOOK_DEG)
    }

    /// Replaces a hooked end: walking back from its end along the descent,
    /// the first node from which a straight segment to where its disc
    /// touches ∂P ahead (within [`FORK_ANGLE_DEG`] of the course) makes no
    /// hook ends the line there. When none does, the hooked end stays.
    fn unhook(
        &self,
        start: NodeId,
        d: Coord<f64>,
        rec: Descent,
        st: &mut State,
        polygon: &PreparedPolygon,
    ) {
        let mut nodes = vec![start];
        for &e in &rec.edges {
            nodes.push(self.m.opposite(e, *nodes.last().expect("non-empty")));
        }
        self.undo(&rec, st);
        for k in (0..nodes.len()).rev() {
            let v = nodes[k];
            let course = if k == 0 {
                d
            } else {
                self.arrival(rec.edges[k - 1], v)
            };
            let p = self.pos(v);
            let cone = |deg: f64| {
                let (s, c) = deg.to_radians().sin_cos();
                Coord {
                    x: course.x * c - course.y * s,
                    y: course.x * s + course.y * c,
                }
            };
            let Some((q, dist)) =
                self.boundary
                    .nearest_in_sector(p, cone(-FORK_ANGLE_DEG), cone(FORK_ANGLE_DEG))
            else {
                continue;
            };
            if dist <= 0.0 || dist > FORK_REACH * self.radius(v).max(self.tol) {
                continue;
            }
            let trial = Descent {
                edges: rec.edges[..k].to_vec(),
                segment: Some(q),
            };
            if !self.hooks(start, &trial, st, polygon) {
                for &e in &trial.edges {
                    st.set(self.m, e, true);
                }
                st.segments.push((v, q));
                return;
            }
        }
        // Nothing better: the end as the descent made it.
        for &e in &rec.edges {
            st.set(self.m, e, true);
        }
        if let Some(q) = rec.segment {
            let last = *nodes.last().expect("non-empty");
            st.segments.push((last, q));
        }
    }

    /// Takes back what `rec` added.
    fn undo(&self, rec: &Descent, st: &mut State) {
        for &e in &rec.edges {
            st.release(self.m, e);
        }
        if rec.segment.is_some() {
            st.segments.pop();
        }
    }

    /// The end's line from its end point back through the descent from
    /// `start` and the kept line behind `start` (six radii of `start` at
    /// most).
    fn end_line(&self, start: NodeId, rec: &Descent, st: &State) -> Vec<Coord<f64>> {
        let mut fwd = vec![self.pos(start)];
        let mut at = start;
        for &e in &rec.edges {
            let c = self.m.oriented_coords(e, at);
            fwd.extend_from_slice(&c[1..]);
            at = self.m.opposite(e, at);
        }
        fwd.extend(rec.segment);
        fwd.reverse();
        // Behind the start, along the kept line.
        let limit = 6.0 * self.radius(start);
        let (mut at, mut via, mut walked) = (start, rec.edges.first().copied(), 0.0);
        for _ in 0..self.m.edges().len() {
            let Some(e) = self.next_kept(at, via, st) else {
                break;
            };
            let c = self.m.oriented_coords(e, at);
            fwd.extend_from_slice(&c[1..]);
            walked += self.len[e.index()];
            at = self.m.opposite(e, at);
            via = Some(e);
            if walked > limit || st.kdeg[at.index()] != 2 {
                break;
            }
        }
        fwd
    }

    /// The kept edge at `at` other than `via`, walking along a kept line.
    fn next_kept(&self, at: NodeId, via: Option<EdgeId>, st: &State) -> Option<EdgeId> {
        self.adj[at.index()]
            .iter()
            .copied()
            .find(|&x| st.keep[x.index()] && Some(x) != via)
    }

    /// The start of `leaf`'s end zone: walking back along the kept line,
    /// the first node whose distance from the leaf along the line reaches
    /// [`ZONE`] times its radius (one local width), never past a kept
    /// junction; and the kept edges from there to the leaf. The end is
    /// decided anew from there, so a line that bends into a corner over
    /// its last width is straightened.
    fn end_zone(&self, leaf: NodeId, st: &State) -> (NodeId, Vec<EdgeId>) {
        let mut tail = Vec::new();
        let (mut at, mut via) = (leaf, None);
        let mut s = 0.0;
        for _ in 0..self.m.edges().len() {
            let Some(e) = self.next_kept(at, via, st) else {
                break;
            };
            let o = self.m.opposite(e, at);
            if st.kdeg[o.index()] != 2 {
                break;
            }
            s += self.len[e.index()];
            tail.push(e);
            at = o;
            via = Some(e);
            if s >= ZONE * self.radius(o) {
                break;
            }
        }
        (at, tail)
    }

    fn most_aligned(&self, v: NodeId, d: Coord<f64>, children: &[EdgeId]) -> Option<EdgeId> {
        children
            .iter()
            .filter_map(|&c| Some((c, dot(self.departure(c, v)?, d))))
            .max_by(|a, b| a.1.total_cmp(&b.1).then(b.0.cmp(&a.0)))
            .map(|(c, _)| c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random tree of `n` nodes in the unit square's interior (each node
    /// joined to a random earlier one), with random radii.
    fn random_tree(n: usize, seed: u64) -> SkeletonGraph {
        let mut s = seed;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut g = SkeletonGraph::new();
        let mut ids = Vec::new();
        for i in 0..n {
            let p = Coord {
                x: 0.1 + 0.8 * next(),
                y: 0.1 + 0.8 * next(),
            };
            let id = g.add_node(p, 0.1 * next(), None);
            if i > 0 {
                let j = (next() * i as f64) as usize;
                g.add_edge(ids[j], id, Vec::new());
            }
            ids.push(id);
        }
        g
    }

    #[test]
    fn remembered_subtree_depths_equal_the_walk() {
        let ring = vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)];
        let square = geo::Polygon::new(geo::LineString::from(ring), vec![]);
        let polygon = PreparedPolygon::new(&square).unwrap();
        for seed in 1..20u64 {
            let g = random_tree(200, seed * 7919);
            let mut e = Extender::new(&g, &polygon);
            assert!(e.forest);
            // Some edges taken, as kept edges and earlier steps would be.
            let taken: Vec<bool> = (0..g.edges().len()).map(|i| i % 11 == 3).collect();
            let mut remembered = Vec::new();
            for (i, ed) in g.edges().iter().enumerate() {
                for from in [ed.a, ed.b] {
                    remembered.push(e.depth(from, EdgeId::from_index(i), &taken, f64::INFINITY));
                }
            }
            e.forest = false;
            let mut k = 0;
            for (i, ed) in g.edges().iter().enumerate() {
                for from in [ed.a, ed.b] {
                    let walked = e.depth(from, EdgeId::from_index(i), &taken, f64::INFINITY);
                    let r = remembered[k];
                    assert!(
                        (walked - r).abs() <= 1e-12 * walked.max(1.0),
                        "{walked} {r}"
                    );
                    k += 1;
                }
            }
        }
        // A cycle: not a forest, so every depth is walked.
        let mut g = random_tree(10, 3);
        g.add_edge(NodeId::from_index(0), NodeId::from_index(9), Vec::new());
        assert!(!Extender::new(&g, &polygon).forest);
    }
}
