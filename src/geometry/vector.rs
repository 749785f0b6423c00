//! Vector arithmetic on [`geo::Coord`]: the one home of `dot`, `cross` and
//! the two lengths, used everywhere below the per-feature path.
//!
//! Each is the plain expression (no fused multiply-add: Rust never contracts
//! floating-point operations), so replacing a written-out `a.x * b.x + a.y *
//! b.y` by [`dot`] gives the same bits. The two lengths differ in their last
//! bits: [`norm`] is `√(x² + y²)` and [`hypot`] is `f64::hypot`; each caller
//! keeps the one it always had, so that outputs do not change.

use geo::Coord;

/// `a · b`.
#[inline]
pub fn dot(a: Coord<f64>, b: Coord<f64>) -> f64 {
    a.x * b.x + a.y * b.y
}

/// `a × b` (the z component): positive when `b` turns left of `a`.
#[inline]
pub fn cross(a: Coord<f64>, b: Coord<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Length of a vector: `√(x² + y²)`, without `hypot`'s care for overflow
/// (which costs several times as much and which projected coordinates never
/// need).
#[inline]
pub fn norm(d: Coord<f64>) -> f64 {
    (d.x * d.x + d.y * d.y).sqrt()
}

/// Length of a vector by `f64::hypot` (no overflow or underflow in the
/// squares; a different last bit from [`norm`] now and then).
#[inline]
pub fn hypot(d: Coord<f64>) -> f64 {
    d.x.hypot(d.y)
}

/// `hypot(d) <= tol`, the same answer bit for bit, with `hypot` only
/// when both components are within `tol`: `hypot` is never below the larger
/// component (a faithfully rounded `√(x² + y²) ≥ max(|x|, |y|)` cannot
/// round below that floating-point number), so a larger component decides
/// alone — as it does for nearly every pair of points compared with a
/// tolerance.
#[inline]
pub fn within_hypot(d: Coord<f64>, tol: f64) -> bool {
    d.x.abs() <= tol && d.y.abs() <= tol && d.x.hypot(d.y) <= tol
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_and_lengths() {
        let (a, b) = (Coord { x: 3.0, y: 4.0 }, Coord { x: -2.0, y: 1.0 });
        assert_eq!(dot(a, b), -2.0);
        assert_eq!(cross(a, b), 11.0);
        assert_eq!(norm(a), 5.0);
        assert_eq!(hypot(a), 5.0);
        assert!(within_hypot(a, 5.0) && !within_hypot(a, 4.999));
        // hypot survives squares that overflow.
        let huge = Coord { x: 1e200, y: 1e200 };
        assert!(norm(huge).is_infinite() && hypot(huge).is_finite());
    }
}
