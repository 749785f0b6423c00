//! The declarative description of an output layer, below every step so
//! that each can declare its own layers and columns next to its code (as a
//! PDAL stage declares its dimensions): a [`LayerDef`] is a layer's name,
//! when it is written, its geometry type and its columns, each column with
//! its type, when it is written and how its value is taken from a row. The
//! writer (`io::writer`), the Python table and the reader of an output
//! (`io::readback`) all work from these descriptions, gathered in one
//! [`crate::output::Plan`].

use crate::feature::Value;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

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
    /// MULTIPOLYGON.
    MultiPolygon,
    /// POINT.
    Point,
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
    /// Polygons.
    MultiPolygon(&'a geo::MultiPolygon<f64>),
    /// Lines with an M value per vertex (line by line).
    LinesM(&'a geo::MultiLineString<f64>, &'a [Vec<f64>]),
    /// A geometry as WKB.
    Wkb(&'a [u8]),
    /// Any geometry (a registered step's rows).
    Geometry(&'a geo::Geometry<f64>),
}

/// When a layer or a column is part of the output: always, or only when
/// the pipeline has what it says ([`crate::output::Plan`] knows which hold).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum When {
    /// Always.
    Always,
    /// With `output.explode`.
    Explode,
    /// When the pipeline has a `collapse` step.
    Collapse,
    /// With `input.merge_adjacent`.
    Merge,
    /// With `input.connect`.
    Connect,
    /// With `output.candidates`.
    Candidates,
    /// With `output.bars`.
    Bars,
    /// With `output.widths`.
    Widths,
    /// With `output.measures: width` (the skeleton layer's lines carry M).
    Measures,
    /// When the pipeline has the step of this name (a registered step's
    /// own layers and columns).
    Step(&'static str),
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

/// A column written only when `when` holds.
pub const fn col_when<R>(
    when: When,
    name: &'static str,
    ty: ColumnType,
    get: fn(&R) -> Cell,
) -> Column<R> {
    Column {
        name,
        ty,
        get,
        when,
    }
}

impl<R> Clone for Column<R> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<R> Copy for Column<R> {}

/// Where a layer's source fields come from, and a row's values of them.
pub enum Attributes<R: 'static> {
    /// The layer has no source fields.
    None,
    /// The input's fields.
    Input(fn(&R) -> &[Value]),
    /// The fields of `input.neighbours` (the units of a coverage).
    Neighbours(fn(&R) -> &[Value]),
}

impl<R> Clone for Attributes<R> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<R> Copy for Attributes<R> {}

/// The source whose fields a layer carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fields {
    /// The input's.
    Input,
    /// `input.neighbours`'.
    Neighbours,
}

impl<R> Attributes<R> {
    /// Whose fields, if any.
    pub fn fields(&self) -> Option<Fields> {
        match self {
            Attributes::None => None,
            Attributes::Input(_) => Some(Fields::Input),
            Attributes::Neighbours(_) => Some(Fields::Neighbours),
        }
    }

    /// A row's values of them (none when the layer has no fields).
    pub fn of<'r>(&self, r: &'r R) -> &'r [Value] {
        match self {
            Attributes::None => &[],
            Attributes::Input(f) | Attributes::Neighbours(f) => f(r),
        }
    }
}

/// One output layer.
pub struct LayerDef<R: 'static> {
    /// Layer name (the skeleton layer's is configurable: `output.layer`).
    pub name: &'static str,
    /// When the layer is written.
    pub when: When,
    /// Geometry type.
    pub geometry: GeometryKind,
    /// The row's geometry.
    pub shape: for<'a> fn(&'a R) -> Option<Shape<'a>>,
    /// Source fields written first, under their own names: none, the
    /// input's (the skeleton layer) or the neighbours' (the partitioned
    /// coverage).
    pub attributes: Attributes<R>,
    /// The tool's columns.
    pub columns: &'static [Column<R>],
}

impl<R> LayerDef<R> {
    /// The names of the tool's columns.
    pub fn column_names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.columns.iter().map(|c| c.name)
    }
}

/// An integer cell; NULL when the value does not fit.
pub fn int(v: impl TryInto<i64>) -> Cell {
    v.try_into().map_or(Cell::Null, Cell::Int)
}

/// A text cell.
pub fn text(s: &str) -> Cell {
    Cell::Text(s.to_string())
}

/// A source FID cell (NULL for none).
pub fn fid(v: Option<u64>) -> Cell {
    v.map_or(Cell::Null, int)
}

/// A number cell (NULL for none).
pub fn real(v: Option<f64>) -> Cell {
    v.map_or(Cell::Null, Cell::Real)
}

/// One row of a layer that a registered step declares ([`StepLayer`]):
/// its geometry and its cells, each named by its column (in any order,
/// every column of the layer once: a value cannot land in the wrong
/// column); the feature's `src_fid` (and source fields, when the layer has
/// them) are added by the per-feature path.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRow {
    /// The row's geometry.
    pub geometry: Option<geo::Geometry<f64>>,
    /// `(column, cell)` for every column of the layer.
    pub cells: Vec<(&'static str, Cell)>,
}

impl StepRow {
    /// The cell of column `name` (NULL when the row has none).
    pub fn cell(&self, name: &str) -> Cell {
        self.cells
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(Cell::Null, |(_, c)| c.clone())
    }
}

/// A layer declared by a registered step: its rows are [`StepRow`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepLayer {
    /// Layer name.
    pub name: &'static str,
    /// Geometry type.
    pub geometry: GeometryKind,
    /// Whose fields come first: the input's (a layer of rows per feature:
    /// then `polygon_part` with `explode` and `members` with merged
    /// polygons follow `src_fid`, as in the skeleton layer), the units' of
    /// `input.neighbours` (a layer of the coverage's units, `src_fid` the
    /// unit's), or none.
    pub fields: Option<Fields>,
    /// The step's columns (after `src_fid`), in order.
    pub columns: &'static [(&'static str, ColumnType)],
}

impl StepLayer {
    /// Whether `row` fits this layer — one cell for every column and none
    /// for a column the layer does not have, each NULL or of the column's
    /// type (an integer within the range of an `Int32` column), and a
    /// geometry of the layer's kind (none for an attribute table, any for
    /// `Unknown`; a row may have no geometry) — or what does not: the run
    /// checks every row a step makes, so that a step's mistake is an error
    /// naming the step instead of a column written empty or wrong.
    pub fn check(&self, row: &StepRow) -> Result<(), String> {
        let layer = self.name;
        if let Some((name, _)) = row
            .cells
            .iter()
            .find(|(n, _)| !self.columns.iter().any(|(c, _)| c == n))
        {
            return Err(format!(
                "a row of layer `{layer}` has a cell for column `{name}`, which the layer does not have"
            ));
        }
        for (name, ty) in self.columns {
            let named: Vec<&Cell> = row
                .cells
                .iter()
                .filter(|(n, _)| n == name)
                .map(|(_, c)| c)
                .collect();
            let cell = match named[..] {
                [cell] => cell,
                [] => {
                    return Err(format!(
                        "a row of layer `{layer}` has no cell for column `{name}`"
                    ))
                }
                _ => {
                    return Err(format!(
                        "a row of layer `{layer}` has {} cells for column `{name}`",
                        named.len()
                    ))
                }
            };
            let fits = match (cell, ty) {
                (Cell::Null, _) => true,
                (Cell::Int(v), ColumnType::Int32) => i32::try_from(*v).is_ok(),
                (Cell::Int(_), ColumnType::Int64) => true,
                (Cell::Real(_), ColumnType::Real) => true,
                (Cell::Text(_), ColumnType::Text) => true,
                _ => false,
            };
            if !fits {
                return Err(format!(
                    "column `{name}` of layer `{layer}` is {ty:?}, and a row gives it {cell:?}"
                ));
            }
        }
        use geo::Geometry as G;
        let kind_fits = match (&row.geometry, self.geometry) {
            (None, _) | (Some(_), GeometryKind::Unknown) => true,
            (Some(_), GeometryKind::None) => false,
            (Some(g), kind) => matches!(
                (g, kind),
                (G::MultiLineString(_), GeometryKind::MultiLineString)
                    | (G::LineString(_), GeometryKind::LineString)
                    | (G::Polygon(_), GeometryKind::Polygon)
                    | (G::MultiPolygon(_), GeometryKind::MultiPolygon)
                    | (G::Point(_), GeometryKind::Point)
            ),
        };
        if !kind_fits {
            return Err(format!(
                "layer `{layer}` holds {:?} geometries, and a row gives it another kind",
                self.geometry
            ));
        }
        Ok(())
    }
}

/// A layer chosen by name or by index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum LayerRef {
    /// Zero-based layer index.
    Index(usize),
    /// Layer name.
    Name(String),
}

impl std::fmt::Display for LayerRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LayerRef::Index(i) => write!(f, "#{i}"),
            LayerRef::Name(n) => write!(f, "`{n}`"),
        }
    }
}

/// A layer of any OGR source read beside the polygons: the coverage of
/// `input.neighbours`, the lines of `input.connect`, or a registered
/// step's side input (its option named by [`crate::process::step::Needs::side`]).
/// Read through one path, reprojected to the polygons' CRS.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerSource {
    /// Any OGR data source string (may be the same file as `input.source`).
    pub source: String,
    /// Layer name or zero-based index; default the first layer.
    #[serde(default)]
    pub layer: Option<LayerRef>,
    /// OGR SQL attribute filter: only these features are read.
    #[serde(default, rename = "where")]
    pub where_: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    const LINES: StepLayer = StepLayer {
        name: "lines",
        geometry: GeometryKind::LineString,
        fields: None,
        columns: &[("n", ColumnType::Int32), ("kind", ColumnType::Text)],
    };

    fn row(geometry: Option<geo::Geometry<f64>>, cells: Vec<Cell>) -> StepRow {
        let cells = ["n", "kind"].into_iter().zip(cells).collect();
        StepRow { geometry, cells }
    }

    #[test]
    fn a_step_row_fits_its_layer_or_says_what_does_not() {
        let line = || {
            Some(geo::Geometry::LineString(
                vec![(0.0, 0.0), (1.0, 1.0)].into(),
            ))
        };
        let text = || Cell::Text("a".into());
        assert_eq!(
            LINES.check(&row(line(), vec![Cell::Int(3), text()])),
            Ok(())
        );
        assert_eq!(
            LINES.check(&row(None, vec![Cell::Null, Cell::Null])),
            Ok(())
        );
        let e = LINES.check(&row(line(), vec![Cell::Int(3)])).unwrap_err();
        assert_eq!(e, "a row of layer `lines` has no cell for column `kind`");
        let mut three = row(line(), vec![Cell::Int(3), text()]);
        three.cells.push(("n", Cell::Int(4)));
        let e = LINES.check(&three).unwrap_err();
        assert_eq!(e, "a row of layer `lines` has 2 cells for column `n`");
        three.cells[2].0 = "m";
        let e = LINES.check(&three).unwrap_err();
        assert!(
            e.contains("column `m`, which the layer does not have"),
            "{e}"
        );
        // In any order.
        let swapped = StepRow {
            geometry: line(),
            cells: vec![("kind", text()), ("n", Cell::Int(3))],
        };
        assert_eq!(LINES.check(&swapped), Ok(()));
        assert_eq!(swapped.cell("n"), Cell::Int(3));
        let e = LINES
            .check(&row(line(), vec![Cell::Int(1 << 40), text()]))
            .unwrap_err();
        assert!(e.starts_with("column `n` of layer `lines` is Int32"), "{e}");
        let point = Some(geo::Geometry::Point((0.0, 0.0).into()));
        let e = LINES
            .check(&row(point.clone(), vec![Cell::Int(3), text()]))
            .unwrap_err();
        assert!(e.contains("holds LineString geometries"), "{e}");
        let table = StepLayer {
            geometry: GeometryKind::None,
            ..LINES
        };
        assert!(table
            .check(&row(point, vec![Cell::Int(3), text()]))
            .is_err());
    }
}
