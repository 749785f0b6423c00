//! `StSk` — the interior straight skeleton (SPEC §3). Not yet implemented.

use super::{MethodError, MethodId, SkeletonMethod};
use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;

/// Straight skeleton of a polygon with holes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StraightSkeleton;

impl SkeletonMethod for StraightSkeleton {
    fn id(&self) -> MethodId {
        MethodId::StSk
    }

    fn skeletonise(&self, _polygon: &PreparedPolygon) -> Result<SkeletonGraph, MethodError> {
        Err(MethodError::Failed {
            method: MethodId::StSk,
            reason: "not implemented yet".into(),
        })
    }
}
