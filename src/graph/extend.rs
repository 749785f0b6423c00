//! Extension of legs to the boundary (SPEC §5).

use super::SkeletonGraph;
use crate::geometry::PreparedPolygon;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How leaves are joined to ∂P.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ExtendMode {
    /// Continue the leg's direction to the first boundary hit.
    #[default]
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

impl Default for ExtendParams {
    fn default() -> Self {
        Self {
            mode: ExtendMode::Ray,
        }
    }
}

/// Extends the legs of `graph` to ∂P (not yet implemented).
pub fn extend(
    graph: &SkeletonGraph,
    polygon: &PreparedPolygon,
    params: &ExtendParams,
) -> SkeletonGraph {
    let _ = (polygon, params);
    graph.clone()
}
