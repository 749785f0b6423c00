//! The layers every run can write (SPEC §9), described as data: the
//! skeleton layer, `candidates`, `bars`, `widths`, `rejected` and the run
//! record. The steps' own layers are declared next to their code
//! (`collapse::AREAS`, `connect::CONNECTIONS`, a registered step's
//! [`crate::layer::StepLayer`]s).
//!
//! Rows are plain data made by the per-feature work ([`crate::process`]);
//! nothing here touches GDAL.

use crate::feature::Value;
use crate::layer::{
    col, col_when, fid, int, real, text, Attributes, Cell, Column, ColumnType, GeometryKind,
    LayerDef, Shape, When,
};
use crate::score::Scores;
use ColumnType::{Int32, Int64, Real, Text};

/// The names of the columns that are read back (`io::readback`) as well as
/// written: one spelling for both.
pub mod name {
    /// The source feature's FID.
    pub const SRC_FID: &str = "src_fid";
    /// The polygon part (with `explode`).
    pub const POLYGON_PART: &str = "polygon_part";
    /// The method.
    pub const METHOD: &str = "method";
    /// Whether the candidate was chosen.
    pub const CHOSEN: &str = "chosen";
    /// Bars N.
    pub const BARS: &str = "bars";
    /// Hits n.
    pub const HITS: &str = "hits";
    /// n / N.
    pub const COVERAGE: &str = "coverage";
    /// s.
    pub const DEVIATION: &str = "deviation";
    /// S.
    pub const DEVIATION_PARTS: &str = "deviation_parts";
    /// SZ.
    pub const DISTORTION_SUM: &str = "distortion_sum";
    /// Z.
    pub const DISTORTION: &str = "distortion";
    /// Connected components.
    pub const COMPONENTS: &str = "components";
    /// Legs before pruning.
    pub const LEGS_RAW: &str = "legs_raw";
    /// Legs.
    pub const LEGS: &str = "legs";
    /// MakeValid changed the input.
    pub const REPAIRED: &str = "repaired";
    /// Why the scores are missing.
    pub const NOTE: &str = "note";
    /// Collapsed (1) or kept (0) lines.
    pub const COLLAPSED: &str = "collapsed";
    /// Merged members.
    pub const MEMBERS: &str = "members";
    /// A method's error.
    pub const ERROR: &str = "error";
    /// d_L.
    pub const D_LEFT: &str = "d_left";
    /// d_P.
    pub const D_RIGHT: &str = "d_right";
    /// Δd.
    pub const DELTA_D: &str = "delta_d";
    /// z.
    pub const Z: &str = "z";
    /// The branch hit.
    pub const BRANCH: &str = "branch";

    /// The run record's columns.
    pub mod run {
        /// The pipeline name.
        pub const NAME: &str = "name";
        /// Start, UTC.
        pub const STARTED_UTC: &str = "started_utc";
        /// End, UTC.
        pub const FINISHED_UTC: &str = "finished_utc";
        /// Tool version.
        pub const TOOL_VERSION: &str = "tool_version";
        /// The pipeline text.
        pub const PIPELINE: &str = "pipeline";
        /// Input source and layer, for people.
        pub const INPUT: &str = "input";
        /// The input source, absolute.
        pub const INPUT_SOURCE: &str = "input_source";
        /// The input layer.
        pub const INPUT_LAYER: &str = "input_layer";
        /// `input.reproject`.
        pub const INPUT_REPROJECT: &str = "input_reproject";
        /// The skeleton layer name.
        pub const SKELETON_LAYER: &str = "skeleton_layer";
        /// Features read.
        pub const FEATURES_READ: &str = "features_read";
        /// Features written.
        pub const FEATURES_WRITTEN: &str = "features_written";
        /// Features rejected.
        pub const FEATURES_REJECTED: &str = "features_rejected";
        /// Features filtered.
        pub const FEATURES_FILTERED: &str = "features_filtered";
        /// Worker threads.
        pub const THREADS: &str = "threads";
        /// Wall time.
        pub const ELAPSED_S: &str = "elapsed_s";
        /// Step times, JSON.
        pub const STAGE_SECONDS: &str = "stage_seconds";
        /// The area of the collapsed polygons the units held before a
        /// partition cut it out of them (NULL: no partition).
        pub const AREA_HELD: &str = "area_held";
    }
}

/// A row with the paper's scores.
pub trait Scored {
    /// The scores, when the pipeline scores.
    fn scores(&self) -> Option<&Scores>;
}

fn s_bars<R: Scored>(r: &R) -> Cell {
    r.scores().map_or(Cell::Null, |s| int(s.bars))
}
fn s_hits<R: Scored>(r: &R) -> Cell {
    r.scores().map_or(Cell::Null, |s| int(s.hits))
}
fn s_coverage<R: Scored>(r: &R) -> Cell {
    real(r.scores().map(|s| s.coverage))
}
fn s_deviation<R: Scored>(r: &R) -> Cell {
    real(r.scores().map(|s| s.deviation))
}
fn s_deviation_parts<R: Scored>(r: &R) -> Cell {
    real(r.scores().map(|s| s.deviation_parts))
}
fn s_distortion_sum<R: Scored>(r: &R) -> Cell {
    real(r.scores().map(|s| s.distortion_sum))
}
fn s_distortion<R: Scored>(r: &R) -> Cell {
    real(r.scores().map(|s| s.distortion))
}

/// The score columns of a [`Scored`] row type, in SPEC order.
macro_rules! score_columns {
    ($r:ty) => {
        [
            col(name::BARS, Int64, s_bars::<$r>),
            col(name::HITS, Int64, s_hits::<$r>),
            col(name::COVERAGE, Real, s_coverage::<$r>),
            col(name::DEVIATION, Real, s_deviation::<$r>),
            col(name::DEVIATION_PARTS, Real, s_deviation_parts::<$r>),
            col(name::DISTORTION_SUM, Real, s_distortion_sum::<$r>),
            col(name::DISTORTION, Real, s_distortion::<$r>),
        ]
    };
}

/// Concatenates column arrays into one static slice.
macro_rules! columns {
    ($r:ty; $($part:expr),+ $(,)?) => {{
        const PARTS: &[&[Column<$r>]] = &[$(&$part),+];
        const N: usize = {
            let (mut n, mut p) = (0, 0);
            while p < PARTS.len() {
                n += PARTS[p].len();
                p += 1;
            }
            n
        };
        const ALL: [Column<$r>; N] = {
            let mut out = [PARTS[0][0]; N];
            let (mut i, mut p) = (0, 0);
            while p < PARTS.len() {
                let mut k = 0;
                while k < PARTS[p].len() {
                    out[i] = PARTS[p][k];
                    i += 1;
                    k += 1;
                }
                p += 1;
            }
            out
        };
        &ALL
    }};
}

/// One row of the skeleton layer.
#[derive(Debug, Clone, PartialEq)]
pub struct SkeletonRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Index of the polygon part (with `explode`).
    pub polygon_part: Option<usize>,
    /// Source attributes.
    pub attributes: Vec<Value>,
    /// The skeleton.
    pub geometry: geo::MultiLineString<f64>,
    /// The chosen method.
    pub method: String,
    /// Its scores, when scored.
    pub scores: Option<Scores>,
    /// Connected components of the skeleton.
    pub components: usize,
    /// Legs of the skeleton.
    pub legs: usize,
    /// MakeValid changed the input.
    pub repaired: bool,
    /// Why the scores are missing, when they are.
    pub note: Option<String>,
    /// With a `collapse` step: the lines where the polygon collapsed (true)
    /// or the centreline through its kept areas (false).
    pub collapsed: Option<bool>,
    /// With `input.merge_adjacent`: the source FIDs dissolved into this
    /// feature, comma-separated.
    pub members: Option<String>,
    /// With `output.measures: width`: the M value of every vertex, line by
    /// line (the local width 2r).
    pub measures: Option<Vec<Vec<f64>>>,
}

impl Scored for SkeletonRow {
    fn scores(&self) -> Option<&Scores> {
        self.scores.as_ref()
    }
}

/// The skeleton layer (named by `output.layer`, default `skeletons`).
pub const SKELETONS: LayerDef<SkeletonRow> = LayerDef {
    name: "skeletons",
    when: When::Always,
    geometry: GeometryKind::MultiLineString,
    shape: |r| {
        Some(match &r.measures {
            Some(m) => Shape::LinesM(&r.geometry, m),
            None => Shape::Lines(&r.geometry),
        })
    },
    attributes: Attributes::Input(|r| &r.attributes),
    columns: columns!(SkeletonRow;
        [
            col(name::SRC_FID, Int64, |r: &SkeletonRow| fid(r.src_fid)),
            col_when(When::Explode, name::POLYGON_PART, Int32, |r: &SkeletonRow| r.polygon_part.map_or(Cell::Null, int)),
            col(name::METHOD, Text, |r: &SkeletonRow| text(&r.method)),
        ],
        score_columns!(SkeletonRow),
        [
            col(name::COMPONENTS, Int32, |r: &SkeletonRow| int(r.components)),
            col(name::LEGS, Int32, |r: &SkeletonRow| int(r.legs)),
            col(name::REPAIRED, Int32, |r: &SkeletonRow| int(i64::from(r.repaired))),
            col(name::NOTE, Text, |r: &SkeletonRow| r.note.as_deref().map_or(Cell::Null, text)),
            col_when(When::Collapse, name::COLLAPSED, Int32, |r: &SkeletonRow| r.collapsed.map_or(Cell::Null, |c| int(i64::from(c)))),
            col_when(When::Merge, name::MEMBERS, Text, |r: &SkeletonRow| r.members.as_deref().map_or(Cell::Null, text)),
        ],
    ),
};

/// One row of the `candidates` layer: one method's result for one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Index of the polygon part (with `explode`).
    pub polygon_part: Option<usize>,
    /// The method.
    pub method: String,
    /// The skeleton, or `None` when the method failed.
    pub geometry: Option<geo::MultiLineString<f64>>,
    /// Scores, when scored.
    pub scores: Option<Scores>,
    /// Whether this candidate was chosen.
    pub chosen: bool,
    /// Connected components.
    pub components: usize,
    /// Legs before pruning.
    pub legs_raw: usize,
    /// Legs after pruning and extension.
    pub legs: usize,
    /// Why the method failed.
    pub error: Option<String>,
}

impl Scored for CandidateRow {
    fn scores(&self) -> Option<&Scores> {
        self.scores.as_ref()
    }
}

/// The `candidates` layer.
pub const CANDIDATES: LayerDef<CandidateRow> = LayerDef {
    name: "candidates",
    when: When::Candidates,
    geometry: GeometryKind::MultiLineString,
    shape: |r| r.geometry.as_ref().map(Shape::Lines),
    attributes: Attributes::None,
    columns: columns!(CandidateRow;
        [
            col(name::SRC_FID, Int64, |r: &CandidateRow| fid(r.src_fid)),
            col(name::POLYGON_PART, Int32, |r: &CandidateRow| r.polygon_part.map_or(Cell::Null, int)),
            col(name::METHOD, Text, |r: &CandidateRow| text(&r.method)),
            col(name::CHOSEN, Int32, |r: &CandidateRow| int(i64::from(r.chosen))),
        ],
        score_columns!(CandidateRow),
        [
            col(name::COMPONENTS, Int32, |r: &CandidateRow| int(r.components)),
            col(name::LEGS_RAW, Int32, |r: &CandidateRow| int(r.legs_raw)),
            col(name::LEGS, Int32, |r: &CandidateRow| int(r.legs)),
            col(name::ERROR, Text, |r: &CandidateRow| r.error.as_deref().map_or(Cell::Null, text)),
        ],
    ),
};

/// One row of the `bars` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct BarRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// The method.
    pub method: String,
    /// From the bar's origin to its hit (the origin alone for a miss).
    pub geometry: geo::LineString<f64>,
    /// d_L; `None` for a miss.
    pub d_left: Option<f64>,
    /// d_P.
    pub d_right: Option<f64>,
    /// Δd.
    pub delta_d: Option<f64>,
    /// z.
    pub z: Option<f64>,
    /// The skeleton branch (the paper's part) that was hit.
    pub branch: Option<usize>,
}

/// The `bars` layer.
pub const BARS: LayerDef<BarRow> = LayerDef {
    name: "bars",
    when: When::Bars,
    geometry: GeometryKind::LineString,
    shape: |r| Some(Shape::Line(r.geometry.clone())),
    attributes: Attributes::None,
    columns: &[
        col(name::SRC_FID, Int64, |r| fid(r.src_fid)),
        col(name::METHOD, Text, |r| text(&r.method)),
        col(name::D_LEFT, Real, |r| real(r.d_left)),
        col(name::D_RIGHT, Real, |r| real(r.d_right)),
        col(name::DELTA_D, Real, |r| real(r.delta_d)),
        col(name::Z, Real, |r| real(r.z)),
        col(name::BRANCH, Int64, |r| r.branch.map_or(Cell::Null, int)),
    ],
};

/// One row of the `widths` layer: a skeleton segment with the polygon's
/// local width at both ends.
#[derive(Debug, Clone, PartialEq)]
pub struct WidthRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// The method.
    pub method: String,
    /// The segment.
    pub geometry: geo::Line<f64>,
    /// Width (2 r) at the start.
    pub width_start: f64,
    /// Width (2 r) at the end.
    pub width_end: f64,
}

/// The `widths` layer.
pub const WIDTHS: LayerDef<WidthRow> = LayerDef {
    name: "widths",
    when: When::Widths,
    geometry: GeometryKind::LineString,
    shape: |r| {
        Some(Shape::Line(geo::LineString(vec![
            r.geometry.start,
            r.geometry.end,
        ])))
    },
    attributes: Attributes::None,
    columns: &[
        col(name::SRC_FID, Int64, |r| fid(r.src_fid)),
        col(name::METHOD, Text, |r| text(&r.method)),
        col("width_start", Real, |r| Cell::Real(r.width_start)),
        col("width_end", Real, |r| Cell::Real(r.width_end)),
        col("width", Real, |r| {
            Cell::Real((r.width_start + r.width_end) / 2.0)
        }),
    ],
};

/// One row of the `rejected` layer.
#[derive(Debug, Clone, PartialEq)]
pub struct RejectedRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Why the feature was not processed.
    pub reason: String,
    /// The input geometry as WKB, when there was one.
    pub wkb: Option<Vec<u8>>,
}

/// The `rejected` layer.
pub const REJECTED: LayerDef<RejectedRow> = LayerDef {
    name: "rejected",
    when: When::Always,
    geometry: GeometryKind::Unknown,
    shape: |r| r.wkb.as_deref().map(Shape::Wkb),
    attributes: Attributes::None,
    columns: &[
        col(name::SRC_FID, Int64, |r| fid(r.src_fid)),
        col("reason", Text, |r| text(&r.reason)),
    ],
};

/// The `skeletonise_runs` row: provenance of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Pipeline name.
    pub name: String,
    /// Start, UTC, RFC 3339.
    pub started_utc: String,
    /// End, UTC, RFC 3339.
    pub finished_utc: String,
    /// Tool version.
    pub tool_version: String,
    /// The pipeline text (with overrides).
    pub pipeline: String,
    /// Input source and layer, for people.
    pub input: String,
    /// The input source as it opens from any working directory (an existing
    /// local path made absolute), for `skeletonise report` to reopen the
    /// polygons.
    pub input_source: String,
    /// The input layer's name.
    pub input_layer: String,
    /// `input.reproject`, when the polygons were reprojected.
    pub input_reproject: Option<String>,
    /// The name of the skeleton layer (`output.layer`).
    pub skeleton_layer: String,
    /// Features read.
    pub read: u64,
    /// Features written.
    pub written: u64,
    /// Features rejected.
    pub rejected: u64,
    /// Features filtered by where/bbox/min_area.
    pub filtered: u64,
    /// Wall time.
    pub elapsed_s: f64,
    /// Worker threads.
    pub threads: usize,
    /// Thread time per method and step, JSON (`{"MA": {"skeleton": s,
    /// "prune_extend": s, "score": s}, …}`).
    pub stage_seconds: String,
    /// With `partition`: the area of the collapsed polygons the units held
    /// before (cut out of them and given by the rule), CRS units².
    pub area_held: Option<f64>,
}

/// The `skeletonise_runs` attribute table.
pub const RUNS: LayerDef<RunRecord> = LayerDef {
    name: "skeletonise_runs",
    when: When::Always,
    geometry: GeometryKind::None,
    shape: |_| None,
    attributes: Attributes::None,
    columns: &[
        col(name::run::NAME, Text, |r| text(&r.name)),
        col(name::run::STARTED_UTC, Text, |r| text(&r.started_utc)),
        col(name::run::FINISHED_UTC, Text, |r| text(&r.finished_utc)),
        col(name::run::TOOL_VERSION, Text, |r| text(&r.tool_version)),
        col(name::run::PIPELINE, Text, |r| text(&r.pipeline)),
        col(name::run::INPUT, Text, |r| text(&r.input)),
        col(name::run::INPUT_SOURCE, Text, |r| text(&r.input_source)),
        col(name::run::INPUT_LAYER, Text, |r| text(&r.input_layer)),
        col(name::run::INPUT_REPROJECT, Text, |r| {
            r.input_reproject.as_deref().map_or(Cell::Null, text)
        }),
        col(name::run::SKELETON_LAYER, Text, |r| text(&r.skeleton_layer)),
        col(name::run::FEATURES_READ, Int64, |r| int(r.read)),
        col(name::run::FEATURES_WRITTEN, Int64, |r| int(r.written)),
        col(name::run::FEATURES_REJECTED, Int64, |r| int(r.rejected)),
        col(name::run::FEATURES_FILTERED, Int64, |r| int(r.filtered)),
        col(name::run::THREADS, Int64, |r| int(r.threads)),
        col(name::run::ELAPSED_S, Real, |r| Cell::Real(r.elapsed_s)),
        col(name::run::STAGE_SECONDS, Text, |r| text(&r.stage_seconds)),
        col(name::run::AREA_HELD, Real, |r| {
            r.area_held.map_or(Cell::Null, Cell::Real)
        }),
    ],
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layer::{fid, int, real};

    #[test]
    fn the_skeleton_layer_lists_its_columns_in_spec_order() {
        let names: Vec<&str> = SKELETONS.column_names().collect();
        assert_eq!(
            names,
            [
                "src_fid",
                "polygon_part",
                "method",
                "bars",
                "hits",
                "coverage",
                "deviation",
                "deviation_parts",
                "distortion_sum",
                "distortion",
                "components",
                "legs",
                "repaired",
                "note",
                "collapsed",
                "members"
            ]
        );
        let cands: Vec<&str> = CANDIDATES.column_names().collect();
        assert_eq!(cands.len(), 15);
    }

    #[test]
    fn cells_map_absent_and_out_of_range_values_to_null() {
        assert_eq!(fid(None), Cell::Null);
        assert_eq!(int(u64::MAX), Cell::Null);
        assert_eq!(real(None), Cell::Null);
    }
}
