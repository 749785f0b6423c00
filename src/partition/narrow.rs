//! A partial partition (`width`): only the narrow parts of a collapsed
//! polygon are given away. What is narrow is decided as `collapse` decides
//! it, on the medial axis's discs (`crate::narrow`): its cuts — the two
//! radii from a change point to the bank — are added to the new
//! boundaries, noded with them (a point where a cut crosses a boundary is
//! put into both, with one coordinate), and the faces that lie in the
//! parts `collapse` keeps stay polygons of their own.

use crate::geometry::segment::{
    closest_on_segment, crossing_point, inner_points_along, properly_cross,
};
use crate::geometry::vector::norm;
use geo::{Coord, Polygon};
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{RTree, AABB};
use rustc_hash::FxHashMap;

/// A segment of a line in the index: its box, the line and the segment.
type Indexed = GeomWithData<Rectangle<[f64; 2]>, (usize, usize)>;

/// Where points go into lines: by (line, segment index).
type Inserts = FxHashMap<(usize, usize), Vec<Coord<f64>>>;

/// Puts the points where the lines of `cuts` meet those of `lines` into
/// both: a proper crossing's point into the two segments; an end of a
/// segment within `tol` of the other segment into it (or, within `tol` of
/// one of that segment's ends, the cut's vertex moved onto that end, so
/// the two share it exactly).
pub(super) fn node(cuts: &mut [Vec<Coord<f64>>], lines: &mut [Vec<Coord<f64>>], tol: f64) {
    let boxes: Vec<Indexed> = lines
        .iter()
        .enumerate()
        .flat_map(|(i, l)| {
            l.windows(2).enumerate().map(move |(j, w)| {
                GeomWithData::new(
                    Rectangle::from_corners([w[0].x, w[0].y], [w[1].x, w[1].y]),
                    (i, j),
                )
            })
        })
        .collect();
    let tree = RTree::bulk_load(boxes);
    let mut into_cuts = Inserts::default();
    let mut into_lines = Inserts::default();
    for (i, cut) in cuts.iter_mut().enumerate() {
        for j in 0..cut.len().saturating_sub(1) {
            let (a, b) = (cut[j], cut[j + 1]);
            let env = AABB::from_corners(
                [a.x.min(b.x) - tol, a.y.min(b.y) - tol],
                [a.x.max(b.x) + tol, a.y.max(b.y) + tol],
            );
            for hit in tree.locate_in_envelope_intersecting(&env) {
                let (k, m) = hit.data;
                let (c, d) = (lines[k][m], lines[k][m + 1]);
                // The cut's ends on the line's segment: moved onto its
                // ends, or put into it.
                for e in [j, j + 1] {
                    let v = cut[e];
                    if let Some(&end) = [c, d].iter().find(|&&q| norm(v - q) <= tol) {
                        cut[e] = end;
                    } else if norm(closest_on_segment(c, d, v).0 - v) <= tol {
                        into_lines.entry((k, m)).or_default().push(v);
                    }
                }
                let (a, b) = (cut[j], cut[j + 1]);
                // The line's ends on the cut's segment.
                for q in [c, d] {
                    if q != a && q != b && norm(closest_on_segment(a, b, q).0 - q) <= tol {
                        into_cuts.entry((i, j)).or_default().push(q);
                    }
                }
                if properly_cross(a, b, c, d) {
                    let x = crossing_point(a, b, c, d);
                    if [a, b, c, d].iter().all(|&q| norm(x - q) > tol) {
                        into_cuts.entry((i, j)).or_default().push(x);
                        into_lines.entry((k, m)).or_default().push(x);
                    }
                }
            }
        }
    }
    insert(cuts, &into_cuts);
    insert(lines, &into_lines);
}

/// The points of `inserts` put into their segments, in order along each.
fn insert(lines: &mut [Vec<Coord<f64>>], inserts: &Inserts) {
    for (i, l) in lines.iter_mut().enumerate() {
        if !(0..l.len()).any(|j| inserts.contains_key(&(i, j))) {
            continue;
        }
        let mut out = Vec::with_capacity(l.len() + 2);
        for (j, w) in l.windows(2).enumerate() {
            out.push(w[0]);
            if let Some(extra) = inserts.get(&(i, j)) {
                out.extend(inner_points_along(w[0], w[1], extra));
            }
        }
        out.push(l[l.len() - 1]);
        out.dedup();
        *l = out;
    }
}

/// Whether `face` lies in one of the `wide` parts: its inner point does.
pub(super) fn is_wide(face: &Polygon<f64>, wide: &[Polygon<f64>]) -> bool {
    use geo::{Contains, InteriorPoint};
    if wide.is_empty() {
        return false;
    }
    face.interior_point()
        .is_some_and(|x| wide.iter().any(|w| w.contains(&x)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    #[test]
    fn a_crossing_is_put_into_both_with_one_coordinate() {
        let mut cuts = vec![vec![c(0., 0.), c(0., 10.)]];
        let mut lines = vec![vec![c(-5., 5.), c(5., 5.), c(5., 8.)]];
        node(&mut cuts, &mut lines, 1e-9);
        assert_eq!(cuts[0], vec![c(0., 0.), c(0., 5.), c(0., 10.)]);
        assert_eq!(lines[0], vec![c(-5., 5.), c(0., 5.), c(5., 5.), c(5., 8.)]);
    }

    #[test]
    fn a_cut_vertex_near_a_line_vertex_moves_onto_it() {
        let mut cuts = vec![vec![c(0., 0.), c(1e-12, 5.), c(0., 10.)]];
        let mut lines = vec![vec![c(-5., 5.), c(0., 5.), c(5., 5.)]];
        node(&mut cuts, &mut lines, 1e-9);
        assert_eq!(cuts[0][1], c(0., 5.));
        assert_eq!(lines[0].len(), 3);
    }
}
