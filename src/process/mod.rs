//! The per-feature work: prepare → skeleton → prune → extend → score →
//! select (then connect, collapse and registered steps), on owned `geo`
//! geometry with no I/O and no global state, so that features can be
//! processed in parallel with identical results for any thread count.
//!
//! The files run one way: `types` (parameters, candidates, outcomes) →
//! `prepare` → `candidates` (every method's skeleton, pruned, extended and
//! scored) → `outcome` (the choice and the steps after it) → `rows` (the
//! output rows of a feature) → `run` (the run driver every caller shares:
//! counts, `on_error`, and the rows made once after the last feature);
//! `step` holds the registered steps, `merge` the dissolving of adjacent
//! polygons (for the reader thread).

mod candidates;
pub mod merge;
mod outcome;
mod prepare;
pub mod rows;
pub mod run;
pub mod step;
mod types;

pub use crate::geometry::parts::polygon_parts;
pub use candidates::map_in_order;
pub use outcome::{process, process_checked, process_given, StepError};
pub use prepare::{prepare, prepare_checked, NotPrepared, PrepareParams};
pub use rows::{feature_rows, FeatureRows, RowOptions, Skeletons, Status};
pub use run::{FailedFeature, FinishError, Run, RunCounts};
pub use types::{
    Candidate, CandidateError, CandidateSkeleton, FeatureOutcome, ProcessParams, Processed,
    StageTimes, StepTime, COLLAPSE_NEEDS,
};
