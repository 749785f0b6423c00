//! Drawing one feature for the page: CRS coordinates to a small integer
//! frame, lines simplified for display within a vertex budget, bars in
//! classes of z, and the node radius r (distance to ∂P) at every vertex
//! drawn.
//!
//! Everything here is for display only: the GeoPackage holds the full
//! geometry, the scores are computed on it, and the radii come from the
//! full-resolution boundary.

use crate::geometry::segment::closest_on_segment;
use crate::geometry::Boundary;
use crate::output::BarRow;
use geo::{Coord, LineString};
use std::fmt::Write as _;

/// Frame units on the longer side of a feature's bounding box: coordinates
/// are rounded to 1/10 000 of the feature's extent.
pub const FRAME: f64 = 10_000.0;
/// Most vertices of a feature's polygon drawn.
pub const POLYGON_VERTICES: usize = 4_000;
/// Most vertices of one method's skeleton drawn.
pub const SKELETON_VERTICES: usize = 1_500;
/// Most bars drawn per method: half of them the largest z, half evenly
/// spaced along the boundary.
pub const BARS_PER_METHOD: usize = 400;
/// Lower bounds of the classes of z in which bars are coloured.
pub const Z_CLASSES: [f64; 6] = [0.0, 0.01, 0.03, 0.06, 0.1, 0.2];

/// Largest bytes one drawn vertex takes (`l-10000 -10000`), and one radius.
const VERTEX_BYTES: usize = 14;
const RADIUS_BYTES: usize = 9;
/// Largest bytes of one drawn bar (`M10000 10000l-10000 -10000`).
const BAR_BYTES: usize = 28;
/// Allowance for a section's markup besides its geometry: headings, the
/// score table, captions (per method, and once).
const MARKUP_PER_METHOD: usize = 1_200;
const MARKUP: usize = 3_000;

/// The most bytes a feature section with `methods` methods takes.
pub fn section_bound(methods: usize) -> usize {
    MARKUP
        + POLYGON_VERTICES * VERTEX_BYTES
        + methods
            * (SKELETON_VERTICES * (VERTEX_BYTES + RADIUS_BYTES)
                + BARS_PER_METHOD * BAR_BYTES
                + MARKUP_PER_METHOD)
}

/// Maps CRS coordinates to frame units (y down), rounded to integers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// CRS x of frame x = 0.
    pub x0: f64,
    /// CRS y of frame y = 0 (the top).
    pub y0: f64,
    /// Frame units per CRS unit.
    pub scale: f64,
    /// Frame width.
    pub w: i64,
    /// Frame height.
    pub h: i64,
}

impl Frame {
    /// The frame of a bounding box.
    pub fn around(min: Coord<f64>, max: Coord<f64>) -> Self {
        let extent = (max.x - min.x).max(max.y - min.y);
        let scale = if extent > 0.0 && extent.is_finite() {
            FRAME / extent
        } else {
            1.0
        };
        Self {
            x0: min.x,
            y0: max.y,
            scale,
            w: (((max.x - min.x) * scale).round() as i64).max(1),
            h: (((max.y - min.y) * scale).round() as i64).max(1),
        }
    }

    fn q(&self, c: Coord<f64>) -> (i64, i64) {
        (
            ((c.x - self.x0) * self.scale).round() as i64,
            ((self.y0 - c.y) * self.scale).round() as i64,
        )
    }

    /// Appends `line` as `M x y l dx dy dx dy…` (closed with `z`), leaving
    /// out vertices that round onto the one before; the CRS coordinates of
    /// the vertices written go to `kept`. A line that rounds to one point is
    /// left out.
    pub fn encode(
        &self,
        line: &[Coord<f64>],
        close: bool,
        out: &mut String,
        kept: &mut Vec<Coord<f64>>,
    ) {
        let mut pts: Vec<((i64, i64), Coord<f64>)> = Vec::with_capacity(line.len());
        for &c in line {
            let p = self.q(c);
            if pts.last().is_none_or(|(l, _)| *l != p) {
                pts.push((p, c));
            }
        }
        if close && pts.len() > 1 && pts[0].0 == pts[pts.len() - 1].0 {
            pts.pop();
        }
        if pts.len() < 2 {
            return;
        }
        let ((x, y), _) = pts[0];
        let _ = write!(out, "M{x} {y}");
        for (i, w) in pts.windows(2).enumerate() {
            let (dx, dy) = (w[1].0 .0 - w[0].0 .0, w[1].0 .1 - w[0].0 .1);
            let _ = write!(out, "{}{dx} {dy}", if i == 0 { "l" } else { " " });
        }
        if close {
            out.push('z');
        }
        kept.extend(pts.iter().map(|(_, c)| *c));
    }
}

fn diagonal(l: &LineString<f64>) -> f64 {
    let (mut lo, mut hi) = (
        Coord {
            x: f64::INFINITY,
            y: f64::INFINITY,
        },
        Coord {
            x: f64::NEG_INFINITY,
            y: f64::NEG_INFINITY,
        },
    );
    for c in &l.0 {
        lo = Coord {
            x: lo.x.min(c.x),
            y: lo.y.min(c.y),
        };
        hi = Coord {
            x: hi.x.max(c.x),
            y: hi.y.max(c.y),
        };
    }
    (hi.x - lo.x).hypot(hi.y - lo.y)
}

/// Vertices per run of Ramer–Douglas–Peucker: its worst case (a zig-zag)
/// is quadratic in the run's length, so long lines go in runs (their
/// joints kept).
const RDP_RUN: usize = 2_000;

/// Ramer–Douglas–Peucker with a stack instead of recursion (no line can
/// exhaust the thread's stack), after dropping the vertices within `eps`
/// of the last one kept (linear, and what makes dense lines cheap).
fn simplify_line(points: &[Coord<f64>], eps: f64) -> LineString<f64> {
    let mut thinned: Vec<Coord<f64>> = Vec::with_capacity(points.len());
    for (i, &p) in points.iter().enumerate() {
        let last = i + 1 == points.len();
        match thinned.last() {
            Some(&q) if !last && (p - q).x.hypot((p - q).y) < eps => {}
            _ => thinned.push(p),
        }
    }
    let n = thinned.len();
    if n < 3 {
        return LineString(thinned);
    }
    let mut keep = vec![false; n];
    let mut stack: Vec<(usize, usize)> = (0..n - 1)
        .step_by(RDP_RUN)
        .map(|a| (a, (a + RDP_RUN).min(n - 1)))
        .collect();
    for &(a, b) in &stack {
        (keep[a], keep[b]) = (true, true);
    }
    while let Some((a, b)) = stack.pop() {
        let (mut far, mut dmax) = (a, 0.0);
        for (i, &p) in thinned.iter().enumerate().take(b).skip(a + 1) {
            let (c, _) = closest_on_segment(thinned[a], thinned[b], p);
            let d = (c - p).x.hypot((c - p).y);
            if d > dmax {
                (far, dmax) = (i, d);
            }
        }
        if dmax > eps {
            keep[far] = true;
            stack.extend([(a, far), (far, b)]);
        }
    }
    LineString(
        thinned
            .iter()
            .zip(keep)
            .filter_map(|(p, k)| k.then_some(*p))
            .collect(),
    )
}

/// The lines simplified (Ramer–Douglas–Peucker) at the smallest tolerance,
/// doubling from `start`, that leaves at most `budget` vertices; lines (or
/// rings, when `rings`) smaller than the tolerance are left out, so that the
/// budget is always met. Returns the lines and the tolerance used.
pub fn simplify_within(
    lines: &[LineString<f64>],
    budget: usize,
    start: f64,
    rings: bool,
) -> (Vec<LineString<f64>>, f64) {
    let total: usize = lines.iter().map(|l| l.0.len()).sum();
    let mut eps = start.max(f64::MIN_POSITIVE);
    if total <= budget {
        return (lines.to_vec(), 0.0);
    }
    let min_len = if rings { 4 } else { 2 };
    loop {
        let out: Vec<LineString<f64>> = lines
            .iter()
            .filter(|l| diagonal(l) >= eps)
            .map(|l| simplify_line(&l.0, eps))
            .filter(|l| l.0.len() >= min_len)
            .collect();
        if out.iter().map(|l| l.0.len()).sum::<usize>() <= budget {
            return (out, eps);
        }
        eps *= 2.0;
    }
}

/// The segments of every ring, in one index: distances to ∂P of a
/// multipolygon.
pub fn boundary_of(rings: &[LineString<f64>]) -> Boundary {
    Boundary::from_rings(rings)
}

pub(crate) use crate::numbers::sig;

/// The node radius r (distance to ∂P) at every point, space-separated.
pub fn radii(boundary: &Boundary, points: &[Coord<f64>]) -> String {
    let v: Vec<String> = points
        .iter()
        .map(|&p| sig(boundary.distance(p), 4))
        .collect();
    v.join(" ")
}

/// The class of z (index into [`Z_CLASSES`]).
pub fn z_class(z: f64) -> usize {
    Z_CLASSES.iter().rposition(|&lo| z >= lo).unwrap_or(0)
}

/// The bars of one method that hit its skeleton, at most
/// [`BARS_PER_METHOD`]: all of them, or half the budget with the largest z
/// and half evenly spaced among the others (in boundary order).
pub fn bars_shown(bars: &[&BarRow]) -> Vec<usize> {
    let hits: Vec<usize> = (0..bars.len())
        .filter(|&i| bars[i].z.is_some() && bars[i].geometry.0.len() >= 2)
        .collect();
    if hits.len() <= BARS_PER_METHOD {
        return hits;
    }
    let mut by_z = hits.clone();
    by_z.sort_by(|&a, &b| {
        bars[b]
            .z
            .unwrap_or(0.0)
            .total_cmp(&bars[a].z.unwrap_or(0.0))
    });
    let worst = BARS_PER_METHOD / 2;
    let mut keep: Vec<usize> = by_z[..worst].to_vec();
    let rest: Vec<usize> = by_z[worst..].to_vec();
    let mut rest_in_order = rest;
    rest_in_order.sort_unstable();
    let n = BARS_PER_METHOD - worst;
    let step = rest_in_order.len() as f64 / n as f64;
    keep.extend((0..n).map(|k| rest_in_order[(k as f64 * step) as usize]));
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// One path per class of z: `(class, d)` of the bars `shown`.
pub fn bar_paths(frame: &Frame, bars: &[&BarRow], shown: &[usize]) -> Vec<(usize, String)> {
    let mut paths = vec![String::new(); Z_CLASSES.len()];
    for &i in shown {
        let b = bars[i];
        let (Some(z), [a, h, ..]) = (b.z, b.geometry.0.as_slice()) else {
            continue;
        };
        let ((x, y), (hx, hy)) = (frame.q(*a), frame.q(*h));
        let _ = write!(paths[z_class(z)], "M{x} {y}l{} {}", hx - x, hy - y);
    }
    paths
        .into_iter()
        .enumerate()
        .filter(|(_, d)| !d.is_empty())
        .collect()
}

/// One method's skeleton as drawn.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DrawnSkeleton {
    /// The path (`d`).
    pub d: String,
    /// r at every vertex of the path, in order.
    pub radii: String,
    /// Vertices drawn, and in the GeoPackage.
    pub vertices: (usize, usize),
    /// The bars shown, one path per class of z.
    pub bars: Vec<(usize, String)>,
    /// Bars shown, and bars that hit the skeleton.
    pub bar_count: (usize, usize),
}

/// A feature as drawn: its frame, polygon and every candidate's skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// The frame.
    pub frame: Frame,
    /// The polygon's path (`d`).
    pub polygon: String,
    /// Polygon vertices drawn, and in the source.
    pub polygon_vertices: (usize, usize),
    /// Every candidate's skeleton, in the section's order.
    pub skeletons: Vec<DrawnSkeleton>,
}

fn rings_of(p: &geo::MultiPolygon<f64>) -> Vec<LineString<f64>> {
    p.0.iter()
        .flat_map(|p| std::iter::once(p.exterior()).chain(p.interiors()))
        .cloned()
        .collect()
}

/// The bounding box of lines: `(min, max)`, or `None` when there are none.
fn bbox(lines: &[LineString<f64>]) -> Option<(Coord<f64>, Coord<f64>)> {
    let mut it = lines.iter().flat_map(|l| l.0.iter());
    let first = *it.next()?;
    Some(it.fold((first, first), |(lo, hi), c| {
        (
            Coord {
                x: lo.x.min(c.x),
                y: lo.y.min(c.y),
            },
            Coord {
                x: hi.x.max(c.x),
                y: hi.y.max(c.y),
            },
        )
    }))
}

/// Draws a section: the polygon (or, without it, the skeletons) sets the
/// frame; each line is simplified within its budget from half a frame unit
/// (below what the rounding shows) up.
pub fn section(s: &super::Section) -> Drawn {
    let rings = s.polygon.as_ref().map(rings_of).unwrap_or_default();
    let skeletons: Vec<Vec<LineString<f64>>> = s
        .candidates
        .iter()
        .map(|c| c.geometry.as_ref().map(|g| g.0.clone()).unwrap_or_default())
        .collect();
    let all: Vec<LineString<f64>> = skeletons.iter().flatten().cloned().collect();
    let (lo, hi) = bbox(&rings)
        .or_else(|| bbox(&all))
        .unwrap_or((Coord { x: 0.0, y: 0.0 }, Coord { x: 1.0, y: 1.0 }));
    let frame = Frame::around(lo, hi);
    let start = 0.5 / frame.scale;
    let (shown_rings, _) = simplify_within(&rings, POLYGON_VERTICES, start, true);
    let mut polygon = String::new();
    let mut kept = Vec::new();
    for r in &shown_rings {
        frame.encode(&r.0, true, &mut polygon, &mut kept);
    }
    let polygon_vertices = (kept.len(), rings.iter().map(|r| r.0.len()).sum());
    let boundary = boundary_of(&rings);
    let drawn = s
        .candidates
        .iter()
        .zip(&skeletons)
        .map(|(c, lines)| {
            let (shown, _) = simplify_within(lines, SKELETON_VERTICES, start, false);
            let (mut d, mut kept) = (String::new(), Vec::new());
            for l in &shown {
                frame.encode(&l.0, false, &mut d, &mut kept);
            }
            let bars: Vec<&BarRow> = s.bars.iter().filter(|b| b.method == c.method).collect();
            let chosen_bars = bars_shown(&bars);
            let hits = bars.iter().filter(|b| b.z.is_some()).count();
            DrawnSkeleton {
                radii: if rings.is_empty() {
                    String::new()
                } else {
                    radii(&boundary, &kept)
                },
                d,
                vertices: (kept.len(), lines.iter().map(|l| l.0.len()).sum()),
                bars: bar_paths(&frame, &bars, &chosen_bars),
                bar_count: (chosen_bars.len(), hits),
            }
        })
        .collect();
    Drawn {
        frame,
        polygon,
        polygon_vertices,
        skeletons: drawn,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::line_string;

    #[test]
    fn coordinates_are_relative_integers_in_a_frame_with_y_down() {
        let f = Frame::around(Coord { x: 100.0, y: 50.0 }, Coord { x: 300.0, y: 150.0 });
        assert_eq!((f.w, f.h), (10_000, 5_000));
        let (mut d, mut kept) = (String::new(), Vec::new());
        let line = line_string![(x: 100.0, y: 150.0), (x: 100.001, y: 150.0), (x: 300.0, y: 50.0)];
        f.encode(&line.0, false, &mut d, &mut kept);
        // The second vertex rounds onto the first and is left out.
        assert_eq!(d, "M0 0l10000 5000");
        assert_eq!(kept.len(), 2);
    }

    #[test]
    fn simplification_meets_the_budget_and_keeps_small_inputs_exact() {
        let wiggly = LineString::from(
            (0..10_000)
                .map(|i| (i as f64, if i % 2 == 0 { 0.0 } else { 0.3 }))
                .collect::<Vec<_>>(),
        );
        let (out, eps) = simplify_within(std::slice::from_ref(&wiggly), 1_000, 0.01, false);
        assert!(out.iter().map(|l| l.0.len()).sum::<usize>() <= 1_000);
        assert!(eps > 0.15, "{eps}");
        let small = line_string![(x: 0.0, y: 0.0), (x: 1.0, y: 0.1), (x: 2.0, y: 0.0)];
        let (same, eps) = simplify_within(std::slice::from_ref(&small), 1_000, 0.5, false);
        assert_eq!((same[0].clone(), eps), (small, 0.0));
    }

    #[test]
    fn many_tiny_lines_are_left_out_rather_than_break_the_budget() {
        let tiny: Vec<LineString<f64>> = (0..5_000)
            .map(|i| line_string![(x: i as f64, y: 0.0), (x: i as f64 + 0.5, y: 0.0)])
            .collect();
        let (out, _) = simplify_within(&tiny, 1_000, 0.01, false);
        assert!(out.iter().map(|l| l.0.len()).sum::<usize>() <= 1_000);
    }

    #[test]
    fn bars_keep_the_worst_and_an_even_spread() {
        let rows: Vec<BarRow> = (0..2_000)
            .map(|i| BarRow {
                src_fid: Some(1),
                method: "CDT".into(),
                geometry: line_string![(x: i as f64, y: 0.0), (x: i as f64, y: 1.0)],
                d_left: Some(1.0),
                d_right: Some(1.0),
                delta_d: Some(0.0),
                z: Some(if i == 1_234 { 0.9 } else { 0.001 }),
                branch: Some(0),
            })
            .collect();
        let refs: Vec<&BarRow> = rows.iter().collect();
        let shown = bars_shown(&refs);
        assert!(shown.len() <= BARS_PER_METHOD && shown.len() > BARS_PER_METHOD - 10);
        assert!(shown.contains(&1_234));
        assert!(
            shown.first() < Some(&20) && shown.last() > Some(&1_950),
            "{shown:?}"
        );
        assert_eq!(z_class(0.9), 5);
        assert_eq!(z_class(0.0), 0);
        assert_eq!(z_class(0.05), 2);
    }

    #[test]
    fn numbers_have_significant_digits_without_trailing_zeros() {
        assert_eq!(sig(1234.5678, 4), "1235");
        assert_eq!(sig(0.012345, 3), "0.0123");
        assert_eq!(sig(2.5, 4), "2.5");
        assert_eq!(sig(0.0, 4), "0");
    }
}
