//! The rows a feature (or a batch) produces, layer by layer, and every
//! layer seen the same way whatever its row type ([`Layer`]), so that the
//! writer, the Python table and the plan go over one list.

use super::layers::{
    BarRow, CandidateRow, RejectedRow, RunRecord, SkeletonRow, WidthRow, BARS, CANDIDATES,
    REJECTED, RUNS, SKELETONS, WIDTHS,
};
use crate::collapse::{AreaRow, AREAS};
use crate::connect::{ConnectionRow, NetworkRow, CONNECTIONS, NETWORK};
use crate::feature::Value;
use crate::layer::{Cell, ColumnType, GeometryKind, LayerDef, Shape, StepLayer, StepRow, When};
use crate::partition::{BoundaryRow, CoverageRow, GivenRow, BOUNDARIES, COVERAGE, GIVEN};

/// A row of a registered step's layer, with what the per-feature path
/// knows of its feature.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// Source attributes (written when the layer has them).
    pub attributes: Vec<Value>,
    /// The step's geometry and cells.
    pub row: StepRow,
}

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
    /// `network` rows (the skeletons' per feature, the lines' once, after
    /// the features).
    pub network: Vec<NetworkRow>,
    /// `boundaries` rows (a partition's new boundaries).
    pub boundaries: Vec<BoundaryRow>,
    /// `given` rows (a partition's areas given).
    pub given: Vec<GivenRow>,
    /// `coverage` rows (the units, grown: written once, after the features).
    pub coverage: Vec<CoverageRow>,
    /// The pieces given to each unit (its FID): not a layer, but what the
    /// `coverage` rows are made of at the end of a run.
    pub grown: Vec<(Option<u64>, crate::partition::Growth)>,
    /// `rejected` rows.
    pub rejected: Vec<RejectedRow>,
    /// Rows of registered steps' layers, by layer name.
    pub extra: std::collections::BTreeMap<&'static str, Vec<ExtraRow>>,
    /// The run record (written once, at the end of a run).
    pub runs: Vec<RunRecord>,
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
        self.network.append(&mut other.network);
        self.boundaries.append(&mut other.boundaries);
        self.given.append(&mut other.given);
        self.coverage.append(&mut other.coverage);
        self.grown.append(&mut other.grown);
        self.rejected.append(&mut other.rejected);
        for (layer, mut rows) in other.extra {
            self.extra.entry(layer).or_default().append(&mut rows);
        }
        self.runs.append(&mut other.runs);
    }

    /// Rows in every layer together.
    pub fn len(&self) -> usize {
        self.skeletons.len()
            + self.candidates.len()
            + self.bars.len()
            + self.widths.len()
            + self.areas.len()
            + self.connections.len()
            + self.network.len()
            + self.boundaries.len()
            + self.given.len()
            + self.coverage.len()
            + self.rejected.len()
            + self.extra.values().map(Vec::len).sum::<usize>()
            + self.runs.len()
    }

    /// True when there is no row in any layer.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A column as every layer describes it: name, type and when it is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ColumnInfo {
    /// Column name.
    pub name: &'static str,
    /// Column type.
    pub ty: ColumnType,
    /// When it is written.
    pub when: When,
}

/// A layer of the output, whatever its row type: what the writer, the
/// Python table and the plan need of it. The rows are those of a [`Rows`].
pub trait Layer: Sync {
    /// The layer's own name (the skeleton layer's is the plan's).
    fn name(&self) -> &'static str;
    /// When it is written.
    fn when(&self) -> When;
    /// Its geometry type.
    fn geometry(&self) -> GeometryKind;
    /// Whose source fields come first, if any.
    fn fields(&self) -> Option<crate::layer::Fields>;
    /// The tool's columns, in order.
    fn columns(&self) -> Vec<ColumnInfo>;
    /// How many rows of this layer `rows` holds.
    fn count(&self, rows: &Rows) -> usize;
    /// Row `i`'s geometry.
    fn shape<'r>(&self, rows: &'r Rows, i: usize) -> Option<Shape<'r>>;
    /// Row `i`'s source fields (empty when the layer has none).
    fn attributes<'r>(&self, rows: &'r Rows, i: usize) -> &'r [Value];
    /// Row `i`'s value in column `column` (an index into [`Layer::columns`]).
    fn cell(&self, rows: &Rows, i: usize, column: usize) -> Cell;
}

/// A built-in layer: its declarative description and where its rows are
/// in a [`Rows`].
pub struct Builtin<R: 'static> {
    /// The description.
    pub def: &'static LayerDef<R>,
    /// Its rows.
    pub rows: fn(&Rows) -> &[R],
}

impl<R: Sync + 'static> Layer for Builtin<R> {
    fn name(&self) -> &'static str {
        self.def.name
    }
    fn when(&self) -> When {
        self.def.when
    }
    fn geometry(&self) -> GeometryKind {
        self.def.geometry
    }
    fn fields(&self) -> Option<crate::layer::Fields> {
        self.def.attributes.fields()
    }
    fn columns(&self) -> Vec<ColumnInfo> {
        self.def
            .columns
            .iter()
            .map(|c| ColumnInfo {
                name: c.name,
                ty: c.ty,
                when: c.when,
            })
            .collect()
    }
    fn count(&self, rows: &Rows) -> usize {
        (self.rows)(rows).len()
    }
    fn shape<'r>(&self, rows: &'r Rows, i: usize) -> Option<Shape<'r>> {
        (self.def.shape)(&(self.rows)(rows)[i])
    }
    fn attributes<'r>(&self, rows: &'r Rows, i: usize) -> &'r [Value] {
        self.def.attributes.of(&(self.rows)(rows)[i])
    }
    fn cell(&self, rows: &Rows, i: usize, column: usize) -> Cell {
        (self.def.columns[column].get)(&(self.rows)(rows)[i])
    }
}

/// A registered step's layer: its rows are the [`ExtraRow`]s filed under
/// its name; `src_fid` comes first, then the step's columns.
fn own<'r>(layer: &StepLayer, rows: &'r Rows) -> &'r [ExtraRow] {
    rows.extra.get(layer.name).map_or(&[], Vec::as_slice)
}

impl Layer for StepLayer {
    fn name(&self) -> &'static str {
        self.name
    }
    fn when(&self) -> When {
        When::Always
    }
    fn geometry(&self) -> GeometryKind {
        self.geometry
    }
    fn fields(&self) -> Option<crate::layer::Fields> {
        self.attributes.then_some(crate::layer::Fields::Input)
    }
    fn columns(&self) -> Vec<ColumnInfo> {
        std::iter::once(("src_fid", ColumnType::Int64))
            .chain(self.columns.iter().copied())
            .map(|(name, ty)| ColumnInfo {
                name,
                ty,
                when: When::Always,
            })
            .collect()
    }
    fn count(&self, rows: &Rows) -> usize {
        own(self, rows).len()
    }
    fn shape<'r>(&self, rows: &'r Rows, i: usize) -> Option<Shape<'r>> {
        own(self, rows)[i]
            .row
            .geometry
            .as_ref()
            .map(Shape::Geometry)
    }
    fn attributes<'r>(&self, rows: &'r Rows, i: usize) -> &'r [Value] {
        if self.attributes {
            &own(self, rows)[i].attributes
        } else {
            &[]
        }
    }
    fn cell(&self, rows: &Rows, i: usize, column: usize) -> Cell {
        let r = &own(self, rows)[i];
        match column {
            0 => crate::layer::fid(r.src_fid),
            k => r.row.cells.get(k - 1).cloned().unwrap_or(Cell::Null),
        }
    }
}

/// The skeleton layer.
pub static SKELETON_LAYER: Builtin<SkeletonRow> = Builtin {
    def: &SKELETONS,
    rows: |r| &r.skeletons,
};

/// The `candidates` layer.
pub static CANDIDATE_LAYER: Builtin<CandidateRow> = Builtin {
    def: &CANDIDATES,
    rows: |r| &r.candidates,
};

/// Every built-in layer, in the order they are created (the run record,
/// written once at the end of a run, last).
pub static BUILTIN: [&dyn Layer; 12] = [
    &SKELETON_LAYER,
    &CANDIDATE_LAYER,
    &Builtin {
        def: &BARS,
        rows: |r| &r.bars,
    },
    &Builtin {
        def: &WIDTHS,
        rows: |r| &r.widths,
    },
    &Builtin {
        def: &AREAS,
        rows: |r| &r.areas,
    },
    &Builtin {
        def: &CONNECTIONS,
        rows: |r| &r.connections,
    },
    &Builtin {
        def: &NETWORK,
        rows: |r| &r.network,
    },
    &Builtin {
        def: &COVERAGE,
        rows: |r| &r.coverage,
    },
    &Builtin {
        def: &BOUNDARIES,
        rows: |r| &r.boundaries,
    },
    &Builtin {
        def: &GIVEN,
        rows: |r| &r.given,
    },
    &Builtin {
        def: &REJECTED,
        rows: |r| &r.rejected,
    },
    &Builtin {
        def: &RUNS,
        rows: |r| &r.runs,
    },
];
