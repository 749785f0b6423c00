//! Skeleton methods (SPEC §3), each a plug-in behind [`SkeletonMethod`].
//!
//! | id | module |
//! |---|---|
//! | `VD`, `DVD` | [`voronoi`] |
//! | `CDT` | [`cdt`] |
//! | `StSk` | [`straight_skeleton`] |
//! | `MA` | [`medial_axis`] |
//!
//! Adding a method is one new module plus one [`MethodEntry`] (in
//! [`BUILTIN`], or added to a [`Registry`] with [`Registry::with`]): its
//! parsing, help, schema and construction come from the entry. Every method returns a [`SkeletonGraph`] whose node radii are
//! distances to ∂P, whose points lie in P and whose edges do not cross ∂P.

pub mod budget;
pub mod cdt;
pub mod medial_axis;
pub mod straight_skeleton;
pub mod voronoi;

pub use budget::MethodContext;

use crate::geometry::PreparedPolygon;
use crate::graph::SkeletonGraph;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A method's identifier, as written in pipeline files and the `method`
/// attribute. The built-in ones are constants; a method added to a
/// [`Registry`] brings its own (`MethodId::new("Centroid")`).
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MethodId(&'static str);

impl MethodId {
    /// Voronoi diagram of the boundary vertices.
    pub const VD: MethodId = MethodId("VD");
    /// Voronoi diagram of the densified boundary.
    pub const DVD: MethodId = MethodId("DVD");
    /// Constrained Delaunay triangulation (De Lucia & Black rules).
    pub const CDT: MethodId = MethodId("CDT");
    /// Straight skeleton.
    pub const STSK: MethodId = MethodId("StSk");
    /// Medial axis (transform).
    pub const MA: MethodId = MethodId("MA");
    /// A skeleton made by another tool and scored with `skeletonise score`
    /// (its rows carry the tool's label instead).
    pub const EXTERNAL: MethodId = MethodId("external");

    /// The identifier of a method outside the built-in ones.
    pub const fn new(id: &'static str) -> Self {
        MethodId(id)
    }

    /// The built-in methods, in the order the paper presents them.
    pub fn builtin() -> impl Iterator<Item = MethodId> {
        BUILTIN.iter().map(|e| e.id)
    }

    /// The identifier as written in pipeline files and output attributes.
    pub fn as_str(self) -> &'static str {
        self.0
    }

    /// One-line description (of a built-in method; empty otherwise).
    pub fn description(self) -> &'static str {
        Registry::builtin().get(self).map_or("", |e| e.description)
    }
}

impl std::fmt::Debug for MethodId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

impl std::fmt::Display for MethodId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

impl std::str::FromStr for MethodId {
    type Err = String;
    /// A built-in method by its identifier (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Registry::builtin().parse(s)
    }
}

impl Serialize for MethodId {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.0)
    }
}

impl<'de> Deserialize<'de> for MethodId {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl JsonSchema for MethodId {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "MethodId".into()
    }
    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let ids: Vec<&str> = BUILTIN.iter().map(|e| e.id.as_str()).collect();
        schemars::json_schema!({
            "description": "A skeleton method (`skeletonise methods` describes them).",
            "type": "string",
            "enum": ids,
        })
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
    /// The method ran out of its time budget on this polygon.
    #[error("{method} stopped after {seconds} s on this polygon (`skeleton.timeout_s`); raise the budget, or leave {method} out for such polygons")]
    TimedOut {
        /// The method.
        method: MethodId,
        /// The budget, in seconds.
        seconds: f64,
    },
    /// The method's pruning, extension or scores ran past its time budget
    /// on this polygon (the budget covers every stage of its work).
    #[error("{method} ran past `skeleton.timeout_s` ({seconds} s) on this polygon while {stage}; raise the budget, or leave {method} out for such polygons")]
    StageTimedOut {
        /// The method.
        method: MethodId,
        /// The budget, in seconds.
        seconds: f64,
        /// The stage, e.g. "pruning and extending".
        stage: &'static str,
    },
    /// The method predicted that this polygon would cost more than its
    /// budget and did not start.
    #[error(
        "{method} skipped: it {reason}; raise the budget, or leave {method} out for such polygons"
    )]
    OverBudget {
        /// The method.
        method: MethodId,
        /// The prediction and the budget it exceeds.
        reason: String,
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

/// The paper's recommendation first: ties in selection go to the earlier method.
fn default_methods() -> Vec<MethodId> {
    vec![
        MethodId::MA,
        MethodId::STSK,
        MethodId::DVD,
        MethodId::CDT,
        MethodId::VD,
    ]
}

fn default_reference() -> MethodId {
    MethodId::MA
}

/// Options of the `skeleton` step: which methods run, the reference for the
/// shared structure, and each method's own options (written flat in the
/// step, e.g. `densify:` for DVD, `arc_tolerance:` for MA).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SkeletonParams {
    /// Methods to run on every polygon; ties in selection go to the earlier one.
    #[serde(default = "default_methods")]
    pub methods: Vec<MethodId>,
    /// The method whose pruned and extended skeleton sets the legs every
    /// method is pruned to (with `prune.structure: shared`); when it is not
    /// among `methods` or fails on a polygon, the first that succeeds in the
    /// order MA, StSk, DVD, CDT, VD.
    #[serde(default = "default_reference")]
    pub reference: MethodId,
    /// DVD's options.
    #[serde(flatten)]
    pub voronoi: voronoi::VoronoiOptions,
    /// MA's options.
    #[serde(flatten)]
    pub medial_axis: medial_axis::MedialAxisOptions,
    /// Most seconds one method may spend on one polygon part; past it that
    /// method fails for that feature with the reason (0: no limit).
    #[serde(default = "default_timeout_s")]
    pub timeout_s: f64,
    /// Most megabytes of working memory one method may use on one polygon
    /// part (0: no limit). Only a method whose memory can grow faster than
    /// its input checks it: the straight skeleton, whose split events are
    /// quadratic in a large round polygon.
    #[serde(default = "default_max_memory_mb")]
    pub max_memory_mb: f64,
}

/// The largest `timeout_s` (about 31 years; 0 is the way to no limit):
/// larger ones are not representable as a deadline.
pub const MAX_TIMEOUT_S: f64 = 1e9;

fn default_timeout_s() -> f64 {
    120.0
}

fn default_max_memory_mb() -> f64 {
    2048.0
}

impl SkeletonParams {
    /// The order in which methods are tried as the reference structure.
    pub fn reference_order(&self) -> Vec<MethodId> {
        let mut order = vec![self.reference];
        order.extend(
            default_methods()
                .into_iter()
                .filter(|m| *m != self.reference),
        );
        order
    }

    /// Checks the options: `(key, message)` of the first that is wrong.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if self.methods.is_empty() {
            return Err((
                "methods".into(),
                "list at least one method: VD, DVD, CDT, StSk, MA".into(),
            ));
        }
        let mut seen = std::collections::HashSet::new();
        if let Some(d) = self.methods.iter().find(|m| !seen.insert(**m)) {
            return Err(("methods".into(), format!("method {d} is listed twice")));
        }
        if !(0.0..=MAX_TIMEOUT_S).contains(&self.timeout_s) {
            return Err((
                "timeout_s".into(),
                format!("timeout_s is a number of seconds between 0 and {MAX_TIMEOUT_S:e} (0: no limit)"),
            ));
        }
        if !(self.max_memory_mb >= 0.0 && self.max_memory_mb.is_finite()) {
            return Err((
                "max_memory_mb".into(),
                "max_memory_mb is a number of megabytes ≥ 0 (0: no limit)".into(),
            ));
        }
        self.voronoi.validate()?;
        self.medial_axis.validate()
    }

    /// The budget per method and polygon part.
    pub fn budget(&self) -> budget::Budget {
        budget::Budget {
            time: (self.timeout_s > 0.0)
                .then(|| std::time::Duration::from_secs_f64(self.timeout_s)),
            memory: (self.max_memory_mb > 0.0).then_some((self.max_memory_mb * 1e6) as u64),
        }
    }
}

impl Default for SkeletonParams {
    fn default() -> Self {
        Self {
            methods: default_methods(),
            reference: default_reference(),
            voronoi: voronoi::VoronoiOptions::default(),
            medial_axis: medial_axis::MedialAxisOptions::default(),
            timeout_s: default_timeout_s(),
            max_memory_mb: default_max_memory_mb(),
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
    /// The raw skeleton of `polygon` (before pruning and extension), within
    /// the budget of `ctx` (a method with long loops checks it; see
    /// [`budget`]). `&MethodContext::default()` sets no limit.
    fn skeletonise(
        &self,
        polygon: &PreparedPolygon,
        ctx: &MethodContext,
    ) -> Result<SkeletonGraph, MethodError>;

    /// [`Self::skeletonise`], and for a method made on the segment Voronoi
    /// diagram of the boundary, that diagram's cells inside the polygon
    /// ([`medial_axis::cells::cell_edges`] with the default arc tolerance),
    /// made from the same diagram, with the time they took: what
    /// `partition` splits the polygon along, without a diagram of its own.
    /// `None` for every other method (the default).
    fn skeletonise_with_cells(
        &self,
        polygon: &PreparedPolygon,
        ctx: &MethodContext,
    ) -> Result<(SkeletonGraph, Option<medial_axis::cells::DiagramCells>), MethodError> {
        Ok((self.skeletonise(polygon, ctx)?, None))
    }
}

/// One method as the registry knows it: its identifier, name, description
/// and constructor. Parsing, help, the JSON Schema's list and construction
/// all come from these entries.
#[derive(Clone, Copy)]
pub struct MethodEntry {
    /// Identifier in pipeline files and the `method` attribute.
    pub id: MethodId,
    /// Full name.
    pub name: &'static str,
    /// One-line description for `skeletonise methods`.
    pub description: &'static str,
    /// Keys of the `skeleton` step that configure this method.
    pub options: &'static [&'static str],
    /// An instance configured by the step's options.
    pub build: fn(&SkeletonParams) -> Box<dyn SkeletonMethod>,
}

impl std::fmt::Debug for MethodEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MethodEntry").field("id", &self.id).finish()
    }
}

/// The built-in methods, in the order the paper presents them.
pub const BUILTIN: &[MethodEntry] = &[
    MethodEntry {
        id: MethodId::VD,
        name: "Voronoi diagram",
        description: "Voronoi diagram of the boundary vertices; finite edges inside P that do not cross the boundary",
        options: &[],
        build: |_| Box::new(voronoi::Voronoi::plain()),
    },
    MethodEntry {
        id: MethodId::DVD,
        name: "densified Voronoi diagram",
        description: "Voronoi diagram after densifying every boundary edge (densify: {factor: k} or {spacing: d})",
        options: &["densify", "max_points"],
        build: |p| Box::new(voronoi::Voronoi::densified(p.voronoi.densify.into(), p.voronoi.max_points)),
    },
    MethodEntry {
        id: MethodId::CDT,
        name: "constrained Delaunay triangulation",
        description: "constrained Delaunay triangulation, skeleton per triangle by De Lucia & Black's rules (paper Fig. 3)",
        options: &[],
        build: |_| Box::new(cdt::Cdt),
    },
    MethodEntry {
        id: MethodId::STSK,
        name: "straight skeleton",
        description: "straight skeleton: trace of the wavefront vertices as the edges move inward at unit speed",
        options: &[],
        build: |_| Box::new(straight_skeleton::StraightSkeleton),
    },
    MethodEntry {
        id: MethodId::MA,
        name: "medial axis",
        description: "medial axis: Voronoi diagram of the boundary segments inside P, without edges from reflex vertices",
        options: &["arc_tolerance"],
        build: |p| Box::new(medial_axis::MedialAxis::new(p.medial_axis.arc_tolerance)),
    },
];

/// The methods a run can use: the built-in ones, plus any added with
/// [`Registry::with`].
#[derive(Debug, Clone)]
pub struct Registry {
    entries: Vec<MethodEntry>,
}

impl PartialEq for Registry {
    fn eq(&self, o: &Self) -> bool {
        self.entries
            .iter()
            .map(|e| e.id)
            .eq(o.entries.iter().map(|e| e.id))
    }
}

impl Default for Registry {
    fn default() -> Self {
        Self::builtin()
    }
}

impl Registry {
    /// The built-in methods.
    pub fn builtin() -> Self {
        Self {
            entries: BUILTIN.to_vec(),
        }
    }

    /// This registry with one more method (replacing one with the same id).
    pub fn with(mut self, entry: MethodEntry) -> Self {
        self.entries.retain(|e| e.id != entry.id);
        self.entries.push(entry);
        self
    }

    /// Every entry, in registration order.
    pub fn entries(&self) -> &[MethodEntry] {
        &self.entries
    }

    /// The entry of method `id`.
    pub fn get(&self, id: MethodId) -> Option<&MethodEntry> {
        self.entries.iter().find(|e| e.id == id)
    }

    /// The method named `s` (case-insensitive).
    pub fn parse(&self, s: &str) -> Result<MethodId, String> {
        self.entries
            .iter()
            .find(|e| e.id.as_str().eq_ignore_ascii_case(s))
            .map(|e| e.id)
            .ok_or_else(|| {
                let ids: Vec<&str> = self.entries.iter().map(|e| e.id.as_str()).collect();
                format!("unknown method `{s}`; expected one of {}", ids.join(", "))
            })
    }

    /// An instance of method `id` configured by `params` (`None`: `id`
    /// is not registered).
    pub fn build(&self, id: MethodId, params: &SkeletonParams) -> Option<Box<dyn SkeletonMethod>> {
        self.get(id).map(|e| (e.build)(params))
    }
}

/// An instance of the built-in method `id` configured by `params`.
///
/// # Panics
/// When `id` is not a built-in method (use a [`Registry`] for others).
pub fn build(id: MethodId, params: &SkeletonParams) -> Box<dyn SkeletonMethod> {
    Registry::builtin()
        .build(id, params)
        .expect("a built-in method")
}

/// `method`'s skeleton of `polygon` without a budget, its graph's
/// invariants checked: how the methods' unit tests run a method.
#[cfg(test)]
pub(crate) fn checked_skeleton(
    method: &dyn SkeletonMethod,
    polygon: &PreparedPolygon,
) -> SkeletonGraph {
    let g = method
        .skeletonise(polygon, &MethodContext::default())
        .unwrap_or_else(|e| panic!("{}: {e}", method.id()));
    if let Err(e) = g.check_invariants() {
        panic!("{}: {e}", method.id());
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_builds_the_method_it_names() {
        for e in BUILTIN {
            assert_eq!((e.build)(&SkeletonParams::default()).id(), e.id);
        }
    }

    #[test]
    fn ids_parse_case_insensitively_and_unknown_ones_list_the_known() {
        assert_eq!("stsk".parse::<MethodId>(), Ok(MethodId::STSK));
        let e = "XYZ".parse::<MethodId>().unwrap_err();
        assert!(e.contains("VD, DVD, CDT, StSk, MA"), "{e}");
    }
}
