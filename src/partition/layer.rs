//! The layers a partition writes, declared next to the step: `coverage`
//! (every unit, grown by what it received), `boundaries` (the new
//! boundaries inside each collapsed polygon) and `given` (the area each
//! unit received from each polygon).

use crate::feature::Value;
use crate::layer::{
    col, fid, real, Attributes, Cell, ColumnType, GeometryKind, LayerDef, Shape, When,
};
use geo::{MultiLineString, MultiPolygon};

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

/// The `coverage` layer.
pub const COVERAGE: LayerDef<CoverageRow> = LayerDef {
    name: "coverage",
    when: When::Partition,
    geometry: GeometryKind::MultiPolygon,
    shape: |r| Some(Shape::MultiPolygon(&r.geometry)),
    attributes: Attributes::Neighbours(|r| &r.attributes),
    columns: &[
        col("src_fid", ColumnType::Int64, |r| fid(r.src_fid)),
        col("received", ColumnType::Real, |r| Cell::Real(r.received)),
        col("held", ColumnType::Real, |r| Cell::Real(r.held)),
    ],
};

/// One row of `boundaries`: the new boundary between two owners inside one
/// collapsed polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryRow {
    /// The collapsed polygon's FID.
    pub src_fid: Option<u64>,
    /// The unit on the lines' left, walking them (`None`: unowned).
    pub left_fid: Option<u64>,
    /// The unit on their right.
    pub right_fid: Option<u64>,
    /// The lines.
    pub geometry: MultiLineString<f64>,
    /// Their length.
    pub length: f64,
}

/// The `boundaries` layer.
pub const BOUNDARIES: LayerDef<BoundaryRow> = LayerDef {
    name: "boundaries",
    when: When::Partition,
    geometry: GeometryKind::MultiLineString,
    shape: |r| Some(Shape::Lines(&r.geometry)),
    attributes: Attributes::None,
    columns: &[
        col("src_fid", ColumnType::Int64, |r| fid(r.src_fid)),
        col("left_fid", ColumnType::Int64, |r| fid(r.left_fid)),
        col("right_fid", ColumnType::Int64, |r| fid(r.right_fid)),
        col("length", ColumnType::Real, |r| real(Some(r.length))),
    ],
};

/// One row of `given`: the area one collapsed polygon gave one unit.
#[derive(Debug, Clone, PartialEq)]
pub struct GivenRow {
    /// The collapsed polygon's FID.
    pub src_fid: Option<u64>,
    /// The unit's FID.
    pub unit_fid: Option<u64>,
    /// The area given.
    pub area: f64,
    /// The area of the polygon the unit held before (`overlap: cut`): how
    /// far the cartographic boundary moved from the legal one.
    pub held: f64,
}

/// The `given` layer (an attribute table).
pub const GIVEN: LayerDef<GivenRow> = LayerDef {
    name: "given",
    when: When::Partition,
    geometry: GeometryKind::None,
    shape: |_| None,
    attributes: Attributes::None,
    columns: &[
        col("src_fid", ColumnType::Int64, |r| fid(r.src_fid)),
        col("unit_fid", ColumnType::Int64, |r| fid(r.unit_fid)),
        col("area", ColumnType::Real, |r| real(Some(r.area))),
        col("held", ColumnType::Real, |r| real(Some(r.held))),
    ],
};
