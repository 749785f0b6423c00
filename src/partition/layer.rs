//! The layers a partition writes, declared next to the step: `coverage`
//! (every unit, grown by what it received), `boundaries` (the new
//! boundaries inside each collapsed polygon), `given` (the area each unit
//! received from each polygon) and `areas` (what stays a polygon: the wide
//! parts and what no unit takes).

use crate::feature::Value;
use crate::layer::{ColumnType, Fields, GeometryKind, StepLayer};
use geo::MultiPolygon;

/// One row of `coverage`: a unit of `input.neighbours`, grown by the
/// pieces it received (unchanged, bit for bit, when it received none).
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageRow {
    /// The unit's FID.
    pub src_fid: Option<u64>,
    /// Its fields.
    pub attributes: Vec<Value>,
    /// Its geometry.
    pub geometry: MultiPolygon<f64>,
    /// The area it received (0 for none).
    pub received: f64,
    /// The area of the collapsed polygons it held before (`overlap: cut`;
    /// 0 for none): cut out of it and given by the rule.
    pub held: f64,
}

/// The `coverage` layer: the units' fields, `src_fid` (the unit's), then
/// these columns.
pub const COVERAGE: StepLayer = StepLayer {
    name: "coverage",
    geometry: GeometryKind::MultiPolygon,
    fields: Some(Fields::Neighbours),
    columns: &[("received", ColumnType::Real), ("held", ColumnType::Real)],
};

/// The `boundaries` layer: the new boundary between two owners inside one
/// collapsed polygon (`src_fid`), the units on the lines' left and right
/// walking them (NULL: unowned), and the lines' length.
pub const BOUNDARIES: StepLayer = StepLayer {
    name: "boundaries",
    geometry: GeometryKind::MultiLineString,
    fields: None,
    columns: &[
        ("left_fid", ColumnType::Int64),
        ("right_fid", ColumnType::Int64),
        ("length", ColumnType::Real),
    ],
};

/// The `given` layer (an attribute table): the area one collapsed polygon
/// (`src_fid`) gave one unit, and the area of it the unit held before
/// (`overlap: cut`): how far the cartographic boundary moved from the legal
/// one.
pub const GIVEN: StepLayer = StepLayer {
    name: "given",
    geometry: GeometryKind::None,
    fields: None,
    columns: &[
        ("unit_fid", ColumnType::Int64),
        ("area", ColumnType::Real),
        ("held", ColumnType::Real),
    ],
};

/// The `areas` layer of a partition: what stays a polygon, with the
/// collapsed polygon's fields — `wide` (a part wider than `width`, with the
/// cuts on its boundary) or `unowned` (nearest to bank no unit owns).
pub const AREAS: StepLayer = StepLayer {
    name: "areas",
    geometry: GeometryKind::Polygon,
    fields: Some(Fields::Input),
    columns: &[("cuts", ColumnType::Int32), ("kind", ColumnType::Text)],
};

/// Every layer of the step.
pub const LAYERS: &[StepLayer] = &[COVERAGE, BOUNDARIES, GIVEN, AREAS];
