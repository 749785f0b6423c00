//! The run driver every caller shares — the command line's pipeline and the
//! Python module (and so Dask and QGIS): features go in, in read order, as
//! [`FeatureRows`] (computed by [`super::feature_rows`] on any thread); the
//! run counts them, applies `on_error: fail`, keeps what the steps need
//! after the last feature (the pieces each unit received, the points where
//! the network's lines met the polygons), and [`Run::finish`] makes those
//! rows once: the network's lines split at the polygons, the partitioned
//! coverage. No I/O: the caller reads, writes and logs.

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
    /// Units of the partitioned coverage, when the run partitions (set by
    /// [`Run::finish`]).
    pub units: Option<u64>,
    /// With a partition: the area the units held of the collapsed polygons
    /// before (set by [`Run::finish`]).
    pub area_held: f64,
    /// The CPU time of `partition` and of each registered step, by the
    /// step's name in the order first met: on the features, and after the
    /// last one (the coverage assembled, a step's finish).
    pub step_times: Vec<(&'static str, Duration)>,
}

/// Why the work after the last feature failed: the run stops and writes
/// nothing (exit 65).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FinishError {
    /// A unit of the partitioned coverage cannot be written valid.
    #[error("partition: {0}")]
    Coverage(#[from] crate::partition::UnitError),
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
    grown: Vec<(Option<u64>, crate::partition::Growth)>,
    met: Vec<(Option<u64>, geo::Coord<f64>)>,
    /// The per-feature rows of each registered step whose finish reads
    /// them (by its index in `params.extra`).
    kept: Vec<Vec<(Option<u64>, &'static str, StepRow)>>,
}

impl<'a> Run<'a> {
    /// A run of `params`; with `fail` (`on_error: fail`) the first
    /// rejected feature stops it.
    pub fn new(params: &'a ProcessParams, fail: bool) -> Self {
        Self {
            params,
            fail,
            counts: RunCounts::default(),
            grown: Vec::new(),
            met: Vec::new(),
            kept: vec![Vec::new(); params.extra.len()],
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
                fid: f.fid.map_or_else(|| "(no fid)".into(), |x| x.to_string()),
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
        self.keep_for_finish(&rows);
        self.grown.append(&mut rows.grown);
        self.met.extend(
            rows.connections
                .iter()
                .filter_map(|l| l.geometry.0.last().map(|&p| (l.line_fid, p))),
        );
        Ok(rows)
    }

    /// Keeps the rows of the registered steps whose finish reads them.
    fn keep_for_finish(&mut self, rows: &Rows) {
        for (e, kept) in self.params.extra.iter().zip(&mut self.kept) {
            if !e.entry.needs.finish {
                continue;
            }
            for layer in e.entry.layers {
                let own = rows.extra.get(layer.name).into_iter().flatten();
                kept.extend(own.map(|r| (r.src_fid, layer.name, r.row.clone())));
            }
        }
    }

    /// The counts so far.
    pub fn counts(&self) -> &RunCounts {
        &self.counts
    }

    /// After the last feature: the network's lines split where they met the
    /// polygons (with `input.connect`), the partitioned coverage — every
    /// unit grown by what it received — (with `partition`), the registered
    /// steps' [finish](super::step::FeatureStep::finish) rows (of the
    /// layers each declares; without source fields), and the counts.
    /// Fails when a unit of the coverage cannot be written valid, or a
    /// registered step's finish fails.
    pub fn finish(mut self) -> Result<(Rows, RunCounts), FinishError> {
        let mut rows = Rows::default();
        for (e, kept) in self.params.extra.iter().zip(std::mem::take(&mut self.kept)) {
            let input = super::step::FinishInput {
                rows: &kept,
                side: e.side.as_deref(),
            };
            let clock = crate::clock::CpuClock::start();
            let made = e.step.finish(&input);
            add_time(&mut self.counts.step_times, e.entry.name, clock.elapsed());
            let made = e.entry.checked(made).map_err(|f| FinishError::Step {
                step: e.entry.name,
                reason: f.0,
            })?;
            for (layer, row) in made {
                rows.extra
                    .entry(layer)
                    .or_default()
                    .push(crate::output::ExtraRow {
                        src_fid: None,
                        attributes: Vec::new(),
                        row,
                    });
            }
        }
        if let Some(net) = &self.params.connect {
            rows.network = net.rows(&self.met);
            self.counts.network = Some(net.len() as u64);
        }
        if let (Some(_), Some(cov)) = (&self.params.partition, &self.params.neighbours) {
            let clock = crate::clock::CpuClock::start();
            let grown = std::mem::take(&mut self.grown);
            rows.coverage = crate::partition::assemble(cov.units(), grown)?;
            let c = &mut self.counts;
            add_time(&mut c.step_times, "partition", clock.elapsed());
            c.units = Some(rows.coverage.len() as u64);
            c.area_held = rows
                .coverage
                .iter()
                .map(|u| u.held)
                .filter(|&a| a > 0.0)
                .sum::<f64>()
                + 0.0;
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
