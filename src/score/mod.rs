//! Scoring (SPEC §6) and method selection (SPEC §7): the paper's deviation
//! and distortion metrics made automatic.
//!
//! The paper (Fig. 4) draws, for every edge of the boundary g, three
//! perpendicular segments p_i — *bars* — at both vertices and at the midpoint,
//! intersects each with the skeleton o^j and measures from the intersection
//! p_i o^j the rectangular projections on the boundary to its left (g_L) and to
//! its right (g_P). Here that manual procedure is automatic:
//!
//! 1. **Bars** ([`bars`]): for every edge e = (a, b) of every ring, origins a,
//!    the midpoint and b, direction u = the inward unit normal of e. A vertex
//!    bar is valid only where the interior angle exceeds 90° (at sharper
//!    corners u points along or outside the boundary); midpoint bars are always
//!    valid. N = number of valid bars.
//! 2. **Hits**: the first point of the skeleton on the ray origin + t·u,
//!    ε < t ≤ t_exit, where t_exit is where the ray leaves P and
//!    ε = 10⁻⁶ × extent (a closer point is the bar's own origin, e.g. the leg
//!    ending at that vertex). Where the ray runs along a skeleton segment, the
//!    hit is the first point of the overlap. n = hits, coverage = n / N.
//! 3. **Sides**: at hit q on skeleton segment σ (at a skeleton vertex, the
//!    incident segment most nearly perpendicular to u) with left normal ν,
//!    d_L = d(g_L) = distance from q to the nearest point of ∂P in the closed
//!    half-plane (p − q)·ν ≥ 0 and d_P = d(g_P) the same for (p − q)·ν ≤ 0.
//!    "Left" and "right" follow σ's direction along its part, so the sign of
//!    Δd depends on that direction; no metric depends on the sign.
//! 4. **Metrics** ([`metrics`]):
//!    - Δd_i = d_P − d_L (eq. 1);
//!    - z_i = |Δd_i| / (d_L + d_P) ∈ [0, 1] (eq. 8): 0 when the skeleton is
//!      locally in the middle, 1 when it lies on the boundary;
//!    - `deviation` s = √(Σ Δd_i² / (n − 1)) (eq. 2);
//!    - parts k = the branches of the skeleton; s_k as eq. 2 over the hits on
//!      part k (eq. 3), `deviation_parts` S = √(Σ s_k²) (eq. 4);
//!    - `distortion_sum` SZ = Σ z_i (eq. 9), `distortion` Z = SZ / n (eq. 10).
//!
//! Small samples: with one hit (overall or on a part) the n − 1 of eqs. 2–3
//! would divide by zero; s (or s_k) is then |Δd| of that hit (SPEC §6.6).
//! With no hit at all there is nothing to measure: s, S, SZ and Z are NaN
//! (written as NULL), coverage is 0, and [`select::select`] ranks NaN last, so
//! a skeleton without hits never wins on any metric.
//!
//! s and S are lengths (CRS units) and scale with the data; z and Z are
//! dimensionless; all are invariant under translation and rotation.
//!
//! Both the boundary and the skeleton are held in R-trees, so scoring costs
//! O(N log n) — about as much as building the skeleton.
//!
//! ```
//! use geo::{line_string, polygon, MultiLineString};
//! use skeletonise::geometry::PreparedPolygon;
//! use skeletonise::score::score_skeleton;
//!
//! // A 10 × 2 rectangle and its centre line.
//! let p = PreparedPolygon::new(&polygon![
//!     (x: 0., y: 0.), (x: 10., y: 0.), (x: 10., y: 2.), (x: 0., y: 2.)
//! ]).unwrap();
//! let centre = MultiLineString(vec![line_string![(x: 0., y: 1.), (x: 10., y: 1.)]]);
//! let (scores, _bars) = score_skeleton(&p, &centre);
//! // Four midpoint bars (the 90° corners have no valid vertex bars); the two
//! // from the short sides run along the line and miss.
//! assert_eq!((scores.bars, scores.hits, scores.coverage), (4, 2, 0.5));
//! assert_eq!(scores.distortion, 0.0);
//! ```

mod bars;
pub mod defects;
pub mod join;
mod metrics;
pub mod select;

pub(crate) use bars::PAR_BARS;
pub use bars::{bars, score_skeleton, BarRays};
pub use metrics::metrics;

use geo::Coord;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Options of the `score` step.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScoreParams {}

/// Where a bar met the skeleton and the two sides measured from there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarHit {
    /// The hit point q = p_i o^j on the skeleton.
    pub point: Coord<f64>,
    /// d_L = d(g_L): distance from q to ∂P on the left of the skeleton segment.
    pub d_left: f64,
    /// d_P = d(g_P): distance from q to ∂P on the right.
    pub d_right: f64,
    /// Index of the skeleton part (branch, in [`SkeletonGraph::branches`]
    /// order) that was hit.
    ///
    /// [`SkeletonGraph::branches`]: crate::graph::SkeletonGraph::branches
    pub part: usize,
}

impl BarHit {
    /// Δd = d_P − d_L (eq. 1).
    pub fn delta_d(&self) -> f64 {
        self.d_right - self.d_left
    }

    /// z = |Δd| / (d_L + d_P) (eq. 8); 0 when both distances are 0.
    pub fn z(&self) -> f64 {
        let s = self.d_left + self.d_right;
        if s > 0.0 {
            self.delta_d().abs() / s
        } else {
            0.0
        }
    }
}

/// One valid bar: its origin on ∂P, inward direction and hit (if any).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bar {
    /// Origin on the boundary (an edge's vertex or midpoint).
    pub origin: Coord<f64>,
    /// Inward unit normal u of the boundary edge.
    pub dir: Coord<f64>,
    /// The first skeleton point on the bar, or `None` for a miss.
    pub hit: Option<BarHit>,
}

/// The paper's metrics for one skeleton (see the module docs for the
/// definitions and the small-sample rules).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Scores {
    /// N: valid bars.
    pub bars: usize,
    /// n: bars that hit the skeleton.
    pub hits: usize,
    /// n / N (0 when N = 0).
    pub coverage: f64,
    /// s (eq. 2), CRS units; NaN without hits.
    pub deviation: f64,
    /// S (eqs. 3–4), CRS units; NaN without hits.
    pub deviation_parts: f64,
    /// SZ (eq. 9); NaN without hits.
    pub distortion_sum: f64,
    /// Z (eq. 10), in [0, 1]; NaN without hits.
    pub distortion: f64,
}
