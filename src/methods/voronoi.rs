//! `VD` and `DVD` — skeletons from the Voronoi diagram of boundary vertices
//! (SPEC §3). Not yet implemented.

use super::{MethodError, MethodId, SkeletonMethod};
use crate::geometry::{densify::Density, PreparedPolygon};
use crate::graph::SkeletonGraph;

/// Voronoi skeleton of the (optionally densified) boundary vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Voronoi {
    density: Option<Density>,
    max_points: usize,
}

impl Voronoi {
    /// `VD`: the boundary vertices as they are.
    pub fn plain() -> Self {
        Self {
            density: None,
            max_points: usize::MAX,
        }
    }

    /// `DVD`: vertices plus pseudo-nodes, at most `max_points` in all.
    pub fn densified(density: Density, max_points: usize) -> Self {
        Self {
            density: Some(density),
            max_points,
        }
    }
}

impl SkeletonMethod for Voronoi {
    fn id(&self) -> MethodId {
        if self.density.is_some() {
            MethodId::Dvd
        } else {
            MethodId::Vd
        }
    }

    fn skeletonise(&self, _polygon: &PreparedPolygon) -> Result<SkeletonGraph, MethodError> {
        let _ = self.max_points;
        Err(MethodError::Failed {
            method: self.id(),
            reason: "not implemented yet".into(),
        })
    }
}
