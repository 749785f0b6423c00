//! Measures of a skeleton's lines near their ends, shared by the steps that
//! shape the ends and by the defect counts: arc-length positions, the local
//! width at an end, and how much an end turns.

use super::{polyline_length, NodeId, SkeletonGraph};
use crate::geometry::PreparedPolygon;
use geo::Coord;

/// Relative tolerance (× polygon extent) within which a node lies on ∂P;
/// above the coarsest coordinate resolution of any method (MA's grid,
/// ≤ 1.5 × 10⁻⁸ × extent).
pub const ON_BOUNDARY_END: f64 = 1e-7;

/// A line end that turns by more than this (degrees) within its last local
/// width is a hook.
pub const HOOK_DEG: f64 = 60.0;

/// The point at arc length `s` along `line` (its end when `s` ≥ its length).
pub fn point_at(line: &[Coord<f64>], s: f64) -> Coord<f64> {
    let mut left = s;
    for w in line.windows(2) {
        let d = w[1] - w[0];
        let l = crate::geometry::norm(d);
        if l >= left && l > 0.0 {
            return w[0] + d * (left / l);
        }
        left -= l;
    }
    *line.last().expect("a polyline has at least one point")
}

/// The angle between two directions, in degrees (`None` for a zero vector).
pub fn angle_deg(a: Coord<f64>, b: Coord<f64>) -> Option<f64> {
    let (la, lb) = (a.x.hypot(a.y), b.x.hypot(b.y));
    if la == 0.0 || lb == 0.0 {
        return None;
    }
    let c = ((a.x * b.x + a.y * b.y) / (la * lb)).clamp(-1.0, 1.0);
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
    let b = polygon.boundary();
    let total = polyline_length(coords);
    // Arc length s grows with slope 1 and the radius at most with slope 1,
    // so s − 2 r(s) changes sign once on a medial line; sample it finely
    // enough and bisect the first sign change.
    // f rises with slope at most 3 (s with slope 1, −2r with slope at most
    // 2), so from f(s) < 0 it stays negative up to s + |f(s)|/3: samples
    // there are skipped unevaluated (the same sample is the first at or
    // above zero, the same answer).
    let steps = 64;
    let f = |s: f64| s - 2.0 * b.distance(point_at(coords, s));
    let mut lo = 0.0;
    let mut negative_below = 0.0;
    for i in 1..=steps {
        let s = total * i as f64 / steps as f64;
        if s < negative_below {
            lo = s;
            continue;
        }
        let v = f(s);
        negative_below = s - v / 3.0 * (1.0 - 1e-9);
        if v >= 0.0 {
            let mut hi = s;
            for _ in 0..30 {
                let mid = 0.5 * (lo + hi);
                if f(mid) >= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return (hi, b.distance(point_at(coords, hi)));
        }
        lo = s;
    }
    (total, b.distance(point_at(coords, total)))
}

/// The turn (degrees) of every line end of `g`, a skeleton of `polygon`, in
/// node order (see the module documentation).
pub fn end_turns(g: &SkeletonGraph, polygon: &PreparedPolygon) -> Vec<f64> {
    let adj = g.adjacency();
    let mut out = Vec::new();
    for n in 0..g.nodes().len() {
        if adj[n].len() != 1 {
            continue;
        }
        let coords = g.line_from(NodeId(n as u32), &adj);
        if let Some(t) = end_turn(&coords, polygon) {
            out.push(t);
        }
    }
    out
}

/// The turn of the line `coords` at its first point (see the module docs).
pub fn end_turn(coords: &[Coord<f64>], polygon: &PreparedPolygon) -> Option<f64> {
    let total = polyline_length(coords);
    if total <= 0.0 {
        return None;
    }
    let (w, _) = end_width_point(coords, polygon);
    let e = coords[0];
    let last = coords.iter().copied().find(|&c| c != e)?;
    let before = point_at(coords, w.min(total));
    let start = point_at(coords, (1.5 * w).min(total));
    if before == start {
        return Some(0.0);
    }
    angle_deg(before - start, e - last)
}
