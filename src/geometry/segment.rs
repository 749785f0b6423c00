//! Segment predicates: the one home of orientation, crossing, ray and
//! nearest-point tests on segments, used by the boundary index
//! ([`super::Boundary`] and its passes), validity, the skeleton's planarity,
//! the methods and the collapse step.
//!
//! # Tie rules
//!
//! * [`orient`] is exact (robust adaptive arithmetic): zero means exactly
//!   collinear, and the predicates built on it ([`properly_cross`],
//!   [`on_segment`], [`crosses_rightward`]) are exact too.
//! * [`properly_cross`]: touching at an end point, or running along each
//!   other, is *not* a crossing.
//! * [`segment_parameter`] and [`lines_meet`]: parallel lines (a zero
//!   denominator, computed in floating point) do not meet; a parameter of
//!   exactly 0 or 1 is on the segment.
//! * [`ray_segment`]: a parameter `t ≥ 0` counts (the origin itself);
//!   a segment collinear with the ray gives its nearest overlapping point.
//! * [`crosses_rightward`]: the half-open rule on vertices (an end counts
//!   when the other end is strictly above the ray), so a ray through a
//!   vertex counts it once.
//! * [`closest_on_segment`], `closest_point`, `segment_distance_2`: an
//!   end wins when the foot of the perpendicular is at or beyond it; a
//!   zero-length segment is its start.
//! * `nearer_2`: distances compared as their roots, so that squares whose
//!   roots are equal tie (the first found stays).
//! * `clip_by_sides` and [`clip_to_half_plane`]: closed half-planes (a
//!   point on the line is in).

use super::tolerance::ROOT_MARGIN;
use super::vector::{cross, dot, hypot};
use geo::Coord;

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
        hypot(self.b - self.a)
    }

    /// Closest point of the segment to `p`, and its parameter in [0, 1].
    pub fn closest(&self, p: Coord<f64>) -> (Coord<f64>, f64) {
        closest_on_segment(self.a, self.b, p)
    }
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

/// True when `p` lies on the closed segment `ab` (exactly collinear and
/// within its box).
pub fn on_segment(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> bool {
    orient(a, b, p) == 0.0
        && p.x >= a.x.min(b.x)
        && p.x <= a.x.max(b.x)
        && p.y >= a.y.min(b.y)
        && p.y <= a.y.max(b.y)
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

/// The crossing point of two segments that [`properly_cross`]: on `ab`, at
/// the ratio of the exact orientations of its ends to `pq`.
pub fn crossing_point(p: Coord<f64>, q: Coord<f64>, a: Coord<f64>, b: Coord<f64>) -> Coord<f64> {
    let oa = orient(p, q, a);
    let ob = orient(p, q, b);
    let t = oa / (oa - ob);
    a + (b - a) * t
}

/// Where the line `p + t r` meets the line `a + u (b − a)`: `(t, u)`, or
/// `None` when they are parallel (`r × (b − a)` is zero).
#[inline]
pub fn lines_meet(
    p: Coord<f64>,
    r: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
) -> Option<(f64, f64)> {
    let s = b - a;
    let den = cross(r, s);
    if den == 0.0 {
        return None;
    }
    let d = a - p;
    Some((cross(d, s) / den, cross(d, r) / den))
}

/// Where segment `pq` meets segment `ab`, as the parameter `t` of
/// `p + t (q − p)`, when they meet in one point (not parallel).
pub fn segment_parameter(
    p: Coord<f64>,
    q: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
) -> Option<f64> {
    let (t, u) = lines_meet(p, q - p, a, b)?;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some(t)
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
        return ray_along_segment(o, d, a, b);
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

/// [`ray_segment`] for a segment parallel to the ray: only a collinear
/// overlap counts, at its point nearest the origin.
fn ray_along_segment(
    o: Coord<f64>,
    d: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
) -> Option<(f64, f64)> {
    let (e, w) = (b - a, a - o);
    if cross(w, d) != 0.0 {
        return None;
    }
    let dd = dot(d, d);
    if dd == 0.0 {
        return None;
    }
    let ta = dot(w, d) / dd;
    let tb = dot(b - o, d) / dd;
    let (t, s) = if ta <= tb { (ta, 0.0) } else { (tb, 1.0) };
    let tmax = if ta <= tb { tb } else { ta };
    if tmax < 0.0 {
        return None;
    }
    if t >= 0.0 {
        return Some((t, s));
    }
    // Origin lies on the segment.
    let sl = dot(e, e);
    let s0 = if sl == 0.0 { 0.0 } else { dot(o - a, e) / sl };
    Some((0.0, s0.clamp(0.0, 1.0)))
}

/// True when the ray from `p` towards +x crosses `s` (half-open rule on
/// vertices): the crossing parity of a point-in-polygon test.
pub fn crosses_rightward(s: &BoundarySegment, p: Coord<f64>) -> bool {
    let (a, b) = (s.a, s.b);
    if (a.y > p.y) == (b.y > p.y) {
        return false;
    }
    let o = orient(a, b, p);
    let upward = b.y > a.y;
    (upward && o > 0.0) || (!upward && o < 0.0)
}

/// The points of `pts` (lying on segment `ab`) in order from `a` to `b`,
/// each once, without `a` and `b` themselves: what goes between the ends
/// when they are put into the segment.
pub fn inner_points_along(a: Coord<f64>, b: Coord<f64>, pts: &[Coord<f64>]) -> Vec<Coord<f64>> {
    let d = b - a;
    let t = |c: &Coord<f64>| dot(*c - a, d);
    let mut out: Vec<Coord<f64>> = pts.iter().copied().filter(|&c| c != a && c != b).collect();
    out.sort_by(|p, q| t(p).total_cmp(&t(q)));
    out.dedup();
    out
}

/// Closest point of segment `ab` to `p` and its parameter `t` in [0, 1].
pub fn closest_on_segment(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> (Coord<f64>, f64) {
    let d = b - a;
    let l2 = dot(d, d);
    if l2 == 0.0 {
        return (a, 0.0);
    }
    let t = (dot(p - a, d) / l2).clamp(0.0, 1.0);
    (a + d * t, t)
}

/// [`closest_on_segment`]'s point without its parameter, dividing only when
/// the foot is interior (see [`segment_distance_2`]: the same point, but
/// for the sign of a zero coordinate).
pub(crate) fn closest_point(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> Coord<f64> {
    let d = b - a;
    let along = dot(p - a, d);
    let l2 = dot(d, d);
    if along <= 0.0 || l2 == 0.0 {
        a
    } else if along < l2 {
        a + d * (along / l2)
    } else {
        a + d
    }
}

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
pub(crate) fn segment_distance_2(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> f64 {
    let dir = b - a;
    let along = dot(p - a, dir);
    let l2 = dot(dir, dir);
    let n = if along <= 0.0 {
        a
    } else if along < l2 {
        a + dir * (along / l2)
    } else {
        b
    };
    let d = n - p;
    dot(d, d)
}

/// True when the distance whose square is `d2` is smaller than the one
/// whose square is `best2`, compared as roots (as the tree search compares
/// them): a root is never smaller when its square is not, and is smaller
/// when its square is smaller by more than the roots' rounding (a relative
/// 2⁻⁵³ each), so only squares closer than that need their roots.
#[inline]
pub(crate) fn nearer_2(d2: f64, best2: f64) -> bool {
    d2 < best2 && (d2 < best2 * (1.0 - ROOT_MARGIN) || d2.sqrt() < best2.sqrt())
}

/// Segment `ab` cut down to where a linear function with values `fa` at `a`
/// and `fb` at `b` is ≥ 0, or `None` when it is negative at both ends.
pub(crate) fn clip_by_sides(
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

/// Segment `ab` clipped to the closed half-plane `(x − q) · n ≥ 0`, or
/// `None` when it lies wholly outside it.
pub fn clip_to_half_plane(
    a: Coord<f64>,
    b: Coord<f64>,
    q: Coord<f64>,
    n: Coord<f64>,
) -> Option<(Coord<f64>, Coord<f64>)> {
    clip_by_sides(a, b, dot(a - q, n), dot(b - q, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn crossings_and_their_tie_rules() {
        let (p, q) = (c(0., 0.), c(2., 2.));
        assert!(properly_cross(p, q, c(0., 2.), c(2., 0.)));
        assert_eq!(crossing_point(p, q, c(0., 2.), c(2., 0.)), c(1., 1.));
        // Touching at an end, or running along, is no crossing.
        assert!(!properly_cross(p, q, c(1., 1.), c(2., 0.)));
        assert!(!properly_cross(p, q, c(1., 1.), c(3., 3.)));
        assert!(on_segment(p, q, c(1., 1.)) && !on_segment(p, q, c(3., 3.)));
        assert_eq!(segment_parameter(p, q, c(0., 2.), c(2., 0.)), Some(0.5));
        assert_eq!(segment_parameter(p, q, c(2., 0.), c(4., 2.)), None);
        // An end is on the segment.
        assert_eq!(segment_parameter(p, q, c(2., 2.), c(3., 0.)), Some(1.0));
    }

    #[test]
    fn rays_meet_segments_and_collinear_overlaps() {
        let (o, d) = (c(0., 0.), c(1., 0.));
        assert_eq!(ray_segment(o, d, c(2., -1.), c(2., 1.)), Some((2.0, 0.5)));
        assert_eq!(ray_segment(o, d, c(-2., -1.), c(-2., 1.)), None);
        // Along the ray: its nearer end; through the origin: the origin.
        assert_eq!(ray_segment(o, d, c(5., 0.), c(3., 0.)), Some((3.0, 1.0)));
        assert_eq!(ray_segment(o, d, c(-1., 0.), c(1., 0.)), Some((0.0, 0.5)));
        let s = BoundarySegment {
            a: c(1., -1.),
            b: c(1., 1.),
            ring: 0,
            index: 0,
        };
        assert!(crosses_rightward(&s, o));
        // Half-open: through the upper end does not count, the lower does.
        assert!(!crosses_rightward(&s, c(0., 1.)));
        assert!(crosses_rightward(&s, c(0., -1.)));
    }

    #[test]
    fn nearest_points_and_distances() {
        let (a, b) = (c(0., 0.), c(4., 0.));
        assert_eq!(closest_on_segment(a, b, c(1., 3.)), (c(1., 0.), 0.25));
        assert_eq!(closest_point(a, b, c(-1., 3.)), a);
        assert_eq!(closest_point(a, b, c(9., 3.)), b);
        assert_eq!(segment_distance_2(a, b, c(6., 0.)), 4.0);
        assert_eq!(segment_distance_2(a, a, c(3., 4.)), 25.0);
        assert!(nearer_2(1.0, 2.0) && !nearer_2(2.0, 2.0));
        assert_eq!(
            clip_to_half_plane(a, b, c(1., 0.), c(1., 0.)),
            Some((c(1., 0.), b))
        );
        assert_eq!(clip_to_half_plane(a, b, c(5., 0.), c(1., 0.)), None);
    }
}
