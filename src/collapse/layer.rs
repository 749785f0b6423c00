//! The `areas` layer, declared next to the step that fills it.

use crate::feature::Value;
use crate::layer::{
    col, col_when, fid, int, text, Attributes, Cell, ColumnType, GeometryKind, LayerDef, Shape,
    When,
};

/// One row of the `areas` layer: a piece of a polygon kept as an area by
/// the `collapse` step.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Index of the polygon part (with `explode`).
    pub polygon_part: Option<usize>,
    /// Source attributes.
    pub attributes: Vec<Value>,
    /// The piece.
    pub geometry: geo::Polygon<f64>,
    /// Cuts on its boundary, where collapsed lines meet it.
    pub cuts: usize,
    /// With `input.merge_adjacent`: the source FIDs dissolved, comma-separated.
    pub members: Option<String>,
}

/// The `areas` layer (with a `collapse` step).
pub const AREAS: LayerDef<AreaRow> = LayerDef {
    name: "areas",
    when: When::Collapse,
    geometry: GeometryKind::Polygon,
    shape: |r| Some(Shape::Polygon(&r.geometry)),
    attributes: Attributes::Input(|r| &r.attributes),
    columns: &[
        col("src_fid", ColumnType::Int64, |r| fid(r.src_fid)),
        col_when(When::Explode, "polygon_part", ColumnType::Int32, |r| {
            r.polygon_part.map_or(Cell::Null, int)
        }),
        col("cuts", ColumnType::Int32, |r| int(r.cuts)),
        col_when(When::Merge, "members", ColumnType::Text, |r| {
            r.members.as_deref().map_or(Cell::Null, text)
        }),
    ],
};
