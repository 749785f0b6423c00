//! The output GeoPackage (SPEC §9): the layers every run can write
//! (`layers`, described as data with [`crate::layer::LayerDef`]), the rows
//! a feature produces ([`Rows`]), every layer seen the same way whatever
//! its rows ([`Layer`]), the [`Plan`] of what a run writes, and a layer's
//! rows as columns ([`columns`]: the Python package's table).
//!
//! Nothing here touches GDAL.

pub mod columns;
mod layers;
mod plan;
mod rows;

pub use crate::layer::{
    col, col_when, Cell, Column, ColumnType, GeometryKind, LayerDef, Shape, StepLayer, StepRow,
    When,
};
pub use layers::{
    name, BarRow, CandidateRow, RejectedRow, RunRecord, Scored, SkeletonRow, WidthRow, BARS,
    CANDIDATES, REJECTED, RUNS, SKELETONS, WIDTHS,
};
pub use plan::{source_names, Plan};
pub use rows::{
    Builtin, ColumnInfo, ExtraRow, Kept, Layer, Rows, BUILTIN, CANDIDATE_LAYER, SKELETON_LAYER,
};
