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

    /// Events queued (stale ones included).
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Time of the earliest event, without removing it.
    pub fn peek_time(&self) -> Option<f64> {
        self.heap.peek().map(|e| e.t)
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

/// Split candidates of reflex vertex `v` against the given lines, sorted by
/// time; only times up to `t_max` (when the vertex's ray leaves P) count.
pub fn split_candidates(
    w: &Wavefront,
    v: VertexId,
    lines: impl Iterator<Item = LineId>,
    t_max: f64,
    tol: f64,
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
            (t <= t_max + tol).then_some(SplitCandidate { t, line: l })
        })
        .collect();
    out.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.line.cmp(&b.line)));
    out
}
