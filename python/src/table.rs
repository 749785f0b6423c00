//! Rows of a layer to columns, from the layer's declarative table
//! (`skeletonise::output::LayerDef`): the names, types and values are the
//! ones the command line writes to the GeoPackage.

use geo::MultiLineString;
use skeletonise::output::{Cell, ColumnType, LayerDef, Shape, When};

/// One output row: a row of the layer, or a feature without one (rejected
/// or filtered), of which only `src_fid` is known.
pub enum Out<'a, R> {
    /// A row of the layer.
    Row(&'a R),
    /// A rejected or filtered feature.
    Empty(Option<u64>),
}

/// The values of one column.
pub enum Values {
    /// Integers and where they are NULL.
    Int(Vec<i64>, Vec<bool>),
    /// Numbers, NaN for NULL (as the writer writes non-finite values as NULL).
    Real(Vec<f64>),
    /// Texts.
    Text(Vec<Option<String>>),
}

/// A column: name, type and values.
pub struct ColumnData {
    /// Column name.
    pub name: &'static str,
    /// Column type.
    pub ty: ColumnType,
    /// Values, one per row.
    pub values: Values,
}

/// The columns of `def` (those with `explode` included when asked) over
/// `rows`.
pub fn columns<R>(def: &LayerDef<R>, explode: bool, rows: &[Out<'_, R>]) -> Vec<ColumnData> {
    def.columns
        .iter()
        .filter(|c| c.when == When::Always || (c.when == When::Explode && explode))
        .map(|c| {
            let cell = |r: &Out<'_, R>| match r {
                Out::Row(r) => (c.get)(r),
                Out::Empty(fid) if c.name == "src_fid" => fid
                    .and_then(|f| i64::try_from(f).ok())
                    .map_or(Cell::Null, Cell::Int),
                Out::Empty(_) => Cell::Null,
            };
            let values = match c.ty {
                ColumnType::Int32 | ColumnType::Int64 => {
                    let (mut v, mut null) = (
                        Vec::with_capacity(rows.len()),
                        Vec::with_capacity(rows.len()),
                    );
                    for r in rows {
                        match cell(r) {
                            Cell::Int(i) => {
                                v.push(i);
                                null.push(false);
                            }
                            _ => {
                                v.push(0);
                                null.push(true);
                            }
                        }
                    }
                    Values::Int(v, null)
                }
                ColumnType::Real => Values::Real(
                    rows.iter()
                        .map(|r| match cell(r) {
                            Cell::Real(x) if x.is_finite() => x,
                            Cell::Int(i) => i as f64,
                            _ => f64::NAN,
                        })
                        .collect(),
                ),
                ColumnType::Text => Values::Text(
                    rows.iter()
                        .map(|r| match cell(r) {
                            Cell::Text(s) => Some(s),
                            _ => None,
                        })
                        .collect(),
                ),
            };
            ColumnData {
                name: c.name,
                ty: c.ty,
                values,
            }
        })
        .collect()
}

/// The geometry of every row, from the layer's `shape`: lines, or `None`.
pub fn lines<'a, R>(
    def: &LayerDef<R>,
    rows: &'a [Out<'a, R>],
) -> Vec<Option<MultiLineString<f64>>> {
    rows.iter()
        .map(|r| match r {
            Out::Row(r) => match (def.shape)(r) {
                Some(Shape::Lines(m)) => Some(m.clone()),
                Some(Shape::Line(l)) => Some(MultiLineString(vec![l])),
                Some(Shape::LinesM(m, _)) => Some(m.clone()),
                Some(Shape::Polygon(_) | Shape::Wkb(_)) | None => None,
            },
            Out::Empty(_) => None,
        })
        .collect()
}

/// Geometries as GeoArrow MULTILINESTRING buffers: interleaved x, y; the
/// start of every line in points; the start of every geometry in lines;
/// and which are NULL.
pub struct Ragged {
    /// x0, y0, x1, y1, …
    pub coords: Vec<f64>,
    /// Start of each line (in points), and the end.
    pub line_offsets: Vec<i64>,
    /// Start of each geometry (in lines), and the end.
    pub geom_offsets: Vec<i64>,
    /// NULL geometries.
    pub null: Vec<bool>,
}

/// Encodes `geoms` as [`Ragged`] buffers.
pub fn ragged(geoms: &[Option<MultiLineString<f64>>]) -> Ragged {
    let points: usize = geoms
        .iter()
        .flatten()
        .flat_map(|m| &m.0)
        .map(|l| l.0.len())
        .sum();
    let lines: usize = geoms.iter().flatten().map(|m| m.0.len()).sum();
    let mut r = Ragged {
        coords: Vec::with_capacity(2 * points),
        line_offsets: Vec::with_capacity(lines + 1),
        geom_offsets: Vec::with_capacity(geoms.len() + 1),
        null: Vec::with_capacity(geoms.len()),
    };
    r.line_offsets.push(0);
    r.geom_offsets.push(0);
    for g in geoms {
        r.null.push(g.is_none());
        for l in g.iter().flat_map(|m| &m.0) {
            for c in &l.0 {
                r.coords.push(c.x);
                r.coords.push(c.y);
            }
            r.line_offsets.push((r.coords.len() / 2) as i64);
        }
        r.geom_offsets.push((r.line_offsets.len() - 1) as i64);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::LineString;

    #[test]
    fn ragged_buffers_follow_geoarrow() {
        let a = MultiLineString(vec![
            LineString::from(vec![(0., 0.), (1., 1.)]),
            LineString::from(vec![(2., 2.), (3., 3.), (4., 4.)]),
        ]);
        let r = ragged(&[Some(a), None, Some(MultiLineString(vec![]))]);
        assert_eq!(r.line_offsets, [0, 2, 5]);
        assert_eq!(r.geom_offsets, [0, 2, 2, 2]);
        assert_eq!(r.null, [false, true, false]);
        assert_eq!(r.coords.len(), 10);
    }
}
