//! The output GeoPackage's layers (SPEC §9), described as data: each layer
//! is one [`LayerDef`] — its name, geometry type and columns, each column
//! with its type and how its value is taken from a row. The writer
//! (`io::writer`, with the `gdal` feature) creates and fills any layer from its description,
//! so adding a column is one entry in one table below.
//!
//! Rows are plain data made by the per-feature work ([`crate::process`]);
//! nothing here touches GDAL.

use crate::feature::Value;
use crate::score::Scores;
use ColumnType::{Int32, Int64, Real, Text};

/// The type of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    /// 32-bit integer.
    Int32,
    /// 64-bit integer.
    Int64,
    /// Floating point.
    Real,
    /// Text.
    Text,
}

/// A value written to a column.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// NULL.
    Null,
    /// An integer (written as the column's integer type).
    Int(i64),
    /// A number; non-finite values are written as NULL.
    Real(f64),
    /// Text.
    Text(String),
}

/// The geometry type of a layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GeometryKind {
    /// MULTILINESTRING.
    MultiLineString,
    /// LINESTRING.
    LineString,
    /// POLYGON.
    Polygon,
    /// Any geometry (the `rejected` layer keeps the input's).
    Unknown,
    /// An attribute table.
    None,
}

/// A row's geometry, borrowed or made for writing.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape<'a> {
    /// Lines.
    Lines(&'a geo::MultiLineString<f64>),
    /// One line.
    Line(geo::LineString<f64>),
    /// One polygon.
    Polygon(&'a geo::Polygon<f64>),
    /// Lines with an M value per vertex (line by line).
    LinesM(&'a geo::MultiLineString<f64>, &'a [Vec<f64>]),
    /// A geometry as WKB.
    Wkb(&'a [u8]),
}

/// When a column is part of its layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum When {
    /// Always.
    Always,
    /// Only with `output.explode`.
    Explode,
    /// Only when the pipeline has a `collapse` step.
    Collapse,
    /// Only with `input.merge_adjacent`.
    Merge,
}

/// One column of a layer.
pub struct Column<R> {
    /// Column name.
    pub name: &'static str,
    /// Column type.
    pub ty: ColumnType,
    /// The column's value in a row.
    pub get: fn(&R) -> Cell,
    /// When the column is written.
    pub when: When,
}

/// A column written always.
pub const fn col<R>(name: &'static str, ty: ColumnType, get: fn(&R) -> Cell) -> Column<R> {
    Column {
        name,
        ty,
        get,
        when: When::Always,
    }
}

/// A column written only when the pipeline collapses.
pub const fn col_collapse<R>(name: &'static str, ty: ColumnType, get: fn(&R) -> Cell) -> Column<R> {
    Column {
        name,
        ty,
        get,
        when: When::Collapse,
    }
}

/// A column written only with `input.merge_adjacent`.
pub const fn col_merge<R>(name: &'static str, ty: ColumnType, get: fn(&R) -> Cell) -> Column<R> {
    Column {
        name,
        ty,
        get,
        when: When::Merge,
    }
}

/// A column written only with `output.explode`.
pub const fn col_explode<R>(name: &'static str, ty: ColumnType, get: fn(&R) -> Cell) -> Column<R> {
    Column {
        name,
        ty,
        get,
        when: When::Explode,
    }
}

impl<R> Clone for Column<R> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<R> Copy for Column<R> {}

/// One output layer.
pub struct LayerDef<R: 'static> {
    /// Layer name (the skeleton layer's is configurable: `output.layer`).
    pub name: &'static str,
    /// Geometry type.
    pub geometry: GeometryKind,
    /// The row's geometry.
    pub shape: for<'a> fn(&'a R) -> Option<Shape<'a>>,
    /// The source feature's attributes, written first under the source's
    /// field names (the skeleton layer).
    pub attributes: Option<fn(&R) -> &[Value]>,
    /// The tool's columns.
    pub columns: &'static [Column<R>],
}

impl<R> LayerDef<R> {
    /// The names of the tool's columns.
    pub fn column_names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.columns.iter().map(|c| c.name)
    }
}

fn int(v: impl TryInto<i64>) -> Cell {
    v.try_into().map_or(Cell::Null, Cell::Int)
}

fn text(s: &str) -> Cell {
    Cell::Text(s.to_string())
}

fn fid(v: Option<u64>) -> Cell {
    v.map_or(Cell::Null, int)
}

fn real(v: Option<f64>) -> Cell {
    v.map_or(Cell::Null, Cell::Real)
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
            col("bars", Int64, s_bars::<$r>),
            col("hits", Int64, s_hits::<$r>),
            col("coverage", Real, s_coverage::<$r>),
            col("deviation", Real, s_deviation::<$r>),
            col("deviation_parts", Real, s_deviation_parts::<$r>),
            col("distortion_sum", Real, s_distortion_sum::<$r>),
            col("distortion", Real, s_distortion::<$r>),
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
    geometry: GeometryKind::MultiLineString,
    shape: |r| {
        Some(match &r.measures {
            Some(m) => Shape::LinesM(&r.geometry, m),
            None => Shape::Lines(&r.geometry),
        })
    },
    attributes: Some(|r| &r.attributes),
    columns: columns!(SkeletonRow;
        [
            col("src_fid", Int64, |r: &SkeletonRow| fid(r.src_fid)),
            col_explode("polygon_part", Int32, |r: &SkeletonRow| r.polygon_part.map_or(Cell::Null, int)),
            col("method", Text, |r: &SkeletonRow| text(&r.method)),
        ],
        score_columns!(SkeletonRow),
        [
            col("components", Int32, |r: &SkeletonRow| int(r.components)),
            col("legs", Int32, |r: &SkeletonRow| int(r.legs)),
            col("repaired", Int32, |r: &SkeletonRow| int(i64::from(r.repaired))),
            col("note", Text, |r: &SkeletonRow| r.note.as_deref().map_or(Cell::Null, text)),
            col_collapse("collapsed", Int32, |r: &SkeletonRow| r.collapsed.map_or(Cell::Null, |c| int(i64::from(c)))),
            col_merge("members", Text, |r: &SkeletonRow| r.members.as_deref().map_or(Cell::Null, text)),
        ],
    ),
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
    geometry: GeometryKind::Polygon,
    shape: |r| Some(Shape::Polygon(&r.geometry)),
    attributes: Some(|r| &r.attributes),
    columns: &[
        col("src_fid", Int64, |r| fid(r.src_fid)),
        col_explode("polygon_part", Int32, |r| {
            r.polygon_part.map_or(Cell::Null, int)
        }),
        col("cuts", Int32, |r| int(r.cuts)),
        col_merge("members", Text, |r| {
            r.members.as_deref().map_or(Cell::Null, text)
        }),
    ],
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
    geometry: GeometryKind::MultiLineString,
    shape: |r| r.geometry.as_ref().map(Shape::Lines),
    attributes: None,
    columns: columns!(CandidateRow;
        [
            col("src_fid", Int64, |r: &CandidateRow| fid(r.src_fid)),
            col("polygon_part", Int32, |r: &CandidateRow| r.polygon_part.map_or(Cell::Null, int)),
            col("method", Text, |r: &CandidateRow| text(&r.method)),
            col("chosen", Int32, |r: &CandidateRow| int(i64::from(r.chosen))),
        ],
        score_columns!(CandidateRow),
        [
            col("components", Int32, |r: &CandidateRow| int(r.components)),
            col("legs_raw", Int32, |r: &CandidateRow| int(r.legs_raw)),
            col("legs", Int32, |r: &CandidateRow| int(r.legs)),
            col("error", Text, |r: &CandidateRow| r.error.as_deref().map_or(Cell::Null, text)),
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
    geometry: GeometryKind::LineString,
    shape: |r| Some(Shape::Line(r.geometry.clone())),
    attributes: None,
    columns: &[
        col("src_fid", Int64, |r| fid(r.src_fid)),
        col("method", Text, |r| text(&r.method)),
        col("d_left", Real, |r| real(r.d_left)),
        col("d_right", Real, |r| real(r.d_right)),
        col("delta_d", Real, |r| real(r.delta_d)),
        col("z", Real, |r| real(r.z)),
        col("branch", Int64, |r| r.branch.map_or(Cell::Null, int)),
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
    geometry: GeometryKind::LineString,
    shape: |r| {
        Some(Shape::Line(geo::LineString(vec![
            r.geometry.start,
            r.geometry.end,
        ])))
    },
    attributes: None,
    columns: &[
        col("src_fid", Int64, |r| fid(r.src_fid)),
        col("method", Text, |r| text(&r.method)),
        col("width_start", Real, |r| Cell::Real(r.width_start)),
        col("width_end", Real, |r| Cell::Real(r.width_end)),
        col("width", Real, |r| {
            Cell::Real((r.width_start + r.width_end) / 2.0)
        }),
    ],
};

/// One row of the `connections` layer: a leg added to a skeleton for a
/// line of `input.connect`.
#[derive(Debug, Clone, PartialEq)]
pub struct ConnectionRow {
    /// Source FID of the polygon.
    pub src_fid: Option<u64>,
    /// FID of the network line the leg serves.
    pub line_fid: Option<u64>,
    /// The leg, from the skeleton to the connection point on the boundary.
    pub geometry: geo::LineString<f64>,
}

/// The `connections` layer (with `input.connect`).
pub const CONNECTIONS: LayerDef<ConnectionRow> = LayerDef {
    name: "connections",
    geometry: GeometryKind::LineString,
    shape: |r| Some(Shape::Line(r.geometry.clone())),
    attributes: None,
    columns: &[
        col("src_fid", Int64, |r| fid(r.src_fid)),
        col("line_fid", Int64, |r| fid(r.line_fid)),
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
    geometry: GeometryKind::Unknown,
    shape: |r| r.wkb.as_deref().map(Shape::Wkb),
    attributes: None,
    columns: &[
        col("src_fid", Int64, |r| fid(r.src_fid)),
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
}

/// The `skeletonise_runs` attribute table.
pub const RUNS: LayerDef<RunRecord> = LayerDef {
    name: "skeletonise_runs",
    geometry: GeometryKind::None,
    shape: |_| None,
    attributes: None,
    columns: &[
        col("name", Text, |r| text(&r.name)),
        col("started_utc", Text, |r| text(&r.started_utc)),
        col("finished_utc", Text, |r| text(&r.finished_utc)),
        col("tool_version", Text, |r| text(&r.tool_version)),
        col("pipeline", Text, |r| text(&r.pipeline)),
        col("input", Text, |r| text(&r.input)),
        col("input_source", Text, |r| text(&r.input_source)),
        col("input_layer", Text, |r| text(&r.input_layer)),
        col("input_reproject", Text, |r| {
            r.input_reproject.as_deref().map_or(Cell::Null, text)
        }),
        col("skeleton_layer", Text, |r| text(&r.skeleton_layer)),
        col("features_read", Int64, |r| int(r.read)),
        col("features_written", Int64, |r| int(r.written)),
        col("features_rejected", Int64, |r| int(r.rejected)),
        col("features_filtered", Int64, |r| int(r.filtered)),
        col("threads", Int64, |r| int(r.threads)),
        col("elapsed_s", Real, |r| Cell::Real(r.elapsed_s)),
        col("stage_seconds", Text, |r| text(&r.stage_seconds)),
    ],
};

/// The names of every layer the tool writes besides the skeleton layer
/// (whose name `output.layer` gives and must not be one of these).
pub const TOOL_LAYERS: [&str; 7] = [
    CANDIDATES.name,
    BARS.name,
    WIDTHS.name,
    AREAS.name,
    CONNECTIONS.name,
    REJECTED.name,
    RUNS.name,
];

/// The rows one feature produces, layer by layer.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rows {
    /// Skeleton layer rows.
    pub skeletons: Vec<SkeletonRow>,
    /// `candidates` rows.
    pub candidates: Vec<CandidateRow>,
    /// `bars` rows.
    pub bars: Vec<BarRow>,
    /// `widths` rows.
    pub widths: Vec<WidthRow>,
    /// `areas` rows.
    pub areas: Vec<AreaRow>,
    /// `connections` rows.
    pub connections: Vec<ConnectionRow>,
    /// `rejected` rows.
    pub rejected: Vec<RejectedRow>,
}

impl Rows {
    /// Appends `other`'s rows.
    pub fn append(&mut self, mut other: Rows) {
        self.skeletons.append(&mut other.skeletons);
        self.candidates.append(&mut other.candidates);
        self.bars.append(&mut other.bars);
        self.widths.append(&mut other.widths);
        self.areas.append(&mut other.areas);
        self.connections.append(&mut other.connections);
        self.rejected.append(&mut other.rejected);
    }

    /// Rows in every layer together.
    pub fn len(&self) -> usize {
        self.skeletons.len()
            + self.candidates.len()
            + self.bars.len()
            + self.widths.len()
            + self.areas.len()
            + self.connections.len()
            + self.rejected.len()
    }

    /// True when there is no row in any layer.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
