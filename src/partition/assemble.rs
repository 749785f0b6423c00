//! The partitioned coverage: every unit grown by the pieces it received.
//! Where a piece meets its unit, the piece's vertices that lie on one of
//! the unit's edges are inserted there; then the unit and its pieces share
//! their common edges vertex for vertex, and their union drops those edges
//! exactly ([`crate::geometry::coverage::coverage_union`]): no vertex
//! moves, the area is the sum of the areas. A unit that received nothing is
//! written as it was read, bit for bit.

use super::layer::CoverageRow;
use super::owners::{with_inserted, Inserts, Unit};
use super::UnitError;
use crate::geometry::overlay::{self, signed_union, Edits};
use crate::geometry::tolerance::SAME_POINT;
use crate::geometry::vector::norm;
use crate::geometry::{Boundary, PreparedPolygon};
use geo::{Area, BoundingRect, Coord, MultiPolygon, Polygon};
use rustc_hash::FxHashMap;

/// What a collapsed polygon does to a unit of the coverage.
#[derive(Debug, Clone, PartialEq)]
pub enum Growth {
    /// A piece given to it.
    Given(Polygon<f64>),
    /// A piece it held, cut out of it (`overlap: cut`).
    Held(Polygon<f64>),
    /// How it was snapped onto a bank.
    Snapped(Edits),
}

/// Everything done to one unit.
#[derive(Default)]
struct Changes {
    given: Vec<Polygon<f64>>,
    held: Vec<Polygon<f64>>,
    edits: Edits,
}

/// The `coverage` rows: every unit, in the order given, snapped, with what
/// it held cut out and grown by the pieces `grown` gives it (by FID); or
/// the first unit that could not be made valid, with the reason.
pub fn assemble(
    units: &[Unit],
    grown: Vec<(Option<u64>, Growth)>,
) -> Result<Vec<CoverageRow>, UnitError> {
    let mut by_fid: FxHashMap<u64, Changes> = FxHashMap::default();
    for (fid, g) in grown {
        let Some(f) = fid else { continue };
        let c = by_fid.entry(f).or_default();
        match g {
            Growth::Given(p) => c.given.push(p),
            Growth::Held(p) => c.held.push(p),
            Growth::Snapped(e) => c.edits.merge(&e),
        }
    }
    units
        .iter()
        .map(|u| {
            let changes = u.fid.and_then(|f| by_fid.remove(&f)).unwrap_or_default();
            let received = overlay::area(&changes.given);
            let held = overlay::area(&changes.held);
            let geometry = if changes.given.is_empty()
                && changes.held.is_empty()
                && changes.edits.is_empty()
            {
                u.geometry.clone()
            } else if changes.held.is_empty() && changes.edits.is_empty() {
                grow(&u.geometry, &changes.given)
            } else {
                let g = changed(&u.geometry, &changes);
                checked(u, &g, &changes)?;
                g
            };
            Ok(CoverageRow {
                src_fid: u.fid,
                attributes: u.attributes.clone(),
                geometry,
                received,
                held,
            })
        })
        .collect()
}

/// A unit snapped, what it held cut out, what it was given put in.
fn changed(unit: &MultiPolygon<f64>, c: &Changes) -> MultiPolygon<f64> {
    let snapped = c.edits.apply(unit);
    let mut plus = snapped.0;
    plus.extend(c.given.iter().cloned());
    MultiPolygon(signed_union(&plus, &c.held, tolerance(c)))
}

/// The tolerance that puts a unit together again: `SAME_POINT` × the
/// smallest collapsed polygon's extent that changed it (each was cut and
/// partitioned at its own scale; a country's extent would merge vertices a
/// millimetre apart on a small lake), but never below what the coordinates
/// resolve.
fn tolerance(c: &Changes) -> f64 {
    let pieces = c.given.iter().chain(&c.held);
    let smallest = pieces
        .clone()
        .filter_map(|p| p.bounding_rect())
        .map(|r| r.width().max(r.height()))
        .fold(f64::INFINITY, f64::min);
    let largest = pieces
        .filter_map(|p| p.bounding_rect())
        .map(|r| {
            r.min()
                .x
                .abs()
                .max(r.min().y.abs())
                .max(r.max().x.abs())
                .max(r.max().y.abs())
        })
        .fold(0.0, f64::max);
    let resolution = 64.0 * f64::EPSILON * largest;
    match smallest.is_finite() {
        true => (SAME_POINT * smallest).max(resolution),
        false => resolution,
    }
}

/// Why a changed unit cannot be written: a part that is not a valid
/// polygon, or an area other than the unit's, less what it held, plus what
/// it was given.
fn checked(u: &Unit, g: &MultiPolygon<f64>, c: &Changes) -> Result<(), UnitError> {
    let fid = || crate::feature::fid_text(u.fid);
    for p in &g.0 {
        let problem = match PreparedPolygon::new(p) {
            Ok(pp) => crate::geometry::validity::problem(&pp),
            Err(e) => Some(e.to_string()),
        };
        if let Some(why) = problem {
            return Err(UnitError::NotValidGrown { fid: fid(), why });
        }
    }
    let want = c.edits.apply(&u.geometry).unsigned_area() - overlay::area(&c.held)
        + overlay::area(&c.given);
    let got = g.unsigned_area();
    let scale = u.geometry.unsigned_area() + overlay::area(&c.given);
    if (got - want).abs() > 1e-9 * scale.max(f64::MIN_POSITIVE) {
        return Err(UnitError::AreaNotKept {
            fid: fid(),
            got,
            want,
        });
    }
    Ok(())
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
    MultiPolygon(crate::geometry::coverage::coverage_union(&all))
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
