//! Insignificant sides: the leg rule applied to whole subtrees.
//!
//! A leg is judged at its junction j against j's disc. On a rough boundary
//! (spiky banks, a raster's staircase, a digitised scan) the medial axis
//! grows a thicket of small junctions in the boundary's own roughness: each
//! small leg protrudes many radii beyond its tiny junction's disc, so the
//! leg rule keeps it, and the thicket keeps the branch that leads out to
//! it, although the whole thicket lies within a few metres of the bank of a
//! disc kilometres wide. Seen from the junction J where the branch leaves
//! the rest of the skeleton, the branch and all it carries form one *side*
//! of J, and the rule for a leg applies to the side unchanged: its extent
//! is the farthest reach along the skeleton from J (the length to a leaf
//! plus that leaf's reach, the largest over the side), and it is
//! insignificant when that protrudes less than `ratio` radii beyond J's
//! disc and it is no arm (the mouth measured on the way to its farthest
//! leaf). Such a side goes as a whole. A side that runs far along the
//! skeleton but stays close to J's disc in space (a branch running along a
//! rough rim, as the medial axis of a rough near-circular arc does) is
//! measured in space instead: the farthest `|q − J| + r_q` over its points,
//! bounded from above by a disc around each node that holds all it carries
//! (built bottom-up with the peeling, so no side is walked twice). A side
//! that ends the skeleton on a cut (a river reach's end, reach without
//! limit) of real width against J's disc (`arm_width`) is never judged; a
//! "cut end" a metre wide in the roughness of a rim counts with its radius.
//! After the sides are judged, a junction left with two branches is settled
//! as when a leg goes (its sibling leg insignificant at it goes too).
//!
//! Where a line itself runs into a rough rim, the thicket at its end hangs
//! from junctions as narrow as its own, so no side of it is insignificant
//! where it hangs; it is judged against the line a little way back instead
//! (`terminal_thicket`), and goes when it lies within that point's disc
//! scaled by `1 + ratio` and all its discs are tiny against it.
//!
//! A side is only judged where the rest of the skeleton seen from J is
//! significant at J (it reaches `ratio` radii beyond J's disc): a thicket
//! on the rim of a lake is small against the lake, but in a compact island
//! every branch is small against every other, and which of them stays is
//! the main-axis rule's to decide (see `legs`).
//!
//! Sides are found by peeling the skeleton from its leaves: a node is
//! peeled when all but one of its branches lead to peeled nodes. What each
//! side carries (its farthest reach, the disc that bounds it) is summed up
//! bottom-up in peeling order and what lies beyond each node's parent
//! top-down, so all is O(n) plus one boundary query per side that needs
//! its mouth. Only sides that contain a junction are judged here; single
//! legs are left to the least-significant-first pruning, which judges them
//! by the same rule. A junction always keeps at least two branches, so a
//! side is never cut down to a leaf here, and the cycles around holes are
//! never peeled.

use super::work::Work;
use super::{LegMeasure, PruneParams};
use crate::geometry::vector::hypot;
use crate::graph::NodeId;
use std::collections::VecDeque;

/// A peeled side of a node: the piece to the child and the child.
type Side = (u32, NodeId);

/// What peeling knows of a node and the side below it.
#[derive(Debug, Clone, Default)]
struct Below {
    /// Farthest reach from the node into what it carries (its own reach
    /// when it carries nothing), along the skeleton.
    extent: f64,
    /// The side through which the farthest reach runs.
    deepest: Option<Side>,
    /// Whether the node or anything it carries is a junction.
    has_junction: bool,
    /// The peeled sides it carries.
    children: Vec<Side>,
    /// Radius of a disc centred on the node that holds everything it
    /// carries with its discs (the reach of a leaf; a cut end, whose reach
    /// is unlimited, with its radius: a cut end in the roughness of a rim
    /// is no end seen from a disc kilometres wide, and a river reach's end
    /// is far from every disc it could be judged against).
    bound: f64,
    /// The largest radius of a cut end it carries (−∞ for none).
    cut_radius: f64,
    /// The piece to the node's parent (None at a tree's root and on cycles).
    up: Option<u32>,
    /// The largest radius of the nodes it carries, itself included.
    max_radius: f64,
    /// The largest distance from the parent of the points of the piece up
    /// to it (its interior points and the joints of joined pieces).
    piece_reach: f64,
    /// Farthest reach along the skeleton from the node through its parent
    /// (+∞ on a cycle, −∞ at the root of a tree).
    above: f64,
}

/// Removes every side that contains a junction and is insignificant at the
/// node it hangs from, where the rest is significant (see the module
/// documentation).
pub(super) fn prune_sides(w: &mut Work, params: &PruneParams, collapsed: &mut Vec<NodeId>) {
    let (order, mut below) = peel(w);
    for &v in &order {
        sum_up(w, v, &mut below);
    }
    for &v in order.iter().rev() {
        hand_down(w, v, &mut below);
    }
    let ascent = Ascent::new(w, &order, &below);
    let mut touched = Vec::new();
    for &v in &order {
        if let Some(removed) = judge(w, params, v, &below, &ascent) {
            touched.push((v, removed));
        }
    }
    // A junction left with two branches is settled as when a leg goes (its
    // sibling leg may go too), once every side has been judged: joining
    // pieces earlier would hide them from the sides above.
    for (v, removed) in touched {
        w.settle(v, removed, params, collapsed);
    }
}

/// Peels the skeleton from its leaves: the nodes in peeling order (then the
/// nodes on cycles, which are never peeled) and each node's peeled sides.
fn peel(w: &Work) -> (Vec<NodeId>, Vec<Below>) {
    let n = w.graph.nodes().len();
    let degree: Vec<usize> = (0..n).map(|i| w.deg(NodeId::from_index(i))).collect();
    let mut left = degree.clone();
    let mut below: Vec<Below> = (0..n)
        .map(|i| {
            let (reach, radius) = (w.reach[i], w.radius(NodeId::from_index(i)));
            Below {
                extent: reach,
                has_junction: degree[i] >= 3,
                bound: if reach.is_finite() {
                    reach.max(radius)
                } else {
                    radius
                },
                above: f64::INFINITY,
                max_radius: radius,
                cut_radius: if reach.is_finite() {
                    f64::NEG_INFINITY
                } else {
                    radius
                },
                ..Default::default()
            }
        })
        .collect();
    let mut peeled = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut queue: VecDeque<NodeId> = (0..n)
        .filter(|&i| left[i] == 1)
        .map(NodeId::from_index)
        .collect();
    while let Some(v) = queue.pop_front() {
        if peeled[v.index()] {
            continue;
        }
        peeled[v.index()] = true;
        order.push(v);
        let up = w.adj[v.index()]
            .iter()
            .copied()
            .find(|&p| !peeled[w.other(p, v).index()] && w.other(p, v) != v);
        let Some(p) = up else {
            below[v.index()].above = f64::NEG_INFINITY; // the root of a tree
            continue;
        };
        let parent = w.other(p, v);
        below[v.index()].up = Some(p);
        below[parent.index()].children.push((p, v));
        left[parent.index()] -= 1;
        if left[parent.index()] == 1 {
            queue.push_back(parent);
        }
    }
    order.extend(
        (0..n)
            .filter(|&i| !peeled[i] && !below[i].children.is_empty())
            .map(NodeId::from_index),
    );
    (order, below)
}

/// Extent along the skeleton of the side `(p, c)` seen from its parent.
fn side_extent(w: &Work, below: &[Below], (p, c): Side) -> f64 {
    w.pieces[p as usize].len + below[c.index()].extent
}

/// Sums up what `v` carries from its children (all summed up before it).
fn sum_up(w: &Work, v: NodeId, below: &mut [Below]) {
    let vpos = w.graph.node(v).pos;
    let b = &below[v.index()];
    let (mut extent, mut deepest, mut has_junction, mut bound) =
        (b.extent, None, b.has_junction, b.bound);
    let (mut cut_radius, mut max_radius) = (b.cut_radius, b.max_radius);
    let mut pieces = Vec::with_capacity(b.children.len());
    for &(p, c) in &b.children {
        let side = side_extent(w, below, (p, c));
        if side > extent {
            extent = side;
            deepest = Some((p, c));
        }
        let cb = &below[c.index()];
        has_junction |= cb.has_junction;
        cut_radius = cut_radius.max(cb.cut_radius);
        max_radius = max_radius.max(cb.max_radius);
        bound = bound.max(hypot(w.graph.node(c).pos - vpos) + cb.bound);
        pieces.push((c, piece_reach(w, p, vpos)));
    }
    for &(c, r) in &pieces {
        below[c.index()].piece_reach = r;
        bound = bound.max(r);
    }
    let b = &mut below[v.index()];
    (b.extent, b.deepest, b.has_junction, b.bound) = (extent, deepest, has_junction, bound);
    (b.cut_radius, b.max_radius) = (cut_radius, max_radius);
}

/// Hands down to each child of `v` how far the skeleton reaches beyond `v`
/// seen from it: through `v`'s parent, `v`'s own reach or another side.
fn hand_down(w: &Work, v: NodeId, below: &mut [Below]) {
    let b = &below[v.index()];
    let own = w.reach[v.index()].max(b.above);
    let (sides, first, second) = side_extents(w, below, v);
    let children = b.children.clone();
    for (&(p, c), &x) in children.iter().zip(&sides) {
        let other = if x == first { second } else { first };
        below[c.index()].above = w.pieces[p as usize].len + own.max(other);
    }
}

/// The extent of each peeled side of `v` (in the order of its children),
/// with the largest and the second largest of them.
fn side_extents(w: &Work, below: &[Below], v: NodeId) -> (Vec<f64>, f64, f64) {
    let sides: Vec<f64> = below[v.index()]
        .children
        .iter()
        .map(|&s| side_extent(w, below, s))
        .collect();
    let (first, second) = two_largest(&sides);
    (sides, first, second)
}

/// The largest and the second largest of `xs` (−∞ where there is none;
/// equal when the largest is there twice).
fn two_largest(xs: &[f64]) -> (f64, f64) {
    let (mut first, mut second) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for &x in xs {
        if x > first {
            (first, second) = (x, first);
        } else if x > second {
            second = x;
        }
    }
    (first, second)
}

/// Judges the peeled sides of `v` and removes the insignificant ones that
/// contain a junction, least significant first, while `v` keeps two
/// branches and the rest of the skeleton seen from `v` is significant.
fn judge(
    w: &mut Work,
    params: &PruneParams,
    v: NodeId,
    below: &[Below],
    ascent: &Ascent,
) -> Option<f64> {
    if w.deg(v) < 3 {
        return None;
    }
    let rv = w.radius(v);
    let b = &below[v.index()];
    let significant = |extent: f64| {
        !params.is_insignificant(&LegMeasure {
            extent,
            r_junction: rv,
            r_mouth: 0.0,
        })
    };
    // The rest seen from a side: through the parent, or the farthest other
    // side (the two farthest sides, so each side is looked at once).
    let (sides, first, second) = side_extents(w, below, v);
    let mut candidates: Vec<(f64, (u32, NodeId, f64))> = Vec::new();
    for (&(p, c), &path) in b.children.iter().zip(&sides) {
        if !below[c.index()].has_junction {
            continue;
        }
        let other = if path == first { second } else { first };
        if !significant(b.above.max(other)) {
            continue;
        }
        // A side that ends the skeleton on a cut of real width (a river
        // reach's end) reaches on without limit, whatever its extent in
        // space; a cut end in the roughness of a rim counts with its radius.
        if below[c.index()].cut_radius >= params.arm_width * rv {
            continue;
        }
        // How far out of the disc the side reaches: along the skeleton, or
        // in space when that is less (a branch running along a rough rim).
        let space = spatial_extent(w, below, v, c, (1.0 + params.ratio) * rv);
        let mut leg = LegMeasure {
            extent: space.map_or(path, |e| path.min(e)),
            r_junction: rv,
            r_mouth: f64::INFINITY,
        };
        if !params.is_insignificant(&leg) {
            continue;
        }
        leg.r_mouth = mouth(w, below, v, (p, c), rv);
        if params.is_insignificant(&leg) {
            candidates.push((params.key(&leg), (p, c, path)));
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1 .0.cmp(&b.1 .0)));
    let mut removed = None;
    for (_, (p, c, extent)) in candidates {
        if w.deg(v) <= 2 {
            break;
        }
        remove_side(w, below, (p, c));
        removed = Some(removed.map_or(extent, |r: f64| r.max(extent)));
    }
    if w.deg(v) >= 3 && terminal_thicket(w, params, v, below, ascent) {
        for &side in &b.children {
            remove_side(w, below, side);
        }
    }
    removed
}

/// Whether `v`, where a line runs into a rough rim, carries only a
/// thicket: everything it carries (a disc of radius e around `v`) lies in
/// the disc, scaled by `1 + ratio`, of a point q on the line back towards
/// `v`'s parent (`(1 + ratio) r_q ≥ |q − v| + e`, q tried at e, 2e, 4e…
/// back), the thicket holds junctions of its own, and all its discs are
/// tiny against q's (`arm_width`). Then the line ends at `v` and the
/// extension finishes it: seen from the line's own width a little way back
/// the thicket is the bank's roughness. A blunt end (two legs into corners,
/// no junction beyond) and a cut end of real width are never thickets.
fn terminal_thicket(
    w: &Work,
    params: &PruneParams,
    v: NodeId,
    below: &[Below],
    ascent: &Ascent,
) -> bool {
    let b = &below[v.index()];
    if b.up.is_none() {
        return false;
    }
    let kids = b.children.iter().map(|&(_, c)| &below[c.index()]);
    if !kids.clone().any(|c| c.has_junction) {
        return false;
    }
    // The widest disc of the thicket (a cut end's included).
    let tiny = kids
        .map(|c| c.max_radius.max(c.cut_radius))
        .fold(f64::NEG_INFINITY, f64::max);
    let e = b.bound;
    if !(e.is_finite() && e > 0.0) {
        return false;
    }
    // Back towards the root, trying q at e, 2e, 4e along the way.
    let mut s = e;
    while s <= 4.0 * e {
        let Some((node, walked)) = ascent.piece_at(v, s) else {
            return false;
        };
        let piece = below[node.index()]
            .up
            .expect("a node below a root has a piece up");
        // q is `s - walked` along the piece from `node`: no farther from
        // ∂P than that plus `node`'s radius, which bounds the search.
        let along = s - walked;
        let rq = w
            .boundary
            .distance_within(w.point_at(piece, node, along), w.radius(node) + along);
        if (1.0 + params.ratio) * rq >= s + e && tiny < params.arm_width * rq {
            return true;
        }
        s *= 2.0;
    }
    false
}

/// Every node's way up towards its root (the parent of a peeled node is
/// across its piece up), for finding in O(log n) the piece a given length up
/// from a node: walking it piece by piece cost O(depth) per junction, and a
/// staircase rim's skeleton is deep in pieces a metre long under a disc a
/// kilometre wide (the rasterised Lena: 5 of its 20 s).
struct Ascent {
    /// The parent's index (the node's own at a root and on cycles).
    parent: Vec<u32>,
    /// Length along the pieces up to the root.
    from_root: Vec<f64>,
    /// Pieces up to the root.
    depth: Vec<u32>,
    /// A farther ancestor (Myers' skew-binary jump pointers: every way up is
    /// O(log n) jumps and steps).
    jump: Vec<u32>,
}

impl Ascent {
    /// Built from the root down (`order`: the peeling order, all nodes).
    fn new(w: &Work, order: &[NodeId], below: &[Below]) -> Self {
        Self::build(below.len(), order.iter().rev().map(|v| v.index()), |i| {
            let up = below[i].up?;
            Some((
                w.other(up, NodeId::from_index(i)).index(),
                w.pieces[up as usize].len,
            ))
        })
    }

    /// Of `n` nodes visited parents first (`top_down`), each with its
    /// parent and the length up to it (`up`; `None` at a root).
    fn build(
        n: usize,
        top_down: impl Iterator<Item = usize>,
        up: impl Fn(usize) -> Option<(usize, f64)>,
    ) -> Self {
        let mut a = Ascent {
            parent: (0..n as u32).collect(),
            from_root: vec![0.0; n],
            depth: vec![0; n],
            jump: (0..n as u32).collect(),
        };
        for i in top_down {
            let Some((p, len)) = up(i) else {
                continue;
            };
            a.parent[i] = p as u32;
            a.from_root[i] = a.from_root[p] + len;
            a.depth[i] = a.depth[p] + 1;
            let (j, jj) = (a.jump[p] as usize, a.jump[a.jump[p] as usize] as usize);
            a.jump[i] = if a.depth[p] - a.depth[j] == a.depth[j] - a.depth[jj] {
                jj as u32
            } else {
                p as u32
            };
        }
        a
    }

    /// The first node x on the way up from `v` (v itself included) whose
    /// piece up reaches `s` from v, with the length from v to x: `None`
    /// when the way ends (a root) first.
    fn piece_at(&self, v: NodeId, s: f64) -> Option<(NodeId, f64)> {
        let start = self.from_root[v.index()];
        // How far up from v the top of x's piece is.
        let reach = |x: usize| start - self.from_root[self.parent[x] as usize];
        let is_root = |x: usize| self.parent[x] as usize == x;
        let mut x = v.index();
        loop {
            if is_root(x) {
                return None;
            }
            if s <= reach(x) {
                return Some((NodeId::from_index(x), start - self.from_root[x]));
            }
            let y = self.jump[x] as usize;
            x = if y != x && !is_root(y) && reach(y) < s {
                y
            } else {
                self.parent[x] as usize
            };
        }
    }
}

/// Distance to ∂P where the side `(p, c)` of `v`, followed towards its
/// farthest reach, leaves the disc at `v` (radius `rv`); at the leaf when
/// the path is shorter (as for a leg).
fn mouth(w: &Work, below: &[Below], v: NodeId, (p, c): Side, rv: f64) -> f64 {
    let (mut piece, mut from, mut to, mut s) = (p, v, c, rv);
    loop {
        let len = w.pieces[piece as usize].len;
        if len >= s {
            return w
                .boundary
                .distance_within(w.point_at(piece, from, s), w.radius(from) + s);
        }
        s -= len;
        match below[to.index()].deepest {
            Some((q, next)) => (piece, from, to) = (q, to, next),
            None => return w.radius(to).max(w.reach[to.index()]),
        }
    }
}

/// How far the side of `v` through its child `c` reaches from `v` in space, at most:
/// the largest `|q − v|` over the piece's points and the far side of the
/// disc that bounds what `c` carries — `None` when that reaches `limit`
/// (the side may be significant by the radius rule, and is kept).
fn spatial_extent(w: &Work, below: &[Below], v: NodeId, c: NodeId, limit: f64) -> Option<f64> {
    let cb = &below[c.index()];
    let best = (hypot(w.graph.node(c).pos - w.graph.node(v).pos) + cb.bound).max(cb.piece_reach);
    (best < limit).then_some(best)
}

/// The largest distance from `from` of the points of piece `p`.
fn piece_reach(w: &Work, p: u32, from: geo::Coord<f64>) -> f64 {
    w.piece_coords(p)
        .into_iter()
        .map(|q| hypot(q - from))
        .fold(0.0, f64::max)
}

/// Removes the piece of `side` and everything its child carries.
fn remove_side(w: &mut Work, below: &[Below], side: Side) {
    let mut stack = vec![side];
    while let Some((p, c)) = stack.pop() {
        if w.alive[p as usize] {
            w.remove(p);
        }
        stack.extend(below[c.index()].children.iter().copied());
    }
}

#[cfg(test)]
mod tests {
    use super::Ascent;
    use crate::graph::NodeId;

    /// The jumps find the piece a walk up, piece by piece, finds.
    #[test]
    fn the_piece_a_length_up_is_the_walks() {
        // A random forest: node i's parent among the nodes before it (or none),
        // pieces of random length, long chains among them.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let n = 3000;
        let up: Vec<Option<(usize, f64)>> = (0..n)
            .map(|i| {
                let r = next();
                match (i, r % 50) {
                    (0, _) | (_, 0) => None,
                    (_, 1..=40) => Some((i - 1, (r % 1000) as f64 / 100.0)),
                    _ => Some(((r / 64) as usize % i, (r % 7) as f64 + 0.5)),
                }
            })
            .collect();
        let a = Ascent::build(n, 0..n, |i| up[i]);
        let walk = |v: usize, s: f64| {
            let (mut x, mut walked) = (v, 0.0);
            loop {
                let (p, len) = up[x]?;
                if s <= walked + len {
                    return Some((x, walked));
                }
                walked += len;
                x = p;
            }
        };
        for _ in 0..20_000 {
            let v = next() as usize % n;
            // Off the pieces' ends by far more than the rounding of their
            // sums (the jumps add up lengths from the root, the walk from v).
            let s = (next() % 40_000) as f64 / 100.0 + 0.004_321;
            let got = a
                .piece_at(NodeId::from_index(v), s)
                .map(|(x, w)| (x.index(), w));
            let want = walk(v, s);
            assert_eq!(got.map(|g| g.0), want.map(|w| w.0), "v {v}, s {s}");
            if let (Some(g), Some(w)) = (got, want) {
                assert!((g.1 - w.1).abs() <= 1e-9 * (1.0 + w.1), "v {v}, s {s}");
            }
        }
    }
}
