//! Pruning of insignificant legs (SPEC §4, refined by the issue on the
//! default output's quality).
//!
//! A **leg** ([`crate::graph::Leg`], SPEC §2) is a branch with a leaf ℓ at
//! one end; pruning judges the legs whose other end is a junction j (degree
//! ≥ 3), r_j being the junction's radius (its distance to ∂P, set by every
//! method). With `ratio` = ρ, `arm_ratio` = α and `min_length` = m, a
//! leg of extent L (its length plus the reach of its leaf, see below) is
//!
//! ```text
//!   significant    ⇔  L − r_j ≥ ρ · r_j                         (it protrudes ρ radii beyond the disc at j)
//!                  or  L − r_j ≥ α · 2 r_mouth  and  L − r_j ≥ ρ · r_j / 4     (an arm: long for its own width,
//!                      and r_mouth ≥ β · r_j                                    and of real width against the disc)
//!   insignificant  ⇔  not significant, or L < m
//!   significance   =  (L − r_j) / r_j     (+∞ when r_j = 0)
//! ```
//!
//! where r_mouth is the distance to ∂P where the leg leaves the disc at j
//! (the point at arc length r_j from j; the leaf when the leg is shorter):
//! 2 r_mouth is the width of the arm at its mouth. The first rule alone
//! measures a leg against the junction's radius, so a narrow bay or lobe
//! off a broad lake (a 5 km arm off a 4 km wide basin) was cut although it
//! is several times longer than wide; the arm rule keeps it. A bump of the
//! bank protrudes about as far as it is wide at the mouth (the leg runs into
//! a shallow, wide bulge), so it stays insignificant. The floor `ρ r_j / 4`
//! keeps digitising spikes that are tiny against the local width from
//! counting as arms. With `arm_width` = β, an arm must also be of real
//! width against the disc it leaves: a near-zero-width slot or spike in a
//! river bank is long for its own (zero) width, but it is no arm of the
//! river, and kept it became a spur across the river ending in a hook. The
//! default β = 1/8 (an arm at least an eighth as wide as the junction's
//! disc) is far below the bays and side channels of real lakes and rivers
//! (their mouths measure 0.18–0.45 of r_j on the training layers) and far
//! above a digitising slot or spike (0–0.07).
//!
//! Before the legs, whole *sides* are judged by the same rule (see
//! `sides`): on a rough boundary the medial axis grows thickets of tiny
//! junctions whose legs each protrude far beyond their own junction's disc,
//! and only the side as a whole, seen from the wide junction it hangs from,
//! shows that all of it lies within a few metres of the bank.
//!
//! Modes:
//!
//! * `significance` (default) and `length` (only the `min_length` rule):
//!   see `legs` — least significant leg first, junctions that become
//!   leaves keep the reach of what was cut behind them, never below a simple
//!   path.
//! * `trunk`: keep only the longest leaf-to-leaf path of each component, one
//!   centreline per part (see `trunk`).
//! * `none`: the graph unchanged.
//! * `network` (with `input.connect`): the union of the shortest paths
//!   between the polygon's connection points (see `network` and
//!   [`crate::connect::through_lines`]); `fallback` says what a polygon no
//!   line meets gets instead.
//!
//! Pruning works on the *merged* raw graph (one edge per branch, see
//! [`SkeletonGraph::merged`]) and decides per edge whether it is kept
//! (`prune_mask`), so that the extension step can follow the removed edges
//! back to ∂P (`crate::graph::ends`). [`prune`] returns the kept graph.
//! Everything is sequential and ordered by node and edge indices and
//! coordinates, so the output is the same for any thread count.
//!
//! ```
//! use skeletonise::geometry::PreparedPolygon;
//! use skeletonise::graph::{GraphBuilder, prune::{prune, PruneParams}};
//! use geo::{polygon, Coord};
//! let c = |x, y| Coord { x, y };
//! let p = PreparedPolygon::new(&polygon![(x: 0., y: 0.), (x: 10., y: 0.),
//!                                        (x: 10., y: 4.), (x: 0., y: 4.)]).unwrap();
//! // The medial axis of the rectangle [0, 10] × [0, 4].
//! let mut b = GraphBuilder::new();
//! b.segment(c(2., 2.), c(8., 2.));
//! for (p, q) in [(c(0., 0.), c(2., 2.)), (c(0., 4.), c(2., 2.)),
//!                (c(10., 0.), c(8., 2.)), (c(10., 4.), c(8., 2.))] {
//!     b.segment(p, q);
//! }
//! let g = b.finish(p.boundary());
//! let pruned = prune(&g, &PruneParams::default(), p.boundary());
//! assert_eq!(pruned.edges().len(), 1);
//! assert_eq!(pruned.total_length(), 6.0);
//! ```

pub(crate) mod legs;
pub(crate) mod network;
mod sides;
pub(crate) mod trunk;
mod work;

use super::SkeletonGraph;
use crate::geometry::Boundary;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Why `prune: {mode: network}` cannot run without the lines of
/// `input.connect` (the message of the key `prune.mode`): the command line
/// refuses such a pipeline file, the Python package and QGIS a run without
/// the lines.
pub const NETWORK_NEEDS_CONNECT: &str = "`mode: network` keeps the lines between the points where a line network meets each polygon: add `input.connect: { source: …, layer: … }`, or use another mode";

/// Why `fallback` is refused in any mode but `network` (the message of the
/// key `prune.fallback`).
pub const FALLBACK_OUTSIDE_NETWORK: &str = "`fallback` applies only with `mode: network` (what a polygon that no line of `input.connect` meets gets instead); remove it, or use `mode: network`";

/// How legs are pruned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PruneMode {
    /// Remove legs that do not protrude `ratio` local radii beyond the
    /// inscribed disc at their junction and are not arms (long relative to
    /// their own width), and legs shorter than `min_length`.
    #[default]
    Significance,
    /// Remove legs shorter than `min_length` only.
    Length,
    /// Keep only the longest leaf-to-leaf path of each component.
    Trunk,
    /// Keep every leg.
    None,
    /// Keep the through-lines of a line network (`input.connect`): the
    /// shortest paths along the skeleton between the points where the lines
    /// meet the polygon.
    Network,
}

/// What `network` pruning does with a polygon that no line of
/// `input.connect` meets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Fallback {
    /// Prune it as the default mode does (its significant legs, extended).
    #[default]
    Significance,
    /// Keep its longest leaf-to-leaf path (one centreline).
    Trunk,
    /// Give it no skeleton: it is listed in `rejected` with the reason.
    Drop,
}

/// Whether every method of a feature is pruned to one common structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Structure {
    /// The reference method (`skeleton.reference`) is pruned and extended;
    /// every other method is pruned to the same legs reaching ∂P at the same
    /// places, so that the metrics compare like with like (the paper's
    /// procedure).
    #[default]
    Shared,
    /// Every method is pruned and extended on its own.
    Independent,
}

/// Options of the `prune` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PruneParams {
    /// Pruning mode.
    pub mode: PruneMode,
    /// A leg is insignificant when `length − r_j < ratio · r_j` (and it is no arm).
    pub ratio: f64,
    /// A leg protruding beyond its junction's disc by at least `arm_ratio`
    /// times its width at the mouth is an arm and is kept (0 turns the rule off).
    pub arm_ratio: f64,
    /// An arm must also be at least this wide against its junction's disc:
    /// `r_mouth ≥ arm_width · r_j` (a slot or spike in a bank is no arm; 0
    /// turns this condition off).
    pub arm_width: f64,
    /// Legs shorter than this (CRS units) are insignificant.
    pub min_length: f64,
    /// One common structure for all methods of a feature, or each its own.
    pub structure: Structure,
    /// With `mode: network`, what a polygon no line meets gets instead.
    pub fallback: Fallback,
    /// `merge`: junctions whose inscribed discs overlap become one node at the centre of the largest disc, the stubs between them removed and the lines straightened into it — one node per crossing of a street or road network — and a street cut by an edge within a fifth of its width of straight ends once on it; `keep` (default): every junction stays, and only straight cuts are cuts.
    pub junctions: crate::graph::junctions::Junctions,
    /// Roundabouts made one node: an island (a hole of the polygon) no wider than this (CRS units: the largest distance between two of its vertices) that the lines ring becomes one node at its centre, the ring removed and every road that met it running straight into that node; a turning circle ends its road at its centre. 0 (default): every ring stays. Give a size between the largest roundabout island and the smallest block.
    #[schemars(range(min = 0))]
    pub roundabouts: f64,
}

impl Default for PruneParams {
    fn default() -> Self {
        Self {
            mode: PruneMode::Significance,
            ratio: 1.0,
            arm_ratio: 1.0,
            arm_width: 0.125,
            min_length: 0.0,
            structure: Structure::Shared,
            fallback: Fallback::Significance,
            junctions: crate::graph::junctions::Junctions::Keep,
            roundabouts: 0.0,
        }
    }
}

/// A leg as the rules see it: its extent, its junction's radius and its
/// width at the mouth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LegMeasure {
    /// Length plus the reach of its leaf.
    pub extent: f64,
    /// Radius r_j of its junction.
    pub r_junction: f64,
    /// Distance to ∂P where the leg leaves the junction's disc.
    pub r_mouth: f64,
}

impl PruneParams {
    /// True when a leg is insignificant under this mode (always false for
    /// `trunk` and `none`).
    pub(crate) fn is_insignificant(&self, leg: &LegMeasure) -> bool {
        let LegMeasure {
            extent,
            r_junction: rj,
            r_mouth,
        } = *leg;
        match self.mode {
            PruneMode::Significance => {
                let protrusion = extent - rj;
                let by_radius = protrusion >= self.ratio * rj;
                let arm = self.arm_ratio > 0.0
                    && protrusion >= self.arm_ratio * 2.0 * r_mouth
                    && protrusion >= 0.25 * self.ratio * rj
                    && r_mouth >= self.arm_width * rj;
                !(by_radius || arm) || extent < self.min_length
            }
            PruneMode::Length => extent < self.min_length,
            PruneMode::Trunk | PruneMode::None | PruneMode::Network => false,
        }
    }

    /// Removal priority of a leg: smaller is removed first.
    fn key(&self, leg: &LegMeasure) -> f64 {
        match self.mode {
            PruneMode::Significance => significance(leg.extent, leg.r_junction),
            _ => leg.extent,
        }
    }

    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if !(self.ratio >= 0.0 && self.ratio.is_finite()) {
            return Err(("ratio".into(), "ratio must be a finite number ≥ 0".into()));
        }
        if !(self.arm_ratio >= 0.0 && self.arm_ratio.is_finite()) {
            return Err((
                "arm_ratio".into(),
                "arm_ratio must be a finite number ≥ 0 (0 turns the arm rule off)".into(),
            ));
        }
        if !(0.0..=1.0).contains(&self.arm_width) {
            return Err((
                "arm_width".into(),
                "arm_width must be a number from 0 to 1 (an arm's mouth radius over its junction's radius; 0 turns the condition off)".into(),
            ));
        }
        if self.min_length.is_nan() || self.min_length < 0.0 {
            return Err((
                "min_length".into(),
                "min_length must be ≥ 0 (CRS units)".into(),
            ));
        }
        if !(self.roundabouts >= 0.0 && self.roundabouts.is_finite()) {
            return Err((
                "roundabouts".into(),
                "roundabouts must be a finite number ≥ 0 (CRS units: the widest island made one node; 0 keeps every ring)".into(),
            ));
        }
        if self.mode != PruneMode::Network && self.fallback != Fallback::default() {
            return Err(("fallback".into(), FALLBACK_OUTSIDE_NETWORK.into()));
        }
        Ok(())
    }

    /// The options a polygon that no network line meets is pruned with
    /// (`mode: network`; `None` for `fallback: drop`); the options
    /// themselves in every other mode.
    pub fn without_connections(&self) -> Option<PruneParams> {
        let mode = match (self.mode, self.fallback) {
            (PruneMode::Network, Fallback::Significance) => PruneMode::Significance,
            (PruneMode::Network, Fallback::Trunk) => PruneMode::Trunk,
            (PruneMode::Network, Fallback::Drop) => return None,
            (m, _) => m,
        };
        Some(PruneParams { mode, ..*self })
    }

    /// True for the modes that remove legs one by one.
    pub(crate) fn removes_legs(&self) -> bool {
        matches!(self.mode, PruneMode::Significance | PruneMode::Length)
    }
}

/// Significance of a leg, `(length − r_j) / r_j`: how many local radii it
/// protrudes beyond the inscribed disc at its junction (+∞ when `r_j ≤ 0`).
pub(crate) fn significance(length: f64, r_j: f64) -> f64 {
    if r_j > 0.0 {
        (length - r_j) / r_j
    } else {
        f64::INFINITY
    }
}

/// Which edges of `merged` (a graph whose degree-2 chains are merged, see
/// [`SkeletonGraph::merged`]) pruning keeps, indexed by edge.
pub(crate) fn prune_mask(
    merged: &SkeletonGraph,
    params: &PruneParams,
    boundary: &Boundary,
) -> Vec<bool> {
    match params.mode {
        PruneMode::None => vec![true; merged.edges().len()],
        PruneMode::Significance | PruneMode::Length => legs::mask(merged, params, boundary),
        PruneMode::Trunk => trunk::mask(merged),
        // Without connection points to join (the caller's fallback decides
        // otherwise): the graph as it is.
        PruneMode::Network => vec![true; merged.edges().len()],
    }
}

/// Prunes `graph` per `params`; the result has its degree-2 chains merged
/// (unless the mode is `none`, which returns the graph unchanged).
pub fn prune(graph: &SkeletonGraph, params: &PruneParams, boundary: &Boundary) -> SkeletonGraph {
    if params.mode == PruneMode::None {
        return graph.clone();
    }
    let m = graph.merged();
    let keep = prune_mask(&m, params, boundary);
    m.filter_edges(|e, _| keep[e.index()]).merged()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::NodeId;

    /// Legs of `graph` that are insignificant under `params` at a junction of
    /// degree ≥ 3, as `(leaf, junction, length)`. Empty after [`prune`] with the
    /// same parameters; legs of components that are simple paths never count.
    fn insignificant_legs(
        graph: &SkeletonGraph,
        params: &PruneParams,
        boundary: &Boundary,
    ) -> Vec<(NodeId, NodeId, f64)> {
        graph
            .legs()
            .into_iter()
            .filter(|l| l.junction)
            .filter_map(|l| {
                let len = l.branch.length();
                let rj = graph.node(l.other()).radius;
                // The mouth is measured from the junction.
                let from_junction: Vec<_> = l.branch.coords.iter().rev().copied().collect();
                let leg = LegMeasure {
                    extent: len,
                    r_junction: rj,
                    r_mouth: legs::mouth_radius(&from_junction, rj, boundary),
                };
                params
                    .is_insignificant(&leg)
                    .then_some((l.leaf(), l.other(), len))
            })
            .collect()
    }
    use crate::geometry::PreparedPolygon;
    use crate::graph::GraphBuilder;
    use geo::{polygon, Coord};

    /// A square far larger than every test graph: mouth radii are huge, so
    /// only the radius rule decides.
    fn far() -> Boundary {
        PreparedPolygon::new(&polygon![(x: -1e4, y: -1e4), (x: 1e4, y: -1e4),
            (x: 1e4, y: 1e4), (x: -1e4, y: 1e4)])
        .unwrap()
        .boundary()
        .clone()
    }

    fn trunk_params() -> PruneParams {
        PruneParams {
            mode: PruneMode::Trunk,
            ..Default::default()
        }
    }

    fn leg(extent: f64, r_junction: f64) -> LegMeasure {
        LegMeasure {
            extent,
            r_junction,
            r_mouth: f64::INFINITY,
        }
    }

    fn c(x: f64, y: f64) -> Coord<f64> {
        Coord { x, y }
    }

    /// A star: junction at the origin (radius r) with legs to the given ends.
    fn star(r: f64, ends: &[(f64, f64)]) -> SkeletonGraph {
        let mut b = GraphBuilder::new();
        for &(x, y) in ends {
            b.segment(c(0., 0.), c(x, y));
        }
        let mut g = b.finish_raw();
        g.nodes_mut()[0].radius = r;
        g
    }

    #[test]
    fn significance_rule_matches_spec() {
        let p = PruneParams::default();
        assert!(p.is_insignificant(&leg(1.9, 1.0)));
        assert!(!p.is_insignificant(&leg(2.0, 1.0)));
        let q = PruneParams {
            ratio: 0.5,
            min_length: 3.0,
            ..p
        };
        assert!(!q.is_insignificant(&leg(3.0, 2.0)));
        assert!(q.is_insignificant(&leg(2.9, 1.0)));
        assert!(significance(1.0, 0.0).is_infinite());
    }

    #[test]
    fn arm_rule_keeps_what_is_long_for_its_own_width() {
        let p = PruneParams::default();
        // Protrudes 0.8 r_j beyond a junction of radius 10, 4 wide at the
        // mouth: an arm. The same protrusion 10 wide at the mouth: a bump.
        let arm = LegMeasure {
            extent: 18.0,
            r_junction: 10.0,
            r_mouth: 2.0,
        };
        assert!(!p.is_insignificant(&arm));
        assert!(p.is_insignificant(&LegMeasure {
            r_mouth: 5.0,
            ..arm
        }));
        // Too small against the junction's radius to be an arm at all.
        assert!(p.is_insignificant(&LegMeasure {
            extent: 12.0,
            r_mouth: 0.1,
            ..arm
        }));
        let off = PruneParams {
            arm_ratio: 0.0,
            ..p
        };
        assert!(off.is_insignificant(&arm));
        // A slot: as long, but 0.4 wide against a disc 20 wide, is no arm
        // unless `arm_width` allows it.
        let slot = LegMeasure {
            r_mouth: 0.2,
            ..arm
        };
        assert!(p.is_insignificant(&slot));
        assert!(!PruneParams {
            arm_width: 0.0,
            ..p
        }
        .is_insignificant(&slot));
        assert!(PruneParams {
            arm_width: 1.5,
            ..p
        }
        .validate()
        .is_err());
    }

    /// `fallback` says what `network` pruning gives a polygon no line meets:
    /// in any other mode a fallback other than the default is refused.
    #[test]
    fn a_fallback_outside_network_mode_is_refused() {
        for mode in [
            PruneMode::Significance,
            PruneMode::Length,
            PruneMode::Trunk,
            PruneMode::None,
        ] {
            for fallback in [Fallback::Trunk, Fallback::Drop] {
                let p = PruneParams {
                    mode,
                    fallback,
                    ..Default::default()
                };
                let (key, message) = p.validate().unwrap_err();
                assert_eq!(key, "fallback", "{mode:?} {fallback:?}");
                assert!(message.contains("only with `mode: network`"), "{message}");
            }
            let plain = PruneParams {
                mode,
                ..Default::default()
            };
            assert!(plain.validate().is_ok(), "{mode:?}");
        }
        for fallback in [Fallback::Significance, Fallback::Trunk, Fallback::Drop] {
            let p = PruneParams {
                mode: PruneMode::Network,
                fallback,
                ..Default::default()
            };
            assert!(p.validate().is_ok(), "{fallback:?}");
        }
    }

    #[test]
    fn star_of_whiskers_keeps_its_main_axis() {
        // Every leg is insignificant: the main axis joins the pair with the
        // largest distance plus tip depths (τ = 0.5, 0.2, 0.8 beyond the
        // unit disc): (1.5, 0)–(0, 1.8), 2.34 + 1.3, rather than the pair
        // farthest apart, (1.5, 0)–(−1.2, 0), 2.7 + 0.7, whose end at
        // (−1.2, 0) barely leaves the disc.
        let g = star(1.0, &[(1.5, 0.), (-1.2, 0.), (0., 1.8)]);
        let p = prune(&g, &PruneParams::default(), &far());
        assert_eq!(p.edges().len(), 1);
        assert!(
            (p.total_length() - 3.3).abs() < 1e-12,
            "{}",
            p.total_length()
        );
        assert_eq!(p.leg_count(), 1);
    }

    #[test]
    fn significant_legs_survive_and_whiskers_go() {
        let g = star(1.0, &[(5., 0.), (-5., 0.), (0., 5.), (0., -1.5)]);
        let p = prune(&g, &PruneParams::default(), &far());
        assert_eq!(p.leg_count(), 3);
        assert!((p.total_length() - 15.0).abs() < 1e-12);
        assert!(insignificant_legs(&p, &PruneParams::default(), &far()).is_empty());
        assert_eq!(
            insignificant_legs(&g, &PruneParams::default(), &far()).len(),
            1
        );
    }

    #[test]
    fn length_mode_uses_min_length_only() {
        let g = star(10.0, &[(5., 0.), (-5., 0.), (0., 5.), (0., -1.5)]);
        let params = PruneParams {
            mode: PruneMode::Length,
            min_length: 2.0,
            ..Default::default()
        };
        let p = prune(&g, &params, &far());
        assert_eq!(p.leg_count(), 3);
        assert_eq!(prune(&g, &PruneParams::default(), &far()).leg_count(), 1);
    }

    #[test]
    fn cycle_keeps_its_ring_and_loses_whiskers() {
        // A square ring with one short whisker at each corner (r = 1).
        let mut b = GraphBuilder::new();
        let sq = [c(0., 0.), c(10., 0.), c(10., 10.), c(0., 10.)];
        for i in 0..4 {
            b.segment(sq[i], sq[(i + 1) % 4]);
            b.segment(sq[i], sq[i] + (sq[i] - c(5., 5.)) * 0.1);
        }
        let mut g = b.finish_raw();
        for n in g.nodes_mut() {
            n.radius = 1.0;
        }
        let p = prune(&g, &PruneParams::default(), &far());
        assert_eq!(p.leg_count(), 0);
        assert!((p.total_length() - 40.0).abs() < 1e-9);
        let t = prune(&g, &trunk_params(), &far());
        let deg = t.degrees();
        assert_eq!(deg.iter().filter(|&&d| d == 1).count(), 2);
        assert!(deg.iter().all(|&d| d <= 2));
        assert_eq!(t.components(), 1);
    }

    #[test]
    fn a_main_axis_among_thousands_of_leaves_joins_the_two_farthest() {
        // A junction (r = 10) with 2 100 short legs to points of a spiral
        // inside radius 14, two straight legs to (±19, 0) and two curled
        // legs 19.4 long whose ends lie near the junction: every leg is
        // insignificant, so the main axis is kept — between the leaves
        // farthest apart (found on their convex hull), not along the
        // longest path (the two curls).
        let mut b = GraphBuilder::new();
        for k in 1..=2100 {
            let (r, t) = (14.0 * k as f64 / 2100.0, k as f64 * 0.37);
            b.segment(c(0., 0.), c(r * t.cos(), r * t.sin()));
        }
        b.segment(c(0., 0.), c(19., 0.));
        b.segment(c(0., 0.), c(-19., 0.));
        b.polyline(&[c(0., 0.), c(0.3, 9.8), c(0.6, 0.2)]);
        b.polyline(&[c(0., 0.), c(-0.3, -9.8), c(-0.6, -0.2)]);
        let mut g = b.finish_raw();
        for n in g.nodes_mut() {
            if n.pos == c(0., 0.) {
                n.radius = 10.0;
            }
        }
        let p = prune(&g, &PruneParams::default(), &far());
        assert_eq!(p.edges().len(), 1);
        assert!(
            (p.total_length() - 38.0).abs() < 1e-9,
            "{}",
            p.total_length()
        );
    }

    #[test]
    fn trunk_is_the_tree_diameter() {
        let g = star(1.0, &[(5., 0.), (-7., 0.), (0., 6.), (0., -1.5)]);
        let t = prune(&g, &trunk_params(), &far());
        assert_eq!(t.edges().len(), 1);
        assert!((t.total_length() - 13.0).abs() < 1e-12);
    }

    #[test]
    fn pruning_is_deterministic_and_idempotent() {
        let g = star(1.0, &[(1.5, 0.), (-1.5, 0.), (0., 1.5), (0., -1.5)]);
        let a = prune(&g, &PruneParams::default(), &far());
        assert_eq!(a, prune(&g, &PruneParams::default(), &far()));
        assert_eq!(a, prune(&a, &PruneParams::default(), &far()));
        assert_eq!(a.edges().len(), 1);
    }
}
