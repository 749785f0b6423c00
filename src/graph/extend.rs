//! Extension of legs to the boundary (SPEC §5, refined by the issue on the
//! default output's quality).
//!
//! After pruning, a leaf ℓ with r_ℓ > tolerance stops short of ∂P (most
//! methods end legs inside P, and pruning a leg turns its junction into a
//! leaf). The extension joins every such leaf to ∂P, so that afterwards every
//! leaf lies on ∂P.
//!
//! * `centred` (default): along the method's own removed legs, or between
//!   them where they fork symmetrically — see `crate::graph::ends`. It
//!   needs what pruning removed, so it runs in [`prune_and_extend`]; on an
//!   already pruned graph ([`extend`]) only its straight rays from leaves
//!   inside P and its cut-end rule at leaves on ∂P apply.
//!
//! The straight modes join every leaf inside P with one new straight segment
//! ending in a new node of radius 0:
//!
//! * `ray`: with L the leg's polyline from ℓ and
//!   `q = L(min(2 r_ℓ, length(L)))` (the point at that arc length from ℓ),
//!   cast the ray `ℓ + t · (ℓ − q) / |ℓ − q|`, t > 0, and add the segment from
//!   ℓ to its first hit on ∂P: the leg continues in the direction it had over
//!   the last two local radii, which averages out the zig-zag of discrete
//!   skeletons. When there is no hit, the direction is undefined, or the
//!   segment would leave P (ℓ itself outside P by more than the tolerance,
//!   or crossing ∂P), the leaf falls back to `nearest`.
//! * `nearest`: add the segment from ℓ to the nearest point of ∂P (it cannot
//!   cross ∂P: no boundary point is closer than that point).
//! * `none`: the graph unchanged.
//!
//! r_ℓ is measured afresh as the distance of ℓ to ∂P, and the tolerance is
//! `1e-9 × extent` of the polygon ([`PreparedPolygon::extent`]). Leaves are
//! visited in branch order, so the result is deterministic.
//!
//! ```
//! use skeletonise::geometry::PreparedPolygon;
//! use skeletonise::graph::{GraphBuilder, extend::{extend, ExtendParams}};
//! use geo::{polygon, Coord};
//! let p = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 10., y: 0.),
//!                                        (x: 10., y: 4.), (x: 0., y: 4.)]).unwrap();
//! let mut b = GraphBuilder::new();
//! b.segment(Coord { x: 2., y: 2. }, Coord { x: 8., y: 2. });
//! let g = extend(&b.finish(p.boundary()), &p, &ExtendParams::default());
//! assert_eq!(g.total_length(), 10.0); // from (0, 2) to (10, 2)
//! ```

use super::line::point_at;
use super::prune::{prune, prune_mask, PruneParams};
use super::{polyline_length, SkeletonGraph};
use crate::geometry::tolerance::SAME_POINT;
use crate::geometry::vector::hypot;
use crate::geometry::{Boundary, PreparedPolygon};
use geo::Coord;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How leaves are joined to ∂P.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ExtendMode {
    /// Continue along the method's own removed legs (or between them at a
    /// symmetric fork) to ∂P.
    #[default]
    #[serde(alias = "centered")]
    Centred,
    /// Continue the leg's direction to the first boundary hit.
    Ray,
    /// Join the leaf to the nearest boundary point.
    Nearest,
    /// Leave leaves where they are.
    None,
}

/// Options of the `extend` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ExtendParams {
    /// Extension mode.
    pub mode: ExtendMode,
}

impl From<ExtendMode> for ExtendParams {
    fn from(mode: ExtendMode) -> Self {
        Self { mode }
    }
}

impl Default for ExtendParams {
    fn default() -> Self {
        Self {
            mode: ExtendMode::Centred,
        }
    }
}

/// Extends the legs of `graph` to ∂P (see the module documentation).
pub fn extend(
    graph: &SkeletonGraph,
    polygon: &PreparedPolygon,
    params: &ExtendParams,
) -> SkeletonGraph {
    match params.mode {
        ExtendMode::None => return graph.clone(),
        ExtendMode::Centred => {
            let m = graph.merged();
            let keep = vec![true; m.edges().len()];
            return super::ends::centred(&m, keep, polygon, false);
        }
        ExtendMode::Ray | ExtendMode::Nearest => {}
    }
    let boundary = polygon.boundary();
    let tol = SAME_POINT * polygon.extent();
    let deg = graph.degrees();
    let mut out = graph.clone();
    for b in graph.branches() {
        if b.start == b.end {
            continue;
        }
        for (leaf, from_leaf) in [(b.start, false), (b.end, true)] {
            if deg[leaf.index()] != 1 {
                continue;
            }
            let p = graph.node(leaf).pos;
            let r = boundary.distance(p);
            if r <= tol {
                continue;
            }
            let target = match params.mode {
                ExtendMode::Ray => {
                    let leg: Vec<Coord<f64>> = if from_leaf {
                        b.coords.iter().rev().copied().collect()
                    } else {
                        b.coords.clone()
                    };
                    ray_target(boundary, &leg, r, tol)
                }
                _ => None,
            }
            .or_else(|| boundary.nearest(p).map(|(q, _, _)| q));
            if let Some(q) = target.filter(|&q| q != p) {
                let n = out.add_node(q, 0.0, None);
                out.add_edge(leaf, n, Vec::new());
            }
        }
    }
    out
}

/// Most prune → extend rounds for the straight modes: the first does the
/// work, later ones only remove legs that turned out short once extended
/// (rarely more than one).
const MAX_PRUNE_ROUNDS: usize = 4;

/// Prunes and extends one method's raw skeleton on its own.
///
/// With `centred` the extension follows what pruning removed. With the
/// straight modes and a leg-removing prune mode, pruning runs again on what
/// the extension revealed as insignificant (a leg kept for the reach of what
/// was cut behind its leaf can end up short once extended along its own
/// direction), until stable. With `ray`, `nearest` or `centred` every leaf
/// of the result lies on ∂P; where an added segment crosses a line of the
/// skeleton, both get a node there ([`super::planar`]).
pub fn prune_and_extend(
    raw: &SkeletonGraph,
    polygon: &PreparedPolygon,
    pr: Option<&PruneParams>,
    ex: Option<&ExtendParams>,
) -> SkeletonGraph {
    let boundary = polygon.boundary();
    let mode = ex.map_or(ExtendMode::None, |e| e.mode);
    let g = if mode == ExtendMode::Centred {
        let m = raw.merged();
        let keep = match pr {
            Some(p) => prune_mask(&m, p, boundary),
            None => vec![true; m.edges().len()],
        };
        // A network of corridors may be cut roughly at the data's edge.
        let rough = pr.is_some_and(|p| p.junctions == super::junctions::Junctions::Merge);
        super::ends::centred(&m, keep, polygon, rough)
    } else {
        prune_and_extend_straight(raw, polygon, pr, ex)
    };
    // Added segments may cross a line of the skeleton: node them.
    super::planar::node_crossings(g, boundary).0
}

/// [`prune_and_extend`] for the straight modes (and none).
fn prune_and_extend_straight(
    raw: &SkeletonGraph,
    polygon: &PreparedPolygon,
    pr: Option<&PruneParams>,
    ex: Option<&ExtendParams>,
) -> SkeletonGraph {
    let boundary = polygon.boundary();
    let mut g = match pr {
        Some(p) => prune(raw, p, boundary),
        None => raw.clone(),
    };
    if let Some(ex) = ex.filter(|e| e.mode != ExtendMode::None) {
        g = extend(&g, polygon, ex);
        if let Some(pr) = pr.filter(|p| p.removes_legs()) {
            for _ in 1..MAX_PRUNE_ROUNDS {
                let again = prune(&g, pr, boundary);
                if again.edges().len() == g.edges().len()
                    && again.total_length() == g.total_length()
                {
                    break;
                }
                g = extend(&again, polygon, ex);
            }
        }
    }
    g
}

/// The `ray` target for the leaf `leg[0]` at distance `r` from ∂P, or `None`
/// when the ray is undefined or its segment would leave P.
fn ray_target(boundary: &Boundary, leg: &[Coord<f64>], r: f64, tol: f64) -> Option<Coord<f64>> {
    let p = leg[0];
    let q = point_at(leg, (2.0 * r).min(polyline_length(leg)));
    let d = p - q;
    let norm = hypot(d);
    if norm.is_nan() || norm <= 0.0 || !boundary.contains_with_tolerance(p, tol) {
        return None;
    }
    let dir = d / norm;
    // Any hit lies within the bounding box, so its diagonal bounds t.
    let span = boundary.bbox_max() - boundary.bbox_min();
    let max_t = 2.0 * (hypot(span) + r);
    let hit = boundary.first_hit(p, dir, 0.0, max_t)?;
    let mid = (p + hit.point) * 0.5;
    if !boundary.reaches(p, hit.point) || !boundary.contains_with_tolerance(mid, tol) {
        return None;
    }
    Some(hit.point)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::GraphBuilder;
    use geo::polygon;

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    fn leaves(g: &SkeletonGraph) -> Vec<Coord<f64>> {
        let deg = g.degrees();
        g.nodes()
            .iter()
            .zip(&deg)
            .filter(|(_, &d)| d == 1)
            .map(|(n, _)| n.pos)
            .collect()
    }

    #[test]
    fn point_at_walks_the_polyline() {
        use super::point_at;
        let l = [c(0., 0.), c(1., 0.), c(1., 2.)];
        assert_eq!(point_at(&l, 0.5), c(0.5, 0.));
        assert_eq!(point_at(&l, 2.0), c(1., 1.));
        assert_eq!(point_at(&l, 9.0), c(1., 2.));
    }

    #[test]
    fn ray_follows_the_legs_direction_and_nearest_the_closest_point() {
        // An L-shaped leg in a 20 × 20 square: its last part runs east.
        let p = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 20., y: 0.),
            (x: 20., y: 20.), (x: 0., y: 20.)])
        .unwrap();
        let mut b = GraphBuilder::new();
        b.polyline(&[c(10., 3.), c(10., 10.), c(18., 10.)]);
        let g = b.finish(p.boundary());
        let ray = extend(&g, &p, &ExtendMode::Ray.into());
        let mut l = leaves(&ray);
        l.sort_by(|a, b| a.x.total_cmp(&b.x));
        // Leaf (10, 3), r = 3: the direction comes from (10, 9), so south;
        // leaf (18, 10), r = 2: from (14, 10), so east.
        assert_eq!(l, vec![c(10., 0.), c(20., 10.)]);
        let near = extend(&g, &p, &ExtendMode::Nearest.into());
        let mut l = leaves(&near);
        l.sort_by(|a, b| a.x.total_cmp(&b.x));
        assert_eq!(l, vec![c(10., 0.), c(20., 10.)]);
        let none = extend(&g, &p, &ExtendMode::None.into());
        assert_eq!(none, g);
    }

    #[test]
    fn ray_stops_at_the_first_wall() {
        // A U shape: the leaf in the left arm pointing east stops at the
        // notch wall, never reaching the right arm.
        let p = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 30., y: 0.),
            (x: 30., y: 30.), (x: 20., y: 30.), (x: 20., y: 10.), (x: 10., y: 10.),
            (x: 10., y: 30.), (x: 0., y: 30.)])
        .unwrap();
        let mut b = GraphBuilder::new();
        b.segment(c(5., 25.), c(6., 25.));
        let g = b.finish(p.boundary());
        let e = extend(&g, &p, &ExtendMode::Ray.into());
        let mut l = leaves(&e);
        l.sort_by(|a, b| a.x.total_cmp(&b.x));
        assert_eq!(l, vec![c(0., 25.), c(10., 25.)]);
    }

    #[test]
    fn leaves_on_the_boundary_are_left_alone() {
        let p = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 10., y: 0.),
            (x: 10., y: 4.), (x: 0., y: 4.)])
        .unwrap();
        let mut b = GraphBuilder::new();
        b.segment(c(0., 2.), c(10., 2.));
        let g = b.finish(p.boundary());
        assert_eq!(extend(&g, &p, &ExtendParams::default()), g);
    }
}
