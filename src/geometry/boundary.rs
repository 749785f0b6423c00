//! Spatial index of a polygon's boundary ∂P.
//!
//! One R-tree of boundary segments answers every boundary question the
//! methods and steps ask: distance to ∂P (node radii), point-in-polygon,
//! "does this segment cross ∂P", the first hit of a ray (leg extension, bars)
//! and the nearest boundary point (optionally restricted to a half-plane, for
//! the scoring step's sides). Queries cost O(log n) on real data instead of a
//! scan of all edges.

use super::lanes::{self, Columns};
use super::packed::{
    box_distance_2, box_meets_half_plane, boxes_meet, ray_box, Bbox, Obb, PackedTree, RaySlab,
};
use geo::{Coord, LineString, Polygon};
use std::cell::Cell;
use std::ops::ControlFlow;
use std::sync::OnceLock;

/// One boundary edge, oriented as its ring (interior on the left).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundarySegment {
    /// Start vertex.
    pub a: Coord<f64>,
    /// End vertex.
    pub b: Coord<f64>,
    /// Ring index (0 = exterior).
    pub ring: u32,
    /// Index of the start vertex within its ring.
    pub index: u32,
}

impl BoundarySegment {
    /// Segment length.
    pub fn length(&self) -> f64 {
        (self.b - self.a).x.hypot((self.b - self.a).y)
    }

    /// Closest point of the segment to `p`, and its parameter in [0, 1].
    pub fn closest(&self, p: Coord<f64>) -> (Coord<f64>, f64) {
        closest_on_segment(self.a, self.b, p)
    }
}

/// Closest point of segment `ab` to `p` and its parameter `t` in [0, 1].
pub fn closest_on_segment(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> (Coord<f64>, f64) {
    let d = b - a;
    let l2 = d.x * d.x + d.y * d.y;
    if l2 == 0.0 {
        return (a, 0.0);
    }
    let t = (((p - a).x * d.x + (p - a).y * d.y) / l2).clamp(0.0, 1.0);
    (a + d * t, t)
}

/// [`closest_on_segment`]'s point without its parameter, dividing only when
/// the foot is interior (see [`segment_distance_2`]: the same point, but
/// for the sign of a zero coordinate).
fn closest_point(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> Coord<f64> {
    let d = b - a;
    let dot = (p - a).x * d.x + (p - a).y * d.y;
    let l2 = d.x * d.x + d.y * d.y;
    if dot <= 0.0 || l2 == 0.0 {
        a
    } else if dot < l2 {
        a + d * (dot / l2)
    } else {
        a + d
    }
}

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

/// Squared distance from `p` to segment `ab` (the nearest point computed as
/// the projection parameter strictly inside (0, 1), else an end).
///
/// The parameter is `dot / l2` (`dot` = (p − a)·(b − a), `l2` = |b − a|²),
/// but the division is made only when the foot is interior: `0 < dot/l2`
/// exactly when `0 < dot` (a quotient that underflows to zero gives the
/// same point `a`), and a quotient of floating-point numbers `dot < l2` is
/// below one after rounding (the gap below 1 is 2⁻⁵³, and `dot/l2` is at
/// most 1 − 2⁻⁵³), so `dot/l2 < 1` exactly when `dot < l2`. The same
/// distance, bit for bit, as dividing first; most segments of a pass have
/// their nearest point at an end.
fn segment_distance_2(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> f64 {
    let dir = b - a;
    let dot = (p - a).x * dir.x + (p - a).y * dir.y;
    let l2 = dir.x * dir.x + dir.y * dir.y;
    let n = if dot <= 0.0 {
        a
    } else if dot < l2 {
        a + dir * (dot / l2)
    } else {
        b
    };
    let d = n - p;
    d.x * d.x + d.y * d.y
}

fn cross(a: Coord<f64>, b: Coord<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Robust orientation of `c` relative to the directed line `a → b`:
/// positive = left, negative = right, zero = collinear.
pub fn orient(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>) -> f64 {
    robust::orient2d(
        robust::Coord { x: a.x, y: a.y },
        robust::Coord { x: b.x, y: b.y },
        robust::Coord { x: c.x, y: c.y },
    )
}

/// Where segment `pq` meets segment `ab`, as the parameter `t` of
/// `p + t (q − p)`, when they meet in one point (not parallel).
pub fn segment_parameter(
    p: Coord<f64>,
    q: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
) -> Option<f64> {
    let (r, s) = (q - p, b - a);
    let den = r.x * s.y - r.y * s.x;
    if den == 0.0 {
        return None;
    }
    let d = a - p;
    let t = (d.x * s.y - d.y * s.x) / den;
    let u = (d.x * r.y - d.y * r.x) / den;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some(t)
}

/// True when segments `pq` and `ab` cross at a single point interior to both
/// (a proper crossing); touching at an endpoint or running along each other is
/// not a crossing.
pub fn properly_cross(p: Coord<f64>, q: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> bool {
    let o1 = orient(p, q, a);
    let o2 = orient(p, q, b);
    let o3 = orient(a, b, p);
    let o4 = orient(a, b, q);
    o1 * o2 < 0.0 && o3 * o4 < 0.0
}

/// Intersection parameter of ray `o + t d` with segment `ab`: `(t, s)` where
/// `s` ∈ [0, 1] is the segment parameter. For a collinear overlap the nearest
/// overlapping point is returned.
#[inline]
pub fn ray_segment(
    o: Coord<f64>,
    d: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
) -> Option<(f64, f64)> {
    let e = b - a;
    let den = cross(d, e);
    let w = a - o;
    if den == 0.0 {
        // Parallel: only a collinear overlap counts.
        if cross(w, d) != 0.0 {
            return None;
        }
        let dd = d.x * d.x + d.y * d.y;
        if dd == 0.0 {
            return None;
        }
        let ta = (w.x * d.x + w.y * d.y) / dd;
        let tb = ((b - o).x * d.x + (b - o).y * d.y) / dd;
        let (t, s) = if ta <= tb { (ta, 0.0) } else { (tb, 1.0) };
        let (tmax, _) = if ta <= tb { (tb, 1.0) } else { (ta, 0.0) };
        if tmax < 0.0 {
            return None;
        }
        if t >= 0.0 {
            return Some((t, s));
        }
        // Origin lies on the segment.
        let sl = e.x * e.x + e.y * e.y;
        let s0 = if sl == 0.0 {
            0.0
        } else {
            ((o - a).x * e.x + (o - a).y * e.y) / sl
        };
        return Some((0.0, s0.clamp(0.0, 1.0)));
    }
    // Whether the segment parameter `s = num / den` is in [0, 1], decided
    // without dividing (most segments a ray is tested against miss it): the
    // quotient's sign is that of its operands, and a quotient of
    // floating-point numbers exceeds one after rounding exactly when the
    // numerator's magnitude exceeds the denominator's (the gap above 1 is
    // 2⁻⁵², and the quotient is then above 1 + 2⁻⁵³, which rounds up; see
    // `segment_distance_2` for the gap below). The same decisions as
    // dividing first, but for a negative quotient below 2⁻¹⁰⁷⁴ in magnitude,
    // which would have rounded to −0 and counted as 0.
    let num = cross(w, d);
    let inside = if den > 0.0 {
        0.0 <= num && num <= den
    } else {
        den <= num && num <= 0.0
    };
    if !inside {
        return None;
    }
    let s = num / den;
    let t = cross(w, e) / den;
    (t >= 0.0).then_some((t, s))
}

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

    /// The same boundary answering by the scalar passes alone (no columns):
    /// what the lane passes must agree with.
    #[cfg(test)]
    fn scalar(&self) -> Self {
        Self {
            columns: None,
            ..self.clone()
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

    /// The segment nearest to `p` and its squared distance.
    fn nearest_segment(&self, p: Coord<f64>) -> Option<(f64, u32)> {
        self.nearest_segment_within(p, f64::INFINITY)
    }

    /// The nearest segment among those within squared distance `limit2`.
    fn nearest_segment_within(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        if let Some(c) = self.columns.as_ref().filter(|_| lanes::tame(p)) {
            // The same pass, several segments at a time.
            return c.nearest_2(p, limit2);
        }
        if self.few_segments() {
            // Every segment in index order: the tree's answer (least squared
            // distance within the limit, ties to the lower index).
            let mut best: Option<(f64, u32)> = None;
            for (i, s) in self.segments.iter().enumerate() {
                let d2 = segment_distance_2(s.a, s.b, p);
                if d2 <= limit2 && best.is_none_or(|(bd, _)| d2 < bd) {
                    best = Some((d2, i as u32));
                }
            }
            return best;
        }
        self.nearest_segment_in_tree(p, limit2)
    }

    /// [`Boundary::nearest_segment_within`] through the tree, whatever the
    /// size.
    fn nearest_segment_in_tree(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        let (x, y) = (p.x, p.y);
        self.tree().best_within(
            limit2,
            |b| Some(box_distance_2(b, x, y)),
            Some(|o: &Obb| Some(o.distance_2([x, y]))),
            |i, _| {
                let s = &self.segments[i as usize];
                Some(segment_distance_2(s.a, s.b, p))
            },
        )
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
        Some((c, i as usize, super::norm(c - p)))
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
        self.nearest_segment(p)
            .map(|(d2, _)| d2.sqrt())
            .unwrap_or(f64::INFINITY)
    }

    /// [`Boundary::distance`] when it is known to be at most `bound` (up to
    /// rounding): the bound keeps the search short and never changes the
    /// answer.
    pub fn distance_within(&self, p: Coord<f64>, bound: f64) -> f64 {
        let limit = bound * (1.0 + 1e-9) + f64::MIN_POSITIVE;
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
        // The nearest point on each side so far and its squared distance.
        let mut best: [Option<(Coord<f64>, f64)>; 2] = [None, None];
        if !finite(q) {
            return best;
        }
        if let Some(c) = self
            .columns
            .as_ref()
            .filter(|_| lanes::tame(q) && lanes::tame(normal))
        {
            // The same pass, several segments at a time.
            return c
                .both_sides(q, normal)
                .map(|b| b.map(|(c, d2)| (c, d2.sqrt())));
        }
        let side = |c: Coord<f64>| (c - q).x * normal.x + (c - q).y * normal.y;
        for s in &self.segments {
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
                let d2 = (c - q).x * (c - q).x + (c - q).y * (c - q).y;
                // Segments in index order: the first of equal distances
                // stays, distances compared as roots (as the tree search
                // compares them). A root is never smaller when its square
                // is not, and is smaller when its square is smaller by more
                // than the roots' rounding (a relative 2⁻⁵³ each): only
                // squares closer than that need their roots. The root of
                // the winner is taken at the end: the same answer.
                if best[k].is_none_or(|(_, bd2)| nearer_2(d2, bd2)) {
                    best[k] = Some((c, d2));
                }
            }
        }
        best.map(|b| b.map(|(c, d2)| (c, d2.sqrt())))
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
                    let d = super::norm(c - q);
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
        if let Some(c) = self
            .columns
            .as_ref()
            .filter(|_| lanes::tame(origin) && lanes::tame(dir))
        {
            // The same pass, several segments at a time.
            return c
                .first_param(origin, dir, min_t, max_t)
                .map(|(t, segment)| RayHit {
                    t,
                    point: origin + dir * t,
                    segment,
                });
        }
        if self.few_segments() {
            // Every segment in index order: the tree's answer (lowest t,
            // ties to the lower index) without building or walking it.
            let mut best: Option<(f64, usize)> = None;
            for (i, s) in self.segments.iter().enumerate() {
                let hit = ray_segment(origin, dir, s.a, s.b)
                    .map(|(t, _)| t)
                    .filter(|&t| t > min_t && t <= max_t);
                if let Some(t) = hit {
                    if best.is_none_or(|(bt, _)| t < bt) {
                        best = Some((t, i));
                    }
                }
            }
            return best.map(|(t, segment)| RayHit {
                t,
                point: origin + dir * t,
                segment,
            });
        }
        self.first_hit_in_tree(origin, dir, min_t, max_t)
    }

    /// [`Boundary::first_hit`] through the tree, whatever the size.
    fn first_hit_in_tree(
        &self,
        origin: Coord<f64>,
        dir: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<RayHit> {
        let slab = RaySlab::new(pt(origin), pt(dir), max_t);
        // Axis-aligned boxes only: a ray crossing the polygon passes as many
        // oriented boxes as axis-aligned ones, and their test costs more
        // (callgrind, a noisy circle of 50 000 vertices: the exits 2.3 G
        // instructions with axis-aligned boxes, 3.1 G with oriented ones).
        let (t, i) = self.tree().best(
            |b| slab.enter(b),
            None::<fn(&Obb) -> Option<f64>>,
            |i, _| {
                let s = &self.segments[i as usize];
                ray_segment(origin, dir, s.a, s.b)
                    .map(|(t, _)| t)
                    .filter(|&t| t > min_t && t <= max_t)
            },
        )?;
        Some(RayHit {
            t,
            point: origin + dir * t,
            segment: i as usize,
        })
    }

    /// True when the open segment `pq` properly crosses a boundary segment.
    pub fn crosses(&self, p: Coord<f64>, q: Coord<f64>) -> bool {
        let env = [p.x.min(q.x), p.y.min(q.y), p.x.max(q.x), p.y.max(q.y)];
        self.tree()
            .visit(
                |b| boxes_meet(b, &env),
                |i| {
                    let s = &self.segments[i as usize];
                    if properly_cross(p, q, s.a, s.b) {
                        ControlFlow::Break(())
                    } else {
                        ControlFlow::Continue(())
                    }
                },
            )
            .is_some()
    }

    /// True when the segment from `p` to the boundary point `q` meets ∂P only
    /// at `q`: [`Boundary::crosses`] on the segment stopped a millionth of
    /// its length short of `q`, because a point computed on a boundary
    /// segment lies on it only up to rounding and would "cross" it.
    pub fn reaches(&self, p: Coord<f64>, q: Coord<f64>) -> bool {
        !self.crosses(p, q + (p - q) * 1e-6)
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

    /// Crossing parity of the ray from `p` towards +x against the segments of
    /// the rings for which `ring` is true: `p` is inside the region those rings bound.
    pub fn contains_with_rings(&self, p: Coord<f64>, ring: impl Fn(u32) -> bool) -> bool {
        let max_t = (self.max.x - p.x).max(0.0) + 1.0;
        let mut inside = false;
        self.tree().visit(
            |b| ray_box(b, pt(p), [1.0, 0.0], max_t).is_some(),
            |i| {
                let s = &self.segments[i as usize];
                if ring(s.ring) {
                    inside ^= crosses_up(s, p);
                }
                ControlFlow::<()>::Continue(())
            },
        );
        inside
    }

    /// True when `p` is inside P or within `tol` of ∂P.
    pub fn contains_with_tolerance(&self, p: Coord<f64>, tol: f64) -> bool {
        self.contains(p) || self.distance(p) <= tol
    }
}

/// True when the ray from `p` towards +x crosses `s` (half-open rule on
/// vertices).
fn crosses_up(s: &BoundarySegment, p: Coord<f64>) -> bool {
    let (a, b) = (s.a, s.b);
    if (a.y > p.y) == (b.y > p.y) {
        return false;
    }
    let o = orient(a, b, p);
    let upward = b.y > a.y;
    (upward && o > 0.0) || (!upward && o < 0.0)
}

/// Segment `ab` clipped to the half-plane `(x − q) · n ≥ 0`, or `None` when
/// it lies wholly outside it.
/// A lower bound of the distance from `q` to any point of the box, so also
/// to its part in a half-plane or sector: the distance to the whole box
/// (looser than to the part for a box across an edge line, but cheaper, and
/// few boxes near `q` are; a search gives the same answer with any lower
/// bound), shrunk by a relative 1e-9 so that rounding never makes it exceed
/// a distance computed to a segment in the box.
fn box_lower_bound(b: &Bbox, q: Coord<f64>) -> f64 {
    box_distance_2(b, q.x, q.y).sqrt() * (1.0 - 1e-9)
}

fn clip_to_half_plane(
    a: Coord<f64>,
    b: Coord<f64>,
    q: Coord<f64>,
    n: Coord<f64>,
) -> Option<(Coord<f64>, Coord<f64>)> {
    let fa = (a - q).x * n.x + (a - q).y * n.y;
    let fb = (b - q).x * n.x + (b - q).y * n.y;
    clip_by_sides(a, b, fa, fb)
}

/// True when the distance whose square is `d2` is smaller than the one
/// whose square is `best2`, compared as roots (as the tree search compares
/// them): a root is never smaller when its square is not, and is smaller
/// when its square is smaller by more than the roots' rounding (a relative
/// 2⁻⁵³ each), so only squares closer than that need their roots.
#[inline]
pub(super) fn nearer_2(d2: f64, best2: f64) -> bool {
    d2 < best2 && (d2 < best2 * (1.0 - 1e-15) || d2.sqrt() < best2.sqrt())
}

/// Segment `ab` cut down to where a linear function with values `fa` at `a`
/// and `fb` at `b` is ≥ 0, or `None` when it is negative at both ends.
fn clip_by_sides(
    a: Coord<f64>,
    b: Coord<f64>,
    fa: f64,
    fb: f64,
) -> Option<(Coord<f64>, Coord<f64>)> {
    match (fa >= 0.0, fb >= 0.0) {
        (true, true) => Some((a, b)),
        (false, false) => None,
        (true, false) => Some((a, a + (b - a) * (fa / (fa - fb)))),
        (false, true) => Some((a + (b - a) * (fa / (fa - fb)), b)),
    }
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

    /// A boundary of few segments answers ray and nearest-segment queries
    /// by a pass over them: exactly the tree's answers, ties included.
    /// The lane passes ([`super::lanes`]) give the scalar passes' answers
    /// bit for bit: on random small boundaries (1 to 64 segments, some of
    /// zero length, some collinear) and on a grid where rays run along
    /// segments, through vertices and points sit on segment lines, with
    /// ties of equal distances.
    #[test]
    fn lane_passes_answer_as_the_scalar_passes_do() {
        let bits = |x: f64| x.to_bits();
        let pt_bits = |c: Coord<f64>| (bits(c.x), bits(c.y));
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
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
        // A square grid of unit segments: rays along them, ties everywhere.
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
        let mut answered = [0usize; 3];
        for b in &boundaries {
            assert_eq!(b.columns.is_some(), lanes::available());
            let s = b.scalar();
            for &(p, dir) in &queries {
                for limit2 in [f64::INFINITY, 9.0, 0.0] {
                    let (x, y) = (
                        b.nearest_segment_within(p, limit2),
                        s.nearest_segment_within(p, limit2),
                    );
                    assert_eq!(x.map(|(d, i)| (bits(d), i)), y.map(|(d, i)| (bits(d), i)));
                    answered[0] += usize::from(x.is_some());
                }
                for (min_t, max_t) in [(0.0, f64::INFINITY), (1e-9, 5.0)] {
                    let key =
                        |h: Option<RayHit>| h.map(|h| (bits(h.t), pt_bits(h.point), h.segment));
                    let x = b.first_hit(p, dir, min_t, max_t);
                    assert_eq!(key(x), key(s.first_hit(p, dir, min_t, max_t)));
                    answered[1] += usize::from(x.is_some());
                }
                let key = |r: [Option<(Coord<f64>, f64)>; 2]| {
                    r.map(|o| o.map(|(c, d)| (pt_bits(c), bits(d))))
                };
                let x = b.nearest_on_both_sides(p, dir);
                assert_eq!(key(x), key(s.nearest_on_both_sides(p, dir)));
                answered[2] += x.iter().filter(|o| o.is_some()).count();
            }
        }
        assert!(answered.iter().all(|&n| n > 1000), "{answered:?}");
    }

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
                    let pass = b.first_hit(origin, dir, 1e-9, 1e3);
                    assert_eq!(pass, b.first_hit_in_tree(origin, dir, 1e-9, 1e3));
                    hits += usize::from(pass.is_some());
                    // Nearest segments too, from points along the ray (on
                    // the ring's vertices and edges among them).
                    for t in [0.25, 0.5, 1.0, 1.5] {
                        let p = origin + dir * t;
                        for limit2 in [f64::INFINITY, 4.0] {
                            assert_eq!(
                                b.nearest_segment_within(p, limit2),
                                b.nearest_segment_in_tree(p, limit2)
                            );
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
                    let d = crate::geometry::norm(p - q);
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
