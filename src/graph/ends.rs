//! Centred ends: extension of a pruned skeleton to ∂P along the method's own
//! skeleton (the `centred` mode of the `extend` step, the default).
//!
//! Pruning turns junctions into leaves that stop inside P. A straight ray
//! from such a leaf is not medial: bars that hit it score a large z, and on
//! a bend it turns sideways onto the bank (a *hook*). The method's own
//! skeleton already continues to ∂P — the legs pruning removed behind the
//! leaf — so the centred extension follows the right one of them, *along
//! the axis*, into the polygon's tip.
//!
//! **Tips.** A leaf ℓ of the removed subtree (on ∂P for MA, StSk and CDT;
//! inside P for VD and DVD) is a tip of depth
//!
//! ```text
//!   τ(ℓ) = max over nodes x on the path from x* to ℓ of  |ℓ − x| + r_ℓ − r_x
//! ```
//!
//! where x* is the node of largest radius on the path from the line's end
//! zone to ℓ and r the radius of the inscribed disc at a node (0 on ∂P): how
//! far ℓ's disc reaches beyond the largest disc on its way and beyond every
//! disc after it. A *real* tip reaches at least [`REAL_TIP`] = ½ of r(x*)
//! beyond it: the discs shrink towards it over a stretch long against
//! their width — a lobe, a horn, a narrowing bay, a river's end, a corner
//! sharper than about 80° (a corner of angle α protrudes
//! r(1/sin(α/2) − 1): 0.41 r at 90°, 1 r at 60°). A leaf at a shallow bank
//! vertex lies on the disc it leaves (τ ≈ 0), and a rectangle's corner
//! reaches 0.41 r: neither is a real tip.
//!
//! **The end.** From a leaf ℓ that pruning made, the line's last two local
//! radii (its end zone) are taken back and the end is decided from the
//! zone's start s, coming in along the direction d the kept line had there:
//!
//! * the line follows the medial path from s to the deepest real tip ahead
//!   of it (τ largest among the leaves in the half-plane ahead of s), all
//!   the way to ∂P: the line ends in the tip along the axis, never with a
//!   straight chord across a wide part;
//! * when no tip ahead is real (a round, flat or blunt end), the line
//!   follows the path to the deepest leaf ahead, but ends at the first node
//!   v where removed legs lie on both sides of the course and v's disc
//!   touches ∂P straight ahead between them (within [`FORK_AHEAD_DEG`] of
//!   the course, at most [`FORK_TOUCH`] radii away): with a straight
//!   segment to that contact — the end side's midpoint of a rectangle or
//!   a river reach's square end, the apex of a round end. Where the disc
//!   touches ∂P to one side only (a blunt, lopsided end) the line follows
//!   the medial path into the deepest corner instead;
//! * with nothing ahead, a straight ray along d (or the nearest boundary
//!   point) ends the line.
//!
//! Within the end zone the course stays the line's, so small turns at
//! successive junctions cannot add up to a hook. A descent that reaches a
//! leaf inside P (VD and DVD legs stop short of ∂P) continues its last
//! direction with a straight ray. A leaf that already lies on ∂P (a kept
//! leg, a main axis end, a `trunk` end) is decided anew from its end zone
//! the same way, so a line that ran into one corner of a square end ends
//! at the end side's midpoint instead.
//!
//! At a cut end ([`crate::graph::cut`]) the line always ends on the cut,
//! where the disc at its junction touches it.
//!
//! Every ray is checked against ∂P (no crossing, inside P); a ray that fails
//! falls back to the nearest point of ∂P.

use super::cut::{cut_ends, CutEnd};
use super::line::{end_turn, point_at, HOOK_DEG};
use super::{Adjacency, EdgeId, NodeId, SkeletonGraph};
use crate::geometry::tolerance::ON_BOUNDARY_END;
use crate::geometry::vector::{cross, dot, hypot};
use crate::geometry::{Boundary, PreparedPolygon};
use geo::Coord;

/// A tip is real when it reaches this fraction of the largest disc's
/// radius beyond that disc (see the module documentation).
pub const REAL_TIP: f64 = 0.5;

/// Largest angle between a blunt end's course and its straight last segment.
const FORK_AHEAD_DEG: f64 = 45.0;

/// A blunt end's straight segment is at most this many radii of its node
/// long (the node's disc touches ∂P there).
const FORK_TOUCH: f64 = 3.0;

/// Largest mean local distortion of a straight end ([`Extender::balance`]).
const CHORD_BALANCE: f64 = 0.05;

/// Largest angle between the line's course and a removed leg that the line
/// follows before looking for a fork.
const FOLLOW_ANGLE_DEG: f64 = 30.0;

/// Removed legs whose deepest tip reaches at least this fraction of the
/// deepest one's τ are the substantial ones (whiskers to shallow bank
/// vertices, τ ≈ 0, never steer the end).
const SUBSTANTIAL: f64 = 0.5;

/// Length of the kept line behind an end zone that its end is judged
/// with, in radii of the zone's start.
const BACK: f64 = 6.0;

/// Length of a line's end zone, in radii.
const ZONE: f64 = 2.0;

/// The walk to a tip looks this many radii of the largest disc on its way
/// beyond that disc; a node there counts as a leaf (its disc's reach is in
/// its τ).
const TIP_REACH: f64 = 4.0;

/// Most nodes the walk to the tips visits from one end.
const TIP_NODES: usize = 5_000;

/// The centred extension of a pruned skeleton.
///
/// `m` is the merged raw graph and `keep` the pruning's kept edges of it
/// ([`crate::graph::prune::prune_mask`]); the result is the kept graph with
/// the followed legs and the end segments, merged. With `rough_cuts` a line
/// ends once on a rough cut too ([`cut_ends`]).
pub fn centred(
    m: &SkeletonGraph,
    keep: Vec<bool>,
    polygon: &PreparedPolygon,
    rough_cuts: bool,
) -> SkeletonGraph {
    let e = Extender::new(m, polygon, rough_cuts);
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
        let back = e.line_back(start, behind, &st);
        let rec = e.descend(start, back, &mut st);
        if e.hooks(start, &rec, polygon) {
            e.unhook(start, rec, &mut st, polygon);
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

/// A leaf of a removed subtree, as a line end.
#[derive(Debug, Clone, Copy)]
struct Tip {
    /// Its depth τ: how far its disc reaches beyond the largest disc on the
    /// way to it (and beyond every disc after that one).
    tau: f64,
    /// Radius of the largest disc on the way.
    widest: f64,
    /// The removed edge at the walk's start that leads to it.
    first: EdgeId,
}

impl Tip {
    /// A real tip: it reaches [`REAL_TIP`] of the largest disc's radius
    /// beyond that disc.
    fn is_real(&self) -> bool {
        self.tau >= REAL_TIP * self.widest
    }
}

/// What a descent added: the edges it followed (from its start), its end
/// segment's point on ∂P, and the kept line behind its start.
struct Descent {
    edges: Vec<EdgeId>,
    segment: Option<Coord<f64>>,
    back: Vec<Coord<f64>>,
}

/// What to do at a node of the descent.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Decision {
    /// Continue along this edge.
    Follow(EdgeId),
    /// End with a straight segment to this point of ∂P (a fork or a cut).
    End(Coord<f64>),
    /// Nothing to follow: end here.
    Stop,
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
}

/// A removed leg at a node: its edge, its departure direction and the
/// deepest tip beyond it.
type Leg = (EdgeId, Coord<f64>, Tip);

/// The leg of `legs` most aligned with `d` (on its left for `side` > 0, its
/// right for `side` < 0, either for 0); ties by edge index.
fn most_aligned<'a>(legs: &[&'a Leg], d: Coord<f64>, side: f64) -> Option<&'a Leg> {
    legs.iter()
        .filter(|l| side == 0.0 || cross(d, l.1) * side > 0.0)
        .max_by(|a, b| dot(a.1, d).total_cmp(&dot(b.1, d)).then(b.0.cmp(&a.0)))
        .copied()
}

fn unit(v: Coord<f64>) -> Option<Coord<f64>> {
    let n = hypot(v);
    (n > 0.0 && n.is_finite()).then(|| v / n)
}

impl<'a> Extender<'a> {
    fn new(m: &'a SkeletonGraph, polygon: &'a PreparedPolygon, rough_cuts: bool) -> Self {
        let boundary = polygon.boundary();
        let span = boundary.bbox_max() - boundary.bbox_min();
        let tol = ON_BOUNDARY_END * polygon.extent();
        Self {
            m,
            boundary,
            cuts: cut_ends(m, boundary, tol, rough_cuts)
                .into_iter()
                .map(|c| (c.junction, c))
                .collect(),
            adj: m.adjacency(),
            len: (0..m.edges().len())
                .map(|i| m.edge_length(EdgeId::from_index(i)))
                .collect(),
            tol,
            max_t: 2.0 * hypot(span) + 1.0,
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

    /// The kept line behind `start`, from `start` back along `behind` and
    /// on through the kept line for at most [`BACK`] radii of `start` (the
    /// course is measured over its first two radii, a hook over its first
    /// local widths).
    fn line_back(&self, start: NodeId, behind: EdgeId, st: &State) -> Vec<Coord<f64>> {
        let reach = BACK * self.radius(start);
        let mut line = self.m.oriented_coords(behind, start);
        let (mut at, mut via) = (self.m.opposite(behind, start), behind);
        let mut walked = self.len[behind.index()];
        for _ in 0..self.m.edges().len() {
            if walked >= reach || st.kdeg[at.index()] != 2 {
                break;
            }
            let Some(e) = self.next_kept(at, Some(via), st) else {
                break;
            };
            line.extend_from_slice(&self.m.oriented_coords(e, at)[1..]);
            walked += self.len[e.index()];
            at = self.m.opposite(e, at);
            via = e;
        }
        line
    }

    /// Unit direction in which the line `back` (from its first point
    /// backwards) arrives at its first point, measured over the last two
    /// local radii `r` (the whole line when `r` is 0 or the line shorter).
    fn course(back: &[Coord<f64>], r: f64) -> Coord<f64> {
        let total = super::polyline_length(back);
        let s = if r > 0.0 {
            (ZONE * r).min(total)
        } else {
            total
        };
        unit(back[0] - point_at(back, s)).unwrap_or(Coord { x: 1.0, y: 0.0 })
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

    /// The tips of the removed subtree beyond `start`: every leaf (a node
    /// with no further removed edge, or one [`TIP_REACH`] radii beyond the
    /// largest disc on its way, or where [`TIP_NODES`] nodes have been
    /// visited) with its depth τ and the removed edge at `start` it lies
    /// beyond.
    fn tips(&self, start: NodeId, st: &State) -> Vec<Tip> {
        let mut tips = Vec::new();
        // The walk's current path: node, arc length from `start`, index of
        // the largest disc on the path up to it.
        let mut path: Vec<(NodeId, f64, usize)> = Vec::new();
        let mut stack: Vec<(NodeId, usize, f64)> = vec![(start, 0, 0.0)];
        let mut first: std::collections::HashMap<NodeId, EdgeId> = std::collections::HashMap::new();
        let mut seen = std::collections::HashSet::from([start]);
        let mut budget = TIP_NODES;
        while let Some((n, depth, s)) = stack.pop() {
            path.truncate(depth);
            let widest = match path.last() {
                Some(&(_, _, k)) if self.radius(path[k].0) >= self.radius(n) => k,
                _ => depth,
            };
            path.push((n, s, widest));
            let (x, sx, _) = path[widest];
            let rx = self.radius(x);
            let beyond = s - sx > TIP_REACH * rx.max(self.tol);
            budget = budget.saturating_sub(1);
            let mut leaf = true;
            if !beyond && budget > 0 {
                for &e in &self.adj[n.index()] {
                    let ed = self.m.edge(e);
                    let o = self.m.opposite(e, n);
                    if st.taken[e.index()] || ed.a == ed.b || st.kdeg[o.index()] != 0 {
                        continue;
                    }
                    if seen.insert(o) {
                        first.insert(o, if n == start { e } else { first[&n] });
                        stack.push((o, depth + 1, s + self.len[e.index()]));
                        leaf = false;
                    }
                }
            }
            if leaf && n != start {
                let (p, r) = (self.pos(n), self.radius(n));
                let tau = path[widest..]
                    .iter()
                    .map(|&(y, _, _)| hypot(p - self.pos(y)) + r - self.radius(y))
                    .fold(0.0f64, f64::max);
                tips.push(Tip {
                    tau,
                    widest: rx,
                    first: first[&n],
                });
            }
        }
        tips
    }

    /// The centred-end rule at node `v` for a line coming in along `d`
    /// (see the module documentation).
    fn decide(&self, v: NodeId, d: Coord<f64>, st: &State) -> Decision {
        if let Some(q) = self.cut_at(v, st) {
            return Decision::End(q);
        }
        let tips = self.tips(v, st);
        // The deepest tip beyond each removed edge at v.
        let mut legs: Vec<Leg> = Vec::new();
        for t in tips {
            match legs.iter_mut().find(|l| l.0 == t.first) {
                Some(l) if l.2.tau >= t.tau => {}
                Some(l) => l.2 = t,
                None => {
                    if let Some(u) = self.departure(t.first, v) {
                        legs.push((t.first, u, t));
                    }
                }
            }
        }
        let deepest = legs.iter().map(|l| l.2.tau).fold(0.0f64, f64::max);
        let substantial: Vec<&Leg> = legs
            .iter()
            .filter(|l| l.2.tau >= SUBSTANTIAL * deepest)
            .collect();
        // Most aligned first; ties by edge index (deterministic).
        let aligned = |side: f64| most_aligned(&substantial, d, side);
        let Some(best) = aligned(0.0) else {
            return Decision::Stop;
        };
        // Substantial legs on both sides of the course, not both real tips:
        // the corners of an end side (a rectangle's, a river reach's), and
        // the line ends on the end side between them.
        let sides = match (aligned(1.0), aligned(-1.0)) {
            (Some(l), Some(r)) if !(l.2.is_real() && r.2.is_real()) => Some((l, r)),
            _ => None,
        };
        if dot(best.1, d) >= FOLLOW_ANGLE_DEG.to_radians().cos() {
            return Decision::Follow(best.0);
        }
        if let Some((l, r)) = sides {
            if let Some(q) = self.fork(v, d, r.1, l.1) {
                return Decision::End(q);
            }
        }
        Decision::Follow(best.0)
    }

    /// Where an end forks at `v` (course `d`) between removed legs leaving
    /// along `right` and `left`: the point where v's disc touches ∂P
    /// straight ahead between them (within [`FORK_AHEAD_DEG`] of the
    /// course, no farther than [`FORK_TOUCH`] radii) — the end side's
    /// midpoint of a rectangle, the apex of a round end.
    fn fork(
        &self,
        v: NodeId,
        d: Coord<f64>,
        right: Coord<f64>,
        left: Coord<f64>,
    ) -> Option<Coord<f64>> {
        let p = self.pos(v);
        let (q, dist) = self.boundary.nearest_in_sector(p, right, left)?;
        let ahead = unit(q - p).is_some_and(|u| dot(u, d) >= FORK_AHEAD_DEG.to_radians().cos());
        (dist > 0.0
            && dist <= FORK_TOUCH * self.radius(v)
            && ahead
            && self.balance(p, q) <= CHORD_BALANCE)
            .then_some(q)
    }

    /// How far a straight end from `p` to `q` (on ∂P) lies off the middle:
    /// the mean over points along it of the paper's local distortion
    /// |d_L − d_R| / (d_L + d_R), with d_L and d_R the distances to ∂P on
    /// either side of the segment (0 on the medial axis, 1 on the bank).
    fn balance(&self, p: Coord<f64>, q: Coord<f64>) -> f64 {
        let Some(t) = unit(q - p) else {
            return 0.0;
        };
        let back = t * -1.0;
        let samples = 8;
        let mut sum = 0.0;
        for k in 1..=samples {
            let x = p + (q - p) * (k as f64 / (samples + 1) as f64);
            let side = |from: Coord<f64>, to: Coord<f64>| {
                self.boundary
                    .nearest_in_sector(x, from, to)
                    .map_or(0.0, |(_, dist)| dist)
            };
            let (l, r) = (side(t, back), side(back, t));
            if l + r > 0.0 {
                sum += (l - r).abs() / (l + r);
            }
        }
        sum / samples as f64
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

    /// The cut end at `v`, when the descent reaches its junction with all
    /// its legs still removed.
    fn cut_at(&self, v: NodeId, st: &State) -> Option<Coord<f64>> {
        let cut = self.cuts.get(&v)?;
        let children = self.children(v, st);
        cut.legs
            .iter()
            .all(|l| children.contains(l))
            .then_some(cut.contact)
    }

    /// Descends from `start` (course `d`) into the removed subtree by
    /// [`Self::decide`], keeping the followed edges; records the end
    /// segment when the line ends at a fork, a cut or inside P.
    fn descend(&self, start: NodeId, back: Vec<Coord<f64>>, st: &mut State) -> Descent {
        let mut rec = Descent {
            edges: Vec::new(),
            segment: None,
            back: back.clone(),
        };
        // Within the end zone (two radii of the start) the course stays the
        // line's: following it leg by leg would let the end drift sideways.
        let zone = ZONE * self.radius(start);
        let r0 = if self.on_boundary(start) {
            0.0
        } else {
            self.radius(start)
        };
        let mut d = Self::course(&back, r0);
        // The line walked so far, from its end backwards.
        let mut trail: Vec<Coord<f64>> = back;
        trail.reverse();
        let (mut v, mut walked) = (start, 0.0);
        for _ in 0..=self.m.edges().len() {
            match self.decide(v, d, st) {
                Decision::End(q) => {
                    st.segments.push((v, q));
                    rec.segment = Some(q);
                    return rec;
                }
                Decision::Stop => break,
                Decision::Follow(e) => {
                    st.set(self.m, e, true);
                    rec.edges.push(e);
                    let o = self.m.opposite(e, v);
                    walked += self.len[e.index()];
                    trail.extend_from_slice(&self.m.oriented_coords(e, v)[1..]);
                    if walked > zone {
                        let back: Vec<Coord<f64>> = trail.iter().rev().copied().collect();
                        let r = if self.on_boundary(o) {
                            0.0
                        } else {
                            self.radius(o)
                        };
                        d = Self::course(&back, r);
                    }
                    v = o;
                }
            }
        }
        if !self.on_boundary(v) {
            if let Some(q) = self.straight_end(v, d) {
                st.segments.push((v, q));
                rec.segment = Some(q);
            }
        }
        rec
    }

    /// True when the end `rec` made from `start` is a hook.
    fn hooks(&self, start: NodeId, rec: &Descent, polygon: &PreparedPolygon) -> bool {
        end_turn(&self.end_line(start, rec), polygon).is_some_and(|t| t > HOOK_DEG)
    }

    /// The end's line, from its end point back through the descent from
    /// `start` and the kept line behind `start`.
    fn end_line(&self, start: NodeId, rec: &Descent) -> Vec<Coord<f64>> {
        let mut fwd = vec![self.pos(start)];
        let mut at = start;
        for &e in &rec.edges {
            let c = self.m.oriented_coords(e, at);
            fwd.extend_from_slice(&c[1..]);
            at = self.m.opposite(e, at);
        }
        fwd.extend(rec.segment);
        fwd.reverse();
        fwd.extend_from_slice(&rec.back[1..]);
        fwd
    }

    /// Replaces a hooked end by a straight one along the axis: walking back
    /// from its end along the descent, the first node from which a straight
    /// segment to where its disc touches ∂P ahead (within
    /// [`FORK_AHEAD_DEG`] of the course there, at most [`FORK_TOUCH`] radii
    /// away) is balanced ([`Self::balance`]) and makes no hook ends the
    /// line there. When none does, the hooked end stays: it follows the
    /// medial axis into its corner.
    fn unhook(&self, start: NodeId, rec: Descent, st: &mut State, polygon: &PreparedPolygon) {
        let mut nodes = vec![start];
        for &e in &rec.edges {
            nodes.push(self.m.opposite(e, *nodes.last().expect("non-empty")));
        }
        let mut trail: Vec<Coord<f64>> = rec.back.iter().rev().copied().collect();
        let mut trails = vec![trail.clone()];
        for (k, &e) in rec.edges.iter().enumerate() {
            trail.extend_from_slice(&self.m.oriented_coords(e, nodes[k])[1..]);
            trails.push(trail.clone());
        }
        for k in (0..nodes.len()).rev() {
            let v = nodes[k];
            let back: Vec<Coord<f64>> = trails[k].iter().rev().copied().collect();
            let r = if self.on_boundary(v) {
                0.0
            } else {
                self.radius(v)
            };
            let course = Self::course(&back, r);
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
                    .nearest_in_sector(p, cone(-FORK_AHEAD_DEG), cone(FORK_AHEAD_DEG))
            else {
                continue;
            };
            if dist <= 0.0
                || dist > FORK_TOUCH * self.radius(v).max(self.tol)
                || self.balance(p, q) > CHORD_BALANCE
            {
                continue;
            }
            let trial = Descent {
                edges: rec.edges[..k].to_vec(),
                segment: Some(q),
                back: rec.back.clone(),
            };
            if !self.hooks(start, &trial, polygon) {
                for &e in &rec.edges[k..] {
                    st.release(self.m, e);
                }
                if rec.segment.is_some() {
                    st.segments.pop();
                }
                st.segments.push((v, q));
                return;
            }
        }
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
    /// junction nor past the middle of a line between two leaves (whose
    /// other end has its own zone); and the kept edges from there to the
    /// leaf. The end is decided anew from there, so a line that bends into
    /// a corner over its last width is straightened.
    fn end_zone(&self, leaf: NodeId, st: &State) -> (NodeId, Vec<EdgeId>) {
        let chain = self.chain(leaf, st);
        let limit = match chain.last() {
            Some(&(_, o)) if st.kdeg[o.index()] == 1 => {
                0.5 * chain.iter().map(|(e, _)| self.len[e.index()]).sum::<f64>()
            }
            _ => f64::INFINITY,
        };
        let mut tail = Vec::new();
        let (mut at, mut s) = (leaf, 0.0);
        for &(e, o) in &chain {
            if st.kdeg[o.index()] != 2 || s + self.len[e.index()] > limit {
                break;
            }
            s += self.len[e.index()];
            tail.push(e);
            at = o;
            if s >= ZONE * self.radius(o) {
                break;
            }
        }
        (at, tail)
    }

    /// The kept line from `leaf` to the next node that is no inner node of
    /// it (a junction or the other leaf): its edges, each with the node it
    /// leads to.
    fn chain(&self, leaf: NodeId, st: &State) -> Vec<(EdgeId, NodeId)> {
        let mut out = Vec::new();
        let (mut at, mut via) = (leaf, None);
        for _ in 0..self.m.edges().len() {
            let Some(e) = self.next_kept(at, via, st) else {
                break;
            };
            let o = self.m.opposite(e, at);
            out.push((e, o));
            if st.kdeg[o.index()] != 2 || o == leaf {
                break;
            }
            at = o;
            via = Some(e);
        }
        out
    }
}
