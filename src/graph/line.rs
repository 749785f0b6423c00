//! Measures of a skeleton's lines near their ends, shared by the steps that
//! shape the ends and by the defect counts: arc-length positions, the local
//! width at an end, and how much an end turns.

use super::{NodeId, SkeletonGraph};
use crate::geometry::tolerance::BOUND_MARGIN;
use crate::geometry::vector::{dot, hypot, norm};
use crate::geometry::PreparedPolygon;
use geo::Coord;

/// A line end that turns by more than this (degrees) within its last local
/// width is a hook.
pub const HOOK_DEG: f64 = 60.0;

/// The point at arc length `s` along `line` (its end when `s` ≥ its length).
pub fn point_at(line: &[Coord<f64>], s: f64) -> Coord<f64> {
    walk_to(line, line.windows(2).map(|w| norm(w[1] - w[0])), s)
}

/// [`point_at`] with the segments' lengths given in order (measured as
/// [`point_at`] measures them).
fn walk_to(line: &[Coord<f64>], lengths: impl Iterator<Item = f64>, s: f64) -> Coord<f64> {
    let mut left = s;
    for (w, l) in line.windows(2).zip(lengths) {
        if l >= left && l > 0.0 {
            return w[0] + (w[1] - w[0]) * (left / l);
        }
        left -= l;
    }
    *line.last().expect("a polyline has at least one point")
}

/// A polyline with the lengths of its segments, for many [`point_at`]
/// queries on one line: the same points, bit for bit, without measuring
/// every segment walked again.
struct Measured<'a> {
    line: &'a [Coord<f64>],
    lengths: Vec<f64>,
    /// [`super::polyline_length`] of the line (the same sum).
    total: f64,
}

impl<'a> Measured<'a> {
    fn new(line: &'a [Coord<f64>]) -> Self {
        let lengths: Vec<f64> = line.windows(2).map(|w| norm(w[1] - w[0])).collect();
        let total = lengths.iter().sum();
        Self {
            line,
            lengths,
            total,
        }
    }

    /// [`point_at`].
    fn point_at(&self, s: f64) -> Coord<f64> {
        walk_to(self.line, self.lengths.iter().copied(), s)
    }
}

/// The angle between two directions, in degrees (`None` for a zero vector).
pub fn angle_deg(a: Coord<f64>, b: Coord<f64>) -> Option<f64> {
    let (la, lb) = (hypot(a), hypot(b));
    if la == 0.0 || lb == 0.0 {
        return None;
    }
    let c = (dot(a, b) / (la * lb)).clamp(-1.0, 1.0);
    Some(c.acos().to_degrees())
}

/// The local radius of a line at its end: walking back from the end
/// (`coords[0]`), the distance to ∂P at the first point whose arc length
/// from the end reaches twice that distance (one local width back), or at
/// the far end of `coords` when none does.
pub fn end_radius(coords: &[Coord<f64>], polygon: &PreparedPolygon) -> f64 {
    end_width_point(coords, polygon).1
}

/// Arc length from the end and distance to ∂P of the point one local width
/// back along `coords` (see [`end_radius`]).
pub fn end_width_point(coords: &[Coord<f64>], polygon: &PreparedPolygon) -> (f64, f64) {
    measured_end_width_point(&Measured::new(coords), polygon)
}

/// [`end_width_point`] on a measured line.
fn measured_end_width_point(line: &Measured, polygon: &PreparedPolygon) -> (f64, f64) {
    let b = polygon.boundary();
    let total = line.total;
    // Arc length s grows with slope 1 and the radius at most with slope 1,
    // so s − 2 r(s) changes sign once on a medial line; sample it finely
    // enough and find the first sign change (regula falsi).
    // f rises with slope at most 3 (s with slope 1, −2r with slope at most
    // 2), so from f(s) < 0 it stays negative up to s + |f(s)|/3: samples
    // there are skipped unevaluated (the same sample is the first at or
    // above zero, the same answer).
    let steps = 64;
    // The radius is 1-Lipschitz: the last point measured bounds the next
    // one's distance, which keeps each search short (never changing it).
    let last: std::cell::Cell<Option<(Coord<f64>, f64)>> = std::cell::Cell::new(None);
    let radius = |s: f64| {
        let p = line.point_at(s);
        let r = match last.get() {
            Some((q, rq)) => b.distance_within(p, rq + norm(p - q)),
            None => b.distance(p),
        };
        last.set(Some((p, r)));
        r
    };
    let f = |s: f64| s - 2.0 * radius(s);
    let mut lo = 0.0;
    let mut negative_below = 0.0;
    for i in 1..=steps {
        let s = total * i as f64 / steps as f64;
        if s < negative_below {
            lo = s;
            continue;
        }
        let v = f(s);
        negative_below = s - v / 3.0 * (1.0 - BOUND_MARGIN);
        if v >= 0.0 {
            let hi = first_crossing(&f, (lo, f(lo)), (s, v), total * 2f64.powi(-36));
            return (hi, radius(hi));
        }
        lo = s;
    }
    (total, radius(total))
}

/// A point `hi` with `f(hi) ≥ 0` within `tol` of a sign change of `f` in the
/// bracket `lo` (`f < 0`) .. `hi` (`f ≥ 0`): regula falsi with the Illinois
/// rule (the end kept twice has its value halved) and a midpoint after any
/// step that did not halve the bracket — a handful of evaluations where
/// bisection needs thirty, and never much more than bisection.
fn first_crossing(
    f: &impl Fn(f64) -> f64,
    (mut lo, mut f_lo): (f64, f64),
    (mut hi, mut f_hi): (f64, f64),
    tol: f64,
) -> f64 {
    let mut kept = 0_i8;
    let mut width = hi - lo;
    let mut bisect = false;
    for _ in 0..200 {
        if hi - lo <= tol {
            break;
        }
        let mut x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        if bisect || !(x >= lo && x <= hi) {
            x = 0.5 * (lo + hi);
        }
        // At least half the tolerance inside the bracket: a false position
        // on a root that is an end of the bracket then closes it next step.
        x = x.clamp(lo + 0.5 * tol, hi - 0.5 * tol);
        let fx = f(x);
        if fx >= 0.0 {
            (hi, f_hi) = (x, fx);
            if kept == 1 {
                f_lo *= 0.5;
            }
            kept = 1;
        } else {
            (lo, f_lo) = (x, fx);
            if kept == -1 {
                f_hi *= 0.5;
            }
            kept = -1;
        }
        // A step that did not halve the bracket (a kink, a flat stretch) is
        // followed by a midpoint: never much slower than bisection.
        bisect = hi - lo > 0.5 * width;
        width = hi - lo;
    }
    hi
}

/// The turn (degrees) of every line end of `g`, a skeleton of `polygon`, in
/// node order (see [`crate::score::defects`]: the larger of the turn within
/// the last local width and the last segment's turn against the stretch of
/// half its length before it).
pub fn end_turns(g: &SkeletonGraph, polygon: &PreparedPolygon) -> Vec<f64> {
    let adj = g.adjacency();
    let mut out = Vec::new();
    for n in 0..g.nodes().len() {
        if adj[n].len() != 1 {
            continue;
        }
        let coords = g.line_from(NodeId::from_index(n), &adj);
        if let Some(t) = end_turn(&coords, polygon) {
            out.push(t);
        }
    }
    out
}

/// The turn of the line `coords` at its first point (see the module docs).
pub fn end_turn(coords: &[Coord<f64>], polygon: &PreparedPolygon) -> Option<f64> {
    let line = Measured::new(coords);
    let total = line.total;
    if total <= 0.0 {
        return None;
    }
    let (w, _) = measured_end_width_point(&line, polygon);
    let e = coords[0];
    let last = coords.iter().copied().find(|&c| c != e)?;
    let before = line.point_at(w.min(total));
    let start = line.point_at((1.5 * w).min(total));
    let by_width = if before == start {
        0.0
    } else {
        angle_deg(before - start, e - last)?
    };
    // The last segment against the stretch of half its length before it: a
    // short sideways stub at the very end, which the width's stretch may
    // pass over.
    let l = norm(e - last);
    let (s0, s1) = (
        line.point_at(l.min(total)),
        line.point_at((1.5 * l).min(total)),
    );
    let by_segment = if s0 == s1 {
        0.0
    } else {
        angle_deg(s0 - s1, e - last).unwrap_or(0.0)
    };
    Some(by_width.max(by_segment))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crossing found by regula falsi is the bisection's within the
    /// tolerance, on smooth, kinked and flat-then-rising functions like
    /// `s − 2 r(s)`, in a few evaluations.
    #[test]
    fn first_crossing_agrees_with_bisection() {
        type Case = (Box<dyn Fn(f64) -> f64>, f64, f64);
        let cases: Vec<Case> = vec![
            (
                Box::new(|s: f64| s - 2.0 * (0.3 + 0.1 * s).min(1.0)),
                0.0,
                4.0,
            ),
            (
                Box::new(|s: f64| s - 2.0 * (1.0 - (s - 1.0).abs()).max(0.2)),
                0.0,
                3.0,
            ),
            (Box::new(|s: f64| s * s * s - 0.001), 0.0, 1.0),
            (Box::new(|s: f64| (3.0 * (s - 0.7)).max(-1.0)), 0.0, 2.0),
        ];
        for (k, (f, lo, hi)) in cases.iter().enumerate() {
            let tol = 1e-12;
            let calls = std::cell::Cell::new(0);
            let counted = |s: f64| {
                calls.set(calls.get() + 1);
                f(s)
            };
            let x = first_crossing(&counted, (*lo, f(*lo)), (*hi, f(*hi)), tol);
            let (mut a, mut b) = (*lo, *hi);
            while b - a > tol {
                let m = 0.5 * (a + b);
                if f(m) >= 0.0 {
                    b = m
                } else {
                    a = m
                }
            }
            assert!(f(x) >= 0.0, "case {k}");
            assert!((x - b).abs() <= 2.0 * tol, "case {k}: {x} against {b}");
            assert!(calls.get() <= 50, "case {k}: {} evaluations", calls.get());
        }
    }
}
