//! A static packed R-tree of boxes (the Hilbert-packed layout of
//! `flatbush`): items sorted along a Hilbert curve, grouped eight to a
//! node, level by level, in flat arrays. Built once per polygon; queries
//! allocate nothing (their stack lives on the call stack; the self-join of
//! [`PackedTree::pairs`] keeps its node pairs in a list) and visit each
//! node's children nearest first, so a ray stops soon after its first hit
//! and a nearest-point search soon after its answer.
//!
//! The tree knows only boxes and item numbers: what an item is, and its
//! exact distance or hit, is the caller's (see [`super::Boundary`]). A tree
//! of more than 64 segments ([`PackedTree::of_segments`]) also keeps an
//! oriented box ([`Obb`]) around each node, which the nearest-point and
//! half-plane searches bound with: seen from inside a round polygon, the
//! axis-aligned box of a diagonal or curved stretch of shore reaches far
//! towards the query point, and the side searches of a 200 000-vertex noisy
//! circle's bars scored 446 boxes each with them, 140 with oriented ones.

use super::tolerance::{BOUND_MARGIN, BOX_SLACK, SLAB_SLACK};
use std::mem::MaybeUninit;
use std::ops::ControlFlow;

/// Children per node. Eight rather than flatbush's sixteen: where a
/// search's bound cannot rule out a node's box (the middle of a round lake,
/// nearly equidistant from all its shore), fewer children are scored per
/// node opened — the score of a 200 000-vertex polygon's bars takes 14 %
/// less CPU, small polygons the same (`BENCHMARKS.md`).
const NODE_SIZE: usize = 8;

/// At most this many boxes are paired one by one ([`PackedTree::pairs_of`]):
/// the skeletons and rings of most islands.
const FEW_PAIRED: usize = 48;

/// [`PackedTree::first_pair`] shares out this many node pairs at least…
const SHARED_NODE_PAIRS: usize = 256;

/// …on trees of at least this many items (a smaller one is checked on one
/// thread: the boundary of most polygons, in a run that has a thread per
/// feature already).
const PAIRED_IN_PARALLEL: usize = 1 << 15;

/// Depth-first stack entries a query can need: one node's children per
/// level, and a tree over 2^32 items has 11 levels.
const STACK: usize = NODE_SIZE * 12;

/// An axis-aligned box: `[min x, min y, max x, max y]`.
pub(crate) type Bbox = [f64; 4];

/// The packed tree.
#[derive(Debug, Clone, Default)]
pub(crate) struct PackedTree {
    /// Item boxes (Hilbert order), then the nodes of each level up to the root.
    boxes: Vec<Bbox>,
    /// For an item position: the item's number; for a node: the position of
    /// its first child.
    ids: Vec<u32>,
    /// End position of each level in `boxes` (level 0 = the items).
    level_ends: Vec<usize>,
    /// An oriented box around each node (position − number of items), when
    /// the tree was built from segments and is large enough to gain from
    /// them ([`PackedTree::of_segments`]); empty otherwise.
    oriented: Vec<Obb>,
}

/// An oriented box: centre `c`, unit axis `u`, half-length `hl` along `u`
/// and half-width `hw` across it. Around the segments under a node of a
/// large tree: a chunk of shore is long and thin in its own direction, and
/// its axis-aligned box is not when the shore runs diagonally or curves —
/// from inside a round polygon such boxes reach far towards the query point
/// and can rarely be ruled out. Its bounds are lower bounds under rounding
/// (the extents are widened by a relative 10⁻¹² of the coordinates at
/// construction and every bound is shrunk by a relative 10⁻⁹), so a search
/// gives the same answer with them as with axis-aligned boxes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Obb {
    c: [f64; 2],
    u: [f64; 2],
    hl: f64,
    hw: f64,
}

/// Trees of at most this many items get no oriented boxes: two levels at
/// most, whose few boxes are cheaper to test axis-aligned.
const ORIENTED_MIN: usize = NODE_SIZE * NODE_SIZE;

impl Obb {
    /// Around `points` (at least one), its axis along their principal
    /// direction.
    fn around(points: &[[f64; 2]]) -> Self {
        let k = points.len() as f64;
        let (mut mx, mut my) = (0.0, 0.0);
        for p in points {
            mx += p[0];
            my += p[1];
        }
        let (mx, my) = (mx / k, my / k);
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for p in points {
            let (dx, dy) = (p[0] - mx, p[1] - my);
            sxx += dx * dx;
            sxy += dx * dy;
            syy += dy * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let u = [angle.cos(), angle.sin()];
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            let (dx, dy) = (p[0] - mx, p[1] - my);
            let l = [dx * u[0] + dy * u[1], -dx * u[1] + dy * u[0]];
            for a in 0..2 {
                lo[a] = lo[a].min(l[a]);
                hi[a] = hi[a].max(l[a]);
            }
        }
        let (ca, cb) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
        let c = [mx + ca * u[0] - cb * u[1], my + ca * u[1] + cb * u[0]];
        let (hl, hw) = (0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]));
        // Rounding in the projections above and in a query's: a relative
        // 10⁻¹² of the magnitudes involved is far beyond it.
        let slack = BOX_SLACK * (c[0].abs() + c[1].abs() + hl + hw) + f64::MIN_POSITIVE;
        Self {
            c,
            u,
            hl: hl + slack,
            hw: hw + slack,
        }
    }

    /// `p − c` along and across the axis.
    fn local(&self, p: [f64; 2]) -> [f64; 2] {
        let (dx, dy) = (p[0] - self.c[0], p[1] - self.c[1]);
        [
            dx * self.u[0] + dy * self.u[1],
            -dx * self.u[1] + dy * self.u[0],
        ]
    }

    /// A lower bound of the squared distance from `p` to anything in the box.
    pub(crate) fn distance_2(&self, p: [f64; 2]) -> f64 {
        let l = self.local(p);
        let a = (l[0].abs() - self.hl).max(0.0);
        let b = (l[1].abs() - self.hw).max(0.0);
        (a * a + b * b) * (1.0 - 2.0 * BOUND_MARGIN)
    }

    /// A lower bound of the distance from `q` to the part of the box in the
    /// closed half-planes `(x − q) · n ≥ 0` of every `n` in `normals`, or
    /// `None` when the box is out of one of them (never when a point of it
    /// is in all).
    pub(crate) fn clipped_distance(&self, q: [f64; 2], normals: &[[f64; 2]]) -> Option<f64> {
        let l = self.local(q);
        for n in normals {
            let nl = [
                n[0] * self.u[0] + n[1] * self.u[1],
                -n[0] * self.u[1] + n[1] * self.u[0],
            ];
            // The farthest reach of the box along n, from q.
            let reach =
                -(l[0] * nl[0] + l[1] * nl[1]) + self.hl * nl[0].abs() + self.hw * nl[1].abs();
            let room = BOUND_MARGIN
                * (l[0].abs() + l[1].abs() + self.hl + self.hw)
                * (nl[0].abs() + nl[1].abs());
            if reach < -room {
                return None;
            }
        }
        let a = (l[0].abs() - self.hl).max(0.0);
        let b = (l[1].abs() - self.hw).max(0.0);
        Some(((a * a + b * b) * (1.0 - 2.0 * BOUND_MARGIN)).sqrt())
    }
}

/// What a node or item is to a query: its lower bound (a distance, a ray
/// parameter), `None` to skip it.
type Bound = Option<f64>;

impl PackedTree {
    /// Packs `boxes` (item `i` has box `boxes[i]`).
    pub(crate) fn new(boxes: &[Bbox]) -> Self {
        let n = boxes.len();
        if n == 0 {
            return Self::default();
        }
        if n <= NODE_SIZE {
            return Self::one_node(boxes);
        }
        let level_ends = level_ends(n);
        let total = level_ends[level_ends.len() - 1];
        let mut tree_boxes = Vec::with_capacity(total);
        let mut ids = Vec::with_capacity(total);
        for i in hilbert_order(boxes) {
            tree_boxes.push(boxes[i as usize]);
            ids.push(i);
        }
        let mut start = 0;
        for &end in &level_ends[..level_ends.len() - 1] {
            let mut pos = start;
            while pos < end {
                let stop = (pos + NODE_SIZE).min(end);
                let b = tree_boxes[pos..stop]
                    .iter()
                    .fold(tree_boxes[pos], |acc, b| union(acc, *b));
                tree_boxes.push(b);
                ids.push(pos as u32);
                pos = stop;
            }
            start = end;
        }
        Self {
            boxes: tree_boxes,
            ids,
            level_ends,
            oriented: Vec::new(),
        }
    }

    /// The tree of at most [`NODE_SIZE`] boxes: one node holds every item
    /// (or the item is the root), with no order to find along the curve.
    fn one_node(boxes: &[Bbox]) -> Self {
        let n = boxes.len();
        let mut tree_boxes = Vec::with_capacity(n + 1);
        tree_boxes.extend_from_slice(boxes);
        let mut ids: Vec<u32> = (0..n as u32).collect();
        let mut level_ends = vec![n];
        if n > 1 {
            tree_boxes.push(boxes[1..].iter().fold(boxes[0], |acc, b| union(acc, *b)));
            ids.push(0);
            level_ends.push(n + 1);
        }
        Self {
            boxes: tree_boxes,
            ids,
            level_ends,
            oriented: Vec::new(),
        }
    }

    /// Packs segments (item `i` runs from `ends[i][0]` to `ends[i][1]`),
    /// with an oriented box around every node when there are more than
    /// `ORIENTED_MIN` (64) of them.
    pub(crate) fn of_segments(ends: &[[[f64; 2]; 2]]) -> Self {
        let boxes: Vec<Bbox> = ends
            .iter()
            .map(|[a, b]| {
                [
                    a[0].min(b[0]),
                    a[1].min(b[1]),
                    a[0].max(b[0]),
                    a[1].max(b[1]),
                ]
            })
            .collect();
        let mut tree = Self::new(&boxes);
        let n = tree.len();
        if n <= ORIENTED_MIN {
            return tree;
        }
        // Each node covers a run of item positions: its first child's first
        // item to its last child's last one.
        let mut points: Vec<[f64; 2]> = Vec::with_capacity(2 * n);
        for &i in &tree.ids[..n] {
            points.extend_from_slice(&ends[i as usize]);
        }
        let nodes = tree.boxes.len() - n;
        let mut runs: Vec<(usize, usize)> = Vec::with_capacity(nodes);
        let mut oriented = Vec::with_capacity(nodes);
        for pos in n..tree.boxes.len() {
            let kids = tree.children(pos);
            let run = if kids.start < n {
                (kids.start, kids.end)
            } else {
                (runs[kids.start - n].0, runs[kids.end - 1 - n].1)
            };
            runs.push(run);
            oriented.push(Obb::around(&points[2 * run.0..2 * run.1]));
        }
        tree.oriented = oriented;
        tree
    }

    /// The position of every item (indexed by item number), for
    /// [`PackedTree::remove_at`].
    pub(crate) fn item_positions(&self) -> Vec<u32> {
        let n = self.len();
        let mut pos = vec![0u32; n];
        for (p, &i) in self.ids[..n].iter().enumerate() {
            pos[i as usize] = p as u32;
        }
        pos
    }

    /// Takes the item at position `pos` out of every later query: its box
    /// becomes empty (it meets no box) and each ancestor's box shrinks to
    /// the union of its children's, so that a subtree whose items are all
    /// removed is no longer entered. O(node size · depth). Oriented boxes,
    /// if any, are left as they were (still bounds).
    pub(crate) fn remove_at(&mut self, pos: usize) {
        const EMPTY: Bbox = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        self.boxes[pos] = EMPTY;
        let (mut pos, mut start) = (pos, 0);
        for w in self.level_ends.windows(2) {
            let (end, parent) = (w[0], w[0] + (pos - start) / NODE_SIZE);
            let b = self
                .children(parent)
                .fold(EMPTY, |acc, c| union(acc, self.boxes[c]));
            if b == self.boxes[parent] {
                break;
            }
            self.boxes[parent] = b;
            (pos, start) = (parent, end);
        }
    }

    /// Number of items.
    pub(crate) fn len(&self) -> usize {
        self.level_ends.first().copied().unwrap_or(0)
    }

    /// The children positions of the node at `pos`.
    fn children(&self, pos: usize) -> std::ops::Range<usize> {
        let first = self.ids[pos] as usize;
        // The level the children are on ends at the first level end above them.
        let end = self
            .level_ends
            .iter()
            .copied()
            .find(|&e| e > first)
            .unwrap_or(first);
        first..(first + NODE_SIZE).min(end)
    }

    /// Visits every item whose box `node` accepts (and whose every ancestor's
    /// box it accepts), in no particular order, until `item` breaks.
    pub(crate) fn visit<B>(
        &self,
        node: impl Fn(&Bbox) -> bool,
        mut item: impl FnMut(u32) -> ControlFlow<B>,
    ) -> Option<B> {
        let n = self.len();
        if n == 0 {
            return None;
        }
        let root = self.boxes.len() - 1;
        if !node(&self.boxes[root]) {
            return None;
        }
        if root < n {
            // A single item.
            return item(self.ids[root]).break_value();
        }
        let mut stack = [MaybeUninit::<usize>::uninit(); STACK];
        stack[0] = MaybeUninit::new(root);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            // SAFETY: entries below `top` were written before.
            let pos = unsafe { stack[top].assume_init() };
            for c in self.children(pos) {
                if !node(&self.boxes[c]) {
                    continue;
                }
                if c < n {
                    if let ControlFlow::Break(b) = item(self.ids[c]) {
                        return Some(b);
                    }
                } else {
                    stack[top] = MaybeUninit::new(c);
                    top += 1;
                }
            }
        }
        None
    }

    /// [`PackedTree::pairs`] of the tree over `boxes`, without building one
    /// for a few boxes: every pair is tested in turn (in order: `(0, 1)`,
    /// `(0, 2)`, …), which costs less than packing them.
    pub(crate) fn pairs_of<B>(
        boxes: &[Bbox],
        mut pair: impl FnMut(u32, u32) -> ControlFlow<B>,
    ) -> Option<B> {
        if boxes.len() > FEW_PAIRED {
            return Self::new(boxes).pairs(pair);
        }
        for (i, a) in boxes.iter().enumerate() {
            for (j, b) in boxes.iter().enumerate().skip(i + 1) {
                if boxes_meet(a, b) {
                    if let ControlFlow::Break(x) = pair(i as u32, j as u32) {
                        return Some(x);
                    }
                }
            }
        }
        None
    }

    /// Visits every pair of items whose boxes meet, once each as `(i, j)`
    /// with item numbers `i < j`, in no particular order, until `pair`
    /// breaks. One descent pairs nodes with nodes (a self-join): a query per
    /// item would descend from the root once per item and meet every pair
    /// twice.
    pub(crate) fn pairs<B>(&self, mut pair: impl FnMut(u32, u32) -> ControlFlow<B>) -> Option<B> {
        let n = self.len();
        if n < 2 {
            return None;
        }
        // Node pairs of one level (every leaf is on level 0), a node with
        // itself included: their children's pairs are still to be met.
        let mut todo = vec![(self.boxes.len() - 1, self.boxes.len() - 1)];
        while let Some((a, b)) = todo.pop() {
            if let Some(x) = self.node_pairs(a, b, &mut todo, &mut pair) {
                return Some(x);
            }
        }
        None
    }

    /// The pair `(i, j)`, `i < j`, of items whose boxes meet that is first
    /// in `(i, j)` order among those for which `pair` gives a value, with
    /// that value: a check every pair must pass (every meeting pair is
    /// tested). The self-join of [`Self::pairs`], with the node pairs a few
    /// levels below the root shared out over rayon's threads: one polygon
    /// of a million vertices is checked on every core, not one.
    pub(crate) fn first_pair<T: Send>(
        &self,
        pair: impl Fn(u32, u32) -> Option<T> + Sync,
    ) -> Option<(u32, u32, T)> {
        use rayon::prelude::*;
        fn earlier<T>(a: Option<(u32, u32, T)>, b: Option<(u32, u32, T)>) -> Option<(u32, u32, T)> {
            match (a, b) {
                (Some(a), Some(b)) => Some(if (b.0, b.1) < (a.0, a.1) { b } else { a }),
                (a, b) => a.or(b),
            }
        }
        if self.len() < 2 {
            return None;
        }
        let found = |local: &mut Option<(u32, u32, T)>, i: u32, j: u32| {
            if local.as_ref().is_none_or(|f| (i, j) < (f.0, f.1)) {
                if let Some(v) = pair(i, j) {
                    *local = Some((i, j, v));
                }
            }
            ControlFlow::<()>::Continue(())
        };
        // Breadth first until there are node pairs enough to share.
        let root = self.boxes.len() - 1;
        let mut todo = vec![(root, root)];
        let mut first = None;
        while !todo.is_empty() && todo.len() < SHARED_NODE_PAIRS {
            let mut next = Vec::with_capacity(todo.len() * NODE_SIZE);
            for (a, b) in todo {
                self.node_pairs(a, b, &mut next, |i, j| found(&mut first, i, j));
            }
            todo = next;
        }
        let below = |start: (usize, usize)| {
            let mut local = None;
            let mut stack = vec![start];
            while let Some((a, b)) = stack.pop() {
                self.node_pairs(a, b, &mut stack, |i, j| found(&mut local, i, j));
            }
            local
        };
        let rest = if self.len() < PAIRED_IN_PARALLEL {
            todo.into_iter().map(below).fold(None, earlier)
        } else {
            todo.into_par_iter().map(below).reduce(|| None, earlier)
        };
        earlier(first, rest)
    }

    /// [`Self::first_pair`] of the tree over `boxes`, without building one
    /// for a few boxes (every pair in turn, in order, as
    /// [`Self::pairs_of`]).
    pub(crate) fn first_pair_of<T: Send>(
        boxes: &[Bbox],
        pair: impl Fn(u32, u32) -> Option<T> + Sync,
    ) -> Option<(u32, u32, T)> {
        if boxes.len() > FEW_PAIRED {
            return Self::new(boxes).first_pair(pair);
        }
        Self::pairs_of(boxes, |i, j| match pair(i, j) {
            Some(v) => ControlFlow::Break((i, j, v)),
            None => ControlFlow::Continue(()),
        })
    }

    /// One step of the self-join: the children of nodes `a` and `b` (`a`
    /// with itself when they are the same) whose boxes meet, as node pairs
    /// pushed on `todo` or, on the items' level, item pairs `(i, j)`, `i < j`,
    /// given to `item` until it breaks.
    fn node_pairs<B>(
        &self,
        a: usize,
        b: usize,
        todo: &mut Vec<(usize, usize)>,
        mut item: impl FnMut(u32, u32) -> ControlFlow<B>,
    ) -> Option<B> {
        let n = self.len();
        let (ka, kb) = (self.children(a), self.children(b));
        for ca in ka {
            let first = if a == b { ca } else { kb.start };
            for cb in first..kb.end {
                if !boxes_meet(&self.boxes[ca], &self.boxes[cb]) {
                    continue;
                }
                if ca >= n {
                    todo.push((ca, cb));
                } else if ca != cb {
                    let (i, j) = (self.ids[ca], self.ids[cb]);
                    if let ControlFlow::Break(x) = item(i.min(j), i.max(j)) {
                        return Some(x);
                    }
                }
            }
        }
        None
    }

    /// Branch and bound: visits items in roughly increasing `bound` order
    /// and skips every node and item whose bound is not below the best value
    /// `item` has returned so far. `bound` gives a lower bound of what any
    /// item in a box can score (`None`: nothing in it can count); `item`
    /// scores an item exactly (`None`: it does not count). Returns the best
    /// item's score and number; ties go to the lower item number, so the
    /// answer does not depend on the tree's layout.
    pub(crate) fn best(
        &self,
        bound: impl Fn(&Bbox) -> Bound,
        oriented: Option<impl Fn(&Obb) -> Bound>,
        item: impl FnMut(u32, f64) -> Bound,
    ) -> Option<(f64, u32)> {
        self.best_within(f64::INFINITY, bound, oriented, item)
    }

    /// [`Self::best`] among the items scoring at most `limit`.
    pub(crate) fn best_within(
        &self,
        limit: f64,
        bound: impl Fn(&Bbox) -> Bound,
        oriented: Option<impl Fn(&Obb) -> Bound>,
        mut item: impl FnMut(u32, f64) -> Bound,
    ) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        self.branch_and_bound(
            limit,
            |b| bound(b),
            oriented,
            |id| {
                let cut = best.map_or(limit, |(v, _)| v);
                if let Some(v) = item(id, cut).filter(|&v| v <= limit) {
                    if best.is_none_or(|(bv, bi)| v < bv || (v == bv && id < bi)) {
                        best = Some((v, id));
                    }
                }
                best.map_or(limit, |(v, _)| v)
            },
        );
        best
    }

    /// The traversal under [`Self::best`] and the two-sided searches:
    /// depth first, each node's children in increasing order of their bound,
    /// skipping every node and item whose bound exceeds the cut-off (`limit`
    /// at first, then what `item` returns; equal bounds are still visited,
    /// for the tie rule). Every item that can beat or tie the answer is
    /// scored, so the answer is the one a best-first search gives.
    pub(crate) fn branch_and_bound(
        &self,
        limit: f64,
        bound: impl Fn(&Bbox) -> Bound,
        oriented: Option<impl Fn(&Obb) -> Bound>,
        mut item: impl FnMut(u32) -> f64,
    ) {
        let n = self.len();
        if n == 0 {
            return;
        }
        // A node's bound: from its oriented box when the tree has them and
        // the query can use them.
        let oriented = oriented.filter(|_| !self.oriented.is_empty());
        let root = self.boxes.len() - 1;
        let root_bound = match &oriented {
            Some(f) if root >= n => f(&self.oriented[root - n]),
            _ => bound(&self.boxes[root]),
        };
        let Some(rb) = root_bound.filter(|&b| b <= limit) else {
            return;
        };
        if root < n {
            item(self.ids[root]);
            return;
        }
        let top = self.children(root);
        if top.start < n {
            // One leaf (a small polygon): its items in order, as the heap
            // would visit them, without the heap.
            self.score_items(top, limit, &bound, &mut item);
            return;
        }
        self.depth_first((rb, root), limit, &bound, oriented.as_ref(), &mut item);
    }

    /// Scores the items at `positions` in order, each whose bound is not
    /// above the cut-off (`cut` at first, then what `item` returns); returns
    /// the last cut-off.
    fn score_items(
        &self,
        positions: std::ops::Range<usize>,
        mut cut: f64,
        bound: &impl Fn(&Bbox) -> Bound,
        item: &mut impl FnMut(u32) -> f64,
    ) -> f64 {
        for c in positions {
            if bound(&self.boxes[c]).is_some_and(|b| b <= cut) {
                cut = item(self.ids[c]);
            }
        }
        cut
    }

    /// [`Self::branch_and_bound`] below the root (with its bound), whose
    /// children are nodes: depth first, each node's children nearest first.
    /// The same items are scored as best first would (every item whose
    /// bound is not above the cut-off when it is reached, and the answer's
    /// never is), with a fixed stack on the call stack instead of a heap.
    fn depth_first(
        &self,
        root: (f64, usize),
        limit: f64,
        bound: &impl Fn(&Bbox) -> Bound,
        oriented: Option<&impl Fn(&Obb) -> Bound>,
        item: &mut impl FnMut(u32) -> f64,
    ) {
        let n = self.len();
        let mut stack = [MaybeUninit::<(f64, u32)>::uninit(); STACK];
        stack[0] = MaybeUninit::new((root.0, root.1 as u32));
        let mut top = 1;
        let mut cut = limit;
        while top > 0 {
            top -= 1;
            // SAFETY: entries below `top` were written before.
            let (lb, pos) = unsafe { stack[top].assume_init() };
            if lb > cut {
                continue;
            }
            let children = self.children(pos as usize);
            if children.start < n {
                // Children are items: score every one that can still count.
                cut = self.score_items(children, cut, bound, item);
                continue;
            }
            // The children that can still count, their bounds from their
            // oriented or their axis-aligned boxes, each kind in its own
            // loop.
            let mut sorted = Nearest {
                stack: &mut stack,
                first: top,
                top,
            };
            match oriented {
                Some(f) => {
                    for c in children {
                        if let Some(b) = f(&self.oriented[c - n]).filter(|&b| b <= cut) {
                            sorted.push(b, c);
                        }
                    }
                }
                None => {
                    for c in children {
                        if let Some(b) = bound(&self.boxes[c]).filter(|&b| b <= cut) {
                            sorted.push(b, c);
                        }
                    }
                }
            }
            top = sorted.top;
        }
    }
}

/// One node's children pushed on the depth-first stack above `first`,
/// sorted so that the nearest is on top (insertion sort: at most
/// [`NODE_SIZE`] of them).
struct Nearest<'s> {
    stack: &'s mut [MaybeUninit<(f64, u32)>; STACK],
    first: usize,
    top: usize,
}

impl Nearest<'_> {
    /// Pushes node `c` with bound `b` in its place.
    #[inline]
    fn push(&mut self, b: f64, c: usize) {
        let mut j = self.top;
        // SAFETY: entries first..top were written in this loop.
        while j > self.first && unsafe { self.stack[j - 1].assume_init().0 } < b {
            self.stack[j] = self.stack[j - 1];
            j -= 1;
        }
        self.stack[j] = MaybeUninit::new((b, c as u32));
        self.top += 1;
    }
}

/// The item numbers of `boxes` in the order of their centres along the
/// Hilbert curve over their common box (ties by number).
fn hilbert_order(boxes: &[Bbox]) -> Vec<u32> {
    let mut all = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for b in boxes {
        all = union(all, *b);
    }
    let (w, h) = ((all[2] - all[0]).max(0.0), (all[3] - all[1]).max(0.0));
    let max = f64::from(u16::MAX);
    let key = |b: &Bbox| {
        let cx = if w > 0.0 {
            ((b[0] + b[2]) * 0.5 - all[0]) / w * max
        } else {
            0.0
        };
        let cy = if h > 0.0 {
            ((b[1] + b[3]) * 0.5 - all[1]) / h * max
        } else {
            0.0
        };
        hilbert(cx as u32, cy as u32)
    };
    let mut order: Vec<(u32, u32)> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| (key(b), i as u32))
        .collect();
    order.sort_unstable();
    order.into_iter().map(|(_, i)| i).collect()
}

/// End position of each level of a tree of `n` items (level 0 = the
/// items), [`NODE_SIZE`] children a node, up to the root.
fn level_ends(n: usize) -> Vec<usize> {
    let mut level_ends = vec![n];
    let mut count = n;
    let mut total = n;
    while count > 1 {
        count = count.div_ceil(NODE_SIZE);
        total += count;
        level_ends.push(total);
    }
    level_ends
}

fn union(a: Bbox, b: Bbox) -> Bbox {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

/// Whether two boxes meet (touching counts).
pub(crate) fn boxes_meet(a: &Bbox, b: &Bbox) -> bool {
    a[0] <= b[2] && a[2] >= b[0] && a[1] <= b[3] && a[3] >= b[1]
}

/// Squared distance from `(x, y)` to the box (0 inside).
pub(crate) fn box_distance_2(b: &Bbox, x: f64, y: f64) -> f64 {
    let dx = (b[0] - x).max(0.0).max(x - b[2]);
    let dy = (b[1] - y).max(0.0).max(y - b[3]);
    dx * dx + dy * dy
}

/// The parameter interval `[t0, t1]` over which the ray `o + t·d`,
/// `0 ≤ t ≤ max_t`, is inside the box, or `None`.
pub(crate) fn ray_box(b: &Bbox, o: [f64; 2], d: [f64; 2], max_t: f64) -> Option<(f64, f64)> {
    let mut t0 = 0.0f64;
    let mut t1 = max_t;
    for k in 0..2 {
        let (l, h) = (b[k], b[k + 2]);
        if d[k] == 0.0 {
            if o[k] < l || o[k] > h {
                return None;
            }
        } else {
            let (mut a, mut c) = ((l - o[k]) / d[k], (h - o[k]) / d[k]);
            if a > c {
                std::mem::swap(&mut a, &mut c);
            }
            t0 = t0.max(a);
            t1 = t1.min(c);
            if t0 > t1 {
                return None;
            }
        }
    }
    Some((t0, t1))
}

/// A ray `o + t·d` prepared for many box tests ([`RaySlab::enter`]): the
/// reciprocals of its direction computed once, so each test multiplies
/// instead of dividing (its interval widened by [`SLAB_SLACK`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RaySlab {
    o: [f64; 2],
    d: [f64; 2],
    inv: [f64; 2],
    max_t: f64,
}

impl RaySlab {
    /// The ray `o + t·d`, `0 ≤ t ≤ max_t`.
    pub(crate) fn new(o: [f64; 2], d: [f64; 2], max_t: f64) -> Self {
        Self {
            o,
            d,
            inv: [1.0 / d[0], 1.0 / d[1]],
            max_t,
        }
    }

    /// Where the ray enters the box: a lower bound of [`ray_box`]'s `t0`
    /// (never above it), or `None` when the ray misses the box by more
    /// than rounding. As a search bound it prunes a little less than
    /// [`ray_box`] would, never more.
    #[inline]
    pub(crate) fn enter(&self, b: &Bbox) -> Option<f64> {
        let mut t0 = 0.0f64;
        let mut t1 = self.max_t;
        for k in 0..2 {
            let (l, h) = (b[k], b[k + 2]);
            if self.d[k] == 0.0 {
                if self.o[k] < l || self.o[k] > h {
                    return None;
                }
            } else {
                let (mut a, mut c) = ((l - self.o[k]) * self.inv[k], (h - self.o[k]) * self.inv[k]);
                if a > c {
                    std::mem::swap(&mut a, &mut c);
                }
                t0 = t0.max(a - a.abs() * SLAB_SLACK);
                t1 = t1.min(c + c.abs() * SLAB_SLACK);
                if t0 > t1 {
                    return None;
                }
            }
        }
        Some(t0)
    }
}

/// True when some corner of the box is in the closed half-plane
/// `(x − q) · n ≥ 0`. Safe under rounding for points in the box: the test
/// is on the corner farthest along `n`, and `(x − q) · n` computed in
/// floating point never decreases as `x` moves towards that corner, so a
/// point of the box that tests inside makes the corner test inside too.
pub(crate) fn box_meets_half_plane(b: &Bbox, q: [f64; 2], n: [f64; 2]) -> bool {
    // The corner farthest along n.
    let x = if n[0] >= 0.0 { b[2] } else { b[0] };
    let y = if n[1] >= 0.0 { b[3] } else { b[1] };
    (x - q[0]) * n[0] + (y - q[1]) * n[1] >= 0.0
}

/// Position of `(x, y)` (each < 2^16) along the Hilbert curve (the
/// branch-free form of "Fast Hilbert curve generation, sorting, and range
/// queries", as in flatbush).
fn hilbert(x: u32, y: u32) -> u32 {
    let mut a = x ^ y;
    let mut b = 0xFFFF ^ a;
    let mut c = 0xFFFF ^ (x | y);
    let mut d = x & (y ^ 0xFFFF);

    let mut aa = a | (b >> 1);
    let mut bb = (a >> 1) ^ a;
    let mut cc = ((c >> 1) ^ (b & (d >> 1))) ^ c;
    let mut dd = ((a & (c >> 1)) ^ (d >> 1)) ^ d;

    a = aa;
    b = bb;
    c = cc;
    d = dd;
    aa = (a & (a >> 2)) ^ (b & (b >> 2));
    bb = (a & (b >> 2)) ^ (b & ((a ^ b) >> 2));
    cc ^= (a & (c >> 2)) ^ (b & (d >> 2));
    dd ^= (b & (c >> 2)) ^ ((a ^ b) & (d >> 2));

    a = aa;
    b = bb;
    c = cc;
    d = dd;
    aa = (a & (a >> 4)) ^ (b & (b >> 4));
    bb = (a & (b >> 4)) ^ (b & ((a ^ b) >> 4));
    cc ^= (a & (c >> 4)) ^ (b & (d >> 4));
    dd ^= (b & (c >> 4)) ^ ((a ^ b) & (d >> 4));

    a = aa;
    b = bb;
    c = cc;
    d = dd;
    cc ^= (a & (c >> 8)) ^ (b & (d >> 8));
    dd ^= (b & (c >> 8)) ^ ((a ^ b) & (d >> 8));

    a = cc ^ (cc >> 1);
    b = dd ^ (dd >> 1);

    let mut i0 = x ^ y;
    let mut i1 = b | (0xFFFF ^ (i0 | a));

    i0 = (i0 | (i0 << 8)) & 0x00FF_00FF;
    i0 = (i0 | (i0 << 4)) & 0x0F0F_0F0F;
    i0 = (i0 | (i0 << 2)) & 0x3333_3333;
    i0 = (i0 | (i0 << 1)) & 0x5555_5555;

    i1 = (i1 | (i1 << 8)) & 0x00FF_00FF;
    i1 = (i1 | (i1 << 4)) & 0x0F0F_0F0F;
    i1 = (i1 | (i1 << 2)) & 0x3333_3333;
    i1 = (i1 | (i1 << 1)) & 0x5555_5555;

    (i1 << 1) | i0
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::Coord;

    fn grid(n: usize) -> Vec<Bbox> {
        (0..n)
            .map(|i| {
                let (x, y) = ((i % 37) as f64 * 3.0, (i / 37) as f64 * 2.0);
                [x, y, x + 1.0 + (i % 5) as f64, y + 0.5]
            })
            .collect()
    }

    #[test]
    fn visit_finds_exactly_the_boxes_meeting_a_window() {
        for n in [0, 1, 2, 15, 16, 17, 255, 256, 257, 5000] {
            let boxes = grid(n);
            let t = PackedTree::new(&boxes);
            let w = [10.0, 5.0, 40.0, 30.0];
            let meets = |b: &Bbox| b[0] <= w[2] && b[2] >= w[0] && b[1] <= w[3] && b[3] >= w[1];
            let mut got = Vec::new();
            t.visit(meets, |i| {
                got.push(i);
                ControlFlow::<()>::Continue(())
            });
            got.sort_unstable();
            let want: Vec<u32> = (0..n as u32)
                .filter(|&i| meets(&boxes[i as usize]))
                .collect();
            assert_eq!(got, want, "n = {n}");
        }
    }

    #[test]
    fn removed_items_are_found_no_more_and_their_empty_subtrees_not_entered() {
        let everywhere = [f64::MIN, f64::MIN, f64::MAX, f64::MAX];
        for n in [1, 2, 7, 8, 9, 64, 65, 5000] {
            let boxes = grid(n);
            let mut t = PackedTree::new(&boxes);
            let pos = t.item_positions();
            let found = |t: &PackedTree| {
                let (mut items, nodes) = (Vec::new(), std::cell::Cell::new(0));
                t.visit(
                    |b| {
                        nodes.set(nodes.get() + 1);
                        boxes_meet(b, &everywhere)
                    },
                    |i| {
                        items.push(i);
                        ControlFlow::<()>::Continue(())
                    },
                );
                items.sort_unstable();
                (items, nodes.get())
            };
            // Every item but each seventh removed: the others are found.
            for i in (0..n).filter(|i| i % 7 != 0) {
                t.remove_at(pos[i] as usize);
            }
            let want: Vec<u32> = (0..n as u32).filter(|i| i % 7 == 0).collect();
            assert_eq!(found(&t).0, want, "n = {n}");
            // All removed: the root's box meets nothing, and nothing under
            // it is looked at.
            for i in (0..n).filter(|i| i % 7 == 0) {
                t.remove_at(pos[i] as usize);
            }
            assert_eq!(found(&t), (Vec::new(), 1), "n = {n}");
        }
    }

    #[test]
    fn pairs_are_exactly_the_meeting_boxes_each_once() {
        for n in [0, 1, 2, 15, 16, 17, 255, 256, 257, 3000] {
            let boxes = grid(n);
            let t = PackedTree::new(&boxes);
            let mut got = Vec::new();
            t.pairs(|i, j| {
                got.push((i, j));
                ControlFlow::<()>::Continue(())
            });
            got.sort_unstable();
            let mut want = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    if boxes_meet(&boxes[i], &boxes[j]) {
                        want.push((i as u32, j as u32));
                    }
                }
            }
            assert!(n < 17 || !want.is_empty(), "the grid's boxes overlap");
            assert_eq!(got, want, "n = {n}");
        }
        // A break ends the walk with its value.
        let t = PackedTree::new(&grid(300));
        let mut seen = 0;
        let stop = t.pairs(|i, j| {
            seen += 1;
            if seen == 5 {
                ControlFlow::Break((i, j))
            } else {
                ControlFlow::Continue(())
            }
        });
        assert!(stop.is_some() && seen == 5);
    }

    /// Pairing without a tree (few boxes) or through one (many) finds the
    /// same pairs as the tree, the few in order, and stops at a break.
    #[test]
    fn pairs_of_few_or_many_boxes_are_the_trees_pairs() {
        for n in [0, 1, 2, 17, FEW_PAIRED, FEW_PAIRED + 1, 300] {
            let boxes = grid(n);
            let mut got = Vec::new();
            PackedTree::pairs_of(&boxes, |i, j| {
                got.push((i, j));
                ControlFlow::<()>::Continue(())
            });
            if n <= FEW_PAIRED {
                assert!(got.windows(2).all(|w| w[0] < w[1]), "n = {n}: in order");
            }
            got.sort_unstable();
            let mut want = Vec::new();
            PackedTree::new(&boxes).pairs(|i, j| {
                want.push((i, j));
                ControlFlow::<()>::Continue(())
            });
            want.sort_unstable();
            assert!(n < 17 || !want.is_empty(), "the grid's boxes overlap");
            assert_eq!(got, want, "n = {n}");
            let stop = PackedTree::pairs_of(&boxes, |i, j| ControlFlow::Break((i, j)));
            assert_eq!(stop.is_some(), !want.is_empty(), "n = {n}");
        }
    }

    /// The first pair a check rejects is the first in `(i, j)` order among
    /// the tree's pairs it rejects, on one thread and on many.
    #[test]
    fn first_pair_is_the_first_rejected_pair_in_order() {
        for n in [
            0,
            1,
            2,
            40,
            FEW_PAIRED,
            300,
            5000,
            PAIRED_IN_PARALLEL + 1000,
        ] {
            let boxes = grid(n);
            let t = PackedTree::new(&boxes);
            let mut all = Vec::new();
            t.pairs(|i, j| {
                all.push((i, j));
                ControlFlow::<()>::Continue(())
            });
            all.sort_unstable();
            // Every pair, then only every 7th by a rule on both numbers.
            let every = t.first_pair(|i, j| Some(i + j));
            assert_eq!(every, all.first().map(|&(i, j)| (i, j, i + j)), "n = {n}");
            let rule = |i: u32, j: u32| (i * 31 + j) % 7 == 3 && i > n as u32 / 3;
            let want = all.iter().find(|&&(i, j)| rule(i, j)).copied();
            let got = t.first_pair(|i, j| rule(i, j).then_some(()));
            assert_eq!(got.map(|(i, j, _)| (i, j)), want, "n = {n}");
            // Without a tree for a few boxes: the same pair.
            let few = PackedTree::first_pair_of(&boxes, |i, j| rule(i, j).then_some(()));
            assert_eq!(few.map(|(i, j, _)| (i, j)), want, "n = {n}");
            assert!(n < 300 || want.is_some(), "the grid's boxes overlap");
        }
    }

    #[test]
    fn best_is_the_brute_force_nearest_with_ties_to_the_lower_number() {
        let boxes = grid(3000);
        let t = PackedTree::new(&boxes);
        for (x, y) in [
            (0.0, 0.0),
            (55.5, 31.0),
            (-20.0, 300.0),
            (111.0, 7.3),
            (50.0, 50.0),
        ] {
            let got = t.best(
                |b| Some(box_distance_2(b, x, y)),
                Some(|o: &Obb| Some(o.distance_2([x, y]))),
                |i, _| Some(box_distance_2(&boxes[i as usize], x, y)),
            );
            let want = (0..boxes.len())
                .map(|i| (box_distance_2(&boxes[i], x, y), i as u32))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(got, want, "at ({x}, {y})");
        }
    }

    /// A noisy ring of `n` segments and a spray of segments inside it.
    fn segment_soup(n: usize) -> Vec<[[f64; 2]; 2]> {
        let mut s = 17u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let at = |k: usize, r: f64| {
            let t = std::f64::consts::TAU * k as f64 / n as f64;
            [5.0e5 + r * t.cos(), 6.0e6 + r * t.sin()]
        };
        let mut out = Vec::new();
        let radii: Vec<f64> = (0..n)
            .map(|k| 1e4 * (1.0 + 0.05 * (7.0 * k as f64).sin()) + rnd())
            .collect();
        for k in 0..n {
            out.push([at(k, radii[k]), at((k + 1) % n, radii[(k + 1) % n])]);
        }
        for _ in 0..n / 4 {
            let p = [5.0e5 + 8e3 * (rnd() - 0.5), 6.0e6 + 8e3 * (rnd() - 0.5)];
            out.push([
                p,
                [p[0] + 300.0 * (rnd() - 0.5), p[1] + 300.0 * (rnd() - 0.5)],
            ]);
        }
        out
    }

    #[test]
    fn oriented_boxes_bound_every_segment_under_their_node() {
        let segs = segment_soup(3000);
        let t = PackedTree::of_segments(&segs);
        let n = t.len();
        assert_eq!(
            t.oriented.len(),
            t.boxes.len() - n,
            "a large tree has oriented boxes"
        );
        assert!(PackedTree::of_segments(&segs[..ORIENTED_MIN])
            .oriented
            .is_empty());
        // The items under each node, by walking down from it.
        fn under(t: &PackedTree, pos: usize, out: &mut Vec<u32>) {
            if pos < t.len() {
                out.push(t.ids[pos]);
            } else {
                for c in t.children(pos) {
                    under(t, c, out);
                }
            }
        }
        let queries: Vec<[f64; 2]> = (0..40)
            .map(|k| {
                let a = k as f64 * 0.7;
                let r = 2e3 * (k % 7) as f64;
                [5.0e5 + r * a.cos(), 6.0e6 + r * a.sin()]
            })
            .collect();
        let mut checked = 0;
        for pos in n..t.boxes.len() {
            let o = &t.oriented[pos - n];
            let mut items = Vec::new();
            under(&t, pos, &mut items);
            for q in &queries {
                let normal = [q[1] - 6.0e6, 5.0e5 - q[0]];
                let hp = o.clipped_distance(*q, &[normal]);
                for &i in &items {
                    let [a, b] = segs[i as usize];
                    let (ca, cb) = (Coord { x: a[0], y: a[1] }, Coord { x: b[0], y: b[1] });
                    let qc = Coord { x: q[0], y: q[1] };
                    let c = crate::geometry::segment::closest_on_segment(ca, cb, qc).0;
                    let d2 = (c.x - q[0]).hypot(c.y - q[1]);
                    assert!(o.distance_2(*q) <= d2 * d2, "node {pos}, item {i}");
                    let side = |p: [f64; 2]| (p[0] - q[0]) * normal[0] + (p[1] - q[1]) * normal[1];
                    if side(a) >= 0.0 || side(b) >= 0.0 {
                        let d = hp.expect("a segment in the half-plane keeps its node");
                        assert!(d <= d2, "node {pos}, item {i}: {d} > {d2}");
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 100_000);
    }

    #[test]
    fn prepared_ray_never_prunes_more_than_the_quotients() {
        // Pseudo-random rays and boxes, axis-parallel rays among them.
        let mut x = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 200.0 - 100.0
        };
        let mut entered = 0;
        for k in 0..20_000 {
            let o = [next(), next()];
            let mut d = [next(), next()];
            if k % 7 == 0 {
                d[k % 2] = 0.0;
            }
            let (a, b) = ([next(), next()], [next(), next()]);
            let bx = [
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[0].max(b[0]),
                a[1].max(b[1]),
            ];
            let max_t = next().abs();
            let exact = ray_box(&bx, o, d, max_t);
            let fast = RaySlab::new(o, d, max_t).enter(&bx);
            if let Some((t0, _)) = exact {
                entered += 1;
                assert!(fast.is_some_and(|t| t <= t0), "{o:?} {d:?} {bx:?}");
            }
        }
        assert!(entered > 1_000, "{entered}");
    }

    #[test]
    fn ray_box_interval() {
        let b = [1.0, 1.0, 2.0, 3.0];
        assert_eq!(ray_box(&b, [0.0, 2.0], [1.0, 0.0], 10.0), Some((1.0, 2.0)));
        assert_eq!(ray_box(&b, [0.0, 4.0], [1.0, 0.0], 10.0), None);
        assert_eq!(ray_box(&b, [0.0, 2.0], [1.0, 0.0], 0.5), None);
        assert_eq!(ray_box(&b, [1.5, 0.0], [0.0, 1.0], 10.0), Some((1.0, 3.0)));
    }

    #[test]
    fn half_plane_corner_test() {
        let b = [1.0, 1.0, 2.0, 2.0];
        assert!(box_meets_half_plane(&b, [0.0, 0.0], [1.0, 0.0]));
        assert!(!box_meets_half_plane(&b, [0.0, 0.0], [-1.0, 0.0]));
        assert!(box_meets_half_plane(&b, [2.0, 0.0], [-1.0, 0.0]));
    }
}
