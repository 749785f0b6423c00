//! Boundary densification for the densified Voronoi diagram (DVD): pseudo-nodes
//! inserted on every boundary edge.

use super::vector::hypot;
use geo::{Coord, LineString};

/// How densely to insert pseudo-nodes on boundary edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Density {
    /// `k − 1` equally spaced points on each edge (each edge cut into `k` pieces).
    Factor(u32),
    /// Each edge cut into the fewest equal pieces no longer than this (CRS units).
    Spacing(f64),
}

impl Density {
    /// Number of pieces an edge of length `len` is cut into.
    pub fn pieces(&self, len: f64) -> usize {
        match *self {
            Density::Factor(k) => k.max(1) as usize,
            Density::Spacing(d) if d > 0.0 && len.is_finite() => ((len / d).ceil() as usize).max(1),
            Density::Spacing(_) => 1,
        }
    }
}

/// Number of points a densified closed ring will have (without the closing point).
pub(crate) fn densified_len(ring: &LineString<f64>, density: Density) -> usize {
    ring.lines()
        .map(|l| density.pieces(hypot(l.end - l.start)))
        .fold(0usize, usize::saturating_add)
}

/// The ring's points with pseudo-nodes inserted, not closed: each original
/// vertex followed by the pseudo-nodes of the edge that starts there.
pub(crate) fn densify_ring(ring: &LineString<f64>, density: Density) -> Vec<Coord<f64>> {
    let mut out = Vec::with_capacity(densified_len(ring, density));
    for l in ring.lines() {
        let d = l.end - l.start;
        let k = density.pieces(hypot(d));
        out.push(l.start);
        for i in 1..k {
            let t = i as f64 / k as f64;
            out.push(Coord {
                x: l.start.x + d.x * t,
                y: l.start.y + d.y * t,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::line_string;

    #[test]
    fn factor_and_spacing() {
        let r = line_string![(x: 0., y: 0.), (x: 4., y: 0.), (x: 4., y: 1.), (x: 0., y: 0.)];
        assert_eq!(densify_ring(&r, Density::Factor(4)).len(), 12);
        let pts = densify_ring(&r, Density::Spacing(1.0));
        // 4 + 1 + ceil(sqrt(17)) = 10 pieces
        assert_eq!(pts.len(), 10);
        assert_eq!(pts[1], Coord { x: 1.0, y: 0.0 });
    }
}
