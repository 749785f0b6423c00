//! The per-feature path's data: its parameters (the pipeline's steps), one
//! method's candidate, a feature's outcome.

use super::prepare::PrepareParams;
use crate::collapse::{CollapseParams, PartCollapse};
use crate::connect;
use crate::graph::extend::ExtendParams;
use crate::graph::prune::PruneParams;
use crate::graph::widths::MatSegment;
use crate::methods::{MethodError, MethodId, Registry, SkeletonParams};
use crate::score::select::SelectParams;
use crate::score::{Bar, ScoreParams, Scores};
use geo::MultiLineString;

pub use crate::clock::StageTimes;

/// Everything the per-feature work needs: the steps of the pipeline.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProcessParams {
    /// `prepare` step.
    pub prepare: PrepareParams,
    /// `skeleton` step.
    pub skeleton: SkeletonParams,
    /// `prune` step, when present.
    pub prune: Option<PruneParams>,
    /// `extend` step, when present.
    pub extend: Option<ExtendParams>,
    /// `collapse` step, when present: the chosen skeleton collapses the
    /// polygon where it is narrow.
    pub collapse: Option<CollapseParams>,
    /// `input.connect`: the line network the chosen skeleton gets legs to.
    pub connect: Option<std::sync::Arc<connect::Network>>,
    /// `input.neighbours`: the coverage read beside the polygons (whose
    /// units a partition gives area to).
    pub neighbours: Option<std::sync::Arc<crate::neighbours::Coverage>>,
    /// `score` step, when present.
    pub score: Option<ScoreParams>,
    /// `select` step, when present.
    pub select: Option<SelectParams>,
    /// Keep every bar (for the diagnostic `bars` layer).
    pub keep_bars: bool,
    /// Keep the local widths of the skeleton (for the `widths` layer).
    pub keep_widths: bool,
    /// The local width at every vertex of the written lines (M values,
    /// `output.measures: width`).
    pub keep_measures: bool,
    /// The methods `skeleton.methods` may name.
    pub registry: Registry,
    /// Registered steps, in the pipeline's order.
    pub extra: Vec<super::step::Extra>,
    /// The run's coordinates as longitude and latitude, when its CRS is
    /// known (for registered steps, see [`super::step::StepInput::lonlat`]).
    pub lonlat: Option<super::step::LonLat>,
}

impl ProcessParams {
    /// True when the `skeleton` step keeps MA's raw skeleton for a
    /// registered step that reads it (`label`): MA is among the methods and
    /// has its default options (what the step would make itself).
    pub fn keeps_raw_medial_axis(&self) -> bool {
        self.needs().medial_axis
            && self
                .skeleton
                .methods
                .contains(&crate::methods::MethodId::MA)
            && self.skeleton.medial_axis == Default::default()
    }

    /// What the pipeline's steps need together beyond each feature (the
    /// union of their [`Needs`](super::step::Needs)): the `skeleton` step
    /// keeps MA's raw skeleton, its diagram cells and the chosen graphs
    /// only for a step that reads them, and the reader merges adjacent
    /// polygons exactly only for a step that asks. `collapse` and the
    /// network of `input.connect` read the chosen graphs.
    pub fn needs(&self) -> super::step::Needs {
        use super::step::Needs;
        let network = Needs {
            graphs: self.connect.is_some(),
            ..Needs::NOTHING
        };
        let collapse = self.collapse.map_or(Needs::NOTHING, |_| COLLAPSE_NEEDS);
        self.extra.iter().fold(network.and(collapse), |n, e| {
            n.and(e.step.needs(e.entry.needs))
        })
    }

    /// Every step with its defaults, as a pipeline file that lists
    /// `prepare`, `skeleton`, `prune`, `extend`, `score` and `select` with
    /// no options runs them.
    pub fn all_steps() -> Self {
        Self {
            prune: Some(PruneParams::default()),
            extend: Some(ExtendParams::default()),
            score: Some(ScoreParams::default()),
            select: Some(SelectParams::default()),
            ..Self::default()
        }
    }
}

/// What the `collapse` step needs of the run: the chosen skeleton's graphs
/// (MA's, which it collapses the polygon along).
pub const COLLAPSE_NEEDS: super::step::Needs = super::step::Needs {
    graphs: true,
    ..super::step::Needs::NOTHING
};

/// One method's result for one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The method.
    pub method: MethodId,
    /// The skeleton, or why the method failed on this feature.
    pub result: Result<CandidateSkeleton, CandidateError>,
    /// How long each step took for this method.
    pub time: StageTimes,
}

/// Why a method has no candidate for a feature: the `error` of its row in
/// `candidates`, and, when no method has one, part of the feature's reason
/// in `rejected`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CandidateError {
    /// The method failed, or its budget stopped it.
    #[error(transparent)]
    Method(#[from] MethodError),
    /// The method is not in the run's registry.
    #[error("method {0} is not registered")]
    NotRegistered(MethodId),
    /// The method gives no skeleton of one polygon part while it gives one
    /// of others: a candidate that lost a part is no candidate of the
    /// feature (a one-pixel piece of a vectorised water mask has no Voronoi
    /// skeleton, and with VD alone it would cost the whole river).
    #[error("{method} gives no skeleton of this polygon part (too thin or too small for the method): it has {area} CRS units² of the feature's {whole}; skip parts that small with `prepare: {{ min_area: {min_area} }}`, or list another method in `skeleton.methods` (e.g. {other})")]
    LostPart {
        /// The method.
        method: MethodId,
        /// The part's area, to four significant digits.
        area: String,
        /// The feature's area, to four significant digits.
        whole: String,
        /// A `min_area` that skips the part.
        min_area: String,
        /// A method that gives one.
        other: MethodId,
    },
    /// A panic in the method's work: a bug, which costs this method on this
    /// feature and never the run.
    #[error("{method} failed with an internal error ({what}); the other methods still ran — please report this polygon")]
    Internal {
        /// The method.
        method: MethodId,
        /// The panic's message.
        what: String,
    },
    /// `prune: {mode: network, fallback: drop}` and no line of the network
    /// meets the polygon.
    #[error("no line of `input.connect` meets this polygon, and `prune.fallback` is `drop`; use `fallback: significance` or `trunk` to give such polygons a skeleton")]
    NoConnection,
    /// Pruning stopped though no deadline had passed (a bug).
    #[error("pruning stopped without a deadline")]
    PruningStopped,
    /// The error of one polygon part of several.
    #[error("part {index}: {error}")]
    Part {
        /// The part's index.
        index: usize,
        /// Its error.
        error: Box<CandidateError>,
    },
}

impl CandidateError {
    /// This error of part `index` of a feature of `parts` polygon parts
    /// (named only when there are several).
    pub fn of_part(self, index: usize, parts: usize) -> Self {
        match parts > 1 {
            true => Self::Part {
                index,
                error: Box::new(self),
            },
            false => self,
        }
    }
}

/// A successful skeleton of one feature (all its polygon parts).
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateSkeleton {
    /// The final skeleton (after pruning and extension).
    pub geometry: MultiLineString<f64>,
    /// The paper's metrics, when the pipeline scores.
    pub scores: Option<Scores>,
    /// Connected components of the final skeleton (summed over parts).
    pub components: usize,
    /// Legs of the raw skeleton, before pruning.
    pub legs_raw: usize,
    /// Legs after pruning and extension.
    pub legs: usize,
    /// Line ends that are hooks ([`crate::score::defects`]), when the
    /// pipeline scores.
    pub hooks: usize,
    /// Bars, when requested (`part` indices are unique across polygon parts).
    pub bars: Vec<Bar>,
    /// The skeleton's segments with the disc radius at both ends (the medial
    /// axis transform for MA), when requested.
    pub widths: Vec<MatSegment>,
    /// The finished skeleton graph of every polygon part, when the pipeline
    /// collapses (the `collapse` step works on graphs).
    pub graphs: Vec<crate::graph::SkeletonGraph>,
    /// The raw skeleton of every polygon part (before pruning), kept for MA
    /// when a registered step reads it ([`ProcessParams::keeps_raw_medial_axis`]).
    pub raw: Vec<std::sync::Arc<crate::graph::SkeletonGraph>>,
    /// The cells of MA's segment Voronoi diagram inside every polygon part,
    /// kept when a step [needs them](super::step::Needs::cells) (a
    /// partition splits the polygon along them instead of making the
    /// diagram again; empty otherwise).
    pub cells: Vec<std::sync::Arc<crate::methods::medial_axis::cells::DiagramCells>>,
    /// Something the scores alone do not tell (e.g. a given skeleton that
    /// leaves its polygon), for the row's `note`.
    pub note: Option<String>,
}

/// A step's thread CPU time on one feature: a measurement, not a result
/// (any two compare equal, as [`StageTimes`] do).
#[derive(Debug, Clone, Copy, Default)]
pub struct StepTime(pub std::time::Duration);

impl PartialEq for StepTime {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// What the pipeline writes for one feature.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureOutcome {
    /// Every method's candidate, in `methods` order.
    pub candidates: Vec<Candidate>,
    /// Index of the chosen candidate.
    pub chosen: usize,
    /// Polygon parts skeletonised.
    pub parts: usize,
    /// The chosen skeleton's collapse, part by part, when the pipeline has a
    /// `collapse` step.
    pub collapse: Option<Vec<PartCollapse>>,
    /// The legs added to the chosen skeleton for `input.connect`.
    pub connections: Vec<connect::ConnectionLeg>,
    /// With `output.measures: width`: the local width at every vertex of the
    /// chosen skeleton, line by line.
    pub measures: Option<Vec<Vec<f64>>>,
    /// Rows of the registered steps' layers, each with its layer's name.
    pub extra: Vec<(&'static str, crate::layer::StepRow)>,
    /// What each registered step keeps of the feature for its finish, by
    /// the step's name.
    pub kept: Vec<(&'static str, super::step::Kept)>,
    /// The CPU time on the feature of each registered step, by the step's
    /// name, in the order they ran.
    pub step_times: Vec<(&'static str, StepTime)>,
}

impl FeatureOutcome {
    /// The chosen candidate's skeleton.
    pub fn chosen(&self) -> (&MethodId, &CandidateSkeleton) {
        let c = &self.candidates[self.chosen];
        (
            &c.method,
            c.result.as_ref().expect("the chosen candidate succeeded"),
        )
    }
}

/// Result of processing one feature.
#[derive(Debug, Clone, PartialEq)]
pub enum Processed {
    /// Skeletonised.
    Done(FeatureOutcome),
    /// Skipped by `min_area` (counted as filtered, not rejected).
    Filtered,
    /// Could not be processed; the reason goes to the `rejected` layer.
    Rejected(String),
}
