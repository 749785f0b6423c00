//! Geometry helpers shared by every method and step: ring normalisation
//! (`ring`), boundary densification ([`densify`]) and the spatial index of the
//! boundary ([`boundary`]) used for radii, containment, crossing tests, ray casts
//! and nearest-point queries.
//!
//! The ground floor, which every other file here and every layer above
//! builds on and which imports nothing of the project: vector arithmetic
//! ([`vector`]), segment predicates and their tie rules ([`segment`]) and
//! the table of tolerances ([`tolerance`]). The boundary index is a façade
//! ([`Boundary`]) over three backends: the packed R-tree (`packed`), the
//! scalar passes over few segments (in `boundary`) and the same passes four
//! segments at a time (`lanes`); `packed` and `lanes` import only the
//! ground floor.
//!
//! Everything here works on owned [`geo`] types; nothing touches GDAL.

pub(crate) mod arrangement;
pub mod boundary;
pub mod coverage;
pub mod densify;
pub mod key;
pub(crate) mod lanes;
pub mod overlay;
pub(crate) mod packed;
pub mod parts;
pub(crate) mod ring;
pub mod segment;
pub mod tolerance;
pub(crate) mod validity;
pub mod vector;

pub use boundary::{Boundary, RayHit};
pub use key::CoordKey;
pub use segment::BoundarySegment;
pub use vector::{norm, within_hypot};

use geo::{Coord, Polygon, Rect};
use rstar::primitives::{GeomWithData, Rectangle};
use thiserror::Error;

/// A box in a [`box_index`], with the place of its item.
pub type IndexedBox = GeomWithData<Rectangle<[f64; 2]>, usize>;

/// An R-tree of the boxes of items by their place in `rects` (an item
/// without a box, NULL or empty, is left out): the polygons of a layer,
/// the units of a coverage.
pub fn box_index(rects: impl IntoIterator<Item = Option<Rect<f64>>>) -> rstar::RTree<IndexedBox> {
    rstar::RTree::bulk_load(
        rects
            .into_iter()
            .enumerate()
            .filter_map(|(i, r)| {
                let r = r?;
                Some(GeomWithData::new(
                    Rectangle::from_corners([r.min().x, r.min().y], [r.max().x, r.max().y]),
                    i,
                ))
            })
            .collect(),
    )
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
