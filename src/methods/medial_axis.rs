//! `MA` — the medial axis (transform) from the Voronoi diagram of boundary
//! segments (SPEC §3). Not yet implemented.

use super::{MethodError, MethodId, SkeletonMethod};
use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Largest allowed deviation of a polyline from the parabolic arc it
/// approximates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
pub enum ArcTolerance {
    /// A fraction of the local disc radius (scale-free).
    Relative(f64),
    /// CRS units.
    Absolute(f64),
}

impl Default for ArcTolerance {
    fn default() -> Self {
        ArcTolerance::Relative(0.01)
    }
}

/// Medial axis from the segment Voronoi diagram.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedialAxis {
    tolerance: ArcTolerance,
}

impl MedialAxis {
    /// A medial axis with the given arc tolerance.
    pub fn new(tolerance: ArcTolerance) -> Self {
        Self { tolerance }
    }
}

impl SkeletonMethod for MedialAxis {
    fn id(&self) -> MethodId {
        MethodId::Ma
    }

    fn skeletonise(&self, _polygon: &PreparedPolygon) -> Result<SkeletonGraph, MethodError> {
        let _ = self.tolerance;
        Err(MethodError::Failed {
            method: MethodId::Ma,
            reason: "not implemented yet".into(),
        })
    }
}
