//! A polygon part's label line: the medial-axis path a curved label follows,
//! smoothed, kept off the shore and trimmed at narrow tips, or the centre of
//! its largest inscribed disc where the part is not elongated enough.
//!
//! 1. **Path.** The medial axis, pruned and extended as the default pipeline
//!    does (its legs reach the tips), gives the candidate paths: every
//!    shortest path between two of its leaves. Each is scored by its length
//!    over its curvature, `L / (1 + T / π)`, T its total turning measured
//!    on the path resampled one local width apart (so that a wiggle smaller
//!    than the lake does not count): the longest path that does not wind.
//! 2. **Trim.** A label's letters need room: from each end the path is cut
//!    back while the local radius is below half the path's median radius
//!    (a narrow tip or outflow the text would stick out of). Resampled at a
//!    quarter of the local radius, it is then cut back at an end whose
//!    stretch one local width long turns by more than `smooth` degrees, to
//!    the first point within one local width of the end from which the
//!    stretch does not (a label's end does not bend away).
//! 3. **Smooth.** The path is averaged over a window one local width long, repeatedly, until no
//!    stretch one local width long turns by more than `smooth` degrees (at
//!    most 200 rounds).
//!    Each run of points the smoothing moved then goes back towards the
//!    axis by the least fraction of its move (one for the run, found by
//!    bisection) with which no point turns too much that did not with all
//!    of it: the averaging rounds off more than a bend needs.
//! 4. **Margin.** A smoothed point closer to ∂P than `margin` × the local
//!    radius is moved back towards its medial-axis point until it is not
//!    (the medial-axis point itself is one local radius away).
//! 5. **Gentle enough.** Where the smoothed line still turns by more than
//!    `smooth` over a stretch one local width long (a bend sharper than the
//!    corridor lets the smoothing round off), only the longest run without
//!    such a stretch is kept — of the relaxed line, or of the line as
//!    smoothed when more of that one is gentle enough.
//! 6. **Line or point.** The line is written when the axis path is at
//!    least `min_elongation` times the part's largest width, and so is the
//!    kept run (with the bent ends cut in 2) — or, when the run still keeps
//!    at least half of the axis path, at least `min_elongation` times the
//!    widest local width along it (its own corridor: a run cut at a bend too
//!    sharp for the letters may have left the widest basin behind, as on a
//!    crescent lake with a round bay at one horn; a shorter run is one arm
//!    of the lake). Otherwise (a round lake) the label is the centre of the
//!    largest inscribed disc — the raw medial axis' node of largest radius,
//!    the pole of inaccessibility.

use crate::geometry::vector::hypot;
use crate::geometry::{Boundary, PreparedPolygon};
use crate::graph::{EdgeId, NodeId, SkeletonGraph};
use geo::{Coord, LineString};

/// What a polygon part is labelled with.
#[derive(Debug, Clone, PartialEq)]
pub enum Label {
    /// A curved label along this line.
    Line(LineString<f64>),
    /// A label at this point (the largest disc's centre).
    Point(Coord<f64>),
}

/// A label and its measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Labelled {
    /// The geometry.
    pub label: Label,
    /// Length of the line (0 for a point).
    pub length: f64,
    /// Diameter of the largest inscribed disc (2r).
    pub max_width: f64,
    /// Length of the chosen medial-axis path over `max_width`.
    pub elongation: f64,
}

/// The options the algorithm needs (see [`super::LabelParams`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Shape {
    pub smooth_deg: f64,
    pub margin: f64,
    pub min_elongation: f64,
}

/// The label of polygon part `p` from its finished medial axis `g`
/// (`None` when the axis is empty).
/// The largest inscribed disc is the raw axis' node of largest radius (its
/// nodes carry their disc radius; pruning may drop the node of a wide,
/// short basin).
pub(super) fn label(
    p: &PreparedPolygon,
    raw: &SkeletonGraph,
    g: &SkeletonGraph,
    o: Shape,
) -> Option<Labelled> {
    let b = p.boundary();
    let (centre, r_max) = raw
        .nodes()
        .iter()
        .map(|n| (n.pos, n.radius))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let max_width = 2.0 * r_max;
    let point = |elongation: f64| Labelled {
        label: Label::Point(centre),
        length: 0.0,
        max_width,
        elongation,
    };
    let Some((path, radii)) = best_path(g, b) else {
        return Some(point(0.0));
    };
    let axis_length = length(&path);
    let elongation = axis_length / max_width;
    if elongation < o.min_elongation {
        return Some(point(elongation));
    }
    let (path, radii) = trim(&path, &radii);
    if path.len() < 2 {
        return Some(point(elongation));
    }
    // Where the corridor kept a bend too sharp for the letters, the label
    // runs along the longest stretch that is gentle enough, if that is
    // still long enough for a line (the bent ends cut before smoothing
    // count: a part elongated enough keeps its line).
    let max_turn = o.smooth_deg.to_radians();
    let lines = smooth_inside(&path, &radii, o);
    let bent = lines.bent;
    let relaxed = dedup(keep_off_shore(&lines.relaxed, &lines.at, b, o.margin));
    let whole = relaxed.len();
    let mut run = gentlest_run(relaxed, b, max_turn);
    if run.line.len() < whole {
        // The exact check cut the relaxed line: the line as smoothed, when
        // more of it is gentle enough.
        let smoothed = keep_off_shore(&lines.smoothed, &lines.at, b, o.margin);
        let other = gentlest_run(dedup(smoothed), b, max_turn);
        if length(&other.line) > length(&run.line) {
            run = other;
        }
    }
    // Long enough for the part's largest width; or, when it still keeps
    // most of the axis path, for its own corridor (a run cut at a sharp
    // bend may have left the widest basin, and the largest disc, behind).
    let kept = length(&run.line) + bent;
    let long_enough = |width: f64| width > 0.0 && kept / width >= o.min_elongation;
    let line = LineString(run.line);
    if line.0.len() < 2
        || !(long_enough(max_width) || (kept >= MAIN_SHARE * axis_length && long_enough(run.width)))
    {
        return Some(point(elongation));
    }
    Some(Labelled {
        length: length(&line.0),
        label: Label::Line(line),
        max_width,
        elongation,
    })
}

fn length(c: &[Coord<f64>]) -> f64 {
    c.windows(2).map(|w| hypot(w[1] - w[0])).sum()
}

fn dedup(mut c: Vec<Coord<f64>>) -> Vec<Coord<f64>> {
    c.dedup();
    c
}

/// The leaf-to-leaf shortest path with the best `L / (1 + T / π)`, and the
/// local radius (distance to ∂P) at each of its points.
fn best_path(g: &SkeletonGraph, b: &Boundary) -> Option<(Vec<Coord<f64>>, Vec<f64>)> {
    let m = g.merged();
    let deg = m.degrees();
    let leaves: Vec<NodeId> = (0..deg.len())
        .filter(|&i| deg[i] == 1)
        .map(NodeId::from_index)
        .collect();
    if leaves.len() < 2 {
        return None;
    }
    // Many leaves (a ragged shape): the pairs among the farthest apart.
    let leaves = if leaves.len() > MAX_LEAVES {
        let mut far: Vec<(f64, NodeId)> = leaves
            .iter()
            .map(|&l| {
                let p = m.node(l).pos;
                let d = leaves
                    .iter()
                    .map(|&k| hypot(m.node(k).pos - p))
                    .fold(0.0, f64::max);
                (d, l)
            })
            .collect();
        far.sort_by(|a, b| b.0.total_cmp(&a.0));
        far.into_iter().take(MAX_LEAVES).map(|x| x.1).collect()
    } else {
        leaves
    };
    let usable = vec![true; m.edges().len()];
    // Every point's radius once: the pairs' paths share most of their edges.
    let radii: Vec<Vec<f64>> = (0..m.edges().len())
        .map(|e| {
            m.edge_coords(EdgeId::from_index(e))
                .into_iter()
                .map(|c| b.nearest(c).map_or(0.0, |(_, _, d)| d))
                .collect()
        })
        .collect();
    let mut best: Option<(f64, Vec<Coord<f64>>, Vec<f64>)> = None;
    for (i, &a) in leaves.iter().enumerate() {
        for &z in &leaves[i + 1..] {
            let Some(edges) = crate::graph::prune::trunk::shortest_path(&m, &usable, a, z)
                .filter(|e| !e.is_empty())
            else {
                continue;
            };
            let (path, r) = coords_of(&m, &radii, &edges, z);
            let score = straightness_score(&path, &r);
            if best.as_ref().is_none_or(|(s, _, _)| score > *s) {
                best = Some((score, path, r));
            }
        }
    }
    best.map(|(_, p, r)| (p, r))
}

/// Leaves whose pairs are tried at most (the farthest apart).
const MAX_LEAVES: usize = 12;

/// The coordinates of a path given as edges walked back from `to`, with
/// their radii (`radii`: each edge's, point by point).
fn coords_of(
    m: &SkeletonGraph,
    radii: &[Vec<f64>],
    edges: &[EdgeId],
    to: NodeId,
) -> (Vec<Coord<f64>>, Vec<f64>) {
    let mut out: Vec<Coord<f64>> = vec![m.node(to).pos];
    let mut r_out: Vec<f64> = Vec::new();
    let mut at = to;
    for &e in edges {
        let mut c = m.edge_coords(e);
        let mut r = radii[e.index()].clone();
        if c.first().copied() != Some(m.node(at).pos) {
            c.reverse();
            r.reverse();
        }
        if r_out.is_empty() {
            r_out.push(r[0]);
        }
        out.extend_from_slice(&c[1..]);
        r_out.extend_from_slice(&r[1..]);
        at = m.opposite(e, at);
    }
    (out, r_out)
}

/// `L / (1 + T / π)`: T the total turning of the path resampled one local
/// width apart (`radii`: the local radius at each point of the path).
fn straightness_score(path: &[Coord<f64>], radii: &[f64]) -> f64 {
    let l = length(path);
    let mut coarse: Vec<Coord<f64>> = vec![path[0]];
    let mut since = 0.0;
    for (w, &r) in path.windows(2).zip(&radii[1..]) {
        since += hypot(w[1] - w[0]);
        if since >= (2.0 * r).max(l / 200.0) {
            coarse.push(w[1]);
            since = 0.0;
        }
    }
    if coarse.last() != path.last() {
        coarse.push(path[path.len() - 1]);
    }
    let turning: f64 = coarse
        .windows(3)
        .map(|w| turn(w[1] - w[0], w[2] - w[1]).abs())
        .sum();
    l / (1.0 + turning / std::f64::consts::PI)
}

/// The signed angle from `u` to `v` (radians).
fn turn(u: Coord<f64>, v: Coord<f64>) -> f64 {
    (u.x * v.y - u.y * v.x).atan2(u.x * v.x + u.y * v.y)
}

/// The path cut back at both ends while the local radius is below half
/// the path's median radius.
fn trim(path: &[Coord<f64>], radii: &[f64]) -> (Vec<Coord<f64>>, Vec<f64>) {
    let mut sorted = radii.to_vec();
    sorted.sort_by(f64::total_cmp);
    let floor = 0.5 * sorted[sorted.len() / 2];
    let first = radii.iter().position(|&r| r >= floor).unwrap_or(0);
    let last = radii
        .iter()
        .rposition(|&r| r >= floor)
        .unwrap_or(radii.len() - 1);
    if first >= last {
        return (Vec::new(), Vec::new());
    }
    (path[first..=last].to_vec(), radii[first..=last].to_vec())
}

/// The path resampled and cut at bent ends, smoothed, and relaxed.
struct Smoothed {
    /// The resampled axis points kept, with their radii.
    at: Vec<(Coord<f64>, f64)>,
    /// The line smoothed, point by point of `at`.
    smoothed: Vec<Coord<f64>>,
    /// The line relaxed ([`relax`]), point by point of `at`.
    relaxed: Vec<Coord<f64>>,
    /// The length [`straight_ends`] cut off.
    bent: f64,
}

/// The path smoothed and relaxed (neither yet kept off the shore).
fn smooth_inside(path: &[Coord<f64>], radii: &[f64], o: Shape) -> Smoothed {
    let at = resample(path, radii);
    let (a, z) = straight_ends(&at, o);
    let axis = |pts: &[(Coord<f64>, f64)]| pts.iter().map(|p| p.0).collect::<Vec<_>>();
    let bent = length(&axis(&at[..=a])) + length(&axis(&at[z..]));
    let at = at[a..=z].to_vec();
    let smoothed = smooth(axis(&at), &at, o);
    let relaxed = relax(smoothed.clone(), &at, o);
    Smoothed {
        at,
        smoothed,
        relaxed,
        bent,
    }
}

/// The resampled axis cut back at an end where the stretch one local width
/// long from the end inwards turns by more than `smooth` degrees: to the
/// first point from which it does not, when that point is within one local
/// width of the end (a bend further in is left to the smoothing). A
/// label's end does not bend away (the letters there would leave the
/// curve), and smoothing such a bend would pull the line off the axis for
/// a width on either side of it.
/// Returns the first and last point kept.
fn straight_ends(at: &[(Coord<f64>, f64)], o: Shape) -> (usize, usize) {
    let max_turn = o.smooth_deg.to_radians();
    let window = corridor_windows(at, o.margin);
    let line: Vec<Coord<f64>> = at.iter().map(|p| p.0).collect();
    let n = line.len();
    let forward = too_curved(&line, &window, max_turn);
    let mut rev_line = line.clone();
    rev_line.reverse();
    let mut rev_window = window.clone();
    rev_window.reverse();
    let backward = too_curved(&rev_line, &rev_window, max_turn);
    // From one end inwards: the first point whose stretch is gentle, or the
    // end itself when none is within one local width of it.
    let cut = |bad: &[bool], pts: &[Coord<f64>], w: &[f64]| -> usize {
        let mut along = 0.0;
        for k in 0..pts.len().saturating_sub(1) {
            if !bad[k] {
                return k;
            }
            along += hypot(pts[k + 1] - pts[k]);
            if along > w[0] / (2.0 - o.margin) {
                break;
            }
        }
        0
    };
    let a = cut(&forward, &line, &window);
    let z = n - 1 - cut(&backward, &rev_line, &rev_window);
    if a + 1 >= z {
        return (0, n - 1);
    }
    (a, z)
}

/// Each run of points that smoothing moved off the medial axis, moved back
/// towards it as far as the turn allows: the points of the run keep the
/// least fraction t of their move (the same for the whole run, found by
/// bisection) with which no point turns too much that did not with all of
/// it.
/// Smoothing averages over a whole window round after round; where a bend
/// needed only part of that, the line returns to the centre.
fn relax(mut cur: Vec<Coord<f64>>, at: &[(Coord<f64>, f64)], o: Shape) -> Vec<Coord<f64>> {
    let max_turn = o.smooth_deg.to_radians();
    let window = corridor_windows(at, o.margin);
    let n = cur.len();
    // From `from`, the farthest point (a step of ±1 at a time) within the
    // longest stretch of the points passed and `reach`: the points whose
    // stretches can see a change at `from` (measured along the axis).
    let span = |from: usize, step: isize, reach: f64| -> usize {
        let (mut k, mut along, mut reach) = (from as isize, 0.0, reach);
        while along < reach && (0..n as isize).contains(&(k + step)) {
            along += hypot(at[(k + step) as usize].0 - at[k as usize].0);
            k += step;
            reach = reach.max(window[k as usize]);
        }
        k as usize
    };
    let mut i = 0;
    while i < n {
        if cur[i] == at[i].0 {
            i += 1;
            continue;
        }
        let s = i;
        while i < n && cur[i] != at[i].0 {
            i += 1;
        }
        let longest = window[s..i].iter().cloned().fold(0.0, f64::max);
        let (lo, hi) = (span(s, -1, window[s]), span(i - 1, 1, longest) + 1);
        let moved: Vec<Coord<f64>> = cur[s..i].to_vec();
        let bad_with = |t: f64, line: &mut Vec<Coord<f64>>| -> Vec<bool> {
            for k in s..i {
                line[k] = at[k].0 + (moved[k - s] - at[k].0) * t;
            }
            too_curved(&line[lo..hi], &window[lo..hi], max_turn)
        };
        // No point turns too much that did not with all of the move.
        let allowed = bad_with(1.0, &mut cur);
        let within = |bad: Vec<bool>| bad.iter().zip(&allowed).all(|(&b, &a)| !b || a);
        let (mut t_lo, mut t_hi) = (0.0, 1.0);
        if within(bad_with(0.0, &mut cur)) {
            t_hi = 0.0;
        } else {
            for _ in 0..RELAX_STEPS {
                let mid = 0.5 * (t_lo + t_hi);
                if within(bad_with(mid, &mut cur)) {
                    t_hi = mid;
                } else {
                    t_lo = mid;
                }
            }
        }
        bad_with(t_hi, &mut cur);
    }
    cur
}

/// Bisection steps of [`relax`] (the kept move to within 1/256).
const RELAX_STEPS: usize = 8;

/// The stretch over which the turn is judged while smoothing: a point
/// within the corridor is at most (2 − margin) r from ∂P, so its stretch is
/// judged over `2 (2 − margin) r` (no boundary query per point and round;
/// the exact check follows in `gentlest_run`).
fn corridor_windows(at: &[(Coord<f64>, f64)], margin: f64) -> Vec<f64> {
    at.iter().map(|&(_, r)| 2.0 * (2.0 - margin) * r).collect()
}

/// The stretch over which the turn is judged at each point: `2 d`, d its
/// distance to ∂P (the local width 2r where the line is on the axis).
fn windows(line: &[Coord<f64>], b: &Boundary) -> Vec<f64> {
    line.iter()
        .map(|&c| 2.0 * b.nearest(c).map_or(0.0, |(_, _, d)| d))
        .collect()
}

/// The path resampled at a quarter of the local radius: each point with the
/// medial-axis point it is and that point's radius.
fn resample(path: &[Coord<f64>], radii: &[f64]) -> Vec<(Coord<f64>, f64)> {
    // Resample: points at most r/4 apart (r interpolated).
    let mut pts: Vec<(Coord<f64>, f64)> = vec![(path[0], radii[0])];
    for i in 0..path.len() - 1 {
        let (a, z) = (path[i], path[i + 1]);
        let step = (0.25 * radii[i].min(radii[i + 1])).max(1e-9);
        let n = (hypot(z - a) / step).ceil().clamp(1.0, 10_000.0) as usize;
        for k in 1..=n {
            let t = k as f64 / n as f64;
            pts.push((a + (z - a) * t, radii[i] + (radii[i + 1] - radii[i]) * t));
        }
    }
    pts
}

/// `line` averaged over a window of nine points (one local width: points a
/// quarter radius apart) where it turns too much — only the points of the
/// stretches that turn by more than `max_deg` (and their windows), so that
/// the rest stays on the medial axis — until none does.
fn smooth(mut cur: Vec<Coord<f64>>, at: &[(Coord<f64>, f64)], o: Shape) -> Vec<Coord<f64>> {
    let half = 4usize;
    let max_turn = o.smooth_deg.to_radians();
    let window = corridor_windows(at, o.margin);
    let (mut fewest, mut since) = (usize::MAX, 0);
    for _ in 0..MAX_ROUNDS {
        let bad = too_curved(&cur, &window, max_turn);
        let count = bad.iter().filter(|&&x| x).count();
        if count == 0 {
            break;
        }
        // Where the corridor holds a bend, averaging cannot round it off:
        // stop once the bad points have not become fewer for a while.
        if count < fewest {
            (fewest, since) = (count, 0);
        } else {
            since += 1;
            if since >= STALLED_ROUNDS {
                break;
            }
        }
        let n = cur.len();
        // Each bad point's window is smoothed too.
        let mut touch = vec![false; n];
        for (i, _) in bad.iter().enumerate().filter(|(_, &x)| x) {
            for t in &mut touch[i.saturating_sub(half)..(i + half + 1).min(n)] {
                *t = true;
            }
        }
        let prev = cur.clone();
        for i in (1..n - 1).filter(|&i| touch[i]) {
            let k = half.min(i).min(n - 1 - i);
            let mut s = Coord { x: 0.0, y: 0.0 };
            for q in &prev[i - k..=i + k] {
                s = s + *q;
            }
            // Within the corridor: at most (1 − margin) r from the axis.
            let (axis, r) = at[i];
            let c = s / (2 * k + 1) as f64;
            let off = c - axis;
            let reach = (1.0 - o.margin) * r;
            let d = hypot(off);
            cur[i] = if d > reach && d > 0.0 {
                axis + off * (reach / d)
            } else {
                c
            };
        }
    }
    cur
}

/// Smoothing rounds at most.
const MAX_ROUNDS: usize = 400;

/// Rounds without fewer bad points after which smoothing stops.
const STALLED_ROUNDS: usize = 20;

/// The points of every stretch (starting at a point, `window[i]` long) that
/// turns by more than `max_turn` (radians) somewhere along it. The
/// segments' lengths and turns are found once (a trigonometric call per
/// point, not per point and stretch).
fn too_curved(line: &[Coord<f64>], window: &[f64], max_turn: f64) -> Vec<bool> {
    let n = line.len();
    let mut bad = vec![false; n];
    if n < 3 {
        return bad;
    }
    let seg: Vec<Coord<f64>> = line.windows(2).map(|w| w[1] - w[0]).collect();
    let len: Vec<f64> = seg.iter().map(|&d| hypot(d)).collect();
    // The turn into segment j from the last segment of non-zero length
    // before it (0 for a segment of zero length).
    let mut into = vec![0.0; seg.len()];
    let mut last = (len[0] > 0.0).then_some(0);
    for j in 1..seg.len() {
        if len[j] > 0.0 {
            if let Some(k) = last {
                into[j] = turn(seg[k], seg[j]);
            }
            last = Some(j);
        }
    }
    for i in 0..n - 2 {
        if len[i] == 0.0 {
            continue;
        }
        let (mut along, mut total) = (0.0, 0.0);
        let mut j = i + 1;
        while j + 1 < n && along < window[i] {
            total += into[j];
            if total.abs() > max_turn {
                for b in &mut bad[i..=j] {
                    *b = true;
                }
                break;
            }
            along += len[j];
            j += 1;
        }
    }
    bad
}

/// The share of the axis path a line cut at a sharp bend must keep to be
/// judged by its own corridor's width: more than that labels the lake, less
/// one of its arms (which a point at the largest disc labels better).
const MAIN_SHARE: f64 = 0.5;

/// A stretch of a label line and the widest local width along it.
struct Run {
    line: Vec<Coord<f64>>,
    /// The largest `2 d` over its points, d the distance to ∂P.
    width: f64,
}

/// The longest run of `line` in which no stretch one local width long
/// turns by more than `max_turn` (the whole line when none does).
fn gentlest_run(line: Vec<Coord<f64>>, b: &Boundary, max_turn: f64) -> Run {
    let window = windows(&line, b);
    let bad = too_curved(&line, &window, max_turn);
    let widest = |w: &[f64]| w.iter().copied().fold(0.0, f64::max);
    if !bad.iter().any(|&x| x) {
        let width = widest(&window);
        return Run { line, width };
    }
    // Runs of good points: no stretch starting in one turns too much
    // within it.
    let mut best = (0usize, 0usize, 0.0f64);
    let mut start = None;
    for i in 0..=line.len() {
        let good = i < line.len() && !bad[i];
        match (good, start) {
            (true, None) => start = Some(i),
            (false, Some(s0)) => {
                let l = length(&line[s0..i]);
                if l > best.2 {
                    best = (s0, i - 1, l);
                }
                start = None;
            }
            _ => {}
        }
    }
    Run {
        line: line[best.0..=best.1].to_vec(),
        width: widest(&window[best.0..=best.1]),
    }
}

/// Each point moved back towards its medial-axis point until it is at least
/// `margin` × that point's radius from ∂P (bisection, 20 steps).
fn keep_off_shore(
    line: &[Coord<f64>],
    at: &[(Coord<f64>, f64)],
    b: &Boundary,
    margin: f64,
) -> Vec<Coord<f64>> {
    line.iter()
        .zip(at)
        .map(|(&p, &(axis, r))| {
            let need = margin * r;
            let ok =
                |c: Coord<f64>| b.contains(c) && b.nearest(c).is_some_and(|(_, _, d)| d >= need);
            if ok(p) {
                return p;
            }
            let (mut lo, mut hi) = (0.0, 1.0); // 0: the axis point, 1: p
            for _ in 0..20 {
                let mid = 0.5 * (lo + hi);
                if ok(axis + (p - axis) * mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            axis + (p - axis) * lo
        })
        .collect()
}
