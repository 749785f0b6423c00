//! A layer's rows as columns (one vector of values per column), with the
//! names, types and values the writer gives them: the table the Python
//! package hands to pandas, and a way to see any layer's rows without a
//! GeoPackage.

use super::plan::Plan;
use super::rows::{Layer, Rows};
use crate::layer::{Cell, ColumnType, Shape};
use geo::MultiLineString;

/// One output row: row `i` of the layer, or a feature without one (rejected
/// or filtered), of which only `src_fid` is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Item {
    /// Row `i` of the layer in the [`Rows`].
    Row(usize),
    /// A rejected or filtered feature.
    Empty(Option<u64>),
}

/// The values of one column.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Integers and where they are NULL.
    Int(Vec<i64>, Vec<bool>),
    /// Numbers, NaN for NULL (as the writer writes non-finite values as NULL).
    Real(Vec<f64>),
    /// Texts.
    Text(Vec<Option<String>>),
}

/// A column: name, type and values.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnData {
    /// Column name.
    pub name: &'static str,
    /// Column type.
    pub ty: ColumnType,
    /// Values, one per item.
    pub values: Values,
}

/// The columns of `layer` that `plan` writes, over `items` of `rows`.
pub fn columns(layer: &dyn Layer, plan: &Plan, rows: &Rows, items: &[Item]) -> Vec<ColumnData> {
    plan.columns(layer)
        .into_iter()
        .map(|(k, name, ty)| {
            let cell = |it: &Item| match *it {
                Item::Row(i) => layer.cell(rows, i, k),
                Item::Empty(fid) if name == super::name::SRC_FID => crate::layer::fid(fid),
                Item::Empty(_) => Cell::Null,
            };
            let values = match ty {
                ColumnType::Int32 | ColumnType::Int64 => {
                    let (mut v, mut null) = (
                        Vec::with_capacity(items.len()),
                        Vec::with_capacity(items.len()),
                    );
                    for it in items {
                        match cell(it) {
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
                    items
                        .iter()
                        .map(|it| match cell(it) {
                            Cell::Real(x) if x.is_finite() => x,
                            Cell::Int(i) => i as f64,
                            _ => f64::NAN,
                        })
                        .collect(),
                ),
                ColumnType::Text => Values::Text(
                    items
                        .iter()
                        .map(|it| match cell(it) {
                            Cell::Text(s) => Some(s),
                            _ => None,
                        })
                        .collect(),
                ),
            };
            ColumnData { name, ty, values }
        })
        .collect()
}

/// The lines of every item (from the layer's geometry), or `None`.
pub fn lines(layer: &dyn Layer, rows: &Rows, items: &[Item]) -> Vec<Option<MultiLineString<f64>>> {
    items
        .iter()
        .map(|it| match *it {
            Item::Row(i) => match layer.shape(rows, i) {
                Some(Shape::Lines(m)) | Some(Shape::LinesM(m, _)) => Some(m.clone()),
                Some(Shape::Line(l)) => Some(MultiLineString(vec![l])),
                Some(Shape::Geometry(geo::Geometry::MultiLineString(m))) => Some(m.clone()),
                Some(Shape::Geometry(geo::Geometry::LineString(l))) => {
                    Some(MultiLineString(vec![l.clone()]))
                }
                _ => None,
            },
            Item::Empty(_) => None,
        })
        .collect()
}

/// Geometries as GeoArrow MULTILINESTRING buffers: interleaved x, y; the
/// start of every line in points; the start of every geometry in lines;
/// and which are NULL.
#[derive(Debug, Clone, PartialEq)]
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
