//! `StSk` — the interior straight skeleton of a polygon with holes (SPEC §3,
//! paper "Straight Skeleton", Fig. 2e; Aichholzer et al. 1995).
//!
//! *Definition (SPEC §3):* every boundary edge of P moves inward, parallel to
//! itself, at unit speed; the straight skeleton is the trace of the
//! wavefront vertices. Each node keeps its event time (offset distance)
//! besides its radius (distance to ∂P).
//!
//! # Algorithm
//!
//! Event-driven wavefront propagation: the wavefront's lists (`wavefront`),
//! the event queue (`events`), the event loop (this module), groups of
//! events at one point (`group`), the search for split candidates
//! (`search`, `lines`) and the checks of the result (`verify`):
//!
//! * Every ring becomes a circular list of wavefront vertices (exterior
//!   counter-clockwise, holes clockwise, so P is always on the left). A
//!   vertex moves at velocity `(n1 + n2) / (1 + n1·n2)` along the bisector of
//!   its two edges' inward normals.
//! * Edge events (an edge shrinks to a point) merge its two vertices; split
//!   events (a reflex vertex reaches a non-adjacent wavefront edge) cut one
//!   list into two, or join two lists — that is how holes merge with the
//!   outer wavefront. Lists are re-linked through index handles only.
//! * Degenerate cases: when an event pops, every other valid event within
//!   `tol` of its time and within `tol · (1 + speed)` of its point (both
//!   ends of an edge event) joins it in one *vertex event*: the involved
//!   vertices end there, the wavefront edges their reflex vertices reach
//!   are cut there, and the wavefront is re-linked around the point — one
//!   new vertex per pair of an arriving line and the next leaving line
//!   clockwise (edges between involved vertices have zero length and
//!   vanish); a vertex made by an event does not split at once at a piece
//!   end at its own point (that contact was part of the event); collinear
//!   consecutive edges give a vertex moving along the common normal; two
//!   parallel edges meeting (a rectangle's long sides) create a *fold* — a
//!   vertex between antiparallel coincident lines — which is zipped up
//!   immediately towards the nearer neighbour, tracing the collapsed
//!   strip's centre line; a list of two vertices is a collapsed segment and
//!   one of three a collapsing triangle (also when a vertex event leaves a
//!   single vertex between its two lines: it ends at the event point).
//!   A lone split event whose point is at an end of the wavefront piece it
//!   reaches is a vertex event too (the reflex vertex meets a vertex; cut
//!   there, the piece left a zero-length edge between two vertices moving
//!   as one, whose arcs overlapped). Around an event, an arriving and a
//!   leaving ray in one direction (antiparallel lines meeting along a
//!   segment) are a tie, whatever their rounded angles say. Ring vertices
//!   within `tol` of the vertex before them are dropped first: an edge
//!   that short has no direction (buffers from GEOS hold vertices 3e-15
//!   apart, and the velocities next to them came out NaN). On 6 000
//!   buffered lines (`scripts/make_buffered_lines.py`, seeds 7 and 11)
//!   these took the skeletons with two arcs on top of each other from 115
//!   to none longer than a micrometre.
//! * Split candidates of a reflex vertex are looked up in an R-tree of the
//!   original edges near its ray (bounded by where the ray leaves P),
//!   sorted by time and validated against the current wavefront when
//!   popped; events are kept in a binary heap with lazy invalidation (an
//!   event naming an inactive vertex is dropped). A candidate whose line
//!   has left the wavefront is skipped when queued. The events within `tol`
//!   of the time being handled are held in a grid by place
//!   (`events::Held`), so that a group is found among the events at its
//!   point only: a raster staircase has thousands of events at one time
//!   (every pixel edge collapses at half a pixel), and scanning them all
//!   for each one was quadratic (31 s → 3 s on a 57 000-vertex rasterised
//!   river). A split candidate that finds no piece of its line is passed
//!   over as the events of its time are pulled, before it is held: on a
//!   pixel grid nearly all of them miss (the rasterised Lena: 6.8 M of 6.9 M
//!   events; 12.9 s → 7.3 s). A ray is searched in bands, and the next band
//!   only when the vertex lives to reach the end of the searched part (a
//!   queued *deferred search*, not at once when the band's candidates are
//!   used up); an edge that has left the wavefront is taken out of the
//!   R-tree between events (it never comes back, so its candidates could
//!   only be skipped). On a rough rim of needles 9 in 10 edges a reflex
//!   vertex tried were gone: without them StSk takes 0.44× the time on the
//!   100 000-vertex rough polygon, and 37 s → 11–14 s and 2.7 GB → 0.24 GB
//!   at 200 000, the same skeleton. The cost is about O(n log n) on smooth
//!   real data; on a staircase each reflex corner still tries the
//!   candidates of the rows and columns of pixels it passes, a number that
//!   grows with the width of the polygon in pixels, and on a rim of needles
//!   of a fixed depth the live edges a vertex passes grow with their
//!   density (4× the edges tried per doubling of the vertices). Most of
//!   those edges move away faster than the vertex or are reached only
//!   after the band: a band whose box holds many edges (and every later
//!   band of its vertex) takes them from trees by the direction of their
//!   normals, which skip such edges by a bound on their distance from the
//!   vertex (module `lines`; the same candidates from 7× fewer edges at
//!   200 000 vertices).
//! * "Near its ray" is not a proven bound: a face widens without limit
//!   next to a fast reflex vertex (nearly parallel banks), so a split can
//!   come from an edge far from the ray. Every result is therefore
//!   verified — the wavefront collapses completely, every trace stays in
//!   P, no two traces cross (a vertex that ran through a wavefront edge
//!   leaves its face and crosses its traces) — and a pass that fails is
//!   repeated with a wider search (search passes: 2× and 16× the reach,
//!   then every edge; the exhaustive pass takes every edge whose offset
//!   line the ray reaches before it leaves P, a proven superset).
//!
//! # Files
//!
//! This file is the event loop (`Propagation`: events in time order, the
//! vertex, edge and split events, the wavefront relinked); `search` finds a
//! reflex vertex's split candidates, `verify` checks a pass's traces,
//! `events` holds the queue and the event times, `lines` the index of the
//! original edges by direction class, `wavefront` the vertices and lines.
//!
//! # Tolerance policy
//!
//! Coordinates are shifted by [`PreparedPolygon::origin`] before any
//! arithmetic. One absolute tolerance `tol = 1e-9 · extent` (the larger side
//! of the bounding box) is used for every "same place / same time" decision:
//! whether a split point lies on a wavefront piece, whether a vertex is
//! ahead of a line, whether a fold's two neighbours are equally far. Input
//! orientation is exact (normalised rings, robust predicates in
//! [`crate::geometry`]); two lines are antiparallel (a fold) when
//! `1 + n1·n2 < 1e-12` (nearly antiparallel lines keep a fast vertex, so
//! their events fall at the right time). Verification uses
//! `1e-6 · extent`: a trace end
//! that far outside P, or two traces crossing that far from their ends and
//! from each other's lines, rejects a pass.
//!
//! # Termination and failure
//!
//! Every popped event is counted; more than `1000 · n + 10 000` pops, more
//! than `16 · n + 64` vertices, or a wavefront that does not collapse
//! completely fails a pass; when the exhaustive pass fails too, that is a
//! [`MethodError`] for the polygon, never a hang. A panic
//! inside the propagation is caught and reported the same way.
//!
//! ```
//! use skeletonise::geometry::PreparedPolygon;
//! use skeletonise::methods::{straight_skeleton::StraightSkeleton, MethodContext, SkeletonMethod};
//! use geo::polygon;
//! let p = polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)];
//! let p = PreparedPolygon::new(&p).unwrap();
//! let g = StraightSkeleton.skeletonise(&p, &MethodContext::default()).unwrap();
//! // The centre segment from (1, 1) to (9, 1) and four legs to the corners.
//! assert_eq!(g.leg_count(), 4);
//! assert!(g.nodes().iter().all(|n| n.time.is_some()));
//! ```

pub(crate) mod events;
mod group;
pub(crate) mod lines;
mod search;
mod verify;
pub(crate) mod wavefront;

use super::{MethodContext, MethodError, MethodId, SkeletonMethod};
use crate::geometry::packed::{Bbox, PackedTree};
use crate::geometry::ring::distinct_vertices_within;
use crate::geometry::segment::{lines_meet, properly_cross};
use crate::geometry::tolerance::{SAME_POINT, TRACE_CROSSING};
use crate::geometry::vector::{cross, dot, hypot, within_hypot};
use crate::geometry::{Boundary, PreparedPolygon};
use crate::graph::{GraphBuilder, SkeletonGraph};
use events::{edge_collapse_time, split_candidates, EventKind, EventQueue, Held, SplitCandidate};
use geo::Coord;
use lines::LineIndex;
use std::ops::ControlFlow;
use verify::verify;
use wavefront::{Line, LineId, VertexId, Wavefront, FOLD_EPS};

/// The straight-skeleton method.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StraightSkeleton;

/// Counts of one propagation, for tests and benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    /// Input vertices.
    pub input_vertices: usize,
    /// Wavefront vertices created (input vertices included).
    pub vertices: usize,
    /// Events popped from the queue (stale ones included).
    pub pops: usize,
    /// Events popped whose vertices had gone (stale).
    pub stale: usize,
    /// Split candidates popped that found no piece of their line there.
    pub missed: usize,
    /// Most events queued at once (stale ones included).
    pub max_queue: usize,
    /// Edges tried as split candidates (all reflex vertices).
    pub tried: usize,
    /// Split candidates kept (all reflex vertices).
    pub candidates: usize,
    /// The cost predicted before the propagation: edges to try, and split
    /// candidates to keep.
    pub predicted: (f64, f64),
    /// Search passes run (1 when the first, local one gave a skeleton that
    /// passed verification; see the module documentation).
    pub passes: usize,
}

/// One traced arc: a wavefront vertex's path from creation to its end.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Arc {
    from: Coord<f64>,
    from_t: f64,
    to: Coord<f64>,
    to_t: f64,
}

fn fail(reason: impl Into<String>) -> MethodError {
    MethodError::Failed {
        method: MethodId::STSK,
        reason: reason.into(),
    }
}

/// Bytes one kept split candidate costs (its entry and its share of the
/// list).
const CANDIDATE_BYTES: usize = std::mem::size_of::<SplitCandidate>();

/// The share of the predicted cost taken as the likely cost (see
/// [`propagate`]). The prediction is an upper estimate: it counts every
/// edge near a sampled ray, as at the start. The edges actually tried were
/// 86–120 % of it on rasterised rivers (staircases, whose edges stay in the
/// wavefront), 0.3–12 % on a smooth wavy ellipse and 1.1–1.3 % on the rough
/// polygon of `scripts/make_rough_polygon.py` (most of its edges leave the
/// wavefront before a vertex gets near them). The share is about the
/// lowest of those: a polygon is declined up front only when it would pass
/// the budget even then; any other is stopped by the deadline if it costs
/// more after all. Those shares were measured before the search by
/// direction, which tries fewer edges still (the rasterised Lena 128 M →
/// 50 M, the rough polygon at 200 000 vertices 161 M → 23 M, 0.16 % of the
/// prediction); the time falls less (a staircase's goes to the candidates
/// it keeps, and on the rough polygon it is 0.6× for 0.14× the edges). The
/// share was left as it was, since it stands for the time, which fell far
/// less than the edges tried (StSk fits the default 120 s at 400 000
/// vertices, in 15 s, and is not declined there).
const LIKELY_SHARE: f64 = 1.0 / 64.0;

/// Reflex vertices sampled to predict the propagation's cost.
const PREDICTION_SAMPLE: usize = 64;

/// Seconds per edge tried as a split candidate, which dominates the
/// straight skeleton's cost on large polygons: 46 ns measured over the whole
/// run on the 40 000-vertex wavy ellipse of `examples/stsk_scaling.rs`
/// (217 M tries in 10 s, 2-core machine). A slower machine is still held to
/// the budget by the deadline.
const SECONDS_PER_TRY: f64 = 5e-8;

/// The box of the segment `ab`.
fn segment_box(a: Coord<f64>, b: Coord<f64>) -> Bbox {
    [a.x.min(b.x), a.y.min(b.y), a.x.max(b.x), a.y.max(b.y)]
}

/// Which original edges a reflex vertex's split candidates are taken from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Search {
    /// Edges within `factor · reach` of the vertex's path (reach = length
    /// of its ray inside P): fast, but not a proven bound, since faces
    /// widen without limit next to fast reflex vertices.
    Near(f64),
    /// Every original edge: the proven superset (a split candidate must
    /// be reached before the ray leaves P, which `split_candidates` checks).
    All,
}

/// The search passes tried in turn; a pass whose result fails
/// [`verify`] is repeated with the next, wider one. The last is exhaustive.
const SEARCH_PASSES: [Search; 3] = [Search::Near(2.0), Search::Near(16.0), Search::All];

/// How far a reflex vertex's ray has been searched for split candidates
/// (see [`Propagation::search_band`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Band {
    /// Distance along the ray searched so far.
    searched: f64,
    /// Where the search ends: the ray's exit from P.
    reach: f64,
    /// The first band's length.
    first: f64,
    /// Whether the last band searched held many edges in its box (the
    /// next one, whose box holds that box, is taken by direction at once;
    /// see [`LineIndex::near_ray`]).
    dense: bool,
}

struct Propagation<'a> {
    /// The method's budget: its deadline is checked on the event queue.
    ctx: &'a MethodContext,
    w: Wavefront,
    q: EventQueue,
    /// Events within `tol` of the time being handled, by place.
    held: Held,
    /// The original edges, item `i` being `LineId(i)`; a line that has
    /// left the wavefront is removed ([`Self::drop_gone_lines`]).
    index: LineIndex,
    /// Lines of vertices ended since the last [`Self::drop_gone_lines`].
    ended_lines: Vec<LineId>,
    search: Search,
    boundary: &'a Boundary,
    origin: Coord<f64>,
    candidates: Vec<Vec<SplitCandidate>>,
    /// Per vertex, how far its ray has been searched for split candidates.
    bands: Vec<Band>,
    /// The lines of the band being searched (a buffer kept between bands).
    scratch: Vec<LineId>,
    arcs: Vec<Arc>,
    work: Vec<VertexId>,
    now: f64,
    tol: f64,
    extent: f64,
    max_pops: usize,
    /// Most split candidates the memory budget allows.
    max_candidates: usize,
    max_vertices: usize,
    stats: Stats,
    inconsistent: Option<Coord<f64>>,
}

impl<'a> Propagation<'a> {
    fn new(polygon: &'a PreparedPolygon, search: Search, ctx: &'a MethodContext) -> Self {
        let origin = polygon.origin();
        let n = polygon.vertex_count();
        let extent = polygon.extent().max(f64::MIN_POSITIVE);
        let mut w = Wavefront::default();
        let mut work = Vec::with_capacity(n);
        let tol = SAME_POINT * extent;
        for ring in polygon.rings() {
            let abs = distinct_vertices(&ring.0[..ring.0.len() - 1], tol);
            let abs = &abs[..];
            let pts: Vec<Coord<f64>> = abs.iter().map(|&p| p - origin).collect();
            let m = pts.len();
            let base = w.lines.len();
            for i in 0..m {
                let (a, b) = (pts[i], pts[(i + 1) % m]);
                w.lines.push(Line::new(a, b));
                w.pieces.push(Vec::new());
            }
            let first = w.vertices.len();
            for i in 0..m {
                let left = LineId::from_index(base + (i + m - 1) % m);
                let right = LineId::from_index(base + i);
                let id = w.add_vertex(pts[i], 0.0, left, right, Some(abs[i]));
                work.push(id);
            }
            for i in 0..m {
                let a = VertexId::from_index(first + i);
                let b = VertexId::from_index(first + (i + 1) % m);
                w.link(a, b);
            }
        }
        work.reverse();
        let index = LineIndex::new(&w.lines);
        Self {
            ctx,
            candidates: vec![Vec::new(); w.vertices.len()],
            bands: vec![Band::default(); w.vertices.len()],
            scratch: Vec::new(),
            w,
            q: EventQueue::default(),
            held: Held::default(),
            index,
            ended_lines: Vec::new(),
            search,
            boundary: polygon.boundary(),
            origin,
            arcs: Vec::with_capacity(2 * n),
            work,
            now: 0.0,
            tol,
            extent,
            max_pops: 1000 * n + 10_000,
            max_candidates: ctx
                .memory_limit()
                .map_or(usize::MAX, |b| (b / CANDIDATE_BYTES as u64) as usize),
            max_vertices: 16 * n + 64,
            stats: Stats {
                input_vertices: n,
                ..Stats::default()
            },
            inconsistent: None,
        }
    }

    /// Absolute start point of a vertex's trace.
    fn abs_start(&self, v: VertexId) -> Coord<f64> {
        let x = self.w.v(v);
        x.exact.unwrap_or(x.start + self.origin)
    }

    /// Ends vertex `v` at local point `p` at the current time.
    fn finish(&mut self, v: VertexId, p: Coord<f64>) {
        let from = self.abs_start(v);
        let from_t = self.w.v(v).t0;
        // The trace must end on both of the vertex's offset lines.
        let (l, r) = (self.w.v(v).left, self.w.v(v).right);
        let off = self
            .w
            .line(l)
            .ahead(p, self.now)
            .abs()
            .max(self.w.line(r).ahead(p, self.now).abs());
        if off > 1e5 * self.tol {
            self.inconsistent = Some(p + self.origin);
        }
        self.arcs.push(Arc {
            from,
            from_t,
            to: p + self.origin,
            to_t: self.now,
        });
        self.w.kill(v);
        self.ended_lines.extend([l, r]);
    }

    /// Takes the lines that have left the wavefront out of the split
    /// search's tree. Called between events (during one, a line can be
    /// without a piece until the event's new vertices take it up). A line
    /// without a piece never gets one back, so its split candidates could
    /// only be skipped; on a rough rim most original edges are gone long
    /// before the reflex vertices that search past them (9 in 10 edges
    /// tried on the rough polygon of `scripts/make_rough_polygon.py`).
    fn drop_gone_lines(&mut self) {
        while let Some(l) = self.ended_lines.pop() {
            if !self.w.line_alive(l) {
                self.index.remove(l);
            }
        }
    }

    fn new_vertex(
        &mut self,
        p: Coord<f64>,
        left: LineId,
        right: LineId,
    ) -> Result<VertexId, MethodError> {
        if self.w.vertices.len() >= self.max_vertices {
            return Err(fail(format!(
                "straight skeleton created more than {} wavefront vertices; the polygon is too degenerate",
                self.max_vertices
            )));
        }
        let id = self.w.add_vertex(p, self.now, left, right, None);
        self.candidates.push(Vec::new());
        self.bands.push(Band::default());
        self.work.push(id);
        Ok(id)
    }

    fn run(mut self) -> Result<(Vec<Arc>, Stats), MethodError> {
        self.drain_work()?;
        while let Some((ev, queued)) = self.next_event() {
            self.stats.pops += 1;
            if self.stats.pops.is_multiple_of(4096) {
                self.ctx.check(MethodId::STSK)?;
                self.stats.max_queue = self.stats.max_queue.max(self.q.len());
            }
            if self.stats.pops > self.max_pops {
                return Err(fail(format!(
                    "straight skeleton did not finish within {} events",
                    self.max_pops
                )));
            }
            match ev.kind {
                EventKind::Edge { x, y } => {
                    self.take(queued);
                    if !self.edge_valid(x, y) {
                        self.stats.stale += 1;
                        continue;
                    }
                    self.now = self.now.max(ev.t);
                }
                EventKind::Split { v, candidate } => {
                    if !self.w.v(v).active {
                        self.take(queued);
                        self.stats.stale += 1;
                        continue;
                    }
                    self.now = self.now.max(ev.t);
                    if self.searched_on(queued, v, candidate)? {
                        continue;
                    }
                    let c = self.candidates[v.index()][candidate as usize];
                    if self.find_piece(v, c.line).is_none() {
                        self.stats.missed += 1;
                        // The vertex's next candidate takes the missed one's
                        // place at the head of the queue (one sift instead of
                        // a pop and a push: on a staircase most events are
                        // such misses).
                        let next = self.next_candidate(v, candidate + 1)?;
                        self.follow_with(queued, v, next);
                        self.drain_work()?;
                        continue;
                    }
                    self.take(queued);
                }
            }
            self.event_group(ev)?;
            self.drain_work()?;
            self.drop_gone_lines();
            if let Some(p) = self.inconsistent {
                return Err(fail(format!(
                    "straight skeleton event off its offset lines near ({}, {}) (degenerate simultaneous events)",
                    p.x, p.y
                )));
            }
        }
        if let Some(v) = self.w.vertices.iter().find(|v| v.active) {
            let p = v.start + self.origin;
            return Err(fail(format!(
                "straight skeleton wavefront did not collapse (vertex near ({}, {}))",
                p.x, p.y
            )));
        }
        self.stats.vertices = self.w.vertices.len();
        Ok((self.arcs, self.stats))
    }

    /// The next event: the earlier of the queue's and the held events'. A
    /// held event is taken; the queue's is left at its head (`true`), to
    /// be taken ([`Self::take`]) or replaced.
    fn next_event(&mut self) -> Option<(events::Event, bool)> {
        let queued = self.q.peek().copied();
        match (queued, self.held.peek().copied()) {
            (Some(a), Some(b)) if b > a => self.held.pop().map(|e| (e, false)),
            (None, Some(_)) => self.held.pop().map(|e| (e, false)),
            (a, _) => a.map(|e| (e, true)),
        }
    }

    /// Takes the queue's head when the event being handled is it.
    fn take(&mut self, queued: bool) {
        if queued {
            self.q.pop();
        }
    }

    /// Where a queued event happens now and how far from there its group's
    /// point may be (see [`Self::at`]), with room for the vertices' travel
    /// until the event's time; `None` for a stale event.
    fn event_place(&self, e: &events::Event) -> Option<(Coord<f64>, f64)> {
        let v = match e.kind {
            EventKind::Edge { x, y } => {
                if !self.edge_valid(x, y) {
                    return None;
                }
                x
            }
            EventKind::Split { v, .. } => {
                if !self.w.v(v).active {
                    return None;
                }
                v
            }
        };
        let speed = self.w.v(v).vel.map_or(0.0, hypot);
        let travel = speed * (e.t - self.now).max(0.0);
        Some((
            self.w.pos(v, self.now),
            2.0 * self.tol * (1.0 + speed) + travel + self.tol,
        ))
    }

    fn edge_valid(&self, x: VertexId, y: VertexId) -> bool {
        self.w.v(x).active && self.w.v(y).active && self.w.v(x).next == y
    }

    /// Whether vertex `v` is at `p` now, within `tol · (1 + speed)`.
    fn at(&self, v: VertexId, p: Coord<f64>) -> bool {
        let speed = self.w.v(v).vel.map_or(0.0, hypot);
        let d = self.w.pos(v, self.now) - p;
        within_hypot(d, self.tol * (1.0 + speed))
    }

    fn drain_work(&mut self) -> Result<(), MethodError> {
        while let Some(z) = self.work.pop() {
            self.settle(z)?;
        }
        Ok(())
    }

    /// Resolves small lists and folds at `z`, then queues its events.
    fn settle(&mut self, z: VertexId) -> Result<(), MethodError> {
        if !self.w.v(z).active {
            return Ok(());
        }
        let t = self.now;
        let (prev, next) = (self.w.v(z).prev, self.w.v(z).next);
        if next == z {
            let p = self.w.pos(z, t);
            self.finish(z, p);
            return Ok(());
        }
        if self.w.v(next).next == z {
            // Two vertices: a collapsed segment.
            let (pz, pn) = (self.w.pos(z, t), self.w.pos(next, t));
            self.finish(z, pz);
            self.finish(next, pn);
            self.arcs.push(Arc {
                from: pz + self.origin,
                from_t: t,
                to: pn + self.origin,
                to_t: t,
            });
            return Ok(());
        }
        if self.w.v(z).vel.is_none() {
            return self.zip_fold(z, prev, next);
        }
        if let Some(te) = edge_collapse_time(&self.w, prev, z, t) {
            self.q.push(te, EventKind::Edge { x: prev, y: z });
        }
        if let Some(te) = edge_collapse_time(&self.w, z, next, t) {
            self.q.push(te, EventKind::Edge { x: z, y: next });
        }
        if self.w.v(z).reflex {
            if let Some((reach, first)) = self.ray_reach(z) {
                self.bands[z.index()] = Band {
                    searched: 0.0,
                    reach,
                    first,
                    dense: false,
                };
            }
            self.push_candidate(z, 0)?;
        }
        Ok(())
    }

    /// A fold: `z` lies between two antiparallel coincident lines, so the
    /// overlapping parts of its two edges cancel at once; `z` slides to the
    /// nearer neighbour (or both, when equally far) and merges with it.
    fn zip_fold(&mut self, z: VertexId, w: VertexId, u: VertexId) -> Result<(), MethodError> {
        let t = self.now;
        let pz = self.w.pos(z, t);
        let (pw, pu) = (self.w.pos(w, t), self.w.pos(u, t));
        let dw = hypot(pw - pz);
        let du = hypot(pu - pz);
        let (zl, zr) = (self.w.v(z).left, self.w.v(z).right);
        if (dw - du).abs() <= self.tol {
            let (before, after) = (self.w.v(w).prev, self.w.v(u).next);
            self.finish(z, pw);
            self.finish(w, pw);
            self.finish(u, pw);
            if before == u {
                return Ok(());
            }
            let m = self.new_vertex(pw, self.w.v(w).left, self.w.v(u).right)?;
            self.w.link(before, m);
            self.w.link(m, after);
        } else if dw < du {
            let before = self.w.v(w).prev;
            self.finish(z, pw);
            self.finish(w, pw);
            let m = self.new_vertex(pw, self.w.v(w).left, zr)?;
            self.w.link(before, m);
            self.w.link(m, u);
        } else {
            let after = self.w.v(u).next;
            self.finish(z, pu);
            self.finish(u, pu);
            let m = self.new_vertex(pu, zl, self.w.v(u).right)?;
            self.w.link(w, m);
            self.w.link(m, after);
        }
        Ok(())
    }

    fn edge_event(&mut self, x: VertexId, y: VertexId) -> Result<(), MethodError> {
        let t = self.now;
        let (px, py) = (self.w.pos(x, t), self.w.pos(y, t));
        let p = (px + py) * 0.5;
        let (before, after) = (self.w.v(x).prev, self.w.v(y).next);
        self.finish(x, p);
        self.finish(y, p);
        if after == x {
            return Ok(());
        }
        if after == before {
            // A triangle collapses to its incentre.
            self.finish(after, p);
            return Ok(());
        }
        let m = self.new_vertex(p, self.w.v(x).left, self.w.v(y).right)?;
        self.w.link(before, m);
        self.w.link(m, after);
        Ok(())
    }

    /// The start vertex of the piece of `line`'s wavefront that reflex
    /// vertex `v` touches now, if any.
    fn find_piece(&mut self, v: VertexId, line: LineId) -> Option<VertexId> {
        self.find_piece_at(v, line, self.now)
    }

    /// [`Self::find_piece`] at time `t` (the wavefront as it is now, the
    /// points where they are at `t`).
    fn find_piece_at(&mut self, v: VertexId, line: LineId, t: f64) -> Option<VertexId> {
        let p = self.w.pos(v, t);
        let l = *self.w.line(line);
        let sp = dot(l.dir, p);
        let w = &mut self.w;
        let mut pieces = std::mem::take(&mut w.pieces[line.index()]);
        pieces.retain(|&x| w.v(x).active);
        let tol = self.tol;
        let found = pieces.iter().copied().find(|&x| {
            let y = w.v(x).next;
            if x == v || y == v {
                return false;
            }
            let (px, py) = (w.pos(x, t), w.pos(y, t));
            let (sx, sy) = (dot(l.dir, px), dot(l.dir, py));
            if !(sx - tol <= sp && sp <= sy + tol) {
                return false;
            }
            let at_x = within_hypot(px - p, tol);
            let at_y = within_hypot(py - p, tol);
            // Touching a zero-length piece, or a piece end that already
            // carries one of v's own lines, changes nothing: not a split.
            // A vertex made by an event touching a piece end at once: the
            // event resolved that contact already.
            let fresh = w.v(v).exact.is_none() && w.v(v).t0 >= t - tol;
            let no_op = (fresh && (at_x || at_y))
                || if at_y {
                    at_x || w.v(y).right == w.v(v).right
                } else {
                    at_x && w.v(x).left == w.v(v).left
                };
            !no_op
        });
        w.pieces[line.index()] = pieces;
        found
    }

    fn split_event(&mut self, v: VertexId, x: VertexId, line: LineId) -> Result<(), MethodError> {
        let t = self.now;
        let p = self.w.pos(v, t);
        let y = self.w.v(x).next;
        let (a, b) = (self.w.v(v).prev, self.w.v(v).next);
        let (vl, vr) = (self.w.v(v).left, self.w.v(v).right);
        self.finish(v, p);
        let v1 = self.new_vertex(p, vl, line)?;
        let v2 = self.new_vertex(p, line, vr)?;
        self.w.link(a, v1);
        self.w.link(v1, y);
        self.w.link(x, v2);
        self.w.link(v2, b);
        Ok(())
    }
}

/// A ring's vertices without those within `tol` of the vertex kept before
/// them: an edge shorter than `tol` has no direction to move in — a
/// buffer's output can hold two vertices 3e-15 apart, and the velocities of
/// their neighbours came out NaN, so the wavefront never collapsed. A ring
/// with fewer than three vertices left is kept as it is (and fails as
/// degenerate).
fn distinct_vertices(ring: &[Coord<f64>], tol: f64) -> Vec<Coord<f64>> {
    let kept = distinct_vertices_within(ring, tol);
    if kept.len() < 3 {
        return ring.to_vec();
    }
    kept
}

/// The split event of reflex vertex `v`'s candidate `candidate`.
fn split(v: VertexId, candidate: u32) -> EventKind {
    EventKind::Split { v, candidate }
}

/// One propagation with the given split-candidate search, verified.
fn propagate(
    polygon: &PreparedPolygon,
    search: Search,
    ctx: &MethodContext,
) -> Result<(Vec<Arc>, Stats), MethodError> {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let p = Propagation::new(polygon, search, ctx);
        // The prediction assumes every ray searched to its exit among every
        // edge; the bands stop where the vertex ends and skip the edges
        // gone from the wavefront and those that cannot be candidates,
        // which on a rough rim is several hundred times fewer edges tried
        // (about as predicted on a staircase). The likely time
        // is taken as `LIKELY_SHARE` of the prediction; more than the
        // budget declines the polygon up front, and the deadline
        // stops a run that costs more after all. Memory is not judged up
        // front (the prediction is too far off): the split candidates are
        // counted as they are found, and the run stops with the reason the
        // moment they pass `skeleton.max_memory_mb`. Declined after the
        // first eighth of the sample when that already predicts four times
        // the budget.
        let likely = |(tries, _): (f64, f64)| tries * SECONDS_PER_TRY * LIKELY_SHARE;
        let predicted = p.predict(|estimate| {
            ctx.afford(MethodId::STSK, likely(estimate) / 4.0, 0.0)
                .is_err()
        });
        ctx.afford(MethodId::STSK, likely(predicted), 0.0)?;
        let (arcs, mut stats) = p.run()?;
        stats.predicted = predicted;
        Ok((arcs, stats))
    }));
    let (arcs, stats) = match result {
        Ok(r) => r?,
        Err(_) => return Err(fail("internal error (panic) in the straight skeleton")),
    };
    verify(polygon, &arcs)?;
    Ok((arcs, stats))
}

/// The straight skeleton of `polygon` and the propagation's counts, within
/// the budget of `ctx`.
///
/// The first pass takes split candidates from edges near each reflex
/// vertex's path; when its result fails verification (no collapse,
/// a trace outside P, crossing traces), wider passes follow, the last
/// one exhaustive.
pub fn straight_skeleton_with_stats(
    polygon: &PreparedPolygon,
    ctx: &MethodContext,
) -> Result<(SkeletonGraph, Stats), MethodError> {
    let mut result = Err(fail("no search pass"));
    let mut passes = 0;
    for search in SEARCH_PASSES {
        passes += 1;
        let t = std::time::Instant::now();
        result = propagate(polygon, search, ctx);
        tracing::debug!(
            ?search,
            seconds = t.elapsed().as_secs_f64(),
            error = ?result.as_ref().err(),
            "straight skeleton search pass"
        );
        if result.is_ok() {
            break;
        }
    }
    let (arcs, mut stats) = result?;
    stats.passes = passes;
    let mut b = GraphBuilder::new();
    for a in &arcs {
        if b.segment(a.from, a.to).is_some() {
            let (na, nb) = (b.node(a.from), b.node(a.to));
            b.set_time(na, a.from_t);
            b.set_time(nb, a.to_t);
        }
    }
    Ok((b.finish(polygon.boundary()), stats))
}

impl SkeletonMethod for StraightSkeleton {
    fn id(&self) -> MethodId {
        MethodId::STSK
    }

    fn skeletonise(
        &self,
        polygon: &PreparedPolygon,
        ctx: &MethodContext,
    ) -> Result<SkeletonGraph, MethodError> {
        straight_skeleton_with_stats(polygon, ctx).map(|(g, _)| g)
    }
}

#[cfg(test)]
mod tests {
    use super::verify::trace_pieces;
    use super::*;
    use geo::polygon;

    fn run(p: geo::Polygon<f64>) -> SkeletonGraph {
        crate::methods::checked_skeleton(&StraightSkeleton, &PreparedPolygon::new(&p).unwrap())
    }

    /// The early estimate (the first eighth of the sample, spread over the
    /// polygon) is near the whole sample's, so declining on it at four
    /// times the budget declines only what the whole sample would.
    #[test]
    fn early_prediction_is_near_the_full_one() {
        let n = 4000;
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let ring: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let r = 1000.0 * (1.0 + 0.05 * (7.0 * t).sin()) + 1.5 * u;
                (r * t.cos(), r * t.sin())
            })
            .collect();
        let pp = PreparedPolygon::new(&geo::Polygon::new(ring.into(), vec![])).unwrap();
        let ctx = MethodContext::default();
        let p = Propagation::new(&pp, Search::Near(1.0), &ctx);
        let full = p.predict(|_| false);
        let early = p.predict(|_| true);
        assert!(full.0 > 0.0 && full.1 > 0.0, "{full:?}");
        // A different number: the early one stopped after fewer samples.
        assert_ne!(early, full);
        for (e, f) in [(early.0, full.0), (early.1, full.1)] {
            assert!(
                e > 0.5 * f && e < 2.0 * f,
                "early {early:?} against full {full:?}"
            );
        }
    }

    #[test]
    fn square_is_an_x() {
        let g = run(polygon![(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 4.), (x: 0., y: 4.)]);
        let g = g.merged();
        assert_eq!(g.leg_count(), 4);
        let centre = g
            .nodes()
            .iter()
            .find(|n| n.pos == Coord { x: 2.0, y: 2.0 })
            .unwrap();
        assert_eq!(centre.time, Some(2.0));
        assert_eq!(g.components(), 1);
    }

    #[test]
    fn rectangle_is_a_segment_with_four_legs() {
        let g = run(polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)]);
        assert_eq!(g.leg_count(), 4);
        assert_eq!(g.components(), 1);
        assert!((g.total_length() - (8.0 + 4.0 * 2f64.sqrt())).abs() < 1e-9);
    }

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// A trace from `a` (time 0) to `b` (time 1).
    fn arc(a: Coord<f64>, b: Coord<f64>) -> Arc {
        Arc {
            from: a,
            from_t: 0.0,
            to: b,
            to_t: 1.0,
        }
    }

    #[test]
    fn verification_rejects_crossing_traces_only() {
        let pp = PreparedPolygon::new(
            &polygon![(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.)],
        )
        .unwrap();
        // The X of the square: traces meet at their ends only.
        let x = [
            arc(c(0., 0.), c(5., 5.)),
            arc(c(10., 0.), c(5., 5.)),
            arc(c(10., 10.), c(5., 5.)),
            arc(c(0., 10.), c(5., 5.)),
        ];
        assert!(verify(&pp, &x).is_ok());
        // A trace running through a neighbour's trace is a missed event.
        let mut bad = x;
        bad[0].to = c(7., 4.);
        assert!(verify(&pp, &bad).is_err());
        // A trace leaving P.
        bad = x;
        bad[0].to = c(-1., 5.);
        assert!(verify(&pp, &bad).is_err());
        // Two nearly collinear overlapping traces (a collapsed strip) are
        // rounding, not a crossing.
        let strip = [
            arc(c(1., 5.), c(6., 5.)),
            arc(c(8., 5.0 + 1e-9), c(4., 5.0 - 1e-9)),
        ];
        assert!(verify(&pp, &strip).is_ok());
    }

    /// A long trace among many short ones is boxed in stretches
    /// (`trace_pieces`): a crossing in any stretch is still found, and the
    /// stretches of one trace do not cross each other.
    #[test]
    fn a_long_trace_is_checked_along_its_whole_length() {
        let pp = PreparedPolygon::new(
            &polygon![(x: 0., y: 0.), (x: 100., y: 0.), (x: 100., y: 100.), (x: 0., y: 100.)],
        )
        .unwrap();
        // Short vertical traces along the bottom, and a diagonal across.
        let mut arcs: Vec<Arc> = (1..99)
            .map(|i| arc(c(i as f64 + 0.5, 0.0), c(i as f64 + 0.5, 0.4)))
            .collect();
        arcs.push(arc(c(1.0, 1.0), c(99.0, 99.0)));
        let (owners, boxes) = trace_pieces(&arcs, 1e-6);
        assert!(boxes.len() > arcs.len() + 10);
        assert_eq!(
            owners.iter().filter(|&&o| o == arcs.len() - 1).count(),
            boxes.len() - 98
        );
        assert!(verify(&pp, &arcs).is_ok());
        // A short trace crossed by the long one at 3/4 of its length.
        arcs.push(arc(c(70.0, 80.0), c(80.0, 70.0)));
        let err = verify(&pp, &arcs).unwrap_err().to_string();
        assert!(err.contains("(75, 75)"), "{err}");
    }
}
