//! Skeleton methods (SPEC §3), each a plug-in behind [`SkeletonMethod`].
//!
//! | id | module |
//! |---|---|
//! | `VD`, `DVD` | [`voronoi`] |
//! | `CDT` | [`cdt`] |
//! | `StSk` | [`straight_skeleton`] |
//! | `MA` | [`medial_axis`] |
//!
//! Adding a method is one new module plus one arm in [`MethodId`] and
//! [`build`]. Every method returns a [`SkeletonGraph`] whose node radii are
//! distances to ∂P, whose points lie in P and whose edges do not cross ∂P.

pub mod cdt;
pub mod medial_axis;
pub mod straight_skeleton;
pub mod voronoi;

use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The method identifiers used in pipeline files and the `method` attribute.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
pub enum MethodId {
    /// Voronoi diagram of the boundary vertices.
    #[serde(rename = "VD")]
    Vd,
    /// Voronoi diagram of the densified boundary.
    #[serde(rename = "DVD")]
    Dvd,
    /// Constrained Delaunay triangulation (De Lucia & Black rules).
    #[serde(rename = "CDT")]
    Cdt,
    /// Straight skeleton.
    #[serde(rename = "StSk")]
    StSk,
    /// Medial axis (transform).
    #[serde(rename = "MA")]
    Ma,
}

impl MethodId {
    /// Every method, in the order the paper presents them.
    pub const ALL: [MethodId; 5] = [
        MethodId::Vd,
        MethodId::Dvd,
        MethodId::Cdt,
        MethodId::StSk,
        MethodId::Ma,
    ];

    /// The identifier as written in pipeline files and output attributes.
    pub fn as_str(self) -> &'static str {
        match self {
            MethodId::Vd => "VD",
            MethodId::Dvd => "DVD",
            MethodId::Cdt => "CDT",
            MethodId::StSk => "StSk",
            MethodId::Ma => "MA",
        }
    }

    /// One-line description for `skeletonise methods`.
    pub fn description(self) -> &'static str {
        match self {
            MethodId::Vd => "Voronoi diagram of the boundary vertices; finite edges inside P that do not cross the boundary",
            MethodId::Dvd => "Voronoi diagram after densifying every boundary edge (densify: {factor: k} or {spacing: d})",
            MethodId::Cdt => "constrained Delaunay triangulation, skeleton per triangle by De Lucia & Black's rules (paper Fig. 3)",
            MethodId::StSk => "straight skeleton: trace of the wavefront vertices as the edges move inward at unit speed",
            MethodId::Ma => "medial axis: Voronoi diagram of the boundary segments inside P, without edges from reflex vertices",
        }
    }
}

impl std::fmt::Display for MethodId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for MethodId {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        MethodId::ALL
            .into_iter()
            .find(|m| m.as_str().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown method `{s}`; expected one of VD, DVD, CDT, StSk, MA"))
    }
}

/// Why a method could not skeletonise one polygon. The feature is then
/// rejected for that method with this reason; other methods still run.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MethodError {
    /// Densifying would create more points than allowed.
    #[error("densifying would create {points} points, more than max_points = {max}; use a larger `densify.spacing` or raise `skeleton.max_points`")]
    TooManyPoints {
        /// Points the densification would create.
        points: usize,
        /// The configured cap.
        max: usize,
    },
    /// The boundary could not be triangulated or diagrammed.
    #[error("{method} failed: {reason}")]
    Failed {
        /// The method.
        method: MethodId,
        /// What went wrong, for the `rejected` layer.
        reason: String,
    },
}

/// Densification of the boundary for DVD.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "lowercase")]
pub enum DensifyParams {
    /// `k − 1` equally spaced pseudo-nodes on each boundary edge (paper: 2 and 4).
    Factor(u32),
    /// No piece longer than this many CRS units.
    Spacing(f64),
}

impl Default for DensifyParams {
    fn default() -> Self {
        DensifyParams::Factor(4)
    }
}

impl From<DensifyParams> for crate::geometry::densify::Density {
    fn from(d: DensifyParams) -> Self {
        match d {
            DensifyParams::Factor(k) => Self::Factor(k),
            DensifyParams::Spacing(s) => Self::Spacing(s),
        }
    }
}

/// The paper's recommendation first: ties in selection go to the earlier method.
fn default_methods() -> Vec<MethodId> {
    vec![
        MethodId::Ma,
        MethodId::StSk,
        MethodId::Dvd,
        MethodId::Cdt,
        MethodId::Vd,
    ]
}

fn default_max_points() -> usize {
    2_000_000
}

/// Options of the `skeleton` step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SkeletonParams {
    /// Methods to run on every polygon; ties in selection go to the earlier one.
    #[serde(default = "default_methods")]
    pub methods: Vec<MethodId>,
    /// Boundary densification for DVD.
    #[serde(default)]
    pub densify: DensifyParams,
    /// Most points a densified polygon may have (DVD); more is an error for that feature.
    #[serde(default = "default_max_points")]
    pub max_points: usize,
    /// How closely MA's polylines follow its parabolic arcs.
    #[serde(default)]
    pub arc_tolerance: medial_axis::ArcTolerance,
    /// The method whose pruned and extended skeleton sets the legs every
    /// method is pruned to (with `prune.structure: shared`); when it is not
    /// among `methods` or fails on a polygon, the first that succeeds in the
    /// order MA, StSk, DVD, CDT, VD.
    #[serde(default = "default_reference")]
    pub reference: MethodId,
}

fn default_reference() -> MethodId {
    MethodId::Ma
}

impl SkeletonParams {
    /// The order in which methods are tried as the reference structure.
    pub fn reference_order(&self) -> Vec<MethodId> {
        let mut order = vec![self.reference];
        order.extend(
            [
                MethodId::Ma,
                MethodId::StSk,
                MethodId::Dvd,
                MethodId::Cdt,
                MethodId::Vd,
            ]
            .into_iter()
            .filter(|m| *m != self.reference),
        );
        order
    }
}

impl Default for SkeletonParams {
    fn default() -> Self {
        Self {
            methods: default_methods(),
            densify: DensifyParams::default(),
            max_points: default_max_points(),
            arc_tolerance: medial_axis::ArcTolerance::default(),
            reference: default_reference(),
        }
    }
}

/// A skeleton method: turns one prepared polygon into a skeleton graph.
///
/// Implementations are pure (no I/O, no global state) so that features can be
/// processed in parallel and give the same result for any thread count.
pub trait SkeletonMethod: Send + Sync {
    /// The method's identifier.
    fn id(&self) -> MethodId;
    /// The raw skeleton of `polygon` (before pruning and extension).
    fn skeletonise(&self, polygon: &PreparedPolygon) -> Result<SkeletonGraph, MethodError>;
}

/// The method registry: an instance of method `id` configured by `params`.
pub fn build(id: MethodId, params: &SkeletonParams) -> Box<dyn SkeletonMethod> {
    match id {
        MethodId::Cdt => Box::new(cdt::Cdt),
        MethodId::Vd => Box::new(voronoi::Voronoi::plain()),
        MethodId::Dvd => Box::new(voronoi::Voronoi::densified(
            params.densify.into(),
            params.max_points,
        )),
        MethodId::StSk => Box::new(straight_skeleton::StraightSkeleton),
        MethodId::Ma => Box::new(medial_axis::MedialAxis::new(params.arc_tolerance)),
    }
}
