//! Ring normalisation (SPEC §2): exterior counter-clockwise, holes clockwise,
//! closed, no repeated consecutive vertices.

use super::GeometryError;
use geo::{Coord, LineString, Polygon};

/// Twice the signed area of a closed ring (positive = counter-clockwise).
pub fn signed_area2(ring: &[Coord<f64>]) -> f64 {
    if ring.len() < 3 {
        return 0.0;
    }
    // Shoelace relative to the first vertex keeps precision for huge coordinates.
    let o = ring[0];
    let mut s = 0.0;
    for w in ring.windows(2) {
        let (a, b) = (w[0] - o, w[1] - o);
        s += super::vector::cross(a, b);
    }
    s
}

/// Cleans one ring: drops repeated consecutive vertices (also across the
/// closing point) and returns the distinct vertices, *not* closed.
pub fn distinct_vertices(ring: &LineString<f64>) -> Vec<Coord<f64>> {
    distinct_vertices_within(&ring.0, 0.0)
}

/// [`distinct_vertices`] of a ring's vertices (closed or not), where a
/// vertex within `tol` of the one kept before it (in x, y and distance) is
/// a repeat; `tol = 0` is exact equality.
pub fn distinct_vertices_within(ring: &[Coord<f64>], tol: f64) -> Vec<Coord<f64>> {
    let mut out: Vec<Coord<f64>> = Vec::with_capacity(ring.len());
    for &c in ring {
        if out.last().is_none_or(|&q| !super::within_hypot(c - q, tol)) {
            out.push(c);
        }
    }
    while out.len() > 1 && super::within_hypot(out[out.len() - 1] - out[0], tol) {
        out.pop();
    }
    out
}

fn closed_oriented(mut v: Vec<Coord<f64>>, ccw: bool) -> LineString<f64> {
    v.push(v[0]);
    let area = signed_area2(&v);
    if (area > 0.0) != ccw {
        v.reverse();
    }
    LineString(v)
}

/// Normalises a polygon per SPEC §2. Holes with fewer than three distinct
/// vertices or zero area are dropped (they enclose nothing); a degenerate
/// exterior is an error.
pub fn normalise_polygon(p: &Polygon<f64>) -> Result<Polygon<f64>, GeometryError> {
    for (i, r) in std::iter::once(p.exterior())
        .chain(p.interiors())
        .enumerate()
    {
        if r.0.iter().any(|c| !c.x.is_finite() || !c.y.is_finite()) {
            return Err(GeometryError::NonFinite { ring: i });
        }
    }
    let ext = distinct_vertices(p.exterior());
    if ext.len() < 3 {
        return Err(GeometryError::Degenerate(ext.len()));
    }
    let mut closed = ext.clone();
    closed.push(ext[0]);
    if signed_area2(&closed) == 0.0 {
        return Err(GeometryError::Degenerate(ext.len()));
    }
    let exterior = closed_oriented(ext, true);
    let holes = p
        .interiors()
        .iter()
        .map(distinct_vertices)
        .filter(|h| {
            if h.len() < 3 {
                return false;
            }
            let mut c = h.clone();
            c.push(h[0]);
            signed_area2(&c) != 0.0
        })
        .map(|h| closed_oriented(h, false))
        .collect();
    Ok(Polygon::new(exterior, holes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    #[test]
    fn orients_and_cleans_rings() {
        let p = polygon!(
            exterior: [(x: 0., y: 0.), (x: 0., y: 4.), (x: 0., y: 4.), (x: 4., y: 4.), (x: 4., y: 0.), (x: 0., y: 0.)],
            interiors: [[(x: 1., y: 1.), (x: 2., y: 1.), (x: 2., y: 2.), (x: 1., y: 1.)]],
        );
        let n = normalise_polygon(&p).unwrap();
        assert_eq!(n.exterior().0.len(), 5);
        assert!(signed_area2(&n.exterior().0) > 0.0);
        assert!(signed_area2(&n.interiors()[0].0) < 0.0);
        assert_eq!(n.exterior().0.first(), n.exterior().0.last());
    }

    #[test]
    fn degenerate_exterior_is_an_error() {
        let p = polygon![(x: 0., y: 0.), (x: 1., y: 1.), (x: 2., y: 2.)];
        assert!(matches!(
            normalise_polygon(&p),
            Err(GeometryError::Degenerate(_))
        ));
    }
}
