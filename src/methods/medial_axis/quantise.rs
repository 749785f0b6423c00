//! The integer grid boostvoronoi works on, and ∂P cut into segments on it.
//!
//! Coordinates are taken relative to the polygon's bounding-box corner and
//! multiplied by `scale = 2^k`, the largest power of two with
//! `extent · scale ≤ 2^27` (≈ 1.3e8), rounded, and shifted by [`OFFSET`]
//! (2^27) away from zero, where boostvoronoi's error bounds are relative
//! and fail for circle events near an axis. The grid spacing (the
//! method's coordinate resolution) is therefore `1 / scale < extent / 2^26
//! ≈ 1.5e-8 × extent`, whatever the position of the polygon on Earth. Powers
//! of two make the way back (`origin + (q − OFFSET) / scale`) exact up to one
//! rounding (`q − OFFSET` is exact for a point near the polygon).
//!
//! Rounding can break what boostvoronoi requires of its input (segments meet
//! only at shared endpoints), so the segments are cleaned on the grid:
//!
//! * consecutive vertices that round to the same point are merged;
//! * a vertex within [`SNAP`] grid units of another segment's interior — a
//!   ring touching another ring at a point, or a nearly touching one —
//!   splits that segment, so the touch becomes a shared endpoint;
//! * a segment traversed in both directions (a spike or sliver thinner than
//!   the grid) is removed;
//! * any remaining intersection is an error naming the place, instead of a
//!   diagram built on invalid input.

use crate::geometry::packed::{Bbox, PackedTree};
use geo::Coord;
use rustc_hash::FxHashMap as HashMap;
use std::ops::ControlFlow;

/// Vertices this close (grid units) to another segment's interior are put on it.
/// Rounding moves any point by at most √2/2 units, so a touch becomes a
/// near-touch of at most √2 units; 2 leaves a margin.
pub(super) const SNAP: i64 = 2;

/// A grid point.
pub(super) type Pt = [i64; 2];

/// A directed boundary segment on the grid; P's interior is on its left.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Seg {
    pub a: Pt,
    pub b: Pt,
    /// The input vertex `a` was rounded from (world coordinates).
    pub wa: Coord<f64>,
    /// The input vertex `b` was rounded from.
    pub wb: Coord<f64>,
}

/// The quantisation grid of one polygon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Grid {
    origin: Coord<f64>,
    scale: f64,
}

/// Largest grid coordinate: well inside `i32`, as boostvoronoi requires. A
/// finer grid (up to 2^30) costs about 25 % more time in boostvoronoi's exact
/// predicates on the training rivers for no visible gain.
const GRID_MAX: f64 = (1u64 << 27) as f64;

/// Added to every grid coordinate: the polygon lies in
/// `[OFFSET, OFFSET + GRID_MAX]` on both axes, so no circle event's centre is
/// near zero, where a relative error bound fails on a small absolute error
/// and boostvoronoi falls back to its exact (extended-integer) evaluation.
const OFFSET: i64 = 1 << 27;

impl Grid {
    /// The grid for a polygon with bounding-box corner `origin` and larger
    /// bounding-box side `extent` (> 0).
    pub fn new(origin: Coord<f64>, extent: f64) -> Option<Self> {
        if !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let k = (GRID_MAX / extent).log2().floor();
        if !(-1000.0..=1000.0).contains(&k) {
            return None;
        }
        let mut scale = 2f64.powi(k as i32);
        // log2 may round up at exact powers of two.
        while extent * scale > GRID_MAX {
            scale *= 0.5;
        }
        Some(Self { origin, scale })
    }

    /// Grid units per CRS unit.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The grid spacing in CRS units (the method's coordinate resolution).
    pub fn resolution(&self) -> f64 {
        1.0 / self.scale
    }

    /// The grid point nearest to `c`.
    pub fn quantise(&self, c: Coord<f64>) -> Pt {
        [
            ((c.x - self.origin.x) * self.scale).round() as i64 + OFFSET,
            ((c.y - self.origin.y) * self.scale).round() as i64 + OFFSET,
        ]
    }

    /// World coordinates of a grid-frame position.
    pub fn world(&self, x: f64, y: f64) -> Coord<f64> {
        let k = OFFSET as f64;
        Coord {
            x: self.origin.x + (x - k) / self.scale,
            y: self.origin.y + (y - k) / self.scale,
        }
    }

    /// A length in grid units as CRS units.
    pub fn length(&self, d: f64) -> f64 {
        d / self.scale
    }
}

/// Why the boundary cannot be put on the grid.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Crossing {
    /// Grid position near the problem.
    pub at: Pt,
}

/// Exact orientation of `c` relative to `a → b` (sign of the cross product).
pub(super) fn orient(a: Pt, b: Pt, c: Pt) -> i128 {
    let (ux, uy) = ((b[0] - a[0]) as i128, (b[1] - a[1]) as i128);
    let (vx, vy) = ((c[0] - a[0]) as i128, (c[1] - a[1]) as i128);
    ux * vy - uy * vx
}

fn dot(a: Pt, b: Pt, c: Pt) -> i128 {
    let (ux, uy) = ((b[0] - a[0]) as i128, (b[1] - a[1]) as i128);
    let (vx, vy) = ((c[0] - a[0]) as i128, (c[1] - a[1]) as i128);
    ux * vx + uy * vy
}

fn len2(a: Pt, b: Pt) -> i128 {
    dot(a, b, b)
}

/// The segments' boxes on the grid, widened by `pad` grid units.
fn boxes(segs: &[Seg], pad: f64) -> Vec<Bbox> {
    segs.iter()
        .map(|s| {
            [
                s.a[0].min(s.b[0]) as f64 - pad,
                s.a[1].min(s.b[1]) as f64 - pad,
                s.a[0].max(s.b[0]) as f64 + pad,
                s.a[1].max(s.b[1]) as f64 + pad,
            ]
        })
        .collect()
}

/// The segments of every ring (each closed, first == last), cleaned on the grid.
pub(super) fn segments<'a>(
    grid: &Grid,
    rings: impl Iterator<Item = &'a geo::LineString<f64>>,
) -> Result<Vec<Seg>, Crossing> {
    let mut segs = Vec::new();
    for ring in rings {
        let mut pts: Vec<(Pt, Coord<f64>)> = Vec::with_capacity(ring.0.len());
        for &c in &ring.0 {
            let q = grid.quantise(c);
            if pts.last().map(|l| l.0) != Some(q) {
                pts.push((q, c));
            }
        }
        while pts.len() > 1 && pts.first().map(|f| f.0) == pts.last().map(|l| l.0) {
            pts.pop();
        }
        if pts.len() < 2 {
            continue; // a ring smaller than the grid spacing
        }
        for i in 0..pts.len() {
            let (a, wa) = pts[i];
            let (b, wb) = pts[(i + 1) % pts.len()];
            segs.push(Seg { a, b, wa, wb });
        }
    }
    let segs = split_at_touches(segs);
    let segs = cancel_opposites(segs);
    check_no_crossing(&segs)?;
    Ok(segs)
}

/// [`split_at_touches`] looks a boundary of at least this many vertices up
/// on every core (a smaller one on one: most polygons, in a run that has a
/// thread per feature already).
const SPLIT_IN_PARALLEL: usize = 1 << 15;

/// Splits every segment whose interior passes within [`SNAP`] of a vertex.
fn split_at_touches(segs: Vec<Seg>) -> Vec<Seg> {
    let tree = PackedTree::new(&boxes(&segs, SNAP as f64));
    let mut vertices: Vec<(Pt, Coord<f64>)> = segs.iter().map(|s| (s.a, s.wa)).collect();
    vertices.sort_unstable_by_key(|v| v.0);
    vertices.dedup_by_key(|v| v.0);
    // (segment, position along it, vertex, its world coordinates)
    let splits_at = |&(v, wv): &(Pt, Coord<f64>)| {
        let mut splits: Vec<(usize, i128, Pt, Coord<f64>)> = Vec::new();
        let p = [v[0] as f64, v[1] as f64];
        let holds = |b: &Bbox| b[0] <= p[0] && p[0] <= b[2] && b[1] <= p[1] && p[1] <= b[3];
        tree.visit(holds, |i| {
            let i = i as usize;
            let s = segs[i];
            if v == s.a || v == s.b {
                return ControlFlow::<()>::Continue(());
            }
            let l2 = len2(s.a, s.b);
            let t = dot(s.a, s.b, v);
            if t <= 0 || t >= l2 {
                return ControlFlow::Continue(());
            }
            let o = orient(s.a, s.b, v);
            if o * o <= (SNAP as i128 * SNAP as i128) * l2 {
                splits.push((i, t, v, wv));
            }
            ControlFlow::Continue(())
        });
        splits
    };
    // A long boundary's vertices are looked up on every core (sorted below).
    let mut splits: Vec<(usize, i128, Pt, Coord<f64>)> = if vertices.len() >= SPLIT_IN_PARALLEL {
        use rayon::prelude::*;
        vertices.par_iter().flat_map_iter(splits_at).collect()
    } else {
        vertices.iter().flat_map(splits_at).collect()
    };
    if splits.is_empty() {
        return segs;
    }
    splits.sort_unstable_by_key(|s| (s.0, s.1, s.2));
    let mut out = Vec::with_capacity(segs.len() + splits.len());
    let mut k = 0;
    for (i, s) in segs.iter().enumerate() {
        let (mut cur, mut wcur) = (s.a, s.wa);
        while k < splits.len() && splits[k].0 == i {
            let (v, wv) = (splits[k].2, splits[k].3);
            if v != cur {
                out.push(Seg {
                    a: cur,
                    b: v,
                    wa: wcur,
                    wb: wv,
                });
                (cur, wcur) = (v, wv);
            }
            k += 1;
        }
        if cur != s.b {
            out.push(Seg {
                a: cur,
                b: s.b,
                wa: wcur,
                wb: s.wb,
            });
        }
    }
    out
}

/// Removes segments present in both directions (zero-width parts of ∂P) and
/// repeated copies of the same directed segment. Keeps the input order.
fn cancel_opposites(segs: Vec<Seg>) -> Vec<Seg> {
    let key = |s: &Seg| if s.a <= s.b { (s.a, s.b) } else { (s.b, s.a) };
    let mut net: HashMap<(Pt, Pt), i64> =
        HashMap::with_capacity_and_hasher(segs.len(), Default::default());
    for s in &segs {
        *net.entry(key(s)).or_insert(0) += if s.a <= s.b { 1 } else { -1 };
    }
    if net.len() == segs.len() {
        return segs;
    }
    segs.into_iter()
        .filter(|s| {
            let n = net.get_mut(&key(s)).expect("every segment was counted");
            let forward = s.a <= s.b;
            if (*n > 0 && forward) || (*n < 0 && !forward) {
                // Emit this direction once.
                *n = 0;
                true
            } else {
                false
            }
        })
        .collect()
}

fn on_segment(a: Pt, b: Pt, p: Pt) -> bool {
    orient(a, b, p) == 0
        && p[0] >= a[0].min(b[0])
        && p[0] <= a[0].max(b[0])
        && p[1] >= a[1].min(b[1])
        && p[1] <= a[1].max(b[1])
}

/// True when two segments meet anywhere except at one shared endpoint.
fn bad_pair(s: Seg, t: Seg) -> bool {
    let shared = [s.a, s.b]
        .iter()
        .filter(|p| **p == t.a || **p == t.b)
        .count();
    if shared == 2 {
        return true; // the same segment twice
    }
    if shared == 1 {
        // Only a collinear overlap beyond the shared point is a problem.
        let (p, q) = if s.a == t.a || s.a == t.b {
            (s.b, if s.a == t.a { t.b } else { t.a })
        } else {
            (s.a, if s.b == t.a { t.b } else { t.a })
        };
        return on_segment(t.a, t.b, p) || on_segment(s.a, s.b, q);
    }
    let (o1, o2) = (
        orient(s.a, s.b, t.a).signum(),
        orient(s.a, s.b, t.b).signum(),
    );
    let (o3, o4) = (
        orient(t.a, t.b, s.a).signum(),
        orient(t.a, t.b, s.b).signum(),
    );
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    on_segment(s.a, s.b, t.a)
        || on_segment(s.a, s.b, t.b)
        || on_segment(t.a, t.b, s.a)
        || on_segment(t.a, t.b, s.b)
}

/// The first segment (in order) that meets another one anywhere but at one
/// shared endpoint is reported, at its start.
fn check_no_crossing(segs: &[Seg]) -> Result<(), Crossing> {
    let first = PackedTree::first_pair_of(&boxes(segs, 0.0), |i, j| {
        bad_pair(segs[i as usize], segs[j as usize]).then_some(())
    });
    match first {
        Some((i, _, ())) => Err(Crossing {
            at: segs[i as usize].a,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::LineString;

    fn ring(pts: &[(f64, f64)]) -> LineString<f64> {
        let mut v: Vec<Coord<f64>> = pts.iter().map(|&(x, y)| Coord { x, y }).collect();
        v.push(v[0]);
        LineString(v)
    }

    #[test]
    fn grid_resolution_is_finer_than_2e8_of_the_extent() {
        for extent in [1e-3, 1.0, 10.0, 1234.5, 1e6, 4e7] {
            let g = Grid::new(Coord { x: 5e6, y: -3e6 }, extent).unwrap();
            assert!(extent * g.scale() <= GRID_MAX);
            assert!(extent * g.scale() > GRID_MAX / 2.0);
            assert!(g.resolution() < 1.5e-8 * extent);
            assert_eq!(g.scale().log2().fract(), 0.0);
        }
        assert!(Grid::new(Coord { x: 0.0, y: 0.0 }, 0.0).is_none());
    }

    #[test]
    fn touching_hole_splits_the_exterior_segment() {
        let g = Grid::new(Coord { x: 0.0, y: 0.0 }, 4.0).unwrap();
        // The hole's vertex (2, 0) lies on the exterior's bottom edge.
        let ext = ring(&[(0., 0.), (4., 0.), (4., 4.), (0., 4.)]);
        let hole = ring(&[(2., 0.), (1., 1.), (3., 1.)]);
        let segs = segments(&g, [&ext, &hole].into_iter()).unwrap();
        assert_eq!(segs.len(), 4 + 1 + 3);
        let v = g.quantise(Coord { x: 2.0, y: 0.0 });
        assert_eq!(segs.iter().filter(|s| s.a == v || s.b == v).count(), 4);
    }

    #[test]
    fn sub_grid_spike_vanishes() {
        let g = Grid::new(Coord { x: 0.0, y: 0.0 }, 4.0).unwrap();
        let tiny = g.resolution() * 0.1;
        let ext = ring(&[
            (0., 0.),
            (2., 0.),
            (2.0 + tiny, 3.0),
            (2.0 + 2.0 * tiny, 0.0),
            (4., 0.),
            (4., 4.),
            (0., 4.),
        ]);
        let segs = segments(&g, std::iter::once(&ext)).unwrap();
        let top_of_spike = (3.0 * g.scale()) as i64;
        assert!(segs
            .iter()
            .all(|s| s.a[1] != top_of_spike && s.b[1] != top_of_spike || s.a[1] == s.b[1]));
        assert_eq!(segs.len(), 4 + 1); // bottom edge split at the spike's foot
    }

    #[test]
    fn crossing_rings_are_reported() {
        let g = Grid::new(Coord { x: 0.0, y: 0.0 }, 4.0).unwrap();
        let ext = ring(&[(0., 0.), (4., 0.), (4., 4.), (0., 4.)]);
        let hole = ring(&[(1., 1.), (5., 2.), (1., 3.)]);
        assert!(segments(&g, [&ext, &hole].into_iter()).is_err());
    }
}
