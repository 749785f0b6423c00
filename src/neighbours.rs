//! The coverage read beside the polygons (`input.neighbours`): units of a
//! polygon layer — administrative units, land-cover parcels, building
//! blocks — with their FIDs, geometries and fields, indexed by their boundary
//! segments and boxes. The command line's reader and the Python package
//! make it; a step that [needs it](crate::process::step::Needs::neighbours)
//! reads it (`partition` gives the polygons' area to its units).

use crate::feature::Value;
use geo::{BoundingRect, Coord, MultiPolygon};
use rstar::primitives::{GeomWithData, Line};
use rstar::{RTree, AABB};

/// Why a feature of `input.neighbours` cannot be a unit of the coverage
/// (`fid`: its FID, or `(no fid)`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NotAUnit {
    /// Its geometry is of another type.
    #[error("feature {fid} is not a polygon; the coverage is a layer of polygons")]
    NotAPolygon {
        /// The unit.
        fid: String,
    },
    /// A coordinate is NaN or infinite.
    #[error("feature {fid} has a coordinate that is not a finite number ({x}, {y}); fix or remove the unit")]
    NotFinite {
        /// The unit.
        fid: String,
        /// The coordinate (x).
        x: f64,
        /// The coordinate (y).
        y: f64,
    },
}

/// The default of `input.neighbours.snap`, relative to a collapsed
/// polygon's extent: [`ROUND_OFF`](crate::geometry::tolerance::ROUND_OFF).
pub const DEFAULT_SNAP: f64 = crate::geometry::tolerance::ROUND_OFF;

/// One unit of the neighbours' coverage.
#[derive(Debug, Clone, PartialEq)]
pub struct Unit {
    /// Its FID in the coverage's source.
    pub fid: Option<u64>,
    /// Its geometry, as read.
    pub geometry: MultiPolygon<f64>,
    /// Its fields, in the source's order.
    pub attributes: Vec<Value>,
}

/// A unit's geometry as a coverage takes it: NULL and EMPTY are a unit
/// without area, polygons and multipolygons are taken as they are, and
/// anything else — another type, a NaN or infinite coordinate — is why
/// the unit cannot be (`fid` names it in the message).
pub fn unit_geometry(
    fid: Option<u64>,
    g: Option<&geo::Geometry<f64>>,
) -> Result<MultiPolygon<f64>, NotAUnit> {
    use geo::{CoordsIter, HasDimensions};
    let name = || crate::feature::fid_text(fid);
    let m = match g {
        None => return Ok(MultiPolygon(Vec::new())),
        Some(g) if g.is_empty() => return Ok(MultiPolygon(Vec::new())),
        Some(geo::Geometry::Polygon(p)) => MultiPolygon(vec![p.clone()]),
        Some(geo::Geometry::MultiPolygon(m)) => m.clone(),
        Some(_) => return Err(NotAUnit::NotAPolygon { fid: name() }),
    };
    if let Some(c) = m
        .coords_iter()
        .find(|c| !(c.x.is_finite() && c.y.is_finite()))
    {
        return Err(NotAUnit::NotFinite {
            fid: name(),
            x: c.x,
            y: c.y,
        });
    }
    Ok(MultiPolygon(
        m.0.into_iter().filter(|p| !p.is_empty()).collect(),
    ))
}

/// A unit's boundary segment in the index: the unit and its two ends.
pub(crate) type Indexed = GeomWithData<Line<[f64; 2]>, u32>;

/// The neighbours' coverage, indexed by the units' boundary segments and
/// boxes.
#[derive(Debug)]
pub struct Coverage {
    units: Vec<Unit>,
    segments: RTree<Indexed>,
    boxes: RTree<crate::geometry::IndexedBox>,
    snap: Option<f64>,
}

impl PartialEq for Coverage {
    fn eq(&self, other: &Self) -> bool {
        self.units == other.units
    }
}

impl Coverage {
    /// The coverage of `units`.
    pub fn new(units: Vec<Unit>) -> Self {
        let mut segs = Vec::new();
        for (k, u) in units.iter().enumerate() {
            for p in &u.geometry.0 {
                for r in std::iter::once(p.exterior()).chain(p.interiors()) {
                    for w in r.0.windows(2) {
                        if w[0] != w[1] {
                            segs.push(GeomWithData::new(
                                Line::new([w[0].x, w[0].y], [w[1].x, w[1].y]),
                                k as u32,
                            ));
                        }
                    }
                }
            }
        }
        let boxes = crate::geometry::box_index(units.iter().map(|u| u.geometry.bounding_rect()));
        Self {
            units,
            segments: RTree::bulk_load(segs),
            boxes,
            snap: None,
        }
    }

    /// The coverage with `input.neighbours.snap`: unit vertices and edges
    /// within this distance (CRS units) of a collapsed polygon's bank are
    /// moved onto it (`None`: [`DEFAULT_SNAP`] × the polygon's extent).
    pub fn with_snap(mut self, snap: Option<f64>) -> Self {
        self.snap = snap;
        self
    }

    /// The snapping distance for a collapsed polygon of `extent`.
    pub fn snap_for(&self, extent: f64) -> f64 {
        self.snap.unwrap_or(DEFAULT_SNAP * extent)
    }

    /// The units whose box meets the box `lo`–`hi`, in index order.
    pub fn units_near(&self, lo: Coord<f64>, hi: Coord<f64>) -> Vec<u32> {
        let env = AABB::from_corners([lo.x, lo.y], [hi.x, hi.y]);
        let mut near: Vec<u32> = self
            .boxes
            .locate_in_envelope_intersecting(&env)
            .map(|b| b.data as u32)
            .collect();
        near.sort_unstable();
        near
    }

    /// The units, in the order given.
    pub fn units(&self) -> &[Unit] {
        &self.units
    }

    /// The units' segments whose box meets the box around `a`–`b` grown by
    /// `tol`.
    pub(crate) fn near(
        &self,
        a: Coord<f64>,
        b: Coord<f64>,
        tol: f64,
    ) -> impl Iterator<Item = &Indexed> {
        let env = AABB::from_corners(
            [a.x.min(b.x) - tol, a.y.min(b.y) - tol],
            [a.x.max(b.x) + tol, a.y.max(b.y) + tol],
        );
        self.segments.locate_in_envelope_intersecting(&env)
    }
}
