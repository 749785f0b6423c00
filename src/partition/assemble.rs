//! The partitioned coverage: every unit grown by the pieces it received.
//! Where a piece meets its unit, the piece's vertices that lie on one of
//! the unit's edges are inserted there; then the unit and its pieces share
//! their common edges vertex for vertex, and their union drops those edges
//! exactly ([`crate::geometry::arrangement::coverage_union`]): no vertex
//! moves, the area is the sum of the areas. A unit that received nothing is
//! written as it was read, bit for bit.

use super::layer::CoverageRow;
use super::owners::{with_inserted, Inserts, Unit};
use crate::geometry::tolerance::SAME_POINT;
use crate::geometry::vector::norm;
use crate::geometry::Boundary;
use geo::{Area, BoundingRect, Coord, MultiPolygon, Polygon};
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
    let mut inserts = Inserts::default();
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
    with_inserted(p, &inserts, |c| c)
}
