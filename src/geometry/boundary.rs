//! Spatial index of a polygon's boundary ∂P.
//!
//! One index of boundary segments answers every boundary question the
//! methods and steps ask: distance to ∂P (node radii), point-in-polygon,
//! "does this segment cross ∂P", the first hit of a ray (leg extension, bars)
//! and the nearest boundary point (optionally restricted to a half-plane, for
//! the scoring step's sides). Queries cost O(log n) on real data instead of a
//! scan of all edges.
//!
//! [`Boundary`] is a façade over three backends of one private trait,
//! chosen in one place for the queries that have a pass over every segment
//! besides a tree search (nearest segment, first hit of a ray, nearest point
//! on both sides of a line):
//!
//! * the lane passes (`geometry::lanes`): a boundary of at most 64 segments,
//!   on a processor with AVX2, and a query within `lanes::TAME`;
//! * the scalar passes (`Scan`): a boundary of at most 64 segments
//!   otherwise;
//! * the packed R-tree (`geometry::packed`): a larger boundary, built on the
//!   first query that needs it.
//!
//! All three give the same answers bit for bit, ties included (tested
//! below). The other queries (half-planes, sectors, crossings, containment,
//! pairs) always search the tree.

use super::lanes::{self, Columns};
use super::packed::{
    box_distance_2, box_meets_half_plane, boxes_meet, ray_box, Bbox, Obb, PackedTree, RaySlab,
};
use super::segment::{
    clip_by_sides, clip_to_half_plane, closest_on_segment, closest_point, crosses_rightward,
    nearer_2, properly_cross, ray_segment, segment_distance_2, BoundarySegment,
};
use super::tolerance::{BOUND_MARGIN, SHORT_OF_END};
use super::vector::{dot, norm};
use geo::{Coord, LineString, Polygon};
use std::cell::Cell;
use std::ops::ControlFlow;
use std::sync::OnceLock;

/// The first boundary point met by a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Ray parameter: hit = origin + t · dir.
    pub t: f64,
    /// The hit point.
    pub point: Coord<f64>,
    /// Index of the boundary segment hit (into [`Boundary::segments`]).
    pub segment: usize,
}

/// Packed R-tree of the boundary segments of one polygon (all rings).
///
/// Where several segments answer a query equally well (a ray through a
/// vertex, two segments at the same distance), the one with the lower index
/// in [`Boundary::segments`] is the answer.
#[derive(Debug, Clone)]
pub struct Boundary {
    segments: Vec<BoundarySegment>,
    /// Built on the first query that needs it: a small boundary answers its
    /// ray queries by a pass over the segments, so a skeleton scored by
    /// bars that hit no vertex never builds one.
    tree: OnceLock<PackedTree>,
    /// The segments in columns for the small-boundary passes
    /// ([`super::lanes`]); `None` for a large boundary, or one with a
    /// coordinate beyond [`super::lanes::TAME`] (the scalar passes then).
    columns: Option<Columns>,
    min: Coord<f64>,
    max: Coord<f64>,
}

/// The queries a boundary answers either by a pass over every segment or
/// by a tree search: the same answers, ties to the lower segment index.
trait Backend {
    /// The segment nearest `p` among those within squared distance
    /// `limit2`, and its squared distance ([`segment_distance_2`]).
    fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)>;

    /// The least ray parameter `t`, `min_t < t ≤ max_t`, at which
    /// `origin + t · dir` meets a segment ([`ray_segment`]), and the segment.
    fn first_param(
        &self,
        origin: Coord<f64>,
        dir: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<(f64, usize)>;

    /// The point nearest `q` in each closed half-plane of the line through
    /// `q` across `normal` (the `normal` side first), and its squared
    /// distance.
    fn both_sides(&self, q: Coord<f64>, normal: Coord<f64>) -> [Option<(Coord<f64>, f64)>; 2];
}

impl Backend for Columns {
    fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        Columns::nearest_2(self, p, limit2)
    }

    fn first_param(
        &self,
        o: Coord<f64>,
        d: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<(f64, usize)> {
        Columns::first_param(self, o, d, min_t, max_t)
    }

    fn both_sides(&self, q: Coord<f64>, normal: Coord<f64>) -> [Option<(Coord<f64>, f64)>; 2] {
        Columns::both_sides(self, q, normal)
    }
}

/// The scalar passes over every segment, one at a time: how a boundary of
/// few segments answers without building or walking a tree (and what the
/// lane passes must agree with bit for bit), and how any boundary answers
/// its two-sided query. Each keeps the tree search's answer, ties included
/// (segments in index order, the first of equal values stays).
#[derive(Debug, Clone, Copy)]
struct Scan<'a>(&'a [BoundarySegment]);

impl Backend for Scan<'_> {
    fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        for (i, s) in self.0.iter().enumerate() {
            let d2 = segment_distance_2(s.a, s.b, p);
            if d2 <= limit2 && best.is_none_or(|(bd, _)| d2 < bd) {
                best = Some((d2, i as u32));
            }
        }
        best
    }

    fn first_param(
        &self,
        origin: Coord<f64>,
        dir: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for (i, s) in self.0.iter().enumerate() {
            let hit = ray_segment(origin, dir, s.a, s.b)
                .map(|(t, _)| t)
                .filter(|&t| t > min_t && t <= max_t);
            if let Some(t) = hit {
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, i));
                }
            }
        }
        best
    }

    fn both_sides(&self, q: Coord<f64>, normal: Coord<f64>) -> [Option<(Coord<f64>, f64)>; 2] {
        // The nearest point on each side so far and its squared distance.
        let mut best: [Option<(Coord<f64>, f64)>; 2] = [None, None];
        let side = |c: Coord<f64>| dot(c - q, normal);
        for s in self.0 {
            let (fa, fb) = (side(s.a), side(s.b));
            // The segment clipped to each closed half-plane, as
            // `clip_to_half_plane` clips it (the opposite side's values are
            // the negated ones, exactly).
            let parts = [
                clip_by_sides(s.a, s.b, fa, fb),
                clip_by_sides(s.a, s.b, -fa, -fb),
            ];
            for (k, part) in parts.into_iter().enumerate() {
                let Some((a, b)) = part else { continue };
                let c = closest_point(a, b, q);
                let d2 = dot(c - q, c - q);
                // Segments in index order: the first of equal distances
                // stays, distances compared as roots (as the tree search
                // compares them): see `nearer_2`. The root of the winner is
                // the caller's to take: the same answer.
                if best[k].is_none_or(|(_, bd2)| nearer_2(d2, bd2)) {
                    best[k] = Some((c, d2));
                }
            }
        }
        best
    }
}

/// The tree's searches over `segments` (item `i` of `tree` is segment `i`).
struct Indexed<'a> {
    segments: &'a [BoundarySegment],
    tree: &'a PackedTree,
}

impl Backend for Indexed<'_> {
    fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        let (x, y) = (p.x, p.y);
        self.tree.best_within(
            limit2,
            |b| Some(box_distance_2(b, x, y)),
            Some(|o: &Obb| Some(o.distance_2([x, y]))),
            |i, _| {
                let s = &self.segments[i as usize];
                Some(segment_distance_2(s.a, s.b, p))
            },
        )
    }

    fn first_param(
        &self,
        o: Coord<f64>,
        d: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<(f64, usize)> {
        let slab = RaySlab::new(pt(o), pt(d), max_t);
        // Axis-aligned boxes only: a ray crossing the polygon passes as many
        // oriented boxes as axis-aligned ones, and their test costs more
        // (callgrind, a noisy circle of 50 000 vertices: the exits 2.3 G
        // instructions with axis-aligned boxes, 3.1 G with oriented ones).
        let (t, i) = self.tree.best(
            |b| slab.enter(b),
            None::<fn(&Obb) -> Option<f64>>,
            |i, _| {
                let s = &self.segments[i as usize];
                ray_segment(o, d, s.a, s.b)
                    .map(|(t, _)| t)
                    .filter(|&t| t > min_t && t <= max_t)
            },
        )?;
        Some((t, i as usize))
    }

    /// The scalar pass: one pass costs less than two tree searches on the
    /// boundaries it is asked of (few segments), and gives their answers.
    fn both_sides(&self, q: Coord<f64>, normal: Coord<f64>) -> [Option<(Coord<f64>, f64)>; 2] {
        Scan(self.segments).both_sides(q, normal)
    }
}

/// A point every query can take: the R-tree's nearest-neighbour search
/// cannot order NaN distances, so a non-finite point (from a degenerate
/// computation upstream) gets "no answer" instead.
fn finite(c: Coord<f64>) -> bool {
    c.x.is_finite() && c.y.is_finite()
}

fn pt(c: Coord<f64>) -> [f64; 2] {
    [c.x, c.y]
}

/// A candidate answer of a nearest-point search: point, distance, segment.
type Found = (Coord<f64>, f64, u32);

/// [`Boundary::few_segments`]: up to a tree of two levels without oriented
/// boxes (the pass is branch-free arithmetic; two searches through such a
/// tree cost more on a small polygon: 2 000 islands of 11 vertices on
/// average, all five methods, 1.7 % less CPU time at 48 than at 16).
const FEW_SEGMENTS: usize = 64;

impl Boundary {
    /// Indexes every edge of every ring of `polygon` (rings must be closed).
    pub fn new(polygon: &Polygon<f64>) -> Self {
        Self::from_rings(std::iter::once(polygon.exterior()).chain(polygon.interiors()))
    }

    /// Indexes every edge of `rings` (closed), numbered in the order given.
    pub fn from_rings<'r>(rings: impl IntoIterator<Item = &'r LineString<f64>>) -> Self {
        let mut segments = Vec::new();
        for (ri, ring) in rings.into_iter().enumerate() {
            for (i, w) in ring.0.windows(2).enumerate() {
                if w[0] != w[1] {
                    segments.push(BoundarySegment {
                        a: w[0],
                        b: w[1],
                        ring: ri as u32,
                        index: i as u32,
                    });
                }
            }
        }
        Self::from_segments(segments)
    }

    /// Indexes an explicit list of segments.
    pub fn from_segments(segments: Vec<BoundarySegment>) -> Self {
        let mut min = Coord {
            x: f64::INFINITY,
            y: f64::INFINITY,
        };
        let mut max = Coord {
            x: f64::NEG_INFINITY,
            y: f64::NEG_INFINITY,
        };
        for s in &segments {
            for c in [s.a, s.b] {
                min.x = min.x.min(c.x);
                min.y = min.y.min(c.y);
                max.x = max.x.max(c.x);
                max.y = max.y.max(c.y);
            }
        }
        let columns = if segments.len() <= FEW_SEGMENTS {
            Columns::new(segments.iter().map(|s| (s.a, s.b)))
        } else {
            None
        };
        Self {
            segments,
            tree: OnceLock::new(),
            columns,
            min,
            max,
        }
    }

    /// The packed R-tree of the segments, built on first use.
    fn tree(&self) -> &PackedTree {
        self.tree.get_or_init(|| {
            let ends: Vec<[[f64; 2]; 2]> =
                self.segments.iter().map(|s| [pt(s.a), pt(s.b)]).collect();
            PackedTree::of_segments(&ends)
        })
    }

    /// Answers `ask` by the backend for this boundary and a query whose
    /// points are all `tame` ([`super::lanes::tame`]) or not: the lane
    /// passes when the boundary has columns and the points are tame, the
    /// scalar passes for another boundary of few segments, the tree for a
    /// larger one.
    fn backend<R>(&self, tame: bool, ask: impl FnOnce(&dyn Backend) -> R) -> R {
        match &self.columns {
            Some(c) if tame => ask(c),
            _ if self.few_segments() => ask(&Scan(&self.segments)),
            _ => ask(&Indexed {
                segments: &self.segments,
                tree: self.tree(),
            }),
        }
    }

    /// All boundary segments (ring order).
    pub fn segments(&self) -> &[BoundarySegment] {
        &self.segments
    }

    /// Larger side of the bounding box.
    pub fn extent(&self) -> f64 {
        (self.max.x - self.min.x)
            .max(self.max.y - self.min.y)
            .max(0.0)
    }

    /// Lower-left corner of the bounding box.
    pub fn bbox_min(&self) -> Coord<f64> {
        self.min
    }

    /// Upper-right corner of the bounding box.
    pub fn bbox_max(&self) -> Coord<f64> {
        self.max
    }

    /// The nearest segment among those within squared distance `limit2`.
    fn nearest_segment_within(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        self.backend(lanes::tame(p), |b| b.nearest_2(p, limit2))
    }

    /// [`Boundary::nearest`] among the points at most `limit` from `p`
    /// (`None` if there is none): a known upper bound of the distance keeps
    /// the search short and never changes the answer.
    pub fn nearest_within(&self, p: Coord<f64>, limit: f64) -> Option<(Coord<f64>, usize, f64)> {
        if !finite(p) {
            return None;
        }
        let (_, i) = self.nearest_segment_within(p, limit * limit)?;
        let s = &self.segments[i as usize];
        let (c, _) = s.closest(p);
        Some((c, i as usize, norm(c - p)))
    }

    /// Nearest boundary point to `p`: (point, segment index, distance).
    pub fn nearest(&self, p: Coord<f64>) -> Option<(Coord<f64>, usize, f64)> {
        self.nearest_within(p, f64::INFINITY)
    }

    /// Euclidean distance from `p` to ∂P (the radius of every skeleton node).
    pub fn distance(&self, p: Coord<f64>) -> f64 {
        if !finite(p) {
            return f64::NAN;
        }
        self.nearest_segment_within(p, f64::INFINITY)
            .map(|(d2, _)| d2.sqrt())
            .unwrap_or(f64::INFINITY)
    }

    /// Whether [`Boundary::distance`]`(p) <= limit`, searching only that
    /// far (the same answer; a point far from ∂P costs no longer search
    /// than one near it).
    pub fn is_within(&self, p: Coord<f64>, limit: f64) -> bool {
        let search = limit * (1.0 + BOUND_MARGIN) + f64::MIN_POSITIVE;
        if !finite(p) || !search.is_finite() {
            return self.distance(p) <= limit;
        }
        self.nearest_segment_within(p, search * search)
            .is_some_and(|(d2, _)| d2.sqrt() <= limit)
    }

    /// [`Boundary::distance`] when it is known to be at most `bound` (up to
    /// rounding): the bound keeps the search short and never changes the
    /// answer.
    pub fn distance_within(&self, p: Coord<f64>, bound: f64) -> f64 {
        let limit = bound * (1.0 + BOUND_MARGIN) + f64::MIN_POSITIVE;
        if !finite(p) || !limit.is_finite() {
            return self.distance(p);
        }
        self.nearest_segment_within(p, limit * limit)
            .map(|(d2, _)| d2.sqrt())
            .unwrap_or_else(|| self.distance(p))
    }

    /// Nearest boundary point to `q` within the closed half-plane
    /// `(x − q) · normal ≥ 0`: `(point, distance)`.
    pub fn nearest_in_half_plane(
        &self,
        q: Coord<f64>,
        normal: Coord<f64>,
    ) -> Option<(Coord<f64>, f64)> {
        self.nearest_in_half_plane_within(q, normal, f64::INFINITY)
    }

    /// [`Boundary::nearest_in_half_plane`] among the points at most `limit`
    /// from `q` (`None` if there is none): a known boundary point in the
    /// half-plane makes the search short.
    pub fn nearest_in_half_plane_within(
        &self,
        q: Coord<f64>,
        normal: Coord<f64>,
        limit: f64,
    ) -> Option<(Coord<f64>, f64)> {
        let n = pt(normal);
        self.nearest_clipped(
            q,
            limit,
            |b| box_meets_half_plane(b, pt(q), n).then(|| box_lower_bound(b, q)),
            |o| o.clipped_distance(pt(q), &[n]),
            |a, b| clip_to_half_plane(a, b, q, normal),
        )
    }

    /// [`Boundary::nearest_in_half_plane`] on both sides of the line through
    /// `q` across `normal` at once — `(normal side, opposite side)` — by one
    /// pass over every segment: the same answers, for a boundary of few
    /// segments, where two tree searches cost more than the pass
    /// ([`Boundary::few_segments`]).
    pub fn nearest_on_both_sides(
        &self,
        q: Coord<f64>,
        normal: Coord<f64>,
    ) -> [Option<(Coord<f64>, f64)>; 2] {
        if !finite(q) {
            return [None, None];
        }
        self.backend(lanes::tame(q) && lanes::tame(normal), |b| {
            b.both_sides(q, normal)
        })
        .map(|b| b.map(|(c, d2)| (c, d2.sqrt())))
    }

    /// True when the boundary has so few segments that a pass over all of
    /// them is cheaper than a tree search ([`Boundary::nearest_on_both_sides`]).
    pub fn few_segments(&self) -> bool {
        self.segments.len() <= FEW_SEGMENTS
    }

    /// Nearest boundary point to `q` within the closed sector swept
    /// counter-clockwise from direction `from` to direction `to` (an angle
    /// below 180°): `(point, distance)`. The open segment from `q` to that
    /// point crosses no boundary segment (a crossing would be a nearer
    /// point in the sector).
    pub fn nearest_in_sector(
        &self,
        q: Coord<f64>,
        from: Coord<f64>,
        to: Coord<f64>,
    ) -> Option<(Coord<f64>, f64)> {
        // Inside the sector: left of `from` and right of `to`.
        let n1 = Coord {
            x: -from.y,
            y: from.x,
        };
        let n2 = Coord { x: to.y, y: -to.x };
        self.nearest_clipped(
            q,
            f64::INFINITY,
            |b| {
                (box_meets_half_plane(b, pt(q), pt(n1)) && box_meets_half_plane(b, pt(q), pt(n2)))
                    .then(|| box_lower_bound(b, q))
            },
            |o| o.clipped_distance(pt(q), &[pt(n1), pt(n2)]),
            |a, b| {
                let (a, b) = clip_to_half_plane(a, b, q, n1)?;
                clip_to_half_plane(a, b, q, n2)
            },
        )
    }

    /// Nearest point to `q` of the boundary segments as `clip` cuts them
    /// down (`None`: the whole segment is out); `bound` and `oriented` are
    /// lower bounds of the distance to the region within a box or an
    /// oriented box (`None`: not in it).
    fn nearest_clipped(
        &self,
        q: Coord<f64>,
        limit: f64,
        bound: impl Fn(&Bbox) -> Option<f64>,
        oriented: impl Fn(&Obb) -> Option<f64>,
        clip: impl Fn(Coord<f64>, Coord<f64>) -> Option<(Coord<f64>, Coord<f64>)>,
    ) -> Option<(Coord<f64>, f64)> {
        if !finite(q) {
            return None;
        }
        let best: Cell<Option<Found>> = Cell::new(None);
        self.tree()
            .branch_and_bound(limit, bound, Some(oriented), |i| {
                let s = &self.segments[i as usize];
                if let Some((a, b)) = clip(s.a, s.b) {
                    let c = closest_on_segment(a, b, q).0;
                    let d = norm(c - q);
                    if d <= limit
                        && best
                            .get()
                            .is_none_or(|(_, bd, bi)| d < bd || (d == bd && i < bi))
                    {
                        best.set(Some((c, d, i)));
                    }
                }
                best.get().map_or(limit, |(_, d, _)| d)
            });
        best.get().map(|(c, d, _)| (c, d))
    }

    /// First boundary point on the ray `origin + t · dir` with
    /// `min_t < t ≤ max_t`.
    pub fn first_hit(
        &self,
        origin: Coord<f64>,
        dir: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<RayHit> {
        if !(finite(origin) && finite(dir)) {
            return None;
        }
        let tame = lanes::tame(origin) && lanes::tame(dir);
        let (t, segment) = self.backend(tame, |b| b.first_param(origin, dir, min_t, max_t))?;
        Some(RayHit {
            t,
            point: origin + dir * t,
            segment,
        })
    }

    /// True when the open segment `pq` properly crosses a boundary segment.
    pub fn crosses(&self, p: Coord<f64>, q: Coord<f64>) -> bool {
        self.visit_segments_near(p, q, |i| {
            let s = &self.segments[i];
            if properly_cross(p, q, s.a, s.b) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .is_some()
    }

    /// True when the segment from `p` to the boundary point `q` meets ∂P only
    /// at `q`: [`Boundary::crosses`] on the segment stopped a millionth of
    /// its length short of `q` ([`SHORT_OF_END`]), because a point computed
    /// on a boundary segment lies on it only up to rounding and would
    /// "cross" it.
    pub fn reaches(&self, p: Coord<f64>, q: Coord<f64>) -> bool {
        !self.crosses(p, q + (p - q) * SHORT_OF_END)
    }

    /// Point-in-polygon by crossing parity along the ray towards +x
    /// (half-open rule on vertices). Points exactly on ∂P may go either way:
    /// use [`Boundary::distance`] for a tolerance.
    pub fn contains(&self, p: Coord<f64>) -> bool {
        self.contains_with_rings(p, |_| true)
    }

    /// Indices of the segments whose bounding box meets that of segment `pq`,
    /// in increasing order (whatever the tree's layout).
    pub fn segments_near(&self, p: Coord<f64>, q: Coord<f64>) -> impl Iterator<Item = usize> {
        let mut near = Vec::new();
        self.visit_segments_near(p, q, |i| {
            near.push(i);
            ControlFlow::<()>::Continue(())
        });
        near.sort_unstable();
        near.into_iter()
    }

    /// [`Boundary::segments_near`] without collecting them: `f` sees each
    /// index (in no particular order) until it breaks, with the break value
    /// returned.
    pub fn visit_segments_near<B>(
        &self,
        p: Coord<f64>,
        q: Coord<f64>,
        mut f: impl FnMut(usize) -> ControlFlow<B>,
    ) -> Option<B> {
        let env = [p.x.min(q.x), p.y.min(q.y), p.x.max(q.x), p.y.max(q.y)];
        self.tree()
            .visit(|b| boxes_meet(b, &env), |i| f(i as usize))
    }

    /// Every pair of segments whose boxes meet, once each as `(i, j)` with
    /// `i < j`, in no particular order, until `f` breaks.
    pub fn visit_segment_pairs<B>(
        &self,
        mut f: impl FnMut(usize, usize) -> ControlFlow<B>,
    ) -> Option<B> {
        self.tree().pairs(|i, j| f(i as usize, j as usize))
    }

    /// The pair of segments `(i, j)`, `i < j`, whose boxes meet, first in
    /// `(i, j)` order among those for which `f` gives a value, with that
    /// value (every meeting pair is tested, on every core for a long
    /// boundary).
    pub fn first_segment_pair<T: Send>(
        &self,
        f: impl Fn(usize, usize) -> Option<T> + Sync,
    ) -> Option<(usize, usize, T)> {
        self.tree()
            .first_pair(|i, j| f(i as usize, j as usize))
            .map(|(i, j, v)| (i as usize, j as usize, v))
    }

    /// Crossing parity of the ray from `p` towards +x against the segments of
    /// the rings for which `ring` is true: `p` is inside the region those rings bound.
    pub fn contains_with_rings(&self, p: Coord<f64>, ring: impl Fn(u32) -> bool) -> bool {
        self.parity_toward(p, 0, ring)
    }

    /// Crossing parity of the ray from `p` along axis direction `axis`
    /// (0: +x, 1: −x, 2: +y, 3: −y) against the segments of the rings for
    /// which `ring` is true. Each direction is turned to +x by an exact map
    /// of the coordinates (a swap or a negation), so the half-open rule of
    /// [`crosses_rightward`] holds in every direction; for a point off ∂P
    /// every direction gives the same answer.
    fn parity_toward(&self, p: Coord<f64>, axis: usize, ring: impl Fn(u32) -> bool) -> bool {
        let (dir, reach) = match axis {
            0 => ([1.0, 0.0], self.max.x - p.x),
            1 => ([-1.0, 0.0], p.x - self.min.x),
            2 => ([0.0, 1.0], self.max.y - p.y),
            _ => ([0.0, -1.0], p.y - self.min.y),
        };
        let turn = |c: Coord<f64>| match axis {
            0 => c,
            1 => Coord { x: -c.x, y: c.y },
            2 => Coord { x: c.y, y: c.x },
            _ => Coord { x: -c.y, y: c.x },
        };
        let max_t = reach.max(0.0) + 1.0;
        let q = turn(p);
        let mut inside = false;
        self.tree().visit(
            |b| ray_box(b, pt(p), dir, max_t).is_some(),
            |i| {
                let s = &self.segments[i as usize];
                if ring(s.ring) {
                    let t = BoundarySegment {
                        a: turn(s.a),
                        b: turn(s.b),
                        ..*s
                    };
                    inside ^= crosses_rightward(&t, q);
                }
                ControlFlow::<()>::Continue(())
            },
        );
        inside
    }

    /// True when `p` is inside P or within `tol` of ∂P. The parity ray runs
    /// to the nearest side of the bounding box: on a rough boundary a long
    /// ray passes many segments (the straight skeleton's check of its
    /// 400 000 nodes on the 200 000-vertex rough polygon of
    /// `scripts/make_rough_polygon.py`: 1.1 s along +x). A point off ∂P gets
    /// the same answer in every direction, and one on it is within `tol`.
    pub fn contains_with_tolerance(&self, p: Coord<f64>, tol: f64) -> bool {
        let reach = [
            self.max.x - p.x,
            p.x - self.min.x,
            self.max.y - p.y,
            p.y - self.min.y,
        ];
        let axis = (1..4).fold(0, |k, j| if reach[j] < reach[k] { j } else { k });
        self.parity_toward(p, axis, |_| true) || self.distance(p) <= tol
    }
}

/// A lower bound of the distance from `q` to any point of the box, so also
/// to its part in a half-plane or sector: the distance to the whole box
/// (looser than to the part for a box across an edge line, but cheaper, and
/// few boxes near `q` are; a search gives the same answer with any lower
/// bound), shrunk by [`BOUND_MARGIN`] so that rounding never makes it
/// exceed a distance computed to a segment in the box.
fn box_lower_bound(b: &Bbox, q: Coord<f64>) -> f64 {
    box_distance_2(b, q.x, q.y).sqrt() * (1.0 - BOUND_MARGIN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    fn square_with_hole() -> Boundary {
        let p = polygon!(
            exterior: [(x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 10.), (x: 0., y: 10.), (x: 0., y: 0.)],
            interiors: [[(x: 4., y: 4.), (x: 4., y: 6.), (x: 6., y: 6.), (x: 6., y: 4.), (x: 4., y: 4.)]],
        );
        Boundary::new(&p)
    }

    /// `is_within` answers as the whole distance does, on the limit itself
    /// too (points on a grid around and inside a ring with a hole, limits
    /// from 0 to beyond every point's distance, and each point's own).
    #[test]
    fn is_within_is_the_distance_compared_with_the_limit() {
        let b = square_with_hole();
        for i in -8..=72 {
            for k in -8..=72 {
                let p = Coord {
                    x: i as f64 * 0.21 - 1.3,
                    y: k as f64 * 0.17 - 0.9,
                };
                let d = b.distance(p);
                for limit in [0.0, 0.05, 0.5, 1.0, 3.0, 20.0, d, d * (1.0 - 1e-15)] {
                    assert_eq!(b.is_within(p, limit), d <= limit, "{p:?} {limit} {d}");
                }
            }
        }
    }

    /// The parity ray along each axis direction gives the one answer, for
    /// points on a grid through a jagged ring with a hole (many of them on
    /// the lines of its vertices, where the half-open rule decides).
    #[test]
    fn every_axis_direction_gives_the_same_parity() {
        let n = 90;
        let ring: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let r = if i % 2 == 0 { 10.0 } else { 7.0 };
                ((r * t.cos()).round(), (r * t.sin()).round())
            })
            .collect();
        let p = Polygon::new(
            LineString::from(ring),
            vec![LineString::from(vec![
                (-2., -2.),
                (-2., 2.),
                (2., 2.),
                (2., -2.),
            ])],
        );
        let b = Boundary::new(&p);
        let mut inside = 0;
        for i in -24..=24 {
            for j in -24..=24 {
                let q = Coord {
                    x: i as f64 * 0.5,
                    y: j as f64 * 0.5,
                };
                if b.distance(q) < 1e-9 {
                    continue;
                }
                let want = b.contains(q);
                inside += usize::from(want);
                for axis in 1..4 {
                    assert_eq!(b.parity_toward(q, axis, |_| true), want, "{q:?} {axis}");
                }
                assert_eq!(b.contains_with_tolerance(q, 0.0), want);
            }
        }
        assert!(inside > 300, "{inside}");
    }

    #[test]
    fn distance_contains_crosses() {
        let b = square_with_hole();
        assert_eq!(b.distance(Coord { x: 2.0, y: 5.0 }), 2.0);
        assert!(b.contains(Coord { x: 2.0, y: 5.0 }));
        assert!(!b.contains(Coord { x: 5.0, y: 5.0 }));
        assert!(!b.contains(Coord { x: 11.0, y: 5.0 }));
        assert!(b.crosses(Coord { x: 2.0, y: 5.0 }, Coord { x: 5.0, y: 5.0 }));
        assert!(!b.crosses(Coord { x: 1.0, y: 1.0 }, Coord { x: 3.0, y: 9.0 }));
    }

    /// The boundary of a ring of `n` vertices around the origin, radius 100
    /// with two waves (amplitude, frequency) on it: a tree of several levels.
    fn wavy_ring(n: usize, w1: [f64; 2], w2: [f64; 2]) -> Boundary {
        let ring: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let r = 100.0 + w1[0] * (w1[1] * t).sin() + w2[0] * (w2[1] * t).cos();
                (r * t.cos(), r * t.sin())
            })
            .collect();
        Boundary::new(&geo::Polygon::new(ring.into(), vec![]))
    }

    /// The bounded searches give the unbounded answers: the same nearest
    /// point within any limit at or above its distance, none below it, and
    /// `distance_within` the true distance even from a wrong bound.
    #[test]
    fn bounded_searches_agree_with_unbounded_ones() {
        let b = wavy_ring(600, [7.0, 13.0], [3.0, 41.0]);
        for k in 0..200 {
            let a = k as f64 * 0.7;
            let p = Coord {
                x: (k % 90) as f64 * a.cos(),
                y: (k % 90) as f64 * a.sin(),
            };
            let (c, i, d) = b.nearest(p).unwrap();
            assert_eq!(
                b.nearest_within(p, d * (1.0 + 1e-6)),
                Some((c, i, d)),
                "{p:?}"
            );
            assert_eq!(
                b.nearest_within(p, 10.0 * d + 1.0),
                Some((c, i, d)),
                "{p:?}"
            );
            if d > 0.0 {
                assert_eq!(b.nearest_within(p, 0.5 * d), None, "{p:?}");
            }
            for bound in [0.5 * d, d, 3.0 * d + 5.0] {
                assert_eq!(b.distance_within(p, bound), b.distance(p), "{p:?} {bound}");
            }
        }
    }

    #[test]
    fn ray_hits_first_boundary() {
        let b = square_with_hole();
        let h = b
            .first_hit(
                Coord { x: 1.0, y: 5.0 },
                Coord { x: 1.0, y: 0.0 },
                0.0,
                100.0,
            )
            .unwrap();
        assert_eq!(h.point, Coord { x: 4.0, y: 5.0 });
        let h = b
            .first_hit(
                Coord { x: 1.0, y: 5.0 },
                Coord { x: -1.0, y: 0.0 },
                0.0,
                100.0,
            )
            .unwrap();
        assert_eq!(h.t, 1.0);
    }

    /// The first hit of a ray through the tree is the one a scan of every
    /// segment finds (least parameter, ties to the lower segment number), on
    /// a wavy ring whose tree has several levels, from points inside and
    /// outside, with and without a far limit.
    #[test]
    fn first_hits_match_a_scan() {
        let b = wavy_ring(900, [9.0, 11.0], [2.0, 57.0]);
        for k in 0..400 {
            let a = k as f64 * 0.61;
            let origin = Coord {
                x: a.cos() * (k % 130) as f64,
                y: a.sin() * (k % 130) as f64,
            };
            let dir = Coord {
                x: (k as f64 * 2.3).cos(),
                y: (k as f64 * 2.3).sin(),
            };
            let (min_t, max_t) = (1e-9, if k % 3 == 0 { 40.0 } else { f64::INFINITY });
            let mut want: Option<(f64, usize)> = None;
            for (i, s) in b.segments().iter().enumerate() {
                if let Some((t, _)) = ray_segment(origin, dir, s.a, s.b) {
                    if t > min_t && t <= max_t && want.is_none_or(|(bt, _)| t < bt) {
                        want = Some((t, i));
                    }
                }
            }
            let got = b
                .first_hit(origin, dir, min_t, max_t)
                .map(|h| (h.t, h.segment));
            assert_eq!(got, want, "{origin:?} {dir:?} {max_t}");
        }
    }

    #[test]
    fn sector_nearest() {
        let b = square_with_hole();
        let q = Coord { x: 2.0, y: 2.0 };
        let (e, n) = (Coord { x: 1.0, y: 0.0 }, Coord { x: 0.0, y: 1.0 });
        // Towards the south-west corner only: from (−1, −1)/√2 through
        // south to (1, −1)/√2 the nearest point is straight below.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let (c, d) = b
            .nearest_in_sector(q, Coord { x: -s, y: -s }, Coord { x: s, y: -s })
            .unwrap();
        assert_eq!((c, d), (Coord { x: 2.0, y: 0.0 }, 2.0));
        // North-east quadrant: the hole's corner (4, 4).
        let (c, _) = b.nearest_in_sector(q, e, n).unwrap();
        assert_eq!(c, Coord { x: 4.0, y: 4.0 });
    }

    /// The tree's backend over a boundary of any size.
    fn indexed(b: &Boundary) -> Indexed<'_> {
        Indexed {
            segments: &b.segments,
            tree: b.tree(),
        }
    }

    /// A xorshift generator of numbers in [0, 1).
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Random small boundaries (1 to 64 segments, some of zero length,
    /// some collinear), and a square grid of unit segments (rays along
    /// them, ties everywhere).
    fn small_boundaries(next: &mut impl FnMut() -> f64) -> Vec<Boundary> {
        let mut boundaries = Vec::new();
        for n in 1..=64 {
            // Random segments, with grid-snapped coordinates now and then
            // (exact collinearity, shared ends, zero lengths).
            let mut segs = Vec::new();
            for i in 0..n {
                let snap = i % 3 == 0;
                let mut c = || {
                    let v = next() * 20.0 - 10.0;
                    if snap {
                        v.round()
                    } else {
                        v
                    }
                };
                let a = Coord { x: c(), y: c() };
                let b = if i % 7 == 3 {
                    a
                } else {
                    Coord { x: c(), y: c() }
                };
                segs.push(BoundarySegment {
                    a,
                    b,
                    ring: 0,
                    index: i as u32,
                });
            }
            boundaries.push(Boundary::from_segments(segs));
        }
        let mut grid = Vec::new();
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (i as f64, j as f64);
                for (a, b) in [((x, y), (x + 1.0, y)), ((x, y), (x, y + 1.0))] {
                    grid.push(BoundarySegment {
                        a: a.into(),
                        b: b.into(),
                        ring: 0,
                        index: grid.len() as u32,
                    });
                }
            }
        }
        boundaries.push(Boundary::from_segments(grid));
        boundaries
    }

    /// Query points (on a half grid now and then: on segment lines and
    /// vertices) and directions (axis-parallel now and then).
    fn queries(next: &mut impl FnMut() -> f64) -> Vec<(Coord<f64>, Coord<f64>)> {
        let mut queries = vec![];
        for k in 0..40 {
            let p = Coord {
                x: (next() * 24.0 - 12.0),
                y: (next() * 24.0 - 12.0),
            };
            let p = if k % 4 == 0 {
                Coord {
                    x: p.x.round() * 0.5,
                    y: p.y.round() * 0.5,
                }
            } else {
                p
            };
            let a = next() * std::f64::consts::TAU;
            let dir = match k % 5 {
                0 => Coord { x: 1.0, y: 0.0 },
                1 => Coord { x: 0.0, y: -1.0 },
                _ => Coord {
                    x: a.cos(),
                    y: a.sin(),
                },
            };
            queries.push((p, dir));
        }
        queries
    }

    /// Asks backends `x` and `y` every query at `(p, dir)` and asserts the
    /// same answers bit for bit; counts the answers found per kind.
    fn same_answers(
        x: &dyn Backend,
        y: &dyn Backend,
        (p, dir): (Coord<f64>, Coord<f64>),
        answered: &mut [usize; 3],
    ) {
        let bits = |v: f64| v.to_bits();
        let pt_bits = |c: Coord<f64>| (bits(c.x), bits(c.y));
        for limit2 in [f64::INFINITY, 9.0, 0.0] {
            let (a, b) = (x.nearest_2(p, limit2), y.nearest_2(p, limit2));
            assert_eq!(a.map(|(d, i)| (bits(d), i)), b.map(|(d, i)| (bits(d), i)));
            answered[0] += usize::from(a.is_some());
        }
        for (min_t, max_t) in [(0.0, f64::INFINITY), (1e-9, 5.0)] {
            let key = |h: Option<(f64, usize)>| h.map(|(t, i)| (bits(t), i));
            let a = x.first_param(p, dir, min_t, max_t);
            assert_eq!(key(a), key(y.first_param(p, dir, min_t, max_t)));
            answered[1] += usize::from(a.is_some());
        }
        let key =
            |r: [Option<(Coord<f64>, f64)>; 2]| r.map(|o| o.map(|(c, d)| (pt_bits(c), bits(d))));
        let a = x.both_sides(p, dir);
        assert_eq!(key(a), key(y.both_sides(p, dir)));
        answered[2] += a.iter().filter(|o| o.is_some()).count();
    }

    /// The lane passes ([`super::lanes`]) give the scalar passes' answers
    /// bit for bit: on random small boundaries and on a grid where rays run
    /// along segments, through vertices and points sit on segment lines,
    /// with ties of equal distances.
    #[test]
    fn lane_passes_answer_as_the_scalar_passes_do() {
        let mut next = uniform(0x2545_f491_4f6c_dd1d);
        let boundaries = small_boundaries(&mut next);
        let queries = queries(&mut next);
        let mut answered = [0usize; 3];
        for b in &boundaries {
            assert_eq!(b.columns.is_some(), lanes::available());
            let Some(columns) = &b.columns else { continue };
            for &q in &queries {
                same_answers(columns, &Scan(&b.segments), q, &mut answered);
            }
        }
        if lanes::available() {
            assert!(answered.iter().all(|&n| n > 1000), "{answered:?}");
        }
    }

    /// A boundary of few segments answers ray and nearest-segment queries
    /// by a pass over them: exactly the tree's answers, ties included.
    #[test]
    fn small_boundaries_answer_as_the_tree_does() {
        // A wavy ring of 60 segments (the pass) and rays from inside and
        // outside, through vertices among them; the tree must agree.
        let ring: Vec<(f64, f64)> = (0..60)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 60.0;
                let r = 10.0 + if i % 2 == 0 { 1.0 } else { -1.0 };
                (
                    (r * a.cos() * 8.0).round() / 8.0,
                    (r * a.sin() * 8.0).round() / 8.0,
                )
            })
            .collect();
        let b = Boundary::new(&Polygon::new(LineString::from(ring.clone()), vec![]));
        assert!(b.few_segments());
        let (scan, tree) = (Scan(&b.segments), indexed(&b));
        let mut hits = 0;
        for (k, &(vx, vy)) in ring.iter().enumerate() {
            for (ox, oy) in [(0.0, 0.0), (0.5, -1.25), (30.0, 2.0), (-3.0, 20.0)] {
                let origin = Coord { x: ox, y: oy };
                let v = Coord { x: vx, y: vy };
                let dirs = [
                    v - origin,
                    Coord {
                        x: 1.0,
                        y: k as f64 * 0.1,
                    },
                ];
                for dir in dirs {
                    let pass = scan.first_param(origin, dir, 1e-9, 1e3);
                    assert_eq!(pass, tree.first_param(origin, dir, 1e-9, 1e3));
                    hits += usize::from(pass.is_some());
                    // Nearest segments too, from points along the ray (on
                    // the ring's vertices and edges among them).
                    for t in [0.25, 0.5, 1.0, 1.5] {
                        let p = origin + dir * t;
                        for limit2 in [f64::INFINITY, 4.0] {
                            assert_eq!(scan.nearest_2(p, limit2), tree.nearest_2(p, limit2));
                        }
                    }
                }
            }
        }
        assert!(hits > 300, "{hits}");
    }

    /// The one-pass search of both sides gives exactly the two half-plane
    /// searches' answers, on small rings (its use) and on a large one.
    #[test]
    fn both_sides_at_once_match_the_two_searches() {
        let dir = |a: f64| Coord {
            x: a.cos(),
            y: a.sin(),
        };
        let mut compared = 0;
        for (n, b) in [
            (5, wavy_ring(5, [1.0, 0.0], [0.0, 0.0])),
            (9, wavy_ring(9, [9.0, 3.0], [2.0, 7.0])),
            (16, wavy_ring(16, [9.0, 11.0], [2.0, 57.0])),
            (300, wavy_ring(300, [9.0, 11.0], [2.0, 57.0])),
        ] {
            assert_eq!(b.few_segments(), n <= FEW_SEGMENTS);
            for k in 0..300 {
                let q = dir(k as f64 * 0.61) * ((k % 130) as f64);
                let nu = dir(k as f64 * 2.3);
                let [left, right] = b.nearest_on_both_sides(q, nu);
                assert_eq!(left, b.nearest_in_half_plane(q, nu), "{n}: {q:?} {nu:?}");
                assert_eq!(right, b.nearest_in_half_plane(q, -nu), "{n}: {q:?} {nu:?}");
                compared += usize::from(left.is_some()) + usize::from(right.is_some());
            }
        }
        assert!(compared > 1500);
    }

    /// The tree searches in half-planes and sectors find what a scan of
    /// every segment finds (ties to the lower segment number), on a wavy
    /// ring whose tree has several levels, from points inside and outside.
    #[test]
    fn half_plane_and_sector_searches_match_a_scan() {
        let b = wavy_ring(900, [9.0, 11.0], [2.0, 57.0]);
        type Clip<'a> = &'a dyn Fn(Coord<f64>, Coord<f64>) -> Option<(Coord<f64>, Coord<f64>)>;
        let scan = |q: Coord<f64>, clip: Clip| {
            let mut best: Option<(Coord<f64>, f64)> = None;
            for s in b.segments() {
                if let Some((a, c)) = clip(s.a, s.b) {
                    let p = closest_on_segment(a, c, q).0;
                    let d = norm(p - q);
                    if best.is_none_or(|(_, bd)| d < bd) {
                        best = Some((p, d));
                    }
                }
            }
            best
        };
        let dir = |a: f64| Coord {
            x: a.cos(),
            y: a.sin(),
        };
        for k in 0..400 {
            let a = k as f64 * 0.61;
            let q = dir(a) * ((k % 120) as f64);
            let nu = dir(k as f64 * 2.3);
            let found = b.nearest_in_half_plane(q, nu);
            assert_eq!(
                found,
                scan(q, &|s, t| clip_to_half_plane(s, t, q, nu)),
                "{q:?} {nu:?}"
            );
            let (from, to) = (dir(a), dir(a + 0.2 + (k % 7) as f64 * 0.4));
            let (n1, n2) = (
                Coord {
                    x: -from.y,
                    y: from.x,
                },
                Coord { x: to.y, y: -to.x },
            );
            let expect = scan(q, &|s, t| {
                let (s, t) = clip_to_half_plane(s, t, q, n1)?;
                clip_to_half_plane(s, t, q, n2)
            });
            assert_eq!(
                b.nearest_in_sector(q, from, to),
                expect,
                "{q:?} {from:?} {to:?}"
            );
        }
    }

    #[test]
    fn half_plane_nearest() {
        let b = square_with_hole();
        let q = Coord { x: 2.0, y: 5.0 };
        // Left of an upward skeleton segment at q: normal (-1, 0).
        let (c, d) = b
            .nearest_in_half_plane(q, Coord { x: -1.0, y: 0.0 })
            .unwrap();
        assert_eq!((c, d), (Coord { x: 0.0, y: 5.0 }, 2.0));
        let (c, d) = b
            .nearest_in_half_plane(q, Coord { x: 1.0, y: 0.0 })
            .unwrap();
        assert_eq!((c, d), (Coord { x: 4.0, y: 5.0 }, 2.0));
    }
}
