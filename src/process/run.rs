//! The run driver every caller shares — the command line's pipeline and the
//! Python module (and so Dask and QGIS): features go in, in read order, as
//! [`FeatureRows`] (computed by [`super::feature_rows`] on any thread); the
//! run counts them, applies `on_error: fail`, keeps what is needed after
//! the last feature (the points where the network's lines met the
//! polygons, what the registered steps keep for their finish: the pieces
//! each unit of a partition receives), and [`Run::finish`] makes those rows once: the network's
//! lines split at the polygons, each registered step's finish (the coverage
//! a partition grows). No I/O: the caller reads, writes and logs.

use super::step::Kept;
use super::{FeatureRows, ProcessParams, StageTimes, Status};
use crate::feature::Feature;
use crate::layer::StepRow;
use crate::methods::MethodId;
use crate::output::Rows;
use std::collections::{BTreeMap, BTreeSet};
use std::time::Duration;

/// Counts of a run so far, by source feature (a feature merged from several
/// adjacent ones counts each).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct RunCounts {
    /// Features read.
    pub read: u64,
    /// Features written.
    pub written: u64,
    /// Features rejected.
    pub rejected: u64,
    /// Features filtered (`min_area`).
    pub filtered: u64,
    /// Skeleton rows written.
    pub rows: u64,
    /// Rows per chosen method.
    pub methods: BTreeMap<String, u64>,
    /// Each method's step times, summed over the features.
    pub stages: Vec<(MethodId, StageTimes)>,
    /// Connection legs made.
    pub connections: u64,
    /// The network lines (FIDs) a leg was made for.
    pub lines_used: BTreeSet<Option<u64>>,
    /// Lines of `input.connect`, when the run has a network (set by
    /// [`Run::finish`]).
    pub network: Option<u64>,
    /// The figures registered steps report after the last feature, each
    /// under the name of the run record's column it fills (`area_held`;
    /// set by [`Run::finish`]).
    pub figures: Vec<(&'static str, f64)>,
    /// The CPU time of each registered step, by the step's name in the
    /// order first met: on the features, and after the last one (a step's
    /// finish: the coverage a partition grows).
    pub step_times: Vec<(&'static str, Duration)>,
}

impl RunCounts {
    /// The figure `name` a step reported, if any.
    pub fn figure(&self, name: &str) -> Option<f64> {
        self.figures
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, v)| v)
    }
}

/// Why the work after the last feature failed: the run stops and writes
/// nothing (exit 65).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FinishError {
    /// A registered step's [finish](super::step::FeatureStep::finish) failed.
    #[error("`{step}`: {reason}")]
    Step {
        /// The step (its key in the pipeline file).
        step: &'static str,
        /// Why, as the step says.
        reason: String,
    },
}

/// A feature rejected under `on_error: fail`: the run stops.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FailedFeature {
    /// Its FID, or `(no fid)`.
    pub fid: String,
    /// Why it was rejected.
    pub reason: String,
}

/// One run's counts and what it gathers for after the last feature.
#[derive(Debug)]
pub struct Run<'a> {
    params: &'a ProcessParams,
    fail: bool,
    counts: RunCounts,
    met: Vec<(Option<u64>, geo::Coord<f64>)>,
    /// The per-feature rows of each registered step whose finish reads
    /// them (by its index in `params.extra`).
    kept: Vec<Vec<(Option<u64>, &'static str, StepRow)>>,
    /// What each such step kept of every feature (by its index in
    /// `params.extra`).
    kept_values: Vec<Vec<(Option<u64>, Kept)>>,
}

impl<'a> Run<'a> {
    /// A run of `params`; with `fail` (`on_error: fail`) the first
    /// rejected feature stops it.
    pub fn new(params: &'a ProcessParams, fail: bool) -> Self {
        Self {
            params,
            fail,
            counts: RunCounts::default(),
            met: Vec::new(),
            kept: vec![Vec::new(); params.extra.len()],
            kept_values: vec![Vec::new(); params.extra.len()],
        }
    }

    /// Counts feature `f` with its rows `r` (features in read order) and
    /// keeps what [`Self::finish`] needs; returns the rows to write, or the
    /// rejection that stops the run under `on_error: fail`.
    pub fn add(&mut self, f: &Feature, r: FeatureRows) -> Result<Rows, FailedFeature> {
        let c = &mut self.counts;
        c.read += f.source_count();
        if let (true, Some(rej)) = (self.fail, r.rows.rejected.first()) {
            return Err(FailedFeature {
                fid: crate::feature::fid_text(f.fid),
                reason: rej.reason.clone(),
            });
        }
        match &r.status {
            Status::Rejected => c.rejected += f.source_count(),
            Status::Filtered => c.filtered += f.source_count(),
            Status::Written(methods) => {
                c.written += f.source_count();
                for m in methods {
                    *c.methods.entry(m.clone()).or_default() += 1;
                }
            }
        }
        let mut rows = r.rows;
        c.rows += rows.skeletons.len() as u64;
        c.connections += rows.connections.len() as u64;
        c.lines_used
            .extend(rows.connections.iter().map(|l| l.line_fid));
        for &(name, t) in &r.step_times {
            add_time(&mut c.step_times, name, t);
        }
        for (m, t) in &r.times {
            match c.stages.iter_mut().find(|(x, _)| x == m) {
                Some((_, total)) => *total += *t,
                None => c.stages.push((*m, *t)),
            }
        }
        self.keep_for_finish(&mut rows);
        self.met.extend(
            rows.connections
                .iter()
                .filter_map(|l| l.geometry.0.last().map(|&p| (l.line_fid, p))),
        );
        Ok(rows)
    }

    /// Keeps the rows of the registered steps whose finish reads them, and
    /// what they kept of the features (taken out of `rows`).
    fn keep_for_finish(&mut self, rows: &mut Rows) {
        let mut values = std::mem::take(&mut rows.kept);
        let steps = self.params.extra.iter();
        for ((e, kept), kept_values) in steps.zip(&mut self.kept).zip(&mut self.kept_values) {
            if !e.entry.needs.finish {
                continue;
            }
            for layer in e.entry.layers {
                let own = rows.extra.get(layer.name).into_iter().flatten();
                kept.extend(own.map(|r| (r.src_fid, layer.name, r.row.clone())));
            }
            let (own, others): (Vec<_>, Vec<_>) = values
                .into_iter()
                .partition(|(step, _, _)| *step == e.entry.name);
            kept_values.extend(own.into_iter().map(|(_, fid, k)| (fid, k)));
            values = others;
        }
    }

    /// The counts so far.
    pub fn counts(&self) -> &RunCounts {
        &self.counts
    }

    /// After the last feature: the registered steps'
    /// [finish](super::step::FeatureStep::finish_rows) rows (of the layers
    /// each declares) and figures, the network's lines split where they
    /// met the polygons (with `input.connect`), and the counts. Fails when
    /// a registered step's finish fails (a unit of a partitioned coverage
    /// that cannot be written valid).
    pub fn finish(mut self) -> Result<(Rows, RunCounts), FinishError> {
        let mut rows = Rows::default();
        let kept = std::mem::take(&mut self.kept);
        let kept_values = std::mem::take(&mut self.kept_values);
        for ((e, kept), kept_values) in self.params.extra.iter().zip(kept).zip(kept_values) {
            let kept_values = std::cell::RefCell::new(kept_values);
            let input = super::step::FinishInput {
                rows: &kept,
                kept: &kept_values,
                side: e.side.as_deref(),
                neighbours: self
                    .params
                    .neighbours
                    .as_deref()
                    .filter(|_| e.step.needs(e.entry.needs).neighbours),
            };
            let clock = crate::clock::CpuClock::start();
            let made = e.step.finish_rows(&input);
            add_time(&mut self.counts.step_times, e.entry.name, clock.elapsed());
            let made = e
                .entry
                .checked_finish(made)
                .map_err(|f| FinishError::Step {
                    step: e.entry.name,
                    reason: f.0,
                })?;
            for (layer, row) in made.rows {
                rows.extra.entry(layer).or_default().push(row);
            }
            self.counts.figures.extend(made.figures);
        }
        if let Some(net) = &self.params.connect {
            rows.network = net.rows(&self.met);
            self.counts.network = Some(net.len() as u64);
        }
        Ok((rows, self.counts))
    }
}

/// Adds `t` to step `name`'s time in `times` (a new entry at the end when
/// the step has none yet).
pub(crate) fn add_time(times: &mut Vec<(&'static str, Duration)>, name: &'static str, t: Duration) {
    match times.iter_mut().find(|(n, _)| *n == name) {
        Some((_, total)) => *total += t,
        None => times.push((name, t)),
    }
}
