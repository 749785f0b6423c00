//! The passes over every segment of a small boundary, four segments at a
//! time.
//!
//! A small boundary ([`super::Boundary::few_segments`]) answers its distance,
//! ray and two-sided queries by a pass over all its segments. Done segment
//! by segment, each pass is a chain of unpredictable branches (which end of
//! a segment is nearest, which side of a line it lies on). Here, on x86-64
//! processors with AVX2 (checked once, at run time), each pass takes the
//! segments four at a time, in two steps:
//!
//! 1. without branches, the floating-point values the scalar pass computes
//!    for each of the four, one lane each: every branch's value, then the
//!    one the scalar pass would take (a select), from a copy of the
//!    segments in columns;
//! 2. a scan of the four in index order that keeps the answer with the
//!    scalar pass's comparisons and tie rules.
//!
//! The answers are the scalar passes' bit for bit: each lane's value is the
//! same expression on the same operands (IEEE arithmetic, no fused
//! operations), and a lane whose branch would not be taken is thrown away.
//! Values computed for thrown-away lanes may be NaN or infinite; no trap is
//! possible. The columns are made only for boundaries whose coordinates are
//! all within ±[`TAME`], and used only for query points within it, so that
//! no product overflows and a NaN can only mean "no candidate" (see each
//! pass); other boundaries and points, and other processors, take the
//! scalar passes.

use super::segment::{nearer_2, ray_segment};
use geo::Coord;

/// Largest coordinate magnitude the columns take (see the module docs):
/// squares and products of differences stay far below `f64::MAX`.
pub(crate) const TAME: f64 = 1e100;

/// Segments per step (the columns are padded to a multiple of it).
const W: usize = 4;

/// A small boundary's segments in columns: start `a`, end `b` and
/// direction `d = b − a` (computed once, the same value as `b − a` every
/// time), padded with copies of the first segment to a multiple of [`W`]
/// (the scans stop at the number of segments).
#[derive(Debug, Clone)]
pub(crate) struct Columns {
    n: usize,
    ax: Vec<f64>,
    ay: Vec<f64>,
    bx: Vec<f64>,
    by: Vec<f64>,
    dx: Vec<f64>,
    dy: Vec<f64>,
}

/// True when `c` is within ±[`TAME`] in both coordinates (false for NaN).
#[inline]
pub(crate) fn tame(c: Coord<f64>) -> bool {
    c.x.abs() <= TAME && c.y.abs() <= TAME
}

/// True when this processor runs the lane passes (x86-64 with AVX2).
#[inline]
pub(crate) fn available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

impl Columns {
    /// The columns of `segments` (start, end), or `None` when a coordinate
    /// is not [`tame`] or the processor cannot run the passes.
    pub(crate) fn new(
        segments: impl ExactSizeIterator<Item = (Coord<f64>, Coord<f64>)>,
    ) -> Option<Self> {
        if !available() {
            return None;
        }
        let n = segments.len();
        let cap = n.div_ceil(W) * W;
        let mut c = Columns {
            n,
            ax: Vec::with_capacity(cap),
            ay: Vec::with_capacity(cap),
            bx: Vec::with_capacity(cap),
            by: Vec::with_capacity(cap),
            dx: Vec::with_capacity(cap),
            dy: Vec::with_capacity(cap),
        };
        for (a, b) in segments {
            if !(tame(a) && tame(b)) {
                return None;
            }
            let d = b - a;
            c.ax.push(a.x);
            c.ay.push(a.y);
            c.bx.push(b.x);
            c.by.push(b.y);
            c.dx.push(d.x);
            c.dy.push(d.y);
        }
        for col in [
            &mut c.ax, &mut c.ay, &mut c.bx, &mut c.by, &mut c.dx, &mut c.dy,
        ] {
            let first = col.first().copied().unwrap_or(0.0);
            col.resize(cap, first);
        }
        Some(c)
    }

    /// The segment nearest `p` (tame) among those within squared distance
    /// `limit2`, and its squared distance: the scalar pass
    /// (the boundary's `Scan`: `segment_distance_2` per segment,
    /// the least within the limit, ties to the lower index).
    pub(crate) fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: columns exist only where the processor has AVX2 (`new`).
        return unsafe { avx2::nearest_2(self, p, limit2) };
        #[cfg(not(target_arch = "x86_64"))]
        unreachable!("no columns without AVX2 ({p:?}, {limit2})")
    }

    /// The least ray parameter `t`, `min_t < t ≤ max_t`, at which
    /// `origin + t · dir` (both tame) meets a segment, and the segment:
    /// the scalar pass (the boundary's `Scan`: `ray_segment`
    /// per segment, ties to the lower index). A segment parallel to the ray is decided by
    /// `ray_segment` itself.
    pub(crate) fn first_param(
        &self,
        origin: Coord<f64>,
        dir: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<(f64, usize)> {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: columns exist only where the processor has AVX2 (`new`).
        return unsafe { avx2::first_param(self, origin, dir, min_t, max_t) };
        #[cfg(not(target_arch = "x86_64"))]
        unreachable!("no columns without AVX2 ({origin:?}, {dir:?}, {min_t}, {max_t})")
    }

    /// The point nearest `q` (tame) in each closed half-plane of the line
    /// through `q` across `normal` (tame) — `(x − q) · normal ≥ 0`, then
    /// `≤ 0` — and its squared distance: the scalar two-sided pass
    /// (the boundary's `Scan`: each segment cut by
    /// `clip_by_sides`, its nearest point by `closest_point`, compared by
    /// `nearer_2` in index order).
    pub(crate) fn both_sides(
        &self,
        q: Coord<f64>,
        normal: Coord<f64>,
    ) -> [Option<(Coord<f64>, f64)>; 2] {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: columns exist only where the processor has AVX2 (`new`).
        return unsafe { avx2::both_sides(self, q, normal) };
        #[cfg(not(target_arch = "x86_64"))]
        unreachable!("no columns without AVX2 ({q:?}, {normal:?})")
    }
}

/// The passes in AVX2 instructions, four segments per instruction: each
/// lane's operations are the scalar code's, in the same order, on the same
/// operands (no fused multiply-add), so each lane's values are the scalar
/// code's bit for bit; a select takes the value of the branch the scalar
/// code would take.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{nearer_2, ray_segment, Columns, W};
    use geo::Coord;
    use std::arch::x86_64::*;

    /// Four lanes of column `v` from `base`.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn load(v: &[f64], base: usize) -> __m256d {
        let four: &[f64; W] = v[base..base + W].try_into().expect("padded to whole steps");
        // SAFETY: `four` is four readable f64s; the load is unaligned.
        unsafe { _mm256_loadu_pd(four.as_ptr()) }
    }

    /// The four lanes of `v` as an array.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn store(v: __m256d) -> [f64; W] {
        let mut out = [0.0; W];
        // SAFETY: `out` is four writable f64s; the store is unaligned.
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
        out
    }

    /// The lanes set in mask `m`, as bits. Pad lanes (copies of the first
    /// segment) may be set: they never win, since every scan keeps the
    /// first of equal values.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn bits(m: __m256d) -> u32 {
        _mm256_movemask_pd(m) as u32
    }

    /// Takes the lowest set bit of `bits` off and returns its lane.
    #[inline]
    fn next_lane(bits: &mut u32) -> usize {
        let l = bits.trailing_zeros() as usize;
        *bits &= *bits - 1;
        l
    }

    /// `if c { x } else { y }` per lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn pick(c: __m256d, x: __m256d, y: __m256d) -> __m256d {
        _mm256_blendv_pd(y, x, c)
    }

    /// Four lanes of one coordinate pair.
    type Pair = (__m256d, __m256d);

    /// `a · b` per lane (x products first, as the scalar code adds them).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn dot(a: Pair, b: Pair) -> __m256d {
        _mm256_add_pd(_mm256_mul_pd(a.0, b.0), _mm256_mul_pd(a.1, b.1))
    }

    /// `a − b` per lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn sub(a: Pair, b: Pair) -> Pair {
        (_mm256_sub_pd(a.0, b.0), _mm256_sub_pd(a.1, b.1))
    }

    /// One step's four segments: start `a`, end `b` and direction `d`.
    #[derive(Clone, Copy)]
    struct Step {
        a: Pair,
        b: Pair,
        d: Pair,
    }

    /// The four segments of `c` from `base` as a [`Step`]: a macro, not a
    /// function, so that the six loads stay in the caller's registers (a
    /// `target_feature` function returning them is not inlined and passes
    /// them through memory: 11 % of a small polygon's CDT pipeline).
    macro_rules! step {
        ($c:expr, $base:expr) => {
            Step {
                a: (load(&$c.ax, $base), load(&$c.ay, $base)),
                b: (load(&$c.bx, $base), load(&$c.by, $base)),
                d: (load(&$c.dx, $base), load(&$c.dy, $base)),
            }
        };
    }

    /// The projection of `q` on the lines from `a` along `u` per lane:
    /// `(dot, l2, foot)` with `dot = (q − a) · u`, `l2 = u · u` and the
    /// foot `a + u · (dot / l2)`, as `segment_distance_2` and
    /// `closest_point` compute them (used only where they divide).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn project(a: Pair, u: Pair, q: Pair) -> (__m256d, __m256d, Pair) {
        let along = dot(sub(q, a), u);
        let l2 = dot(u, u);
        let f = _mm256_div_pd(along, l2);
        let foot = (
            _mm256_add_pd(a.0, _mm256_mul_pd(u.0, f)),
            _mm256_add_pd(a.1, _mm256_mul_pd(u.1, f)),
        );
        (along, l2, foot)
    }

    /// Squared distance from `q` to `p` per lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn distance_2(p: Pair, q: Pair) -> __m256d {
        let e = sub(p, q);
        dot(e, e)
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn nearest_2(c: &Columns, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        let q = (_mm256_set1_pd(p.x), _mm256_set1_pd(p.y));
        let (zero, limit) = (_mm256_setzero_pd(), _mm256_set1_pd(limit2));
        let (mut best_d2, mut best) = (f64::INFINITY, usize::MAX);
        let mut base = 0;
        while base < c.n {
            let s = step!(c, base);
            // segment_distance_2: the projection's foot, else an end.
            let (along, l2, foot) = project(s.a, s.d, q);
            let start = _mm256_cmp_pd::<_CMP_LE_OQ>(along, zero);
            let inner = _mm256_cmp_pd::<_CMP_LT_OQ>(along, l2);
            let n = (
                pick(start, s.a.0, pick(inner, foot.0, s.b.0)),
                pick(start, s.a.1, pick(inner, foot.1, s.b.1)),
            );
            let d2 = distance_2(n, q);
            // Only lanes within the limit and below the best so far can win
            // (the best only falls within a step): in index order, each
            // that is still below the best becomes it. The squares of tame
            // coordinates are finite, so an infinite best stands for none.
            let maybe = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(d2, limit),
                _mm256_cmp_pd::<_CMP_LT_OQ>(d2, _mm256_set1_pd(best_d2)),
            );
            let d2s = store(d2);
            let mut set = bits(maybe);
            while set != 0 {
                let l = next_lane(&mut set);
                if d2s[l] < best_d2 {
                    (best_d2, best) = (d2s[l], base + l);
                }
            }
            base += W;
        }
        (best < c.n).then_some((best_d2, best as u32))
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn first_param(
        c: &Columns,
        o: Coord<f64>,
        d: Coord<f64>,
        min_t: f64,
        max_t: f64,
    ) -> Option<(f64, usize)> {
        let (ox, oy) = (_mm256_set1_pd(o.x), _mm256_set1_pd(o.y));
        let (ddx, ddy) = (_mm256_set1_pd(d.x), _mm256_set1_pd(d.y));
        let (zero, nan) = (_mm256_setzero_pd(), _mm256_set1_pd(f64::NAN));
        let mut best: Option<(f64, usize)> = None;
        let mut base = 0;
        while base < c.n {
            // ray_segment for a segment not parallel to the ray: e = b − a,
            // w = a − o; NaN where it misses or t < 0.
            let (ex, ey) = (load(&c.dx, base), load(&c.dy, base));
            let den = _mm256_sub_pd(_mm256_mul_pd(ddx, ey), _mm256_mul_pd(ddy, ex));
            let wx = _mm256_sub_pd(load(&c.ax, base), ox);
            let wy = _mm256_sub_pd(load(&c.ay, base), oy);
            let num = _mm256_sub_pd(_mm256_mul_pd(wx, ddy), _mm256_mul_pd(wy, ddx));
            let up = _mm256_cmp_pd::<_CMP_GT_OQ>(den, zero);
            let in_up = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(zero, num),
                _mm256_cmp_pd::<_CMP_LE_OQ>(num, den),
            );
            let in_down = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(den, num),
                _mm256_cmp_pd::<_CMP_LE_OQ>(num, zero),
            );
            let inside = _mm256_or_pd(_mm256_and_pd(up, in_up), _mm256_andnot_pd(up, in_down));
            let t = _mm256_div_pd(
                _mm256_sub_pd(_mm256_mul_pd(wx, ey), _mm256_mul_pd(wy, ex)),
                den,
            );
            let hit = _mm256_and_pd(inside, _mm256_cmp_pd::<_CMP_GE_OQ>(t, zero));
            // Lanes that may be the answer: hits within the bounds, and
            // segments parallel to the ray (decided by `ray_segment`).
            let within = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GT_OQ>(t, _mm256_set1_pd(min_t)),
                _mm256_cmp_pd::<_CMP_LE_OQ>(t, _mm256_set1_pd(max_t)),
            );
            let maybe = _mm256_or_pd(
                _mm256_and_pd(hit, within),
                _mm256_cmp_pd::<_CMP_EQ_OQ>(den, zero),
            );
            let ts = store(pick(hit, t, nan));
            let dens = store(den);
            let mut set = bits(maybe);
            while set != 0 {
                let l = next_lane(&mut set);
                let t = if dens[l] == 0.0 {
                    let i = base + l;
                    let a = Coord {
                        x: c.ax[i],
                        y: c.ay[i],
                    };
                    let b = Coord {
                        x: c.bx[i],
                        y: c.by[i],
                    };
                    ray_segment(o, d, a, b).map(|(t, _)| t)
                } else {
                    Some(ts[l]).filter(|t| !t.is_nan())
                };
                if let Some(t) = t.filter(|&t| t > min_t && t <= max_t) {
                    if best.is_none_or(|(bt, _)| t < bt) {
                        best = Some((t, base + l));
                    }
                }
            }
            base += W;
        }
        best
    }

    #[target_feature(enable = "avx2")]
    pub(super) fn both_sides(
        c: &Columns,
        q: Coord<f64>,
        nrm: Coord<f64>,
    ) -> [Option<(Coord<f64>, f64)>; 2] {
        let q = (_mm256_set1_pd(q.x), _mm256_set1_pd(q.y));
        let n = (_mm256_set1_pd(nrm.x), _mm256_set1_pd(nrm.y));
        let sign = _mm256_set1_pd(-0.0);
        let mut best: [Option<(Coord<f64>, f64)>; 2] = [None, None];
        let mut base = 0;
        while base < c.n {
            let s = step!(c, base);
            // The side function at both ends; the opposite side's values are
            // their negations (a sign flip, as `-x` is).
            let fa0 = dot(sub(s.a, q), n);
            let fb0 = dot(sub(s.b, q), n);
            for (k, best) in best.iter_mut().enumerate() {
                let (fa, fb) = if k == 0 {
                    (fa0, fb0)
                } else {
                    (_mm256_xor_pd(fa0, sign), _mm256_xor_pd(fb0, sign))
                };
                nearest_on_side(&s, q, (fa, fb), best);
            }
            base += W;
        }
        best
    }

    /// One side of [`both_sides`] for one step's four segments, whose side
    /// function is `fa` at their starts and `fb` at their ends: each
    /// segment's part where it is ≥ 0, that part's point nearest `q`, and
    /// `best` replaced by the first (in index order) that is nearer.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn nearest_on_side(s: &Step, q: Pair, (fa, fb): Pair, best: &mut Option<(Coord<f64>, f64)>) {
        let (zero, nan) = (_mm256_setzero_pd(), _mm256_set1_pd(f64::NAN));
        // clip_by_sides: the whole segment, nothing, or cut where the
        // side function is zero.
        let ia = _mm256_cmp_pd::<_CMP_GE_OQ>(fa, zero);
        let ib = _mm256_cmp_pd::<_CMP_GE_OQ>(fb, zero);
        // Four segments wholly on the other side (as neighbours
        // along a bank often are) have nothing here.
        let part = _mm256_or_pd(ia, ib);
        if bits(part) == 0 {
            return;
        }
        let r = _mm256_div_pd(fa, _mm256_sub_pd(fa, fb));
        let m = (
            _mm256_add_pd(s.a.0, _mm256_mul_pd(s.d.0, r)),
            _mm256_add_pd(s.a.1, _mm256_mul_pd(s.d.1, r)),
        );
        let ca = (pick(ia, s.a.0, m.0), pick(ia, s.a.1, m.1));
        let cb = (pick(ib, s.b.0, m.0), pick(ib, s.b.1, m.1));
        // closest_point of the part to q.
        let u = sub(cb, ca);
        let (along, l2, foot) = project(ca, u, q);
        let start = _mm256_or_pd(
            _mm256_cmp_pd::<_CMP_LE_OQ>(along, zero),
            _mm256_cmp_pd::<_CMP_EQ_OQ>(l2, zero),
        );
        let inner = _mm256_cmp_pd::<_CMP_LT_OQ>(along, l2);
        let x = pick(start, ca.0, pick(inner, foot.0, _mm256_add_pd(ca.0, u.0)));
        let y = pick(start, ca.1, pick(inner, foot.1, _mm256_add_pd(ca.1, u.1)));
        let d2 = distance_2((x, y), q);
        // Lanes with a part on this side that may be nearer than the
        // best so far (`nearer_2` needs a smaller square).
        let maybe = match best {
            Some((_, bd2)) => {
                _mm256_and_pd(part, _mm256_cmp_pd::<_CMP_LT_OQ>(d2, _mm256_set1_pd(*bd2)))
            }
            None => part,
        };
        let d2 = store(pick(part, d2, nan));
        let (xs, ys) = (store(x), store(y));
        let mut set = bits(maybe);
        while set != 0 {
            let l = next_lane(&mut set);
            let d2 = d2[l];
            if !d2.is_nan() && best.is_none_or(|(_, bd2)| nearer_2(d2, bd2)) {
                *best = Some((Coord { x: xs[l], y: ys[l] }, d2));
            }
        }
    }
}
