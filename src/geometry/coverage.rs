//! The coverage toolkit: polygons that meet along shared edges with the same
//! vertices on both sides (the pieces of a partitioned polygon, a unit grown
//! by them, river reaches cut from one river), handled exactly — by the bits
//! of their coordinates ([`CoordKey`]), never within a tolerance.
//!
//! - [`EdgeKey`]: a directed edge by the bits of its two ends.
//! - [`RingEdges`]: every directed edge of a set of polygons' rings with the
//!   polygon on its left, and the edges two of them share (as JTS's
//!   `CoverageRingEdges` finds them): which pieces are neighbours, and along
//!   what.
//! - [`coverage_union`] and [`polygons_of_edges`]: the union of a coverage,
//!   or the polygons a set of directed edges bounds, shared edges cancelling
//!   (made in `geometry::arrangement`, whose half-edge walk they share).

pub use super::arrangement::{coverage_union, polygons_of_edges};
use super::CoordKey;
use geo::{Coord, LineString, Polygon};
use rustc_hash::FxHashMap;

/// A directed edge by the bits of its two ends.
pub type EdgeKey = (CoordKey, CoordKey);

/// The key of the edge from `a` to `b`.
pub fn edge_key(a: Coord<f64>, b: Coord<f64>) -> EdgeKey {
    (CoordKey::from(a), CoordKey::from(b))
}

/// The rings of `p`: its shell, then its holes.
pub fn rings(p: &Polygon<f64>) -> impl Iterator<Item = &LineString<f64>> {
    std::iter::once(p.exterior()).chain(p.interiors())
}

/// Every directed edge of some polygons' rings, with the polygon (its index)
/// that has it on its left when its rings are oriented so (shells
/// counter-clockwise, holes clockwise): two polygons of a coverage share an
/// edge when one has it from `a` to `b` and the other from `b` to `a`.
#[derive(Debug)]
pub struct RingEdges<'a> {
    polygons: &'a [&'a Polygon<f64>],
    left: FxHashMap<EdgeKey, usize>,
}

impl<'a> RingEdges<'a> {
    /// The edges of `polygons` (oriented: see [`RingEdges`]).
    pub fn of(polygons: &'a [&'a Polygon<f64>]) -> Self {
        let mut left = FxHashMap::default();
        for (i, p) in polygons.iter().enumerate() {
            for r in rings(p) {
                for w in r.0.windows(2) {
                    left.insert(edge_key(w[0], w[1]), i);
                }
            }
        }
        Self { polygons, left }
    }

    /// The polygon that has the edge from `a` to `b` on its left.
    pub fn left_of(&self, a: Coord<f64>, b: Coord<f64>) -> Option<usize> {
        self.left.get(&edge_key(a, b)).copied()
    }

    /// Every edge two of the polygons share, once from each side:
    /// `(a, b, i, j)`, polygon `i` on the left of `a`→`b`, polygon `j` on
    /// its right; in the order of the polygons' rings.
    pub fn shared(&self) -> Vec<(Coord<f64>, Coord<f64>, usize, usize)> {
        let mut shared = Vec::new();
        for (i, p) in self.polygons.iter().enumerate() {
            for r in rings(p) {
                for w in r.0.windows(2) {
                    match self.left_of(w[1], w[0]) {
                        Some(j) if j != i => shared.push((w[0], w[1], i, j)),
                        _ => {}
                    }
                }
            }
        }
        shared
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::polygon;

    #[test]
    fn two_squares_share_their_common_edge_once_from_each_side() {
        let a = polygon![(x: 0., y: 0.), (x: 1., y: 0.), (x: 1., y: 1.), (x: 0., y: 1.)];
        let b = polygon![(x: 1., y: 0.), (x: 2., y: 0.), (x: 2., y: 1.), (x: 1., y: 1.)];
        let apart = polygon![(x: 5., y: 5.), (x: 6., y: 5.), (x: 6., y: 6.)];
        let all = [&a, &b, &apart];
        let edges = RingEdges::of(&all);
        assert_eq!(
            edges.left_of(Coord { x: 1., y: 0. }, Coord { x: 1., y: 1. }),
            Some(0)
        );
        assert_eq!(
            edges.left_of(Coord { x: 1., y: 1. }, Coord { x: 1., y: 0. }),
            Some(1)
        );
        let shared = edges.shared();
        assert_eq!(
            shared,
            vec![
                (Coord { x: 1., y: 0. }, Coord { x: 1., y: 1. }, 0, 1),
                (Coord { x: 1., y: 1. }, Coord { x: 1., y: 0. }, 1, 0),
            ]
        );
        // Their union is one square of two, exactly.
        let union = coverage_union(&[a, b]);
        assert_eq!(union.len(), 1);
        assert_eq!(geo::Area::unsigned_area(&union[0]), 2.0);
    }

    #[test]
    fn an_edge_a_tiny_distance_off_is_not_shared() {
        let a = polygon![(x: 0., y: 0.), (x: 1., y: 0.), (x: 1., y: 1.), (x: 0., y: 1.)];
        let b = polygon![(x: 1. + 1e-12, y: 0.), (x: 2., y: 0.), (x: 2., y: 1.), (x: 1., y: 1.)];
        let all = [&a, &b];
        assert!(RingEdges::of(&all).shared().is_empty());
    }
}
