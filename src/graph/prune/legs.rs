//! `significance` and `length` pruning: least significant leg first.
//!
//! A priority queue with lazy invalidation makes this O(n log n) in the
//! number of branches; ties are broken by the leaf's coordinates, then by
//! branch order. When removing a leg leaves its junction j with two
//! branches, one of which is itself a leg insignificant at j while the other
//! is not, that sibling leg goes too (j becomes a leaf): a leg is judged at
//! the junction where it met the rest of the skeleton, so losing a sibling
//! does not rescue it. This is what turns the medial axis of a rectangle (a
//! centre segment and four corner legs) into its centre segment. A junction
//! that becomes a leaf this way keeps the *reach* of what was cut behind it
//! (the larger extent of the two legs), and a leg's length is always counted
//! with the reach of its leaf (`length(leg) + reach(ℓ)`, reach = r_ℓ for an
//! original leaf, 0 on ∂P): without it a long arm whose junctions are closer
//! than two radii apart would be eroded junction by junction down to a
//! stub. When both remaining branches are insignificant legs they are
//! merged instead, so a component is never reduced below a simple path (two
//! leaves); such a component, in which every leg was insignificant (a
//! compact island), keeps its main axis — the path between the two leaves
//! farthest apart — rather than the two legs the removal order happened to
//! leave. A component that
//! already is a path keeps both ends, and legs of a component with cycles
//! (a polygon with holes) are removed down to the cycles.

use super::work::Work;
use super::{LegMeasure, PruneParams};
use crate::geometry::tolerance::ON_BOUNDARY_END;
use crate::geometry::Boundary;
use crate::geometry::CoordKey;
use crate::graph::cut::cut_ends;
use crate::graph::{EdgeId, NodeId, SkeletonGraph};
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// Heap entry; ordered by (key, leaf x, leaf y, piece id).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    key: f64,
    leaf: (f64, f64),
    piece: u32,
}

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        self.key
            .total_cmp(&o.key)
            .then(self.leaf.0.total_cmp(&o.leaf.0))
            .then(self.leaf.1.total_cmp(&o.leaf.1))
            .then(self.piece.cmp(&o.piece))
    }
}

impl Work<'_> {
    /// After a removal at `j` (of branches reaching `removed_extent` from
    /// it): when `j` is left with two branches, the sibling leg
    /// insignificant at `j` goes too (j becomes a leaf keeping the reach of
    /// what was cut behind it), or both are joined (when both are
    /// insignificant legs, `j` is noted in `collapsed`). Returns the branch
    /// to judge again.
    pub(super) fn settle(
        &mut self,
        j: NodeId,
        removed_extent: f64,
        params: &PruneParams,
        collapsed: &mut Vec<NodeId>,
    ) -> Option<u32> {
        if self.deg(j) != 2 {
            return None;
        }
        let (a, b) = (self.adj[j.index()][0], self.adj[j.index()][1]);
        let (ia, ib) = (
            self.insignificant_at(a, j, params),
            self.insignificant_at(b, j, params),
        );
        if ia != ib {
            // The sibling leg insignificant at j goes too; j becomes a leaf
            // of the other branch, which may now be an insignificant leg.
            let (gone, stays) = if ia { (a, b) } else { (b, a) };
            let gone_leaf = self.other(gone, j);
            // j keeps the reach of what was cut behind it, so that a long
            // arm is not eroded junction by junction.
            self.reach[j.index()] = removed_extent.max(self.extent(gone, gone_leaf));
            self.remove(gone);
            Some(stays)
        } else {
            if ia && ib {
                collapsed.push(j);
            }
            self.join(j)
        }
    }

    /// Piece `p` is a leg whose leaf is not `j` and which is insignificant
    /// when judged at `j` (radius r_j).
    fn insignificant_at(&self, p: u32, j: NodeId, params: &PruneParams) -> bool {
        let o = self.other(p, j);
        o != j && self.deg(o) == 1 && params.is_insignificant(&self.measure(p, o, j))
    }

    /// The leg `p` from junction `j` to leaf `leaf` as the rules see it. The
    /// mouth radius (a boundary query) is only measured when the radius rule
    /// alone would remove the leg.
    fn measure(&self, p: u32, leaf: NodeId, j: NodeId) -> LegMeasure {
        let rj = self.radius(j);
        let mut leg = LegMeasure {
            extent: self.extent(p, leaf),
            r_junction: rj,
            r_mouth: f64::INFINITY,
        };
        if params_may_need_mouth(&leg) {
            let len = self.pieces[p as usize].len;
            leg.r_mouth = if len > rj {
                // rj along the leg from j: within 2 rj of ∂P.
                self.boundary
                    .distance_within(self.point_at(p, j, rj), rj + rj)
            } else {
                self.radius(leaf).max(self.reach[leaf.index()])
            };
        }
        leg
    }

    fn entry(&self, p: u32, params: &PruneParams) -> Option<Entry> {
        let (leaf, j) = self.leg(p)?;
        let leg = self.measure(p, leaf, j);
        if !params.is_insignificant(&leg) {
            return None;
        }
        let pos = self.graph.node(leaf).pos;
        Some(Entry {
            key: params.key(&leg),
            leaf: (pos.x, pos.y),
            piece: p,
        })
    }
}

/// The kept edges of `m` (a merged graph) after `significance` or `length`
/// pruning (see the module documentation).
pub fn mask(m: &SkeletonGraph, params: &PruneParams, boundary: &Boundary) -> Vec<bool> {
    let mut w = Work::new(m, boundary);
    // A cut end is an end of the skeleton whatever its legs measure: its
    // corner legs go now (the extension ends the line on the cut), and its
    // junction reaches on without limit, so the leg to it is never cut.
    let tol = ON_BOUNDARY_END * boundary.extent();
    if params.mode == super::PruneMode::Significance {
        let rough = params.junctions == crate::graph::junctions::Junctions::Merge;
        for cut in cut_ends(m, boundary, tol, rough) {
            for leg in cut.tree {
                // Piece `i` of the first ones is edge `i`.
                if w.alive[leg.index()] {
                    w.remove(leg.index() as u32);
                }
            }
            w.reach[cut.junction.index()] = f64::INFINITY;
        }
    }
    let mut collapsed: Vec<NodeId> = Vec::new();
    if params.mode == super::PruneMode::Significance {
        super::sides::prune_sides(&mut w, params, &mut collapsed);
    }
    let mut heap: BinaryHeap<Reverse<Entry>> = (0..w.pieces.len() as u32)
        .filter_map(|p| w.entry(p, params).map(Reverse))
        .collect();
    while let Some(Reverse(e)) = heap.pop() {
        // Lazy invalidation: a piece that was joined or removed is dead, and
        // an alive piece keeps its leaf, length and junction radius.
        if !w.alive[e.piece as usize] {
            continue;
        }
        let Some((leaf, j)) = w.leg(e.piece) else {
            continue;
        };
        let removed_extent = w.extent(e.piece, leaf);
        w.remove(e.piece);
        let next = w.settle(j, removed_extent, params, &mut collapsed);
        if let Some(entry) = next.and_then(|p| w.entry(p, params)) {
            heap.push(Reverse(entry));
        }
    }
    let mut keep = w.keep;
    let mut collapsed: Vec<NodeId> = collapsed;
    collapsed.extend(short_lines(m, &keep, tol));
    if !collapsed.is_empty() {
        // Everything in these components was insignificant: which two legs
        // were left over is an accident of the removal order, so the
        // component keeps its main axis instead.
        let labels = m.component_labels();
        let flagged: std::collections::BTreeSet<usize> =
            collapsed.iter().map(|&j| labels[j.index()]).collect();
        for c in flagged {
            main_axis(m, &labels, c, &mut keep);
        }
    }
    keep
}

/// A node of every kept line that is shorter than the diameter of the
/// largest disc on it and ends inside P at both ends: such a line lies
/// within about one disc — a compact shape whose legs were all
/// insignificant although two of them were left — and its course says
/// nothing about where the shape's tips are; it gets the main axis instead.
fn short_lines(m: &SkeletonGraph, keep: &[bool], tol: f64) -> Vec<NodeId> {
    let n = m.nodes().len();
    let mut uf = crate::graph::UnionFind::new(n);
    let mut deg = vec![0usize; n];
    for (i, e) in m.edges().iter().enumerate() {
        if keep[i] {
            uf.union(e.a.index(), e.b.index());
            deg[e.a.index()] += 1;
            deg[e.b.index()] += 1;
        }
    }
    // Per component root: length, widest radius, leaves, branching.
    let mut length = std::collections::HashMap::<usize, f64>::new();
    for (i, e) in m.edges().iter().enumerate() {
        if keep[i] {
            *length.entry(uf.find(e.a.index())).or_default() +=
                m.edge_length(EdgeId::from_index(i));
        }
    }
    let mut widest = std::collections::HashMap::<usize, f64>::new();
    let mut leaves = std::collections::HashMap::<usize, Vec<usize>>::new();
    let mut branching = std::collections::HashSet::<usize>::new();
    for (k, node) in m.nodes().iter().enumerate() {
        if deg[k] == 0 {
            continue;
        }
        let root = uf.find(k);
        let w = widest.entry(root).or_default();
        *w = w.max(node.radius);
        match deg[k] {
            1 => leaves.entry(root).or_default().push(k),
            2 => {}
            _ => {
                branching.insert(root);
            }
        }
    }
    let mut out: Vec<NodeId> = leaves
        .iter()
        .filter(|(root, ls)| {
            ls.len() == 2
                && !branching.contains(root)
                && ls.iter().all(|&k| m.nodes()[k].radius > tol)
                && length[root] < 2.0 * widest[root]
        })
        .map(|(_, ls)| NodeId::from_index(ls[0]))
        .collect();
    out.sort();
    out
}

/// Most leaves paired in [`deepest_pair`]; a component with more pairs
/// those on its leaves' convex hull and its deepest tips.
const MAX_AXIS_LEAVES: usize = 2000;

/// Ancestors (besides the centre) against whose discs a leaf's depth is
/// measured in [`main_axis`]: the nearest ones on its path to the centre.
const AXIS_TIP_ANCESTORS: usize = 64;

/// Keeps, in component `c` of `m`, only its main axis: the path between
/// its two deepest tips, so a compact island gets a line through its
/// middle from tip to tip rather than a curve between two corners on one
/// side or a line to a shallow bank vertex.
///
/// From the node of largest radius (the centre z, its disc the largest
/// inscribed one), every leaf ℓ has the depth
/// `τ(ℓ) = max over x on the path z..ℓ of |ℓ − x| + r_ℓ − r_x` (how far ℓ
/// reaches beyond the largest disc and every disc after it; the tip depth
/// of `crate::graph::ends`). The axis joins the deepest leaf to the
/// deepest leaf of another branch at z, so that it runs through the
/// largest disc; ties go to the leaf farther from z, then to node order.
fn main_axis(m: &SkeletonGraph, labels: &[usize], c: usize, keep: &mut [bool]) {
    let in_c: Vec<bool> = m.edges().iter().map(|e| labels[e.a.index()] == c).collect();
    let pair = deepest_pair(m, labels, c);
    let path = pair.and_then(|(a, b)| super::trunk::shortest_path(m, &in_c, a, b));
    match path {
        Some(path) => {
            for (i, k) in keep.iter_mut().enumerate() {
                if in_c[i] {
                    *k = false;
                }
            }
            for e in path {
                keep[e.index()] = true;
            }
        }
        None => {
            let trunk = super::trunk::mask(m);
            for (i, k) in keep.iter_mut().enumerate() {
                if in_c[i] {
                    *k = trunk[i];
                }
            }
        }
    }
}

/// The two deepest tips of component `c` in different branches at its
/// centre (see [`main_axis`]).
fn deepest_pair(m: &SkeletonGraph, labels: &[usize], c: usize) -> Option<(NodeId, NodeId)> {
    let centre = (0..m.nodes().len())
        .filter(|&n| labels[n] == c)
        .map(NodeId::from_index)
        .max_by(|a, b| {
            m.node(*a)
                .radius
                .total_cmp(&m.node(*b).radius)
                .then(b.cmp(a))
        })?;
    let adj = m.adjacency();
    let z = m.node(centre);
    // Depth-first from the centre with the path kept: (node, depth, branch).
    let mut path: Vec<NodeId> = Vec::new();
    let mut seen = vec![false; m.nodes().len()];
    seen[centre.index()] = true;
    let mut stack = vec![(centre, 0usize, None::<EdgeId>)];
    // (τ, distance from the centre, leaf, branch)
    let mut tips: Vec<(f64, f64, NodeId, EdgeId)> = Vec::new();
    while let Some((n, depth, branch)) = stack.pop() {
        path.truncate(depth);
        path.push(n);
        let mut leaf = true;
        for &e in &adj[n.index()] {
            let o = m.opposite(e, n);
            if !seen[o.index()] {
                seen[o.index()] = true;
                leaf = false;
                stack.push((o, depth + 1, Some(branch.unwrap_or(e))));
            }
        }
        if let (true, Some(branch)) = (leaf, branch) {
            let l = m.node(n);
            let reach = |x: NodeId| {
                let x = m.node(x);
                crate::geometry::vector::hypot(l.pos - x.pos) + l.radius - x.radius
            };
            let from = path.len().saturating_sub(AXIS_TIP_ANCESTORS);
            let tau = path[from..]
                .iter()
                .map(|&x| reach(x))
                .fold(reach(centre), f64::max)
                .max(0.0);
            let dist = crate::geometry::vector::hypot(l.pos - z.pos);
            tips.push((tau, dist, n, branch));
        }
    }
    // The pair with the largest |a − b| + τ(a) + τ(b): as far apart as the
    // shape is long, with real tips preferred to shallow bank vertices.
    // With many leaves (the thickets of a rough rim) only those on the
    // leaves' convex hull and the deepest ones are paired.
    if tips.len() > MAX_AXIS_LEAVES {
        let hull: std::collections::HashSet<NodeId> =
            hull_leaves(m, &tips.iter().map(|t| t.2).collect::<Vec<_>>())
                .into_iter()
                .collect();
        tips.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.2.cmp(&b.2)));
        let deepest: Vec<NodeId> = tips.iter().take(MAX_AXIS_LEAVES / 4).map(|t| t.2).collect();
        tips.retain(|t| hull.contains(&t.2) || deepest.contains(&t.2));
        tips.truncate(MAX_AXIS_LEAVES);
    }
    let pos = |n: NodeId| m.node(n).pos;
    let mut best: Option<(f64, NodeId, NodeId)> = None;
    for (i, a) in tips.iter().enumerate() {
        for b in &tips[i + 1..] {
            let score = crate::geometry::vector::hypot(pos(a.2) - pos(b.2)) + a.0 + b.0;
            if best.is_none_or(|(s, _, _)| score > s) {
                best = Some((score, a.2, b.2));
            }
        }
    }
    best.map(|(_, a, b)| (a, b))
}

/// The leaves among `leaves` at the corners of their convex hull, in
/// node order.
fn hull_leaves(m: &SkeletonGraph, leaves: &[NodeId]) -> Vec<NodeId> {
    use geo::ConvexHull;
    let points: geo::MultiPoint<f64> = leaves.iter().map(|&n| geo::Point(m.node(n).pos)).collect();
    let corners: std::collections::HashSet<CoordKey> = points
        .convex_hull()
        .exterior()
        .0
        .iter()
        .map(CoordKey::from)
        .collect();
    leaves
        .iter()
        .copied()
        .filter(|&n| {
            let p = m.node(n).pos;
            corners.contains(&CoordKey::from(p))
        })
        .collect()
}

/// True unless the radius rule alone already keeps the leg (then its mouth
/// is never needed); conservative: any mode and ratio may ask.
fn params_may_need_mouth(leg: &LegMeasure) -> bool {
    leg.extent > leg.r_junction
}

/// Distance to ∂P where the leg `coords` (starting at its junction of radius
/// `r_j`) leaves the junction's disc; at its far end when it is shorter.
/// What the pruning worker measures piece by piece, for the tests.
#[cfg(test)]
pub(crate) fn mouth_radius(coords: &[geo::Coord<f64>], r_j: f64, boundary: &Boundary) -> f64 {
    boundary.distance(crate::graph::line::point_at(coords, r_j))
}
