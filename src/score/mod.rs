//! Scoring (SPEC §6) and method selection (SPEC §7): the paper's deviation
//! and distortion metrics made automatic.
//!
//! Scoring is not yet implemented: [`score`] returns no bars.

pub mod select;

use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;
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
    /// The hit point q on the skeleton.
    pub point: Coord<f64>,
    /// d_L: distance from q to ∂P on the left of the skeleton segment.
    pub d_left: f64,
    /// d_P: distance from q to ∂P on the right.
    pub d_right: f64,
    /// Index of the skeleton part (branch) that was hit.
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
    /// Origin on the boundary.
    pub origin: Coord<f64>,
    /// Inward unit normal of the boundary edge.
    pub dir: Coord<f64>,
    /// The first skeleton point on the bar, or `None` for a miss.
    pub hit: Option<BarHit>,
}

/// The paper's metrics for one skeleton.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Scores {
    /// N: valid bars.
    pub bars: usize,
    /// n: bars that hit the skeleton.
    pub hits: usize,
    /// n / N.
    pub coverage: f64,
    /// s (eq. 2).
    pub deviation: f64,
    /// S (eqs. 3–4).
    pub deviation_parts: f64,
    /// SZ (eq. 9).
    pub distortion_sum: f64,
    /// Z (eq. 10).
    pub distortion: f64,
}

/// Bars of `polygon` cast against `skeleton` (not yet implemented: none).
pub fn bars(polygon: &PreparedPolygon, skeleton: &SkeletonGraph) -> Vec<Bar> {
    let _ = (polygon, skeleton);
    Vec::new()
}

/// The metrics of a set of bars (not yet implemented: zeros).
pub fn metrics(bars: &[Bar]) -> Scores {
    Scores {
        bars: bars.len(),
        ..Scores::default()
    }
}
