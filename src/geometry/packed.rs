//! A static packed R-tree of boxes (the Hilbert-packed layout of
//! `flatbush`): items sorted along a Hilbert curve, grouped eight to a
//! node, level by level, in flat arrays. Built once per polygon; queries
//! allocate nothing (their stack lives on the call stack; the self-join of
//! [`PackedTree::pairs`] keeps its node pairs in a list) and visit each
//! node's children nearest first, so a ray stops soon after its first hit
//! and a nearest-point search soon after its answer.
//!
//! The tree knows only boxes and item numbers: what an item is, and its
//! exact distance or hit, is the caller's (see [`super::Boundary`]).

use std::mem::MaybeUninit;
use std::ops::ControlFlow;

/// Children per node. Eight rather than flatbush's sixteen: where a
/// search's bound cannot rule out a node's box (the middle of a round lake,
/// nearly equidistant from all its shore), fewer children are scored per
/// node opened — the score of a 200 000-vertex polygon's bars takes 14 %
/// less CPU, small polygons the same (`BENCHMARKS.md`).
const NODE_SIZE: usize = 8;

/// Depth-first stack entries a query can need: one node's children per
/// level, and a tree over 2^32 items has 11 levels.
const STACK: usize = NODE_SIZE * 12;

/// An axis-aligned box: `[min x, min y, max x, max y]`.
pub type Bbox = [f64; 4];

/// The packed tree.
#[derive(Debug, Clone, Default)]
pub struct PackedTree {
    /// Item boxes (Hilbert order), then the nodes of each level up to the root.
    boxes: Vec<Bbox>,
    /// For an item position: the item's number; for a node: the position of
    /// its first child.
    ids: Vec<u32>,
    /// End position of each level in `boxes` (level 0 = the items).
    level_ends: Vec<usize>,
}

/// What a node or item is to a query: its lower bound (a distance, a ray
/// parameter), `None` to skip it.
type Bound = Option<f64>;

impl PackedTree {
    /// Packs `boxes` (item `i` has box `boxes[i]`).
    pub fn new(boxes: &[Bbox]) -> Self {
        let n = boxes.len();
        if n == 0 {
            return Self::default();
        }
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
        let mut level_ends = vec![n];
        let mut count = n;
        let mut total = n;
        while count > 1 {
            count = count.div_ceil(NODE_SIZE);
            total += count;
            level_ends.push(total);
        }
        let mut tree_boxes = Vec::with_capacity(total);
        let mut ids = Vec::with_capacity(total);
        for &(_, i) in &order {
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
        }
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.level_ends.first().copied().unwrap_or(0)
    }

    /// True when there are no items.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
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
    pub fn visit<B>(
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

    /// Visits every pair of items whose boxes meet, once each as `(i, j)`
    /// with item numbers `i < j`, in no particular order, until `pair`
    /// breaks. One descent pairs nodes with nodes (a self-join): a query per
    /// item would descend from the root once per item and meet every pair
    /// twice.
    pub fn pairs<B>(&self, mut pair: impl FnMut(u32, u32) -> ControlFlow<B>) -> Option<B> {
        let n = self.len();
        if n < 2 {
            return None;
        }
        // Node pairs of one level (every leaf is on level 0), a node with
        // itself included: their children's pairs are still to be met.
        let mut todo = vec![(self.boxes.len() - 1, self.boxes.len() - 1)];
        while let Some((a, b)) = todo.pop() {
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
                        if let ControlFlow::Break(x) = pair(i.min(j), i.max(j)) {
                            return Some(x);
                        }
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
    pub fn best(
        &self,
        bound: impl Fn(&Bbox) -> Bound,
        item: impl FnMut(u32, f64) -> Bound,
    ) -> Option<(f64, u32)> {
        self.best_within(f64::INFINITY, bound, item)
    }

    /// [`Self::best`] among the items scoring at most `limit`.
    pub fn best_within(
        &self,
        limit: f64,
        bound: impl Fn(&Bbox) -> Bound,
        mut item: impl FnMut(u32, f64) -> Bound,
    ) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        self.branch_and_bound(
            limit,
            |b| bound(b),
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
    pub fn branch_and_bound(
        &self,
        limit: f64,
        bound: impl Fn(&Bbox) -> Bound,
        mut item: impl FnMut(u32) -> f64,
    ) {
        let n = self.len();
        if n == 0 {
            return;
        }
        let root = self.boxes.len() - 1;
        let Some(rb) = bound(&self.boxes[root]).filter(|&b| b <= limit) else {
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
            let mut cut = limit;
            for c in top {
                if bound(&self.boxes[c]).is_some_and(|b| b <= cut) {
                    cut = item(self.ids[c]);
                }
            }
            return;
        }
        // Depth first, each node's children nearest first: the same items
        // are scored as best first would (every item whose bound is not
        // above the cut-off when it is reached, and the answer's never is),
        // with a fixed stack on the call stack instead of a heap.
        let mut stack = [MaybeUninit::<(f64, u32)>::uninit(); STACK];
        stack[0] = MaybeUninit::new((rb, root as u32));
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
                for c in children {
                    if bound(&self.boxes[c]).is_some_and(|b| b <= cut) {
                        cut = item(self.ids[c]);
                    }
                }
                continue;
            }
            // The children that can still count, sorted so that the nearest
            // is on top (insertion sort: at most NODE_SIZE of them).
            let first = top;
            for c in children {
                let Some(b) = bound(&self.boxes[c]).filter(|&b| b <= cut) else {
                    continue;
                };
                let mut j = top;
                // SAFETY: entries first..top were written in this loop.
                while j > first && unsafe { stack[j - 1].assume_init().0 } < b {
                    stack[j] = stack[j - 1];
                    j -= 1;
                }
                stack[j] = MaybeUninit::new((b, c as u32));
                top += 1;
            }
        }
    }
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
pub fn boxes_meet(a: &Bbox, b: &Bbox) -> bool {
    a[0] <= b[2] && a[2] >= b[0] && a[1] <= b[3] && a[3] >= b[1]
}

/// Squared distance from `(x, y)` to the box (0 inside).
pub fn box_distance_2(b: &Bbox, x: f64, y: f64) -> f64 {
    let dx = (b[0] - x).max(0.0).max(x - b[2]);
    let dy = (b[1] - y).max(0.0).max(y - b[3]);
    dx * dx + dy * dy
}

/// The parameter interval `[t0, t1]` over which the ray `o + t·d`,
/// `0 ≤ t ≤ max_t`, is inside the box, or `None`.
pub fn ray_box(b: &Bbox, o: [f64; 2], d: [f64; 2], max_t: f64) -> Option<(f64, f64)> {
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

/// True when some corner of the box is in the closed half-plane
/// `(x − q) · n ≥ 0`. Safe under rounding for points in the box: the test
/// is on the corner farthest along `n`, and `(x − q) · n` computed in
/// floating point never decreases as `x` moves towards that corner, so a
/// point of the box that tests inside makes the corner test inside too.
pub fn box_meets_half_plane(b: &Bbox, q: [f64; 2], n: [f64; 2]) -> bool {
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
                |i, _| Some(box_distance_2(&boxes[i as usize], x, y)),
            );
            let want = (0..boxes.len())
                .map(|i| (box_distance_2(&boxes[i], x, y), i as u32))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(got, want, "at ({x}, {y})");
        }
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
