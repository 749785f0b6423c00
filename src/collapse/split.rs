//! Step 4 of the module documentation: the cuts at every change of class,
//! the polygon sliced along them into pieces, the pieces kept or collapsed
//! by the stretches they hold, and the skeleton split at the change points.

use super::classify::Samples;
use super::{Area, PartCollapse};
use crate::geometry::PreparedPolygon;
use crate::graph::GraphBuilder;
use geo::{BoundingRect, Coord, Intersects, LineString, Polygon, Rect};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::float::slice::FloatSlice;
use std::collections::HashSet;

/// How far a cut continues beyond ∂P, relative to its radius, so that the
/// slicing sees it cross the boundary rather than end on it.
const OVERSHOOT: f64 = 1e-4;

/// A change of class on segment `segment` of the samples, at `point`.
struct Change {
    segment: usize,
    point: Coord<f64>,
    /// The cut, when both contacts exist.
    cut: Option<LineString<f64>>,
}

/// The collapse of one polygon part from its classified samples.
pub(super) fn split(s: &Samples, p: &PreparedPolygon) -> PartCollapse {
    let changes: Vec<Change> = s.changes().map(|i| change(s, p, i)).collect();
    let cuts: Vec<LineString<f64>> = changes.iter().filter_map(|c| c.cut.clone()).collect();
    let pieces = if cuts.is_empty() {
        vec![p.polygon().clone()]
    } else {
        slice(p.polygon(), &cuts)
    };
    // One representative sample per stretch, far from the cuts and from ∂P.
    let stretches = s.stretches();
    let ends: HashSet<u32> = changes
        .iter()
        .flat_map(|c| {
            let (a, b, _) = s.segments[c.segment];
            [a, b]
        })
        .collect();
    let d_cut = s.distances(|i, _| ends.contains(&(i as u32)));
    let mut rep: std::collections::HashMap<usize, (usize, f64)> = Default::default();
    if let Some(first) = stretches.first() {
        for &(a, _, _) in &s.segments {
            let i = a as usize;
            let score = d_cut[i].min(s.r[i]);
            let e = rep.entry(first.labels[i]).or_insert((i, f64::NEG_INFINITY));
            if score > e.1 {
                *e = (i, score);
            }
        }
    }
    let boxes: Vec<Rect<f64>> = pieces
        .iter()
        .map(|q| q.bounding_rect().expect("a piece has vertices"))
        .collect();
    let piece_of = |c: Coord<f64>| {
        (0..pieces.len()).find(|&k| boxes[k].intersects(&c) && pieces[k].intersects(&c))
    };
    let mut holds_wide = vec![false; pieces.len()];
    let mut holds_any = vec![false; pieces.len()];
    let mut rep_piece: std::collections::HashMap<usize, Option<usize>> = Default::default();
    for st in &stretches {
        let Some(&(i, _)) = rep.get(&st.root) else {
            continue;
        };
        let k = piece_of(s.pos[i]);
        if let Some(k) = k {
            holds_any[k] = true;
            holds_wide[k] |= !st.narrow;
        }
        rep_piece.insert(st.root, k);
    }
    let kept_piece: Vec<bool> = (0..pieces.len())
        .map(|k| holds_wide[k] || !holds_any[k])
        .collect();
    // A sample is collapsed when narrow and its stretch's piece is not kept.
    let labels = stretches.first().map(|st| st.labels.clone());
    let collapsed = |i: usize| {
        s.narrow[i]
            && labels.as_ref().is_some_and(|l| {
                rep_piece
                    .get(&l[i])
                    .copied()
                    .flatten()
                    .is_none_or(|k| !kept_piece[k])
            })
    };
    let (collapsed_lines, kept_lines) = lines(s, &changes, collapsed);
    let kept: Vec<Polygon<f64>> = pieces
        .into_iter()
        .zip(&kept_piece)
        .filter(|(_, &k)| k)
        .map(|(polygon, _)| polygon)
        .collect();
    let areas = merge(kept)
        .into_iter()
        .map(|polygon| {
            let n = changes
                .iter()
                .filter(|c| c.cut.is_some() && on_boundary(&polygon, c.point, p.extent()))
                .count();
            Area { polygon, cuts: n }
        })
        .collect();
    PartCollapse {
        collapsed: collapsed_lines,
        kept: kept_lines,
        areas,
        cuts,
        ..PartCollapse::default()
    }
}

/// `c` lies on the boundary of `polygon` (within the slicing's rounding).
fn on_boundary(polygon: &Polygon<f64>, c: Coord<f64>, extent: f64) -> bool {
    use geo::{Distance, Euclidean};
    let tol = 1e-7 * extent;
    let Some(b) = polygon.bounding_rect() else {
        return false;
    };
    let (lo, hi) = (b.min(), b.max());
    if c.x < lo.x - tol || c.x > hi.x + tol || c.y < lo.y - tol || c.y > hi.y + tol {
        return false;
    }
    std::iter::once(polygon.exterior())
        .chain(polygon.interiors())
        .any(|r| Euclidean.distance(&geo::Point(c), r) <= tol)
}

/// The change on segment `i`: where the width crosses the collapse width
/// (the segment's middle when it does not), and the cut through it.
fn change(s: &Samples, p: &PreparedPolygon, i: usize) -> Change {
    let (a, b, _) = s.segments[i];
    let (a, b) = (a as usize, b as usize);
    let (da, db) = (2.0 * s.r[a] - s.width, 2.0 * s.r[b] - s.width);
    let t = if (da < 0.0) != (db < 0.0) && da != db {
        da / (da - db)
    } else {
        0.5
    };
    // Never on a sample: a cut through a junction would split its legs.
    let t = t.clamp(0.1, 0.9);
    let point = super::lerp(s.pos[a], s.pos[b], t);
    let d = s.pos[b] - s.pos[a];
    let normal = Coord { x: -d.y, y: d.x };
    let boundary = p.boundary();
    let r = boundary.distance(point);
    let cut = (r > 0.0)
        .then(|| {
            let (left, _) = boundary.nearest_in_half_plane(point, normal)?;
            let (right, _) = boundary.nearest_in_half_plane(point, -normal)?;
            let beyond = |c: Coord<f64>| c + (c - point) * OVERSHOOT;
            (left != point && right != point)
                .then(|| LineString(vec![beyond(left), left, point, right, beyond(right)]))
        })
        .flatten();
    Change {
        segment: i,
        point,
        cut,
    }
}

/// A polygon's rings as i_overlay contours (not closed).
fn contours(polygon: &Polygon<f64>) -> Vec<Vec<[f64; 2]>> {
    let ring = |l: &LineString<f64>| -> Vec<[f64; 2]> {
        let n = l.0.len().saturating_sub(1);
        l.0[..n].iter().map(|c| [c.x, c.y]).collect()
    };
    let mut shape = vec![ring(polygon.exterior())];
    shape.extend(polygon.interiors().iter().map(ring));
    shape
}

/// i_overlay shapes (outer contour, then holes) as polygons.
fn polygons(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Vec<Polygon<f64>> {
    let closed = |c: &Vec<[f64; 2]>| {
        let mut v: Vec<Coord<f64>> = c.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
        if let Some(&f) = v.first() {
            v.push(f);
        }
        LineString(v)
    };
    shapes
        .iter()
        .filter(|contours| !contours.is_empty())
        .map(|contours| {
            Polygon::new(
                closed(&contours[0]),
                contours[1..].iter().map(closed).collect(),
            )
        })
        .collect()
}

/// `polygon` sliced along `cuts` into pieces.
fn slice(polygon: &Polygon<f64>, cuts: &[LineString<f64>]) -> Vec<Polygon<f64>> {
    let strings: Vec<Vec<[f64; 2]>> = cuts
        .iter()
        .map(|c| c.0.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    polygons(contours(polygon).slice_by(&strings, FillRule::NonZero))
}

/// Kept pieces that share a cut (both its sides wide, as where cuts meet
/// at a junction) merged into one area.
fn merge(pieces: Vec<Polygon<f64>>) -> Vec<Polygon<f64>> {
    if pieces.len() < 2 {
        return pieces;
    }
    let shapes: Vec<Vec<Vec<[f64; 2]>>> = pieces.iter().map(contours).collect();
    polygons(shapes.simplify_shape(FillRule::NonZero))
}

/// The skeleton split at the change points into collapsed lines and lines
/// through kept areas, without the vertices the sampling inserted.
fn lines(
    s: &Samples,
    changes: &[Change],
    collapsed: impl Fn(usize) -> bool,
) -> (Vec<LineString<f64>>, Vec<LineString<f64>>) {
    let mut parts = [GraphBuilder::new(), GraphBuilder::new()];
    let split_at: std::collections::HashMap<usize, Coord<f64>> =
        changes.iter().map(|c| (c.segment, c.point)).collect();
    for (i, &(a, b, _)) in s.segments.iter().enumerate() {
        let (a, b) = (a as usize, b as usize);
        let side = |k: usize| usize::from(!collapsed(k));
        match split_at.get(&i) {
            Some(&q) => {
                parts[side(a)].segment(s.pos[a], q);
                parts[side(b)].segment(q, s.pos[b]);
            }
            None if side(a) == side(b) => {
                parts[side(a)].segment(s.pos[a], s.pos[b]);
            }
            // A narrow stretch inside a kept piece meets a wide one.
            None => {
                let q = super::lerp(s.pos[a], s.pos[b], 0.5);
                parts[side(a)].segment(s.pos[a], q);
                parts[side(b)].segment(q, s.pos[b]);
            }
        }
    }
    let inserted: HashSet<(u64, u64)> = (0..s.pos.len())
        .filter(|&i| s.inserted[i])
        .map(|i| (s.pos[i].x.to_bits(), s.pos[i].y.to_bits()))
        .collect();
    let [c, k] = parts.map(|b| {
        b.finish_raw()
            .to_multilinestring()
            .0
            .into_iter()
            .map(|l| {
                let n = l.0.len();
                LineString(
                    l.0.iter()
                        .enumerate()
                        .filter(|&(j, p)| {
                            j == 0
                                || j == n - 1
                                || !inserted.contains(&(p.x.to_bits(), p.y.to_bits()))
                        })
                        .map(|(_, p)| *p)
                        .collect(),
                )
            })
            .collect()
    });
    (c, k)
}
