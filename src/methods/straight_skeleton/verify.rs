//! The checks every straight skeleton passes and a missed split event
//! breaks: every trace inside P, no two traces crossing.

use super::*;

/// Checks that hold for every straight skeleton and that a missed split
/// event breaks: every trace stays in P and no two traces cross (a vertex
/// that ran through a wavefront edge leaves its face, so its trace crosses
/// the traces bounding that face or leaves P). Crossings closer than
/// `1e-6 · extent` to an end of either trace are rounding, not misses.
pub(super) fn verify(polygon: &PreparedPolygon, arcs: &[Arc]) -> Result<(), MethodError> {
    let tol = TRACE_CROSSING * polygon.extent();
    if let Some(a) = arcs
        .iter()
        .find(|a| !polygon.boundary().contains_with_tolerance(a.to, tol))
    {
        return Err(fail(format!(
            "straight skeleton left the polygon near ({}, {}) (a missed event in a degenerate configuration)",
            a.to.x, a.to.y
        )));
    }
    // Every pair of traces with pieces whose boxes meet; the first crossing
    // in trace order is reported.
    let (traces, boxes) = trace_pieces(arcs, tol);
    let mut first: Option<(usize, usize, Coord<f64>)> = None;
    PackedTree::pairs_of(&boxes, |i, j| {
        let (i, j) = (traces[i as usize], traces[j as usize]);
        if i == j {
            return ControlFlow::Continue(());
        }
        let (i, j) = (i.min(j), i.max(j));
        if first.is_none_or(|(fi, fj, _)| (i, j) < (fi, fj)) {
            let (a, b) = (&arcs[i], &arcs[j]);
            if let Some(x) = crossing(a.from, a.to, b.from, b.to, tol) {
                first = Some((i, j, x));
            }
        }
        ControlFlow::<()>::Continue(())
    });
    if let Some((_, _, x)) = first {
        return Err(fail(format!(
            "straight skeleton traces cross near ({}, {}) (a missed split event)",
            x.x, x.y
        )));
    }
    Ok(())
}

/// The point where segments `pq` and `ab` cross, when it is farther than
/// `tol` from all four ends and neither segment lies within `tol` of the
/// other's line (near-collinear overlaps, as collapsed strips of nearly
/// parallel banks give, are rounding too).
/// The boxes the crossing check of [`verify`] pairs: one per trace of
/// non-zero length, or several along a trace longer than
/// [`PIECE_OF_MEAN`] times the mean — each box around a stretch of it that
/// long, widened by `pad` (so rounding in the stretches' ends cannot lose
/// a crossing) — with the trace of each box. A fast reflex vertex draws a
/// long trace across a rough rim: the box around all of it met those of
/// thousands of short traces (58 M pairs on the rough polygon of
/// `scripts/make_rough_polygon.py` at 200 000 vertices, four times as many
/// as at 100 000), the boxes along it few of them.
pub(super) fn trace_pieces(arcs: &[Arc], pad: f64) -> (Vec<usize>, Vec<Bbox>) {
    let traces: Vec<usize> = (0..arcs.len())
        .filter(|&i| arcs[i].from != arcs[i].to)
        .collect();
    let length = |i: usize| {
        let d = arcs[i].to - arcs[i].from;
        (d.x * d.x + d.y * d.y).sqrt()
    };
    let total: f64 = traces.iter().map(|&i| length(i)).sum();
    let step = PIECE_OF_MEAN * total / traces.len().max(1) as f64;
    let (mut owners, mut boxes) = (Vec::with_capacity(traces.len()), Vec::new());
    for &i in &traces {
        let (p, q) = (arcs[i].from, arcs[i].to);
        let pieces = (length(i) / step).ceil().clamp(1.0, 1e6) as usize;
        if pieces == 1 {
            owners.push(i);
            boxes.push(segment_box(p, q));
            continue;
        }
        let at = |k: usize| p + (q - p) * (k as f64 / pieces as f64);
        for k in 0..pieces {
            let b = segment_box(at(k), if k + 1 == pieces { q } else { at(k + 1) });
            owners.push(i);
            boxes.push([b[0] - pad, b[1] - pad, b[2] + pad, b[3] + pad]);
        }
    }
    (owners, boxes)
}

/// A trace longer than this many times the mean trace length is boxed in
/// stretches this long for the crossing check ([`trace_pieces`]).
const PIECE_OF_MEAN: f64 = 4.0;

pub(super) fn crossing(
    p: Coord<f64>,
    q: Coord<f64>,
    a: Coord<f64>,
    b: Coord<f64>,
    tol: f64,
) -> Option<Coord<f64>> {
    if !properly_cross(p, q, a, b) {
        return None;
    }
    let d = q - p;
    let (s, _) = lines_meet(p, d, a, b)?;
    let x = p + d * s;
    let far = |c: Coord<f64>| {
        // `hypot > tol`, the hypot only when no component alone decides.
        let d = c - x;
        d.x.abs() > tol || d.y.abs() > tol || hypot(d) > tol
    };
    let off = |u: Coord<f64>, v: Coord<f64>, c: Coord<f64>| {
        let w = v - u;
        cross(w, c - u).abs() / hypot(w)
    };
    let apart = off(p, q, a).max(off(p, q, b)) > tol && off(a, b, p).max(off(a, b, q)) > tol;
    (apart && far(p) && far(q) && far(a) && far(b)).then_some(x)
}
