//! Spatial index of a polygon's boundary ∂P.
//!
//! One R-tree of boundary segments answers every boundary question the
//! methods and steps ask: distance to ∂P (node radii), point-in-polygon,
//! "does this segment cross ∂P", the first hit of a ray (leg extension, bars)
//! and the nearest boundary point (optionally restricted to a half-plane, for
//! the scoring step's sides). Queries cost O(log n) on real data instead of a
//! scan of all edges.

use geo::{Coord, Polygon};
use rstar::{
    primitives::{GeomWithData, Line as RLine},
    PointDistance, RTree, RTreeObject, SelectionFunction, AABB,
};

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

type Indexed = GeomWithData<RLine<[f64; 2]>, u32>;

/// R-tree of the boundary segments of one polygon (all rings).
#[derive(Debug, Clone)]
pub struct Boundary {
    segments: Vec<BoundarySegment>,
    tree: RTree<Indexed>,
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

/// Selects the R-tree leaves whose envelope a ray (origin, dir, t ≤ max_t) meets.
struct RaySelect {
    o: Coord<f64>,
    d: Coord<f64>,
    max_t: f64,
}

impl RaySelect {
    fn meets(&self, env: &AABB<[f64; 2]>) -> bool {
        let (lo, hi) = (env.lower(), env.upper());
        let mut t0 = 0.0f64;
        let mut t1 = self.max_t;
        for (o, d, l, h) in [
            (self.o.x, self.d.x, lo[0], hi[0]),
            (self.o.y, self.d.y, lo[1], hi[1]),
        ] {
            if d == 0.0 {
                if o < l || o > h {
                    return false;
                }
            } else {
                let (mut a, mut b) = ((l - o) / d, (h - o) / d);
                if a > b {
                    std::mem::swap(&mut a, &mut b);
                }
                t0 = t0.max(a);
                t1 = t1.min(b);
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }
}

impl SelectionFunction<Indexed> for RaySelect {
    fn should_unpack_parent(&self, envelope: &AABB<[f64; 2]>) -> bool {
        self.meets(envelope)
    }
    fn should_unpack_leaf(&self, leaf: &Indexed) -> bool {
        self.meets(&leaf.envelope())
    }
}

/// Intersection parameter of ray `o + t d` with segment `ab`: `(t, s)` where
/// `s` ∈ [0, 1] is the segment parameter. For a collinear overlap the nearest
/// overlapping point is returned.
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
    let t = cross(w, e) / den;
    let s = cross(w, d) / den;
    if t >= 0.0 && (0.0..=1.0).contains(&s) {
        Some((t, s))
    } else {
        None
    }
}

impl Boundary {
    /// Indexes every edge of every ring of `polygon` (rings must be closed).
    pub fn new(polygon: &Polygon<f64>) -> Self {
        let mut segments = Vec::new();
        for (ri, ring) in std::iter::once(polygon.exterior())
            .chain(polygon.interiors())
            .enumerate()
        {
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
        let items: Vec<Indexed> = segments
            .iter()
            .enumerate()
            .map(|(i, s)| GeomWithData::new(RLine::new(pt(s.a), pt(s.b)), i as u32))
            .collect();
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
        Self {
            segments,
            tree: RTree::bulk_load(items),
            min,
            max,
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

    /// Nearest boundary point to `p`: (point, segment index, distance).
    pub fn nearest(&self, p: Coord<f64>) -> Option<(Coord<f64>, usize, f64)> {
        if !finite(p) {
            return None;
        }
        let n = self.tree.nearest_neighbor(&pt(p))?;
        let s = &self.segments[n.data as usize];
        let (c, _) = s.closest(p);
        Some((c, n.data as usize, (c - p).x.hypot((c - p).y)))
    }

    /// Euclidean distance from `p` to ∂P (the radius of every skeleton node).
    pub fn distance(&self, p: Coord<f64>) -> f64 {
        if !finite(p) {
            return f64::NAN;
        }
        self.tree
            .nearest_neighbor(&pt(p))
            .map(|n| n.geom().distance_2(&pt(p)).sqrt())
            .unwrap_or(f64::INFINITY)
    }

    /// Nearest boundary point to `q` within the closed half-plane
    /// `(x − q) · normal ≥ 0`: `(point, distance)`.
    ///
    /// Visits segments in order of distance and stops as soon as the next
    /// segment is farther than the best point found.
    pub fn nearest_in_half_plane(
        &self,
        q: Coord<f64>,
        normal: Coord<f64>,
    ) -> Option<(Coord<f64>, f64)> {
        self.nearest_clipped(q, |a, b| clip_to_half_plane(a, b, q, normal))
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
        self.nearest_clipped(q, |a, b| {
            let (a, b) = clip_to_half_plane(a, b, q, n1)?;
            clip_to_half_plane(a, b, q, n2)
        })
    }

    /// Nearest point to `q` of the boundary segments as `clip` cuts them
    /// down (`None`: the whole segment is out). Visits segments in order of
    /// distance and stops as soon as the next is farther than the best point
    /// found.
    fn nearest_clipped(
        &self,
        q: Coord<f64>,
        clip: impl Fn(Coord<f64>, Coord<f64>) -> Option<(Coord<f64>, Coord<f64>)>,
    ) -> Option<(Coord<f64>, f64)> {
        if !finite(q) {
            return None;
        }
        let mut best: Option<(Coord<f64>, f64)> = None;
        for (item, d2) in self.tree.nearest_neighbor_iter_with_distance_2(&pt(q)) {
            if best.is_some_and(|(_, bd)| d2.sqrt() > bd) {
                break;
            }
            let s = &self.segments[item.data as usize];
            let Some((a, b)) = clip(s.a, s.b) else {
                continue;
            };
            let c = closest_on_segment(a, b, q).0;
            let d = (c - q).x.hypot((c - q).y);
            if best.is_none_or(|(_, bd)| d < bd) {
                best = Some((c, d));
            }
        }
        best
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
        let sel = RaySelect {
            o: origin,
            d: dir,
            max_t,
        };
        let mut best: Option<RayHit> = None;
        for item in self.tree.locate_with_selection_function(sel) {
            let s = &self.segments[item.data as usize];
            if let Some((t, _)) = ray_segment(origin, dir, s.a, s.b) {
                if t > min_t && t <= max_t && best.is_none_or(|b| t < b.t) {
                    best = Some(RayHit {
                        t,
                        point: origin + dir * t,
                        segment: item.data as usize,
                    });
                }
            }
        }
        best
    }

    /// True when the open segment `pq` properly crosses a boundary segment.
    pub fn crosses(&self, p: Coord<f64>, q: Coord<f64>) -> bool {
        let env = AABB::from_corners([p.x.min(q.x), p.y.min(q.y)], [p.x.max(q.x), p.y.max(q.y)]);
        self.tree.locate_in_envelope_intersecting(&env).any(|item| {
            let s = &self.segments[item.data as usize];
            properly_cross(p, q, s.a, s.b)
        })
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

    /// Indices of the segments whose bounding box meets that of segment `pq`.
    pub fn segments_near(&self, p: Coord<f64>, q: Coord<f64>) -> impl Iterator<Item = usize> + '_ {
        let env = AABB::from_corners([p.x.min(q.x), p.y.min(q.y)], [p.x.max(q.x), p.y.max(q.y)]);
        self.tree
            .locate_in_envelope_intersecting(&env)
            .map(|i| i.data as usize)
    }

    /// Crossing parity of the ray from `p` towards +x against the segments of
    /// the rings for which `ring` is true: `p` is inside the region those rings bound.
    pub fn contains_with_rings(&self, p: Coord<f64>, ring: impl Fn(u32) -> bool) -> bool {
        let sel = RaySelect {
            o: p,
            d: Coord { x: 1.0, y: 0.0 },
            max_t: (self.max.x - p.x).max(0.0) + 1.0,
        };
        let mut inside = false;
        for item in self.tree.locate_with_selection_function(sel) {
            let s = &self.segments[item.data as usize];
            if !ring(s.ring) {
                continue;
            }
            let (a, b) = (s.a, s.b);
            if (a.y > p.y) != (b.y > p.y) {
                let o = orient(a, b, p);
                let upward = b.y > a.y;
                if (upward && o > 0.0) || (!upward && o < 0.0) {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// True when `p` is inside P or within `tol` of ∂P.
    pub fn contains_with_tolerance(&self, p: Coord<f64>, tol: f64) -> bool {
        self.contains(p) || self.distance(p) <= tol
    }
}

/// Segment `ab` clipped to the half-plane `(x − q) · n ≥ 0`, or `None` when
/// it lies wholly outside it.
fn clip_to_half_plane(
    a: Coord<f64>,
    b: Coord<f64>,
    q: Coord<f64>,
    n: Coord<f64>,
) -> Option<(Coord<f64>, Coord<f64>)> {
    let fa = (a - q).x * n.x + (a - q).y * n.y;
    let fb = (b - q).x * n.x + (b - q).y * n.y;
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
