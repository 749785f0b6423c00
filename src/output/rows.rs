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

/// A row of a registered step's layer, with what the per-feature path
/// knows of its feature.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraRow {
    /// Source FID.
    pub src_fid: Option<u64>,
    /// The polygon part (with `explode`; written in a layer that carries
    /// the input's fields).
    pub polygon_part: Option<usize>,
    /// The source FIDs of a merged feature, comma-separated (written in a
    /// layer that carries the input's fields when adjacent polygons are
    /// merged).
    pub members: Option<String>,
    /// Source attributes (written when the layer has them).
    pub attributes: Vec<Value>,
    /// The step's geometry and cells.
    pub row: StepRow,
}

impl ExtraRow {
    /// A row made after the last feature, of no feature: `src_fid` NULL,
    /// no fields.
    pub fn summary(row: StepRow) -> Self {
        Self {
            src_fid: None,
            polygon_part: None,
            members: None,
            attributes: Vec::new(),
            row,
        }
    }
}

/// What a step keeps of one feature for its finish (`FeatureStep::finish_rows`)
/// beside its rows (the pieces each unit of a coverage receives): any type
/// of the step's, which its finish downcasts.
#[derive(Clone)]
pub struct Kept(pub std::sync::Arc<dyn std::any::Any + Send + Sync>);

impl std::fmt::Debug for Kept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Kept")
    }
}

impl PartialEq for Kept {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
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
    /// What registered steps keep of each feature for their finish (not a
    /// layer): the step, the feature's FID and the kept value.
    pub kept: Vec<(&'static str, Option<u64>, Kept)>,
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
        self.kept.append(&mut other.kept);
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
        self.fields
    }
    fn columns(&self) -> Vec<ColumnInfo> {
        let col = |name, ty, when| ColumnInfo { name, ty, when };
        std::iter::once(col("src_fid", ColumnType::Int64, When::Always))
            .chain(stamped(self).map(|(name, ty, when, _)| col(name, ty, when)))
            .chain(
                self.columns
                    .iter()
                    .map(|&(name, ty)| col(name, ty, When::Always)),
            )
            .collect()
    }
    fn count(&self, rows: &Rows) -> usize {
        own(self, rows).len()
    }
    fn shape<'r>(&self, rows: &'r Rows, i: usize) -> Option<Shape<'r>> {
        use geo::Geometry as G;
        Some(match own(self, rows)[i].row.geometry.as_ref()? {
            G::Polygon(p) => Shape::Polygon(p),
            G::MultiPolygon(m) => Shape::MultiPolygon(m),
            G::MultiLineString(m) => Shape::Lines(m),
            g => Shape::Geometry(g),
        })
    }
    fn attributes<'r>(&self, rows: &'r Rows, i: usize) -> &'r [Value] {
        match self.fields {
            Some(_) => &own(self, rows)[i].attributes,
            None => &[],
        }
    }
    fn cell(&self, rows: &Rows, i: usize, column: usize) -> Cell {
        let r = &own(self, rows)[i];
        let stamped: Vec<_> = stamped(self).collect();
        match column.checked_sub(1) {
            None => crate::layer::fid(r.src_fid),
            Some(k) => match stamped.get(k) {
                Some((.., of)) => of(r),
                None => self
                    .columns
                    .get(k - stamped.len())
                    .map_or(Cell::Null, |(name, _)| r.row.cell(name)),
            },
        }
    }
}

/// The columns the per-feature path adds after `src_fid` to a registered
/// step's layer that carries the input's fields — `polygon_part` (with
/// `explode`) and `members` (with merged polygons), as the skeleton layer
/// has them — unless the step has a column of that name: name, type, when,
/// and the value of a row.
#[allow(clippy::type_complexity)]
fn stamped(
    layer: &StepLayer,
) -> impl Iterator<Item = (&'static str, ColumnType, When, fn(&ExtraRow) -> Cell)> + '_ {
    let all: [(&'static str, ColumnType, When, fn(&ExtraRow) -> Cell); 2] = [
        ("polygon_part", ColumnType::Int32, When::Explode, |r| {
            r.polygon_part.map_or(Cell::Null, crate::layer::int)
        }),
        ("members", ColumnType::Text, When::Merge, |r| {
            r.members.clone().map_or(Cell::Null, Cell::Text)
        }),
    ];
    let by_feature = layer.fields == Some(crate::layer::Fields::Input);
    all.into_iter()
        .filter(move |(name, ..)| by_feature && !layer.columns.iter().any(|(c, _)| c == name))
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
pub static BUILTIN: [&dyn Layer; 9] = [
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
        def: &REJECTED,
        rows: |r| &r.rejected,
    },
    &Builtin {
        def: &RUNS,
        rows: |r| &r.runs,
    },
];
