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

use super::boundary::{nearer_2, ray_segment};
use geo::Coord;

/// Largest coordinate magnitude the columns take (see the module docs):
/// squares and products of differences stay far below `f64::MAX`.
pub const TAME: f64 = 1e100;

/// Segments per step (the columns are padded to a multiple of it).
const W: usize = 4;

/// A small boundary's segments in columns: start `a`, end `b` and
/// direction `d = b − a` (computed once, the same value as `b − a` every
/// time), padded with copies of the first segment to a multiple of [`W`]
/// (the scans stop at [`Columns::len`]).
#[derive(Debug, Clone)]
pub struct Columns {
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
pub fn tame(c: Coord<f64>) -> bool {
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
    pub fn new(segments: impl ExactSizeIterator<Item = (Coord<f64>, Coord<f64>)>) -> Option<Self> {
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

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True when there is no segment.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The segment nearest `p` (tame) among those within squared distance
    /// `limit2`, and its squared distance: `Boundary`'s scalar pass
    /// (`segment_distance_2` per segment, the least within the limit, ties
    /// to the lower index).
    pub fn nearest_2(&self, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: columns exist only where the processor has AVX2 (`new`).
        return unsafe { avx2::nearest_2(self, p, limit2) };
        #[cfg(not(target_arch = "x86_64"))]
        unreachable!("no columns without AVX2 ({p:?}, {limit2})")
    }

    /// The least ray parameter `t`, `min_t < t ≤ max_t`, at which
    /// `origin + t · dir` (both tame) meets a segment, and the segment:
    /// `Boundary`'s scalar pass (`ray_segment` per segment, ties to the
    /// lower index). A segment parallel to the ray is decided by
    /// `ray_segment` itself.
    pub fn first_param(
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
    /// `≤ 0` — and its squared distance: `Boundary`'s scalar two-sided pass
    /// (each segment cut by `clip_by_sides`, its nearest point by
    /// `closest_point`, compared by `nearer_2` in index order).
    pub fn both_sides(&self, q: Coord<f64>, normal: Coord<f64>) -> [Option<(Coord<f64>, f64)>; 2] {
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

    #[target_feature(enable = "avx2")]
    pub fn nearest_2(c: &Columns, p: Coord<f64>, limit2: f64) -> Option<(f64, u32)> {
        let (px, py) = (_mm256_set1_pd(p.x), _mm256_set1_pd(p.y));
        let (zero, limit) = (_mm256_setzero_pd(), _mm256_set1_pd(limit2));
        let (mut best_d2, mut best) = (f64::INFINITY, usize::MAX);
        let mut base = 0;
        while base < c.n {
            let (ax, ay) = (load(&c.ax, base), load(&c.ay, base));
            let (bx, by) = (load(&c.bx, base), load(&c.by, base));
            let (dx, dy) = (load(&c.dx, base), load(&c.dy, base));
            // segment_distance_2: the projection's foot, else an end.
            let dot = _mm256_add_pd(
                _mm256_mul_pd(_mm256_sub_pd(px, ax), dx),
                _mm256_mul_pd(_mm256_sub_pd(py, ay), dy),
            );
            let l2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
            let f = _mm256_div_pd(dot, l2);
            let start = _mm256_cmp_pd::<_CMP_LE_OQ>(dot, zero);
            let inner = _mm256_cmp_pd::<_CMP_LT_OQ>(dot, l2);
            let nx = pick(
                start,
                ax,
                pick(inner, _mm256_add_pd(ax, _mm256_mul_pd(dx, f)), bx),
            );
            let ny = pick(
                start,
                ay,
                pick(inner, _mm256_add_pd(ay, _mm256_mul_pd(dy, f)), by),
            );
            let (ex, ey) = (_mm256_sub_pd(nx, px), _mm256_sub_pd(ny, py));
            let d2 = _mm256_add_pd(_mm256_mul_pd(ex, ex), _mm256_mul_pd(ey, ey));
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
    pub fn first_param(
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
    pub fn both_sides(
        c: &Columns,
        q: Coord<f64>,
        nrm: Coord<f64>,
    ) -> [Option<(Coord<f64>, f64)>; 2] {
        let (qx, qy) = (_mm256_set1_pd(q.x), _mm256_set1_pd(q.y));
        let (nx, ny) = (_mm256_set1_pd(nrm.x), _mm256_set1_pd(nrm.y));
        let (zero, nan) = (_mm256_setzero_pd(), _mm256_set1_pd(f64::NAN));
        let sign = _mm256_set1_pd(-0.0);
        let mut best: [Option<(Coord<f64>, f64)>; 2] = [None, None];
        let mut base = 0;
        while base < c.n {
            let (ax, ay) = (load(&c.ax, base), load(&c.ay, base));
            let (bx, by) = (load(&c.bx, base), load(&c.by, base));
            let (dx, dy) = (load(&c.dx, base), load(&c.dy, base));
            // The side function at both ends; the opposite side's values are
            // their negations (a sign flip, as `-x` is).
            let fa0 = _mm256_add_pd(
                _mm256_mul_pd(_mm256_sub_pd(ax, qx), nx),
                _mm256_mul_pd(_mm256_sub_pd(ay, qy), ny),
            );
            let fb0 = _mm256_add_pd(
                _mm256_mul_pd(_mm256_sub_pd(bx, qx), nx),
                _mm256_mul_pd(_mm256_sub_pd(by, qy), ny),
            );
            for (k, best) in best.iter_mut().enumerate() {
                let (fa, fb) = if k == 0 {
                    (fa0, fb0)
                } else {
                    (_mm256_xor_pd(fa0, sign), _mm256_xor_pd(fb0, sign))
                };
                // clip_by_sides: the whole segment, nothing, or cut where the
                // side function is zero.
                let ia = _mm256_cmp_pd::<_CMP_GE_OQ>(fa, zero);
                let ib = _mm256_cmp_pd::<_CMP_GE_OQ>(fb, zero);
                // Four segments wholly on the other side (as neighbours
                // along a bank often are) have nothing here.
                let part = _mm256_or_pd(ia, ib);
                if bits(part) == 0 {
                    continue;
                }
                let r = _mm256_div_pd(fa, _mm256_sub_pd(fa, fb));
                let mx = _mm256_add_pd(ax, _mm256_mul_pd(dx, r));
                let my = _mm256_add_pd(ay, _mm256_mul_pd(dy, r));
                let (cax, cay) = (pick(ia, ax, mx), pick(ia, ay, my));
                let (cbx, cby) = (pick(ib, bx, mx), pick(ib, by, my));
                // closest_point of the part to q.
                let (ux, uy) = (_mm256_sub_pd(cbx, cax), _mm256_sub_pd(cby, cay));
                let dot = _mm256_add_pd(
                    _mm256_mul_pd(_mm256_sub_pd(qx, cax), ux),
                    _mm256_mul_pd(_mm256_sub_pd(qy, cay), uy),
                );
                let l2 = _mm256_add_pd(_mm256_mul_pd(ux, ux), _mm256_mul_pd(uy, uy));
                let f = _mm256_div_pd(dot, l2);
                let start = _mm256_or_pd(
                    _mm256_cmp_pd::<_CMP_LE_OQ>(dot, zero),
                    _mm256_cmp_pd::<_CMP_EQ_OQ>(l2, zero),
                );
                let inner = _mm256_cmp_pd::<_CMP_LT_OQ>(dot, l2);
                let x = pick(
                    start,
                    cax,
                    pick(
                        inner,
                        _mm256_add_pd(cax, _mm256_mul_pd(ux, f)),
                        _mm256_add_pd(cax, ux),
                    ),
                );
                let y = pick(
                    start,
                    cay,
                    pick(
                        inner,
                        _mm256_add_pd(cay, _mm256_mul_pd(uy, f)),
                        _mm256_add_pd(cay, uy),
                    ),
                );
                let (ex, ey) = (_mm256_sub_pd(x, qx), _mm256_sub_pd(y, qy));
                let d2 = _mm256_add_pd(_mm256_mul_pd(ex, ex), _mm256_mul_pd(ey, ey));
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
            base += W;
        }
        best
    }
}
