//! The `collapse` step: map production's partial collapse — a polygon
//! replaced by its skeleton line where it is narrower than the collapse
//! `width`, kept as an area where it is wider, the two meeting on cuts
//! across it. The geometry (the rule, the cuts, the exact split) is
//! [`crate::narrow`], which `partition` shares; the step adds its options
//! in the pipeline file, its place after `select` (on the medial axis's
//! lines, within the budget of the steps after `select`), and the `areas`
//! layer.

mod layer;

pub use crate::narrow::{
    collapse, collapse_within, Area, CollapseMode, CollapseParams, PartCollapse,
};
pub use layer::{AreaRow, AREAS};
