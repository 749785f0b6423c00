//! The widths of a skeleton: its Medial Axis Transform segment by segment,
//! each straight piece with the disc radius (half the local width of P) at
//! both ends — for any skeleton graph whose node radii are distances to ∂P,
//! not only the medial axis's.

use super::{polyline_length, EdgeId, SkeletonGraph};
use crate::geometry::vector::hypot;
use crate::geometry::Boundary;
use geo::Line;

/// One straight piece of a Medial Axis Transform: a skeleton segment and the
/// disc radius (local half-width of P) at each end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatSegment {
    /// The segment, in the direction of its edge.
    pub line: Line<f64>,
    /// Disc radius at `line.start`.
    pub r_start: f64,
    /// Disc radius at `line.end`.
    pub r_end: f64,
}

impl MatSegment {
    /// Local width of P (2 × radius) at the start.
    pub fn width_start(&self) -> f64 {
        2.0 * self.r_start
    }

    /// Local width of P (2 × radius) at the end.
    pub fn width_end(&self) -> f64 {
        2.0 * self.r_end
    }

    /// Mean width along the segment (radius varies linearly to first order).
    pub fn mean_width(&self) -> f64 {
        self.r_start + self.r_end
    }
}

/// The Medial Axis Transform of a skeleton, segment by segment: every
/// straight piece of every edge with the disc radius at both ends — what a
/// writer needs for a `width` attribute or M values, and what a cartographer
/// uses to decide what is narrow enough to collapse.
///
/// End nodes carry their radius. Interior polyline vertices (edges merged by
/// pruning, for instance) get their distance to ∂P from `boundary` when given
/// (exact on the medial axis), otherwise a radius interpolated linearly by
/// length between the edge's end nodes. MA's raw output has its parabolic
/// arcs' vertices as edge interiors: give the boundary for their exact radii.
pub fn medial_axis_transform(
    graph: &SkeletonGraph,
    boundary: Option<&Boundary>,
) -> Vec<MatSegment> {
    let mut out = Vec::new();
    for (i, e) in graph.edges().iter().enumerate() {
        let coords = graph.edge_coords(EdgeId::from_index(i));
        let (ra, rb) = (graph.node(e.a).radius, graph.node(e.b).radius);
        let radii: Vec<f64> = match boundary {
            Some(b) => {
                let mut r: Vec<f64> = coords.iter().map(|&c| b.distance(c)).collect();
                let n = r.len();
                r[0] = ra;
                r[n - 1] = rb;
                r
            }
            None => {
                let total = polyline_length(&coords);
                let mut acc = 0.0;
                let mut r = Vec::with_capacity(coords.len());
                for (k, c) in coords.iter().enumerate() {
                    if k > 0 {
                        let d = *c - coords[k - 1];
                        acc += hypot(d);
                    }
                    let t = if total > 0.0 { acc / total } else { 0.0 };
                    r.push(ra + (rb - ra) * t);
                }
                r
            }
        };
        for k in 1..coords.len() {
            out.push(MatSegment {
                line: Line::new(coords[k - 1], coords[k]),
                r_start: radii[k - 1],
                r_end: radii[k],
            });
        }
    }
    out
}
