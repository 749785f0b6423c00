//! Bars, hits and sides (SPEC §6.1–6.3).

use super::{metrics, Bar, BarHit, Scores};
use crate::clock::CpuClock;
use crate::geometry::segment::orient;
use crate::geometry::tolerance::{BAR_ORIGIN, BOUND_MARGIN};
use crate::geometry::vector::{dot, hypot, norm};
use crate::geometry::{Boundary, BoundarySegment, PreparedPolygon};
use crate::graph::{Branch, SkeletonGraph};
use geo::{Coord, MultiLineString};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Bars per parallel task: a polygon with fewer is scored on one thread.
pub(crate) const PAR_BARS: usize = 4096;

/// Left unit normal of the direction `d` (inward for a ring edge, since the
/// interior lies on the left of every ring edge).
fn left_normal(d: Coord<f64>) -> Coord<f64> {
    let l = norm(d);
    Coord {
        x: -d.y / l,
        y: d.x / l,
    }
}

/// True when the interior angle at vertex `v` (between the edges to `prev`
/// and `next`, interior on the left of `prev → v → next`) exceeds 90°: only
/// then do both edges' inward normals at `v` point strictly into the
/// interior. The angle is measured counter-clockwise from `next − v` to
/// `prev − v`; it is at most 90° exactly when `prev` lies in the closed
/// quadrant left of and ahead of `next − v`.
fn vertex_bar_valid(prev: Coord<f64>, v: Coord<f64>, next: Coord<f64>) -> bool {
    let (a, b) = (next - v, prev - v);
    let left = orient(v, next, prev) >= 0.0;
    // A right angle computed with rounding (a rotated rectangle) must not
    // count as obtuse: its bar would run along the next edge.
    let ahead = dot(a, b) >= -RIGHT_ANGLE_TOLERANCE * hypot(a) * hypot(b);
    !(left && ahead)
}

/// Cosine below which (in absolute value) an interior angle counts as 90°.
const RIGHT_ANGLE_TOLERANCE: f64 = 1e-9;

/// The skeleton's segments in an R-tree, each tagged with its part.
///
/// [`Boundary`] is a general segment index (ray casts, nearest points); here
/// it indexes the skeleton: `ring` holds the part (branch) index.
struct SkeletonIndex {
    index: Boundary,
    /// Number of parts (branches).
    parts: usize,
}

/// The same point, bit for bit (−0 and +0 alike).
fn same_point(a: Coord<f64>, b: Coord<f64>) -> bool {
    a.x == b.x && a.y == b.y
}

impl SkeletonIndex {
    /// The segments of `branches` (a skeleton's, [`SkeletonGraph::branches`]).
    fn new(branches: &[Branch]) -> Self {
        let mut segments = Vec::new();
        for (k, branch) in branches.iter().enumerate() {
            for w in branch.coords.windows(2) {
                if w[0] != w[1] {
                    segments.push(BoundarySegment {
                        a: w[0],
                        b: w[1],
                        ring: k as u32,
                        index: segments.len() as u32,
                    });
                }
            }
        }
        Self {
            index: Boundary::from_segments(segments),
            parts: branches.len(),
        }
    }

    /// The segments with an end point at `v`, in index order (found in the
    /// tree when a bar hits a vertex, which few do).
    fn at_vertex(&self, v: Coord<f64>) -> Vec<u32> {
        let segs = self.index.segments();
        let mut incident: Vec<u32> = Vec::new();
        self.index.visit_segments_near(v, v, |i| {
            let s = &segs[i];
            if same_point(s.a, v) || same_point(s.b, v) {
                incident.push(i as u32);
            }
            std::ops::ControlFlow::<()>::Continue(())
        });
        incident.sort_unstable();
        incident
    }

    /// The first skeleton point on `origin + t·u`, `eps < t ≤ max_t`, and the
    /// segment σ the sides are measured against.
    fn hit(
        &self,
        origin: Coord<f64>,
        u: Coord<f64>,
        eps: f64,
        max_t: f64,
    ) -> Option<(Coord<f64>, &BoundarySegment)> {
        let h = self.index.first_hit(origin, u, eps, max_t)?;
        let segs = self.index.segments();
        let s = &segs[h.segment];
        // At a skeleton vertex, the incident segment most nearly
        // perpendicular to the bar (largest angle to u).
        let vertex = [s.a, s.b].into_iter().find(|&v| norm(v - h.point) <= eps);
        let sigma = match vertex {
            Some(v) => self
                .at_vertex(v)
                .iter()
                .map(|&i| &segs[i as usize])
                .min_by(|x, y| {
                    let cx = dot(x.b - x.a, u).abs() / norm(x.b - x.a);
                    let cy = dot(y.b - y.a, u).abs() / norm(y.b - y.a);
                    cx.total_cmp(&cy)
                })
                .unwrap_or(s),
            None => s,
        };
        Some((h.point, sigma))
    }
}

/// The valid bars of `polygon` cast against `skeleton`, with their hits and
/// sides (SPEC §6.1–6.3). Order: ring by ring, edge by edge, and per edge
/// start vertex, midpoint, end vertex (invalid vertex bars left out).
/// `BarHit::part` indexes `skeleton.branches()`.
pub fn bars(polygon: &PreparedPolygon, skeleton: &SkeletonGraph) -> Vec<Bar> {
    BarRays::new(polygon).cast(polygon, skeleton)
}

/// A polygon's bars before they meet a skeleton: origin, direction and
/// where each leaves P. They depend on the polygon alone, so every method's
/// candidate is scored along the same rays, computed once.
#[derive(Debug, Clone, Default)]
pub struct BarRays {
    rays: Vec<Ray>,
}

#[derive(Debug, Clone, Copy)]
struct Ray {
    origin: Coord<f64>,
    dir: Coord<f64>,
    /// Where the ray leaves P (ray parameter).
    exit: f64,
}

impl BarRays {
    /// The valid bars of `polygon` and their exits from P.
    pub fn new(polygon: &PreparedPolygon) -> Self {
        Self::timed(polygon).0
    }

    /// [`BarRays::new`], and, when the exits were found in parallel (a large
    /// polygon's, [`BarRays::parallel`]), the CPU time it took over all
    /// threads; `None` when all was done on the calling thread, whose own
    /// clock then counts it.
    pub fn timed(polygon: &PreparedPolygon) -> (Self, Option<std::time::Duration>) {
        Self::found(polygon, None)
    }

    /// [`BarRays::timed`] for a large polygon whose skeletons are being made
    /// at the same time on the same threads: the exits are found chunk by
    /// chunk on the calling thread, which first helps with any work the
    /// skeletons have queued on the pool, until `skeletons_done` is set;
    /// the rest then on every core. A huge polygon's medial axis queues
    /// its boundary's checks on the pool and then runs its Voronoi sweep
    /// on one core: the exits done at once would hold a core through the
    /// checks and leave it idle through the sweep.
    pub(crate) fn timed_beside(
        polygon: &PreparedPolygon,
        skeletons_done: &AtomicBool,
    ) -> (Self, Option<std::time::Duration>) {
        Self::found(polygon, Some(skeletons_done))
    }

    fn found(
        polygon: &PreparedPolygon,
        beside: Option<&AtomicBool>,
    ) -> (Self, Option<std::time::Duration>) {
        // At most three bars per vertex: no clock for a polygon that cannot
        // have enough of them to be split.
        let clock = (3 * polygon.vertex_count() > PAR_BARS).then(CpuClock::start);
        let boundary = polygon.boundary();
        let eps = BAR_ORIGIN * polygon.extent();
        // No ray stays inside P for longer than the bounding box's diagonal.
        let diagonal = norm(boundary.bbox_max() - boundary.bbox_min());
        let mut rays = Vec::with_capacity(3 * polygon.vertex_count());
        for ring in polygon.rings() {
            let v = &ring.0[..ring.0.len() - 1];
            let m = v.len();
            let valid: Vec<bool> = (0..m)
                .map(|i| vertex_bar_valid(v[(i + m - 1) % m], v[i], v[(i + 1) % m]))
                .collect();
            for i in 0..m {
                let (a, b) = (v[i], v[(i + 1) % m]);
                let u = left_normal(b - a);
                let origins = [
                    (a, valid[i]),
                    ((a + b) * 0.5, true),
                    (b, valid[(i + 1) % m]),
                ];
                for (origin, ok) in origins {
                    if ok {
                        rays.push(Ray {
                            origin,
                            dir: u,
                            exit: diagonal,
                        });
                    }
                }
            }
        }
        // Where each ray leaves P: in parallel for a large polygon (one
        // huge feature must not leave the other cores idle).
        let exits = |chunk: &mut [Ray]| {
            for r in chunk {
                if let Some(h) = boundary.first_hit(r.origin, r.dir, eps, f64::INFINITY) {
                    r.exit = h.t;
                }
            }
        };
        let clock = match clock {
            Some(c) if rays.len() > PAR_BARS => c,
            _ => {
                exits(&mut rays);
                return (Self { rays }, None);
            }
        };
        let mut time = clock.elapsed();
        let mut rest: &mut [Ray] = &mut rays;
        if let Some(done) = beside {
            while !rest.is_empty() && !done.load(Ordering::Relaxed) {
                while let Some(rayon::Yield::Executed) = rayon::yield_now() {}
                let (chunk, tail) = rest.split_at_mut(PAR_BARS.min(rest.len()));
                let clock = CpuClock::start();
                exits(chunk);
                time += clock.elapsed();
                rest = tail;
            }
        }
        time += rest
            .par_chunks_mut(PAR_BARS)
            .map(|chunk| {
                let clock = CpuClock::start();
                exits(chunk);
                clock.elapsed()
            })
            .sum::<std::time::Duration>();
        (Self { rays }, Some(time))
    }

    /// True when [`BarRays::cast`] casts the bars in parallel (else on the
    /// calling thread alone).
    pub fn parallel(&self) -> bool {
        self.rays.len() > PAR_BARS
    }

    /// Number of bars.
    pub fn len(&self) -> usize {
        self.rays.len()
    }

    /// True when the polygon has no valid bar.
    pub fn is_empty(&self) -> bool {
        self.rays.is_empty()
    }

    /// The bars cast against `skeleton` (of the polygon the rays were made
    /// for): hits and sides.
    pub fn cast(&self, polygon: &PreparedPolygon, skeleton: &SkeletonGraph) -> Vec<Bar> {
        self.cast_timed(polygon, skeleton).0
    }

    /// [`BarRays::cast`], and, when the bars were cast in parallel
    /// ([`BarRays::parallel`]), the CPU time it took over all threads; `None`
    /// when they were cast on the calling thread alone, whose own clock then
    /// counts them (a clock reading per small polygon saved). Also the
    /// number of the skeleton's branches (`skeleton.branches().len()`, which
    /// [`BarHit::part`] indexes).
    pub(crate) fn cast_timed(
        &self,
        polygon: &PreparedPolygon,
        skeleton: &SkeletonGraph,
    ) -> (Vec<Bar>, Option<std::time::Duration>, usize) {
        self.cast_on_branches(polygon, &skeleton.branches())
    }

    /// [`BarRays::cast_timed`] on a skeleton's branches
    /// ([`SkeletonGraph::branches`], which the caller may need as well).
    pub(crate) fn cast_on_branches(
        &self,
        polygon: &PreparedPolygon,
        branches: &[Branch],
    ) -> (Vec<Bar>, Option<std::time::Duration>, usize) {
        let eps = BAR_ORIGIN * polygon.extent();
        let cast_all = |sk: &SkeletonIndex, bars: &mut [Bar], rays: &[Ray]| {
            let mut recent = [NOWHERE; 2];
            for (bar, r) in bars.iter_mut().zip(rays) {
                bar.hit = cast(polygon.boundary(), sk, r, eps, &mut recent);
            }
        };
        let unhit = |r: &Ray| Bar {
            origin: r.origin,
            dir: r.dir,
            hit: None,
        };
        if !self.parallel() {
            let sk = SkeletonIndex::new(branches);
            let mut bars: Vec<Bar> = self.rays.iter().map(unhit).collect();
            cast_all(&sk, &mut bars, &self.rays);
            return (bars, None, sk.parts);
        }
        let clock = CpuClock::start();
        let sk = SkeletonIndex::new(branches);
        let time = clock.elapsed();
        // Written in place, chunk by chunk on the threads that cast them
        // (the bars of a huge polygon are tens of megabytes: no copy).
        let mut bars: Vec<Bar> = self.rays.par_iter().map(unhit).collect();
        let cast_time: std::time::Duration = bars
            .par_chunks_mut(PAR_BARS)
            .zip(self.rays.par_chunks(PAR_BARS))
            .map(|(bars, rays)| {
                let clock = CpuClock::start();
                cast_all(&sk, bars, rays);
                clock.elapsed()
            })
            .sum();
        (bars, Some(time + cast_time), sk.parts)
    }
}

/// No point (never in a half-plane): the sides found before the first bar.
const NOWHERE: Coord<f64> = Coord {
    x: f64::NAN,
    y: f64::NAN,
};

/// One bar's hit on the skeleton before it leaves P, and the sides there.
/// `recent` holds the side points of the bar cast before (bars come in
/// boundary order, so they are usually near): boundary points that bound
/// this bar's searches too.
fn cast(
    boundary: &Boundary,
    sk: &SkeletonIndex,
    ray: &Ray,
    eps: f64,
    recent: &mut [Coord<f64>; 2],
) -> Option<BarHit> {
    let (origin, u) = (ray.origin, ray.dir);
    let exit = origin + u * ray.exit;
    sk.hit(origin, u, eps, ray.exit).and_then(|(q, sigma)| {
        let nu = left_normal(sigma.b - sigma.a);
        // The bar's origin and exit, and the previous bar's side points, are
        // boundary points: each in a side's half-plane bounds the nearest
        // distance there (never changing the answer), which keeps the
        // searches short.
        let seeds = [origin, exit, recent[0], recent[1]];
        let side = |n: Coord<f64>| {
            let seed = seeds
                .into_iter()
                .filter(|&c| dot(c - q, n) >= 0.0)
                .map(|c| norm(c - q) * (1.0 + BOUND_MARGIN))
                .fold(f64::INFINITY, f64::min);
            boundary
                .nearest_in_half_plane_within(q, n, seed)
                .or_else(|| boundary.nearest_in_half_plane(q, n))
        };
        let [left, right] = if boundary.few_segments() {
            boundary.nearest_on_both_sides(q, nu)
        } else {
            [side(nu), side(-nu)]
        };
        let (p_left, d_left) = left?;
        let (p_right, d_right) = right?;
        *recent = [p_left, p_right];
        // A hit on ∂P itself (a leaf at a corner reached along the boundary)
        // has no sides to compare: it is a miss.
        if d_left + d_right <= eps {
            return None;
        }
        Some(BarHit {
            point: q,
            d_left,
            d_right,
            part: sigma.ring as usize,
        })
    })
}

/// Scores skeleton linework made by any tool against `polygon`: the lines
/// become a [`SkeletonGraph`] (end points shared bit for bit become nodes;
/// others stay apart, which is harmless for scoring), whose branches are
/// the parts of eqs. 3–4.
pub fn score_skeleton(
    polygon: &PreparedPolygon,
    skeleton: &MultiLineString<f64>,
) -> (Scores, Vec<Bar>) {
    let mut graph = SkeletonGraph::from_lines(skeleton);
    graph.set_radii(polygon.boundary());
    let b = bars(polygon, &graph);
    (metrics(&b), b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    #[test]
    fn vertex_validity_by_interior_angle() {
        let o = Coord { x: 0.0, y: 0.0 };
        let next = Coord { x: 1.0, y: 0.0 };
        let at = |deg: f64| {
            let r = deg.to_radians();
            Coord {
                x: r.cos(),
                y: r.sin(),
            }
        };
        assert!(!vertex_bar_valid(at(45.0), o, next));
        assert!(!vertex_bar_valid(at(90.0), o, next));
        assert!(vertex_bar_valid(at(91.0), o, next));
        assert!(vertex_bar_valid(at(180.0), o, next));
        assert!(vertex_bar_valid(at(270.0), o, next));
        assert!(vertex_bar_valid(at(359.0), o, next));
    }

    #[test]
    fn rays_found_beside_other_work_are_the_rays_found_at_once() {
        // A wavy ring of 4 000 vertices: about 12 000 rays, several chunks.
        let n = 4000;
        let ring: Vec<Coord<f64>> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let r = 1000.0 * (1.0 + 0.3 * (5.0 * t).sin()) + 7.0 * ((i * 7919) % 13) as f64;
                Coord {
                    x: r * t.cos(),
                    y: r * t.sin(),
                }
            })
            .collect();
        let p = PreparedPolygon::new(&geo::Polygon::new(geo::LineString(ring), vec![])).unwrap();
        let (at_once, _) = BarRays::timed(&p);
        assert!(at_once.len() > 2 * PAR_BARS);
        let exits = |r: &BarRays| r.rays.iter().map(|r| r.exit).collect::<Vec<f64>>();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for already_done in [false, true] {
            let done = AtomicBool::new(already_done);
            // Other work queued on the pool meanwhile, which the rays'
            // thread may take on first.
            let (beside, others) = pool.install(|| {
                rayon::join(
                    || BarRays::timed_beside(&p, &done).0,
                    || {
                        let sum: f64 = (0..200_000).into_par_iter().map(|i| i as f64).sum();
                        done.store(true, Ordering::Relaxed);
                        sum
                    },
                )
            });
            assert_eq!(others, 199_999.0 * 100_000.0);
            assert_eq!(exits(&beside), exits(&at_once));
        }
    }

    #[test]
    fn square_has_only_midpoint_bars() {
        let p = PreparedPolygon::new(&polygon![
            (x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 4.), (x: 0., y: 4.)
        ])
        .unwrap();
        let b = bars(&p, &SkeletonGraph::new());
        assert_eq!(b.len(), 4);
        assert!(b.iter().all(|b| b.hit.is_none()));
        assert_eq!(b[0].origin, Coord { x: 2.0, y: 0.0 });
        assert_eq!(b[0].dir, Coord { x: 0.0, y: 1.0 });
    }
}
