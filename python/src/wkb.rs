//! Well-known binary: the geometries the Python side hands over (read) and
//! the skeletons it gets back (write), 2D.
//!
//! Reads ISO and extended (PostGIS) WKB of either byte order; Z and M are
//! dropped, as the command line's reader drops them.

use geo::{Coord, Geometry, LineString, MultiLineString, MultiPoint, MultiPolygon, Point, Polygon};

/// A cursor over WKB bytes.
struct Cursor<'a> {
    buf: &'a [u8],
    pos: usize,
}

/// The layout of one geometry's coordinates.
#[derive(Clone, Copy)]
struct Layout {
    little: bool,
    dims: usize,
}

impl Cursor<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let end = self.pos + N;
        let bytes = self
            .buf
            .get(self.pos..end)
            .ok_or_else(|| format!("truncated WKB: {} bytes, more expected", self.buf.len()))?;
        self.pos = end;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }

    fn u32(&mut self, little: bool) -> Result<u32, String> {
        let b = self.take::<4>()?;
        Ok(if little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    }

    fn count(&mut self, l: Layout, each: usize) -> Result<usize, String> {
        let n = self.u32(l.little)? as usize;
        // A count the remaining bytes cannot hold is corrupt input, not an allocation.
        if n.saturating_mul(each) > self.buf.len() - self.pos {
            return Err(format!("corrupt WKB: a count of {n} exceeds the data"));
        }
        Ok(n)
    }

    fn f64(&mut self, little: bool) -> Result<f64, String> {
        let b = self.take::<8>()?;
        Ok(if little {
            f64::from_le_bytes(b)
        } else {
            f64::from_be_bytes(b)
        })
    }

    fn coord(&mut self, l: Layout) -> Result<Coord<f64>, String> {
        let x = self.f64(l.little)?;
        let y = self.f64(l.little)?;
        for _ in 2..l.dims {
            self.f64(l.little)?;
        }
        Ok(Coord { x, y })
    }

    fn line(&mut self, l: Layout) -> Result<LineString<f64>, String> {
        let n = self.count(l, 8 * l.dims)?;
        (0..n)
            .map(|_| self.coord(l))
            .collect::<Result<_, _>>()
            .map(LineString)
    }

    fn polygon(&mut self, l: Layout) -> Result<Polygon<f64>, String> {
        let n = self.count(l, 4)?;
        let mut rings = (0..n)
            .map(|_| self.line(l))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter();
        let exterior = rings.next().unwrap_or_else(|| LineString(Vec::new()));
        Ok(Polygon::new(exterior, rings.collect()))
    }

    /// One geometry with its header; `expect` is the type a member of a
    /// multi-geometry must have.
    fn geometry(&mut self, expect: Option<u32>) -> Result<Geometry<f64>, String> {
        let little = match self.take::<1>()?[0] {
            0 => false,
            1 => true,
            b => return Err(format!("corrupt WKB: byte order {b}")),
        };
        let raw = self.u32(little)?;
        let (mut ty, mut dims) = (raw & 0x0fff_ffff, 2);
        if raw & 0x8000_0000 != 0 {
            dims += 1;
        }
        if raw & 0x4000_0000 != 0 {
            dims += 1;
        }
        if raw & 0x2000_0000 != 0 {
            self.u32(little)?; // SRID
        }
        match ty / 1000 {
            0 => {}
            1 | 2 => dims += 1,
            3 => dims += 2,
            _ => return Err(format!("unsupported WKB geometry type {raw}")),
        }
        ty %= 1000;
        if let Some(e) = expect {
            if ty != e {
                return Err(format!(
                    "corrupt WKB: member of type {ty} where {e} belongs"
                ));
            }
        }
        let l = Layout { little, dims };
        Ok(match ty {
            1 => {
                let c = self.coord(l)?;
                Geometry::Point(Point(c))
            }
            2 => Geometry::LineString(self.line(l)?),
            3 => Geometry::Polygon(self.polygon(l)?),
            4..=7 => {
                let n = self.count(l, 5)?;
                let member = match ty {
                    4 => Some(1),
                    5 => Some(2),
                    6 => Some(3),
                    _ => None,
                };
                let parts = (0..n)
                    .map(|_| self.geometry(member))
                    .collect::<Result<Vec<_>, _>>()?;
                match ty {
                    4 => Geometry::MultiPoint(MultiPoint(
                        parts.into_iter().filter_map(|g| Point::try_from(g).ok()).collect(),
                    )),
                    5 => Geometry::MultiLineString(MultiLineString(
                        parts
                            .into_iter()
                            .filter_map(|g| LineString::try_from(g).ok())
                            .collect(),
                    )),
                    6 => Geometry::MultiPolygon(MultiPolygon(
                        parts
                            .into_iter()
                            .filter_map(|g| Polygon::try_from(g).ok())
                            .collect(),
                    )),
                    _ => Geometry::GeometryCollection(geo::GeometryCollection(parts)),
                }
            }
            other => {
                return Err(format!(
                    "unsupported WKB geometry type {other} (curves and surfaces are not read; linearise them first)"
                ))
            }
        })
    }
}

/// Reads one geometry from WKB.
pub fn read(buf: &[u8]) -> Result<Geometry<f64>, String> {
    let mut c = Cursor { buf, pos: 0 };
    c.geometry(None)
}

/// Writes a MULTILINESTRING as little-endian ISO WKB, appending to `out`.
pub fn write_lines(m: &MultiLineString<f64>, out: &mut Vec<u8>) {
    out.reserve(9 + m.0.iter().map(|l| 9 + 16 * l.0.len()).sum::<usize>());
    out.push(1);
    out.extend_from_slice(&5u32.to_le_bytes());
    out.extend_from_slice(&(m.0.len() as u32).to_le_bytes());
    for l in &m.0 {
        out.push(1);
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(l.0.len() as u32).to_le_bytes());
        for c in &l.0 {
            out.extend_from_slice(&c.x.to_le_bytes());
            out.extend_from_slice(&c.y.to_le_bytes());
        }
    }
}

/// Writes a MULTIPOLYGON as little-endian ISO WKB, appending to `out`.
pub fn write_polygons(m: &MultiPolygon<f64>, out: &mut Vec<u8>) {
    out.push(1);
    out.extend_from_slice(&6u32.to_le_bytes());
    out.extend_from_slice(&(m.0.len() as u32).to_le_bytes());
    for p in &m.0 {
        write_polygon(p, out);
    }
}

/// Writes a POLYGON as little-endian ISO WKB, appending to `out`.
pub fn write_polygon(p: &Polygon<f64>, out: &mut Vec<u8>) {
    let rings: Vec<&geo::LineString<f64>> =
        std::iter::once(p.exterior()).chain(p.interiors()).collect();
    out.reserve(9 + rings.iter().map(|r| 4 + 16 * r.0.len()).sum::<usize>());
    out.push(1);
    out.extend_from_slice(&3u32.to_le_bytes());
    out.extend_from_slice(&(rings.len() as u32).to_le_bytes());
    for r in rings {
        out.extend_from_slice(&(r.0.len() as u32).to_le_bytes());
        for c in &r.0 {
            out.extend_from_slice(&c.x.to_le_bytes());
            out.extend_from_slice(&c.y.to_le_bytes());
        }
    }
}

/// Writes a point, a line or any areal or lineal geometry as little-endian
/// ISO WKB, appending to `out`; `false` (nothing written) for other kinds.
pub fn write_geometry(g: &Geometry<f64>, out: &mut Vec<u8>) -> bool {
    match g {
        Geometry::Point(p) => {
            out.push(1);
            out.extend_from_slice(&1u32.to_le_bytes());
            out.extend_from_slice(&p.0.x.to_le_bytes());
            out.extend_from_slice(&p.0.y.to_le_bytes());
        }
        Geometry::LineString(l) => {
            // A LINESTRING: the MULTILINESTRING's one member, header and all.
            let mut m = Vec::new();
            write_lines(&MultiLineString(vec![l.clone()]), &mut m);
            out.extend_from_slice(&m[9..]);
        }
        Geometry::MultiLineString(m) => write_lines(m, out),
        Geometry::Polygon(p) => write_polygon(p, out),
        Geometry::MultiPolygon(m) => write_polygons(m, out),
        _ => return false,
    }
    true
}

/// The areal parts of a repaired geometry, as the command line's reader
/// keeps them after MakeValid: a polygon or multipolygon as it is, the
/// polygons of a collection as a multipolygon, or the reason there are none.
pub fn areal_parts(g: Geometry<f64>) -> Result<Geometry<f64>, String> {
    fn collect(g: Geometry<f64>, out: &mut Vec<Polygon<f64>>) {
        match g {
            Geometry::Polygon(p) => out.push(p),
            Geometry::MultiPolygon(mp) => out.extend(mp.0),
            Geometry::GeometryCollection(gc) => gc.0.into_iter().for_each(|g| collect(g, out)),
            _ => {}
        }
    }
    if matches!(g, Geometry::Polygon(_) | Geometry::MultiPolygon(_)) {
        return Ok(g);
    }
    let mut polygons = Vec::new();
    collect(g, &mut polygons);
    if polygons.is_empty() {
        return Err("make_valid left no area (the polygon collapses to lines or points)".into());
    }
    Ok(Geometry::MultiPolygon(MultiPolygon(polygons)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    fn wkb_polygon(little: bool, ty: u32, dims: usize) -> Vec<u8> {
        let u = |v: u32| {
            if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            }
        };
        let f = |v: f64| {
            if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            }
        };
        let mut b = vec![u8::from(little)];
        b.extend(u(ty));
        b.extend(u(1));
        b.extend(u(4));
        for (x, y) in [(0., 0.), (1., 0.), (0., 1.), (0., 0.)] {
            b.extend(f(x));
            b.extend(f(y));
            for _ in 2..dims {
                b.extend(f(7.0));
            }
        }
        b
    }

    #[test]
    fn reads_both_byte_orders_and_drops_z_and_m() {
        let want = Geometry::Polygon(polygon![(x: 0., y: 0.), (x: 1., y: 0.), (x: 0., y: 1.)]);
        assert_eq!(read(&wkb_polygon(true, 3, 2)).unwrap(), want);
        assert_eq!(read(&wkb_polygon(false, 3, 2)).unwrap(), want);
        assert_eq!(read(&wkb_polygon(true, 1003, 3)).unwrap(), want);
        assert_eq!(read(&wkb_polygon(true, 3003, 4)).unwrap(), want);
        assert_eq!(read(&wkb_polygon(true, 0x8000_0003, 3)).unwrap(), want);
    }

    #[test]
    fn polygons_round_trip() {
        let p = Polygon::new(
            LineString::from(vec![(0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (0.0, 0.0)]),
            vec![LineString::from(vec![
                (1.0, 0.5),
                (2.0, 0.5),
                (2.0, 1.0),
                (1.0, 0.5),
            ])],
        );
        let mut out = Vec::new();
        write_polygon(&p, &mut out);
        assert_eq!(read(&out).unwrap(), Geometry::Polygon(p.clone()));
        let m = MultiPolygon(vec![p.clone(), p]);
        out.clear();
        write_polygons(&m, &mut out);
        assert_eq!(read(&out).unwrap(), Geometry::MultiPolygon(m));
    }

    #[test]
    fn corrupt_input_is_an_error_not_a_panic() {
        let b = wkb_polygon(true, 3, 2);
        for n in 0..b.len() {
            assert!(read(&b[..n]).is_err());
        }
        let mut huge = b.clone();
        huge[5..9].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(read(&huge).is_err());
    }

    #[test]
    fn lines_round_trip() {
        let m = MultiLineString(vec![LineString::from(vec![(0., 0.), (1., 2.)])]);
        let mut out = Vec::new();
        write_lines(&m, &mut out);
        assert_eq!(read(&out).unwrap(), Geometry::MultiLineString(m));
    }

    #[test]
    fn areal_parts_keep_polygons_only() {
        let p = polygon![(x: 0., y: 0.), (x: 1., y: 0.), (x: 0., y: 1.)];
        let gc = Geometry::GeometryCollection(geo::GeometryCollection(vec![
            Geometry::Polygon(p.clone()),
            Geometry::LineString(LineString::from(vec![(0., 0.), (5., 5.)])),
        ]));
        assert_eq!(
            areal_parts(gc).unwrap(),
            Geometry::MultiPolygon(MultiPolygon(vec![p]))
        );
        let line = Geometry::LineString(LineString::from(vec![(0., 0.), (5., 5.)]));
        assert!(areal_parts(line).unwrap_err().contains("no area"));
    }
}
