//! The parts of a geometry of any kind that a step works on: its polygons
//! (or why it has none) and its lines.

use geo::{Geometry, LineString, Polygon};

/// The polygon parts of a geometry, or why it has none.
pub fn polygon_parts(geom: Option<&Geometry<f64>>) -> Result<Vec<Polygon<f64>>, String> {
    let Some(geom) = geom else {
        return Err("NULL geometry: the feature has no geometry to skeletonise".into());
    };
    let parts = match geom {
        Geometry::Polygon(p) => vec![p.clone()],
        Geometry::MultiPolygon(mp) => mp.0.clone(),
        Geometry::Rect(r) => vec![r.to_polygon()],
        Geometry::Triangle(t) => vec![t.to_polygon()],
        Geometry::GeometryCollection(gc) => {
            let mut v = Vec::new();
            for g in gc.iter() {
                match polygon_parts(Some(g)) {
                    Ok(p) => v.extend(p),
                    Err(_) => {
                        return Err(format!(
                            "geometry collection with a non-polygon member ({}); only polygons can be skeletonised",
                            kind(g)
                        ))
                    }
                }
            }
            v
        }
        other => {
            return Err(format!(
                "{} geometry: only polygons and multipolygons can be skeletonised",
                kind(other)
            ))
        }
    };
    let parts: Vec<Polygon<f64>> = parts
        .into_iter()
        .filter(|p| !p.exterior().0.is_empty())
        .collect();
    if parts.is_empty() {
        return Err("empty geometry: the polygon has no vertices".into());
    }
    Ok(parts)
}

fn kind(g: &Geometry<f64>) -> &'static str {
    match g {
        Geometry::Point(_) => "point",
        Geometry::MultiPoint(_) => "multipoint",
        Geometry::Line(_) | Geometry::LineString(_) => "line",
        Geometry::MultiLineString(_) => "multilinestring",
        Geometry::Polygon(_) => "polygon",
        Geometry::MultiPolygon(_) => "multipolygon",
        Geometry::GeometryCollection(_) => "geometry collection",
        Geometry::Rect(_) => "rectangle",
        Geometry::Triangle(_) => "triangle",
    }
}

/// The lines of a geometry, appended to `out` (other kinds are skipped).
pub fn lines_of(g: &Geometry<f64>, out: &mut Vec<LineString<f64>>) {
    match g {
        Geometry::LineString(l) => out.push(l.clone()),
        Geometry::MultiLineString(m) => out.extend(m.0.iter().cloned()),
        Geometry::Line(l) => out.push(LineString(vec![l.start, l.end])),
        Geometry::GeometryCollection(c) => c.iter().for_each(|g| lines_of(g, out)),
        _ => {}
    }
}
