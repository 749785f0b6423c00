//! Units as real administrative data have them: covering the collapsed
//! polygon (the legal boundary runs somewhere inside the water), or
//! digitised against another version of its bank, or reprojected from
//! another CRS (the shared vertices off by round-off).
//!
//! Before the bank is given owners, every unit whose box comes within
//! `snap` of the polygon P is snapped onto P's boundary and cut by P
//! ([`crate::geometry::overlay`]): its vertices within `snap` of the bank
//! move onto it, P's vertices within `snap` of its edges are put into them,
//! and what it holds of P (A ∩ P) is cut out. What is left (A − P) meets P
//! along its bank exactly, so the bank's owners are found as on a clean
//! coverage; what a unit held of P is given by the rule like the rest of
//! P. The edits (moves, insertions) and the held pieces go with the result,
//! so that the coverage is written as `unit snapped − held + given`.

use super::owners::{with_inserted, Coverage, Inserts, Unit};
use super::UnitError;
use crate::geometry::overlay::{
    self, contact, overlay, snap_edges, snap_vertices, vertex_index, with_hole, BankInsert,
    Contact, Edits,
};
use crate::geometry::PreparedPolygon;
use geo::{Area, Coord, InteriorPoint, MultiPolygon, Polygon};

/// A unit near the collapsed polygon, snapped and cut.
#[derive(Debug, Clone)]
pub struct NearUnit {
    /// The unit's index in the coverage.
    pub index: u32,
    /// What is left of it outside the polygon.
    pub cut: Vec<Polygon<f64>>,
    /// How it was snapped.
    pub edits: Edits,
    /// What it held of the polygon.
    pub held: Vec<Polygon<f64>>,
}

/// The collapsed polygon with the points units were snapped onto, and the
/// units near it.
#[derive(Debug, Clone)]
pub struct Near {
    /// The polygon, with those points put into its edges.
    pub polygon: Polygon<f64>,
    /// The units within `snap` of its box, in coverage order.
    pub units: Vec<NearUnit>,
}

impl Near {
    /// The units near `p` in `cov`, snapped onto its bank within `snap`
    /// and cut by it (points within `tol` of an edge count as on it).
    /// Or why a unit could not be cut exactly (its pieces would not add up
    /// to it).
    pub fn of(p: &PreparedPolygon, cov: &Coverage, snap: f64, tol: f64) -> Result<Near, UnitError> {
        let b = p.boundary();
        let grow = Coord { x: snap, y: snap };
        let indices = cov.units_near(b.bbox_min() - grow, b.bbox_max() + grow);
        let units = cov.units();
        let mut edits = vec![Edits::default(); indices.len()];
        let mut into_p: Vec<BankInsert> = Vec::new();
        for (e, &k) in edits.iter_mut().zip(&indices) {
            snap_vertices(&units[k as usize].geometry, b, (snap, tol), e, &mut into_p);
        }
        let mut inserts = Inserts::default();
        for ((ring, index), c) in into_p {
            inserts.entry((ring, index)).or_default().push(c);
        }
        let polygon = with_inserted(p.polygon(), &inserts, |c| c);
        let points = vertex_index(&polygon);
        let bank = crate::geometry::Boundary::new(&polygon);
        let probe = geo::InteriorPoint::interior_point(&polygon).map(|q| q.0);
        let near: Result<Vec<NearUnit>, UnitError> = indices
            .iter()
            .zip(edits)
            .map(|(&k, mut e)| {
                let g = &units[k as usize].geometry;
                snap_edges(g, &points, (snap, tol), &mut e);
                let snapped = e.apply(g);
                // Most units of a clean coverage only meet the polygon
                // along its bank: nothing to cut, no overlay.
                match contact(&snapped, &bank, probe, tol) {
                    Contact::Apart => {
                        return Ok(NearUnit {
                            index: k,
                            cut: snapped.0,
                            edits: e,
                            held: Vec::new(),
                        })
                    }
                    // A lake inside a unit: a hole of it, no overlay of
                    // the whole unit (a country holds thousands).
                    Contact::Holds => {
                        if let Some(q) = probe {
                            return Ok(NearUnit {
                                index: k,
                                cut: with_hole(&snapped, &polygon, q),
                                edits: e,
                                held: vec![polygon.clone()],
                            });
                        }
                    }
                    Contact::Crosses => {}
                }
                let o = overlay(&snapped.0, &polygon, tol);
                let (whole, parts) = (
                    snapped.unsigned_area(),
                    overlay::area(&o.outside) + overlay::area(&o.inside),
                );
                if (whole - parts).abs() > 1e-9 * whole.max(p.polygon().unsigned_area()) {
                    return Err(UnitError::NotCutExactly {
                        fid: crate::feature::fid_text(units[k as usize].fid),
                        parts,
                        whole,
                    });
                }
                Ok(NearUnit {
                    index: k,
                    cut: o.outside,
                    edits: e,
                    held: o.inside,
                })
            })
            .collect();
        Ok(Near {
            polygon,
            units: near?,
        })
    }

    /// The near units, cut, as a coverage of their own (unit `i` of it is
    /// `self.units[i]`).
    pub fn coverage(&self, cov: &Coverage) -> Coverage {
        Coverage::new(
            self.units
                .iter()
                .map(|u| Unit {
                    fid: cov.units()[u.index as usize].fid,
                    geometry: MultiPolygon(u.cut.clone()),
                    attributes: Vec::new(),
                })
                .collect(),
        )
    }

    /// The first unit that holds more of the polygon than round-off (a
    /// piece whose mean width, area over half its perimeter, exceeds
    /// `tol`): its index in the coverage, the area it holds and a point
    /// inside that piece.
    pub fn first_overlap(&self, tol: f64) -> Option<(u32, f64, Coord<f64>)> {
        use geo::{Euclidean, Length};
        self.units.iter().find_map(|u| {
            let piece = u.held.iter().find(|h| {
                let perimeter: f64 = std::iter::once(h.exterior())
                    .chain(h.interiors())
                    .map(|r| Euclidean.length(r))
                    .sum();
                h.unsigned_area() > tol * perimeter / 2.0
            })?;
            let at = piece.interior_point()?.0;
            Some((u.index, overlay::area(&u.held), at))
        })
    }
}
