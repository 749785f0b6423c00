//! Geometry helpers shared by every method and step: ring normalisation
//! ([`ring`]), boundary densification ([`densify`]) and the spatial index of the
//! boundary ([`boundary`]) used for radii, containment, crossing tests, ray casts
//! and nearest-point queries.
//!
//! Everything here works on owned [`geo`] types; nothing touches GDAL.

pub mod arrangement;
pub mod boundary;
pub mod densify;
pub mod lanes;
pub mod packed;
pub mod ring;
pub mod validity;

pub use boundary::{Boundary, BoundarySegment, RayHit};

use geo::{Coord, Polygon};
use thiserror::Error;

/// Length of a vector: `√(x² + y²)`, without `hypot`'s care for overflow
/// (which costs several times as much and which projected coordinates never
/// need).
#[inline]
pub fn norm(d: Coord<f64>) -> f64 {
    (d.x * d.x + d.y * d.y).sqrt()
}

/// `d.x.hypot(d.y) <= tol`, the same answer bit for bit, with `hypot` only
/// when both components are within `tol`: `hypot` is never below the larger
/// component (a faithfully rounded `√(x² + y²) ≥ max(|x|, |y|)` cannot
/// round below that floating-point number), so a larger component decides
/// alone — as it does for nearly every pair of points compared with a
/// tolerance.
#[inline]
pub fn within_hypot(d: Coord<f64>, tol: f64) -> bool {
    d.x.abs() <= tol && d.y.abs() <= tol && d.x.hypot(d.y) <= tol
}

/// Why a polygon cannot be prepared for skeletonisation.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum GeometryError {
    /// The exterior ring has fewer than three distinct vertices or no area.
    #[error("degenerate polygon: the exterior ring has {0} distinct vertices and encloses no area (collinear, or a symmetric bow-tie); fix or remove the feature")]
    Degenerate(usize),
    /// A coordinate is NaN or infinite.
    #[error("non-finite coordinate in ring {ring}; fix the source geometry")]
    NonFinite {
        /// Ring index (0 = exterior).
        ring: usize,
    },
    /// The polygon is not valid (self-intersection, touching rings, …).
    #[error("invalid polygon: {0}; enable `prepare: {{ make_valid: true }}` to repair it")]
    Invalid(String),
}

/// A polygon normalised per SPEC §2 together with its boundary index.
///
/// Invariants: the exterior ring is counter-clockwise, holes are clockwise,
/// every ring is closed and has no repeated consecutive vertex, and every
/// ring has at least three distinct vertices.
#[derive(Debug, Clone)]
pub struct PreparedPolygon {
    polygon: Polygon<f64>,
    boundary: Boundary,
    extent: f64,
}

impl PreparedPolygon {
    /// Normalises `polygon` (orientation, closing, duplicate vertices, degenerate
    /// holes dropped) and builds its boundary index.
    pub fn new(polygon: &Polygon<f64>) -> Result<Self, GeometryError> {
        let polygon = validity::split_touches(&ring::normalise_polygon(polygon)?);
        let boundary = Boundary::new(&polygon);
        let extent = boundary.extent();
        Ok(Self {
            polygon,
            boundary,
            extent,
        })
    }

    /// The normalised polygon.
    pub fn polygon(&self) -> &Polygon<f64> {
        &self.polygon
    }

    /// The boundary index of all rings.
    pub fn boundary(&self) -> &Boundary {
        &self.boundary
    }

    /// The larger side of the polygon's bounding box (CRS units); the scale
    /// against which relative tolerances are expressed.
    pub fn extent(&self) -> f64 {
        self.extent
    }

    /// All rings (exterior first), each closed (first == last).
    pub fn rings(&self) -> impl Iterator<Item = &geo::LineString<f64>> {
        std::iter::once(self.polygon.exterior()).chain(self.polygon.interiors())
    }

    /// Total number of distinct vertices over all rings.
    pub fn vertex_count(&self) -> usize {
        self.rings().map(|r| r.0.len() - 1).sum()
    }

    /// Lower-left corner of the bounding box: methods that quantise or need
    /// well-conditioned arithmetic subtract it first (huge coordinates).
    pub fn origin(&self) -> Coord<f64> {
        self.boundary.bbox_min()
    }
}
