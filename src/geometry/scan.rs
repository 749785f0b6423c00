//! The passes over every segment of a boundary, one segment at a time: how
//! a small boundary ([`super::Boundary::few_segments`]) answers its
//! nearest-segment and ray queries without building or walking a tree, and
//! how any boundary answers its two-sided half-plane query.
//!
//! Each pass keeps the tree search's answer, ties included (segments in
//! index order, the first of equal values stays), and is what the lane
//! passes ([`super::lanes`]) must agree with bit for bit.

use super::segment::{
    clip_by_sides, closest_point, nearer_2, ray_segment, segment_distance_2, BoundarySegment,
};
use super::vector::dot;
use geo::Coord;

/// The scalar passes over `segments`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scan<'a>(pub(crate) &'a [BoundarySegment]);

impl Scan<'_> {
    /// The segment nearest `p` among those within squared distance
    /// `limit2`, and its squared distance: the least within the limit,
    /// ties to the lower index.
    pub(crate) fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        for (i, s) in self.0.iter().enumerate() {
            let d2 = segment_distance_2(s.a, s.b, p);
            if d2 <= limit2 && best.is_none_or(|(bd, _)| d2 < bd) {
                best = Some((d2, i as u32));
            }
        }
        best
    }

    /// The least ray parameter `t`, `min_t < t ≤ max_t`, at which
    /// `origin + t · dir` meets a segment ([`ray_segment`]), and the
    /// segment: ties to the lower index.
    pub(crate) fn first_param(
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

    /// The point nearest `q` in each closed half-plane of the line through
    /// `q` across `normal` — `(x − q) · normal ≥ 0`, then `≤ 0` — and its
    /// squared distance.
    pub(crate) fn both_sides(
        &self,
        q: Coord<f64>,
        normal: Coord<f64>,
    ) -> [Option<(Coord<f64>, f64)>; 2] {
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
