//! Events of the wavefront propagation and their priority queue.
//!
//! * Edge events: a wavefront edge between two adjacent vertices shrinks to
//!   a point. Its time is where the edge's length, linear in time, reaches 0.
//! * Split events: a reflex vertex reaches a wavefront edge that is not
//!   adjacent to it. Candidates are computed once per reflex vertex against
//!   the supporting lines of original edges found by an R-tree query near
//!   its ray (bounded by the ray's first hit of ∂P), sorted by time and
//!   re-validated against the current wavefront when popped; a failed
//!   candidate makes way for the vertex's next one.
//!
//! The queue is a `BinaryHeap` of events ordered by time (ties: edge events
//! first, then creation order, for determinism); stale events (a named
//! vertex is no longer active) are dropped when popped.

use super::wavefront::{LineId, VertexId, Wavefront};
use crate::geometry::vector::dot;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// What happens at an event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EventKind {
    /// The edge `x → y` (with `x.next == y`) collapses.
    Edge {
        /// Start vertex of the edge.
        x: VertexId,
        /// End vertex of the edge.
        y: VertexId,
    },
    /// Reflex vertex `v` reaches a piece of the wavefront of `line`.
    Split {
        /// The reflex vertex.
        v: VertexId,
        /// Index of this candidate in the vertex's candidate list.
        candidate: u32,
    },
}

/// One queued event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Event time (offset distance).
    pub t: f64,
    /// Insertion order, to break ties deterministically.
    pub seq: u64,
    /// The event.
    pub kind: EventKind,
}

impl Event {
    fn rank(&self) -> u8 {
        match self.kind {
            EventKind::Edge { .. } => 0,
            EventKind::Split { .. } => 1,
        }
    }
}

impl Eq for Event {}

impl Ord for Event {
    /// Reversed, so that the max-heap pops the earliest event first.
    fn cmp(&self, o: &Self) -> Ordering {
        o.t.total_cmp(&self.t)
            .then(o.rank().cmp(&self.rank()))
            .then(o.seq.cmp(&self.seq))
    }
}

impl PartialOrd for Event {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Min-priority queue of events.
#[derive(Debug, Default)]
pub struct EventQueue {
    heap: BinaryHeap<Event>,
    seq: u64,
}

impl EventQueue {
    /// Queues an event.
    pub fn push(&mut self, t: f64, kind: EventKind) {
        self.seq += 1;
        self.heap.push(Event {
            t,
            seq: self.seq,
            kind,
        });
    }

    /// The earliest event.
    pub fn pop(&mut self) -> Option<Event> {
        self.heap.pop()
    }

    /// Puts an event in place of the earliest one (which must exist): one
    /// sift down the heap instead of a pop and a push.
    pub fn replace_head(&mut self, t: f64, kind: EventKind) {
        self.seq += 1;
        let seq = self.seq;
        if let Some(mut head) = self.heap.peek_mut() {
            *head = Event { t, seq, kind };
        }
    }

    /// Events queued (stale ones included).
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Time of the earliest event, without removing it.
    pub fn peek_time(&self) -> Option<f64> {
        self.heap.peek().map(|e| e.t)
    }

    /// The earliest event, without removing it.
    pub fn peek(&self) -> Option<&Event> {
        self.heap.peek()
    }
}

/// Time at which the edge `x → y` collapses, if it shrinks. Clamped to be
/// no earlier than `now`.
pub fn edge_collapse_time(w: &Wavefront, x: VertexId, y: VertexId, now: f64) -> Option<f64> {
    let (vx, vy) = (w.v(x), w.v(y));
    let (sx, sy) = (vx.vel?, vy.vel?);
    let dir = w.line(vx.right).dir;
    let rate = dot(dir, sy - sx);
    let tref = vx.t0.max(vy.t0);
    let len = dot(dir, w.pos(y, tref) - w.pos(x, tref));
    if rate >= -1e-12 {
        return None;
    }
    Some((tref + (len / -rate).max(0.0)).max(now))
}

/// A potential split event of a reflex vertex: the time at which it reaches
/// the moving supporting line `line`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitCandidate {
    /// Time the vertex reaches the line.
    pub t: f64,
    /// The line.
    pub line: LineId,
}

impl SplitCandidate {
    /// Whether this candidate comes after `other` in a vertex's list
    /// (by time, then by line).
    pub fn follows(&self, other: &SplitCandidate) -> bool {
        self.t.total_cmp(&other.t).then(self.line.cmp(&other.line)) == Ordering::Greater
    }
}

/// Split candidates of reflex vertex `v` against the given lines, sorted by
/// time; only times up to `t_max` (when the vertex's ray leaves P) count,
/// and only candidates that come after `after` in that order (a band of
/// the vertex's ray searched after another finds the earlier band's lines
/// again: they are dropped before the sort).
pub fn split_candidates(
    w: &Wavefront,
    v: VertexId,
    lines: impl Iterator<Item = LineId>,
    t_max: f64,
    tol: f64,
    after: Option<SplitCandidate>,
) -> Vec<SplitCandidate> {
    let vx = w.v(v);
    let Some(s) = vx.vel else {
        return Vec::new();
    };
    let mut out: Vec<SplitCandidate> = lines
        .filter(|&l| l != vx.left && l != vx.right)
        .filter_map(|l| {
            let line = w.line(l);
            let ahead = line.ahead(vx.start, vx.t0);
            let closing = 1.0 - dot(line.normal, s);
            if ahead < -tol || closing <= 1e-12 {
                return None;
            }
            let t = vx.t0 + ahead.max(0.0) / closing;
            let c = SplitCandidate { t, line: l };
            (t <= t_max + tol && after.is_none_or(|a| c.follows(&a))).then_some(c)
        })
        .collect();
    out.sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.line.cmp(&b.line)));
    out
}

/// Events taken out of the queue because they fall within `tol` of the time
/// of an event being handled, indexed by where they happen, so that the
/// events at one point are found without scanning every event at that time.
///
/// A raster staircase makes thousands of events at one time (every pixel
/// edge collapses at half the pixel size): scanning them all for each event
/// of the time, and queueing the others again, was quadratic in their
/// number. Held events keep their place in the order (their `seq`); an event
/// is *live* until it is taken, by a group or as the next event. Each event
/// sits in the grid cell of its point; a query looks at the 3 × 3 cells
/// around its point, so an event's reach `r` must not exceed the cell size —
/// a farther-reaching one (a fast vertex has a large tolerance: rare) is
/// kept in a list scanned on every query. A query takes the events it
/// finds out of their lists, and drops those gone by then: while events keep
/// coming within `tol` of each other the held set is never empty and never
/// cleared, and the wide list, scanned on every query, grew by every event
/// ever held (on the rough polygon at 400 000 vertices StSk spent 21 s of
/// 40 s scanning it; it holds at most 55 live events there).
#[derive(Debug, Default)]
pub struct Held {
    heap: BinaryHeap<Event>,
    live: FxHashSet<u64>,
    cells: FxHashMap<(i64, i64), Vec<Placed>>,
    wide: Vec<Placed>,
    cell: f64,
}

/// A held event, its point and its reach.
pub type Placed = (Event, [f64; 2], f64);

impl Held {
    /// Holds `e`, which happens within `r` of `p`; the grid's cell size is
    /// set by the first event held (`cell`), cleared when nothing is live.
    pub fn hold(&mut self, e: Event, p: [f64; 2], r: f64, cell: f64) {
        if self.live.is_empty() {
            self.heap.clear();
            self.cells.clear();
            self.wide.clear();
            self.cell = cell.max(f64::MIN_POSITIVE);
        }
        self.live.insert(e.seq);
        self.heap.push(e);
        self.place((e, p, r));
    }

    /// Puts a held event in its cell's list, or the wide list.
    fn place(&mut self, placed: Placed) {
        let (_, p, r) = placed;
        match self.key(p) {
            Some(k) if r <= self.cell => self.cells.entry(k).or_default().push(placed),
            _ => self.wide.push(placed),
        }
    }

    fn key(&self, p: [f64; 2]) -> Option<(i64, i64)> {
        let (i, j) = ((p[0] / self.cell).floor(), (p[1] / self.cell).floor());
        // Far inside i64: the grid is in local coordinates at 1e-8 of the
        // polygon's extent.
        (i.abs() < 1e15 && j.abs() < 1e15).then_some((i as i64, j as i64))
    }

    /// The earliest live held event, without taking it.
    pub fn peek(&mut self) -> Option<&Event> {
        while let Some(e) = self.heap.peek() {
            if self.live.contains(&e.seq) {
                break;
            }
            self.heap.pop();
        }
        self.heap.peek()
    }

    /// Takes the earliest live held event.
    pub fn pop(&mut self) -> Option<Event> {
        self.peek()?;
        let e = self.heap.pop()?;
        self.live.remove(&e.seq);
        Some(e)
    }

    /// Takes every live held event whose reach holds `p`, with its place
    /// (for [`Self::put_back`]), in queue order.
    pub fn take_at(&mut self, p: [f64; 2]) -> Vec<Placed> {
        let near = |q: &[f64; 2], r: f64| (q[0] - p[0]).hypot(q[1] - p[1]) <= r;
        let key = self.key(p);
        let live = &mut self.live;
        // The events found leave the list, and so do those gone since.
        let mut found = |list: &mut Vec<Placed>, out: &mut Vec<Placed>| {
            list.retain(|&placed| {
                let (e, q, r) = placed;
                if !live.contains(&e.seq) {
                    return false;
                }
                if near(&q, r) {
                    live.remove(&e.seq);
                    out.push(placed);
                    return false;
                }
                true
            });
        };
        let mut out: Vec<Placed> = Vec::new();
        if let Some((i, j)) = key {
            for k in [
                (i - 1, j - 1),
                (i - 1, j),
                (i - 1, j + 1),
                (i, j - 1),
                (i, j),
            ]
            .into_iter()
            .chain([(i, j + 1), (i + 1, j - 1), (i + 1, j), (i + 1, j + 1)])
            {
                if let Some(v) = self.cells.get_mut(&k) {
                    found(v, &mut out);
                }
            }
        }
        found(&mut self.wide, &mut out);
        // Greatest first is earliest first (the order is reversed for the heap).
        out.sort_by_key(|&(e, _, _)| std::cmp::Reverse(e));
        out
    }

    /// Puts back an event taken by [`Self::take_at`] and not used, in its
    /// place.
    pub fn put_back(&mut self, placed: Placed) {
        self.live.insert(placed.0.seq);
        self.place(placed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edge(t: f64, seq: u64, i: usize) -> Event {
        Event {
            t,
            seq,
            kind: EventKind::Edge {
                x: VertexId::from_index(i),
                y: VertexId::from_index(i + 1),
            },
        }
    }

    #[test]
    fn held_events_are_found_at_their_place_only_and_keep_their_order() {
        let mut h = Held::default();
        // A staircase's simultaneous events: 1000 places 30 apart, two
        // events at place 500 (one reaching from a fast vertex, 0.5 away).
        for i in 0..1000 {
            h.hold(
                edge(15.0, 10 + i as u64, i),
                [30.0 * i as f64, 0.0],
                1e-3,
                4e-3,
            );
        }
        h.hold(edge(15.0, 5, 2000), [15_000.5, 0.0], 0.6, 4e-3);
        let here = h.take_at([15_000.0, 0.0]);
        let seqs: Vec<u64> = here.iter().map(|(e, _, _)| e.seq).collect();
        assert_eq!(seqs, vec![5, 510], "the earliest-queued first");
        assert!(
            h.take_at([15_000.0, 0.0]).is_empty(),
            "taken events are gone"
        );
        // Put back, an event is live again, in its old place in the order.
        h.put_back(here[1]);
        assert_eq!(h.pop().map(|e| e.seq), Some(10));
        assert_eq!(h.take_at([15_000.0, 0.0]).len(), 1);
        // Nothing between places.
        assert!(h.take_at([15.0, 0.0]).is_empty());
        let mut rest = 0;
        while h.pop().is_some() {
            rest += 1;
        }
        assert_eq!(rest, 998);
    }

    /// Fast vertices' events (reach beyond a cell) held and taken one
    /// after another while another event stays live: the list scanned for
    /// them keeps the live ones only, and every one is still found.
    #[test]
    fn taken_wide_events_leave_the_list() {
        let mut h = Held::default();
        // Stays live throughout, so the held set is never cleared.
        h.hold(edge(1.0, 1, 0), [1e6, 1e6], 1e-3, 4e-3);
        for i in 0..10_000u64 {
            let p = [i as f64, 0.0];
            h.hold(edge(1.0, 2 + i, 2), p, 0.5, 4e-3);
            let taken = h.take_at(p);
            assert_eq!(taken.len(), 1);
            assert_eq!(taken[0].0.seq, 2 + i);
        }
        assert!(h.wide.len() <= 1, "{}", h.wide.len());
        // One put back stays, and is found again.
        h.hold(edge(1.0, 20_000, 2), [0.0, 5.0], 0.5, 4e-3);
        let taken = h.take_at([0.0, 5.0]);
        h.put_back(taken[0]);
        assert_eq!(h.take_at([0.2, 5.0]).len(), 1);
        assert_eq!(h.pop().map(|e| e.seq), Some(1));
    }
}
