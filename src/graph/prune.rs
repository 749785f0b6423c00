//! Pruning of insignificant legs (SPEC §4).

use super::SkeletonGraph;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// How legs are pruned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PruneMode {
    /// Remove legs that do not protrude `ratio` local radii beyond the
    /// inscribed disc at their junction (and legs shorter than `min_length`).
    #[default]
    Significance,
    /// Remove legs shorter than `min_length` only.
    Length,
    /// Keep only the longest leaf-to-leaf path of each component.
    Trunk,
    /// Keep every leg.
    None,
}

/// Options of the `prune` step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PruneParams {
    /// Pruning mode.
    pub mode: PruneMode,
    /// A leg is insignificant when `length − r_j < ratio · r_j`.
    pub ratio: f64,
    /// Legs shorter than this (CRS units) are insignificant.
    pub min_length: f64,
}

impl Default for PruneParams {
    fn default() -> Self {
        Self {
            mode: PruneMode::Significance,
            ratio: 1.0,
            min_length: 0.0,
        }
    }
}

/// Prunes `graph` per `params` (not yet implemented beyond `none`).
pub fn prune(graph: &SkeletonGraph, params: &PruneParams) -> SkeletonGraph {
    let _ = params;
    graph.clone()
}
