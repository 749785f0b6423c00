//! The partitioned coverage: every unit grown by the pieces it received.
//! Where a piece meets its unit, the piece's vertices that lie on one of
//! the unit's edges are inserted there; then the unit and its pieces share
//! their common edges vertex for vertex, and their union drops those edges
//! exactly ([`crate::geometry::arrangement::coverage_union`]): no vertex
//! moves, the area is the sum of the areas. A unit that received nothing is
//! written as it was read, bit for bit.

use super::layer::CoverageRow;
use super::owners::Unit;
use crate::geometry::tolerance::SAME_POINT;
use crate::geometry::vector::norm;
use crate::geometry::Boundary;
use geo::{Area, BoundingRect, Coord, LineString, MultiPolygon, Polygon};
use rustc_hash::FxHashMap;

/// The `coverage` rows: every unit, in the order given, grown by the pieces
/// `grown` gives it (by FID).
pub fn assemble(units: &[Unit], grown: Vec<(Option<u64>, Polygon<f64>)>) -> Vec<CoverageRow> {
    let mut by_fid: FxHashMap<u64, Vec<Polygon<f64>>> = FxHashMap::default();
    for (fid, p) in grown {
        if let Some(f) = fid {
            by_fid.entry(f).or_default().push(p);
        }
    }
    units
        .iter()
        .map(|u| {
            let pieces = u.fid.and_then(|f| by_fid.remove(&f)).unwrap_or_default();
            let received: f64 = pieces.iter().map(|p| p.unsigned_area()).sum();
            let geometry = if pieces.is_empty() {
                u.geometry.clone()
            } else {
                grow(&u.geometry, &pieces)
            };
            CoverageRow {
                src_fid: u.fid,
                attributes: u.attributes.clone(),
                geometry,
                received,
            }
        })
        .collect()
}

/// `unit` and `pieces` as one, exactly.
fn grow(unit: &MultiPolygon<f64>, pieces: &[Polygon<f64>]) -> MultiPolygon<f64> {
    let extent = unit
        .bounding_rect()
        .map_or(0.0, |r| r.width().max(r.height()));
    let tol = SAME_POINT * extent;
    let vertices: Vec<Coord<f64>> = pieces
        .iter()
        .flat_map(|p| std::iter::once(p.exterior()).chain(p.interiors()))
        .flat_map(|r| r.0.iter().copied())
        .collect();
    let mut all: Vec<Polygon<f64>> = unit
        .0
        .iter()
        .map(|p| with_vertices(p, &vertices, tol))
        .collect();
    all.extend(pieces.iter().cloned());
    MultiPolygon(crate::geometry::arrangement::coverage_union(&all))
}

/// `p` with every point of `vertices` that lies on one of its edges (within
/// `tol`, not at its ends) inserted there.
fn with_vertices(p: &Polygon<f64>, vertices: &[Coord<f64>], tol: f64) -> Polygon<f64> {
    let b = Boundary::new(p);
    let mut inserts: FxHashMap<(u32, u32), Vec<Coord<f64>>> = FxHashMap::default();
    for &v in vertices {
        let Some((_, i, d)) = b.nearest_within(v, tol) else {
            continue;
        };
        let s = &b.segments()[i];
        if d <= tol && norm(v - s.a) > tol && norm(v - s.b) > tol {
            inserts.entry((s.ring, s.index)).or_default().push(v);
        }
    }
    if inserts.is_empty() {
        return p.clone();
    }
    let ring = |r: usize, l: &LineString<f64>| {
        let mut out = Vec::with_capacity(l.0.len());
        for (i, w) in l.0.windows(2).enumerate() {
            out.push(w[0]);
            if let Some(extra) = inserts.get(&(r as u32, i as u32)) {
                let d = w[1] - w[0];
                let t = |c: &Coord<f64>| (c.x - w[0].x) * d.x + (c.y - w[0].y) * d.y;
                let mut extra = extra.clone();
                extra.sort_by(|a, b| t(a).total_cmp(&t(b)));
                extra.dedup();
                out.extend(extra);
            }
        }
        out.push(l.0[l.0.len() - 1]);
        LineString(out)
    };
    Polygon::new(
        ring(0, p.exterior()),
        p.interiors()
            .iter()
            .enumerate()
            .map(|(k, r)| ring(k + 1, r))
            .collect(),
    )
}
