//! A run: read in batches → process features in parallel (rayon) → write in
//! input order, so the output is identical for any thread count.
//!
//! GDAL is used only on the calling thread (reader and writer); workers run
//! [`crate::process::feature_rows`] on owned data. `run` and `score` are the
//! same [`Job`]: they differ only in where the skeletons come from.

use crate::config::{InputSpec, OnError, OutputSpec, Pipeline};
use crate::feature::Feature;
use crate::io::guard::Protected;
use crate::io::reader::Reader;
use crate::io::writer::{check_output, Writer};
use crate::io::{IoError, SourceInfo};
use crate::methods::MethodId;
use crate::output::{Rows, RunRecord};
use crate::process::{
    feature_rows, FeatureRows, ProcessParams, RowOptions, Skeletons, StageTimes, Status,
};
use crate::reporting::{check_path, write_report, ReportError, ReportJob, ReportSummary};
use geo::MultiLineString;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::mpsc;
use std::time::Instant;
use thiserror::Error;

/// How to run (from the command line, not the pipeline file).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Worker threads; `None` = one per core.
    pub threads: Option<usize>,
    /// Show a progress bar.
    pub progress: bool,
    /// Features per batch (default 256).
    pub batch_size: Option<usize>,
    /// Without a progress bar, log a progress line this often (default
    /// [`PROGRESS_EVERY`]).
    pub progress_every: Option<std::time::Duration>,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// Features read from the source (after `where`/`bbox`).
    pub read: u64,
    /// Features with a skeleton row (read = written + rejected + filtered by `min_area`).
    pub written: u64,
    /// Rows in the skeleton layer (more than `written` with `explode`).
    pub rows: u64,
    /// Features written to `rejected`.
    pub rejected: u64,
    /// Features filtered by `where`, `bbox` or `min_area`.
    pub filtered: u64,
    /// Wall time in seconds.
    pub elapsed_s: f64,
    /// The output file.
    pub output: String,
    /// Chosen method per feature, counted.
    pub methods: Vec<(String, u64)>,
    /// Thread time each method spent, step by step, over the whole run.
    pub stages: Vec<(MethodId, StageTimes)>,
    /// The report written after the run (`output.report`).
    pub report: Option<ReportSummary>,
    /// With `input.connect`: the legs added to skeletons, and the lines of
    /// the network that got at least one.
    pub connect: Option<ConnectCounts>,
}

/// What `input.connect` did in a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ConnectCounts {
    /// Lines in the network.
    pub lines: u64,
    /// Lines that got at least one leg.
    pub lines_used: u64,
    /// Legs added (connection points served).
    pub connections: u64,
}

/// Why a run failed.
#[derive(Debug, Error)]
pub enum RunError {
    /// Reading or writing failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A feature was rejected under `on_error: fail` (exit 65).
    #[error("{}", crate::config::rejected_under_fail(.fid, .reason))]
    Rejected {
        /// Source FID.
        fid: String,
        /// The reason.
        reason: String,
    },
    /// The thread pool could not be created.
    #[error("cannot start {0} worker threads")]
    Threads(usize),
    /// More worker threads than make sense.
    #[error("`--threads {asked}`: give between 1 and {MAX_THREADS} worker threads (this machine has {cores} cores), or leave it out for one per core")]
    TooManyThreads {
        /// Threads asked for.
        asked: usize,
        /// Cores of this machine.
        cores: usize,
    },
    /// The run's output was written but its report was not.
    #[error("the report failed ({0}); the GeoPackage was written, `skeletonise report` makes the report from it")]
    Report(#[from] ReportError),
}

/// Checks everything `run` checks before processing: the input opens, the
/// layer exists, the CRS is projected (or reprojected), the filter is valid
/// and the output can be written. Returns what the source holds.
pub fn validate(p: &Pipeline) -> Result<crate::io::SourceInfo, RunError> {
    let input = &p.file.input;
    let mut reader = Reader::open(input)?;
    reader.probe()?;
    if let Some(reason) = merge_field(input, reader.info()).err() {
        return Err(RunError::Io(reason));
    }
    if let Some(c) = &input.connect {
        let mut lines = Reader::open(&c.input(reader.info().srs_wkt.as_deref()))
            .map_err(|e| connect_error(c, e))?;
        lines.probe()?;
        if lines.info().selected == Some(0) {
            return Err(no_lines(c, lines.info(), 0));
        }
    }
    let job = Job::of(p);
    check_output(&p.file.output, &job.protected())?;
    check_report_path(&job)?;
    Ok(reader.info().clone())
}

/// Skeletons made by another tool, for `skeletonise score`.
#[derive(Debug, Clone, PartialEq)]
pub struct Given {
    /// The tool's name, written to the `method` attribute.
    pub label: String,
    /// Its lines by polygon FID.
    pub lines: HashMap<u64, MultiLineString<f64>>,
}

/// What a run reads, computes and writes: a pipeline file, or `score`'s
/// arguments.
#[derive(Debug, Clone)]
pub struct Job<'a> {
    /// Name for logs and `skeletonise_runs`.
    pub name: String,
    /// What to record as the pipeline in `skeletonise_runs`.
    pub provenance: String,
    /// The polygons.
    pub input: &'a InputSpec,
    /// The output GeoPackage.
    pub output: &'a OutputSpec,
    /// The per-feature steps.
    pub params: ProcessParams,
    /// What to do with features that cannot be processed.
    pub on_error: OnError,
    /// The skeletons when another tool made them.
    pub given: Option<&'a Given>,
    /// Other data sources the job reads (never to be written over), each
    /// with what it is to the job (e.g. "the skeletons source").
    pub other_inputs: Vec<(&'static str, String)>,
    /// The layers and columns the job writes.
    pub plan: crate::output::Plan,
}

impl<'a> Job<'a> {
    /// The job of a pipeline file.
    pub fn of(p: &'a Pipeline) -> Self {
        Self {
            name: p.file.name.clone().unwrap_or_default(),
            provenance: p.provenance_text(),
            input: &p.file.input,
            output: &p.file.output,
            params: p.process_params(),
            on_error: p.file.on_error,
            given: None,
            other_inputs: Vec::new(),
            plan: p.plan(),
        }
    }

    /// Every data source the job reads: no file it writes may be one of
    /// them.
    pub fn protected(&self) -> Vec<Protected<'_>> {
        let mut p = vec![Protected::new("the input", &self.input.source)];
        if let Some(c) = &self.input.connect {
            p.push(Protected::new("the connect source", &c.source));
        }
        p.extend(
            self.other_inputs
                .iter()
                .map(|(role, s)| Protected::new(role, s)),
        );
        p
    }

    fn skeletons(&self, f: &Feature) -> Skeletons<'_> {
        match self.given {
            None => Skeletons::Computed,
            Some(g) => Skeletons::Given {
                label: &g.label,
                lines: f.fid.and_then(|fid| g.lines.get(&fid)),
            },
        }
    }
}

/// Runs the pipeline end to end, then writes its report when the output
/// asks for one (`output.report`).
pub fn run(p: &Pipeline, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let job = Job::of(p);
    check_report_path(&job)?;
    let mut summary = run_job(&job, opts)?;
    let report = job.output.report.as_ref().zip(job.output.report_path());
    if let Some((spec, html)) = report {
        summary.report = Some(write_report(&ReportJob {
            gpkg: summary.output.clone().into(),
            html,
            selection: spec.features.clone(),
            polygons: None,
            overwrite: job.output.overwrite,
        })?);
    }
    Ok(summary)
}

/// Checks the path of the report a job writes after its run (if any):
/// never one of the job's sources or its output GeoPackage, an existing
/// file only with `output.overwrite`.
fn check_report_path(job: &Job<'_>) -> Result<(), RunError> {
    let Some(html) = job.output.report_path() else {
        return Ok(());
    };
    let mut protected = job.protected();
    protected.push(Protected::new("the output GeoPackage", &job.output.path));
    check_path(&html, job.output.overwrite, &protected)?;
    Ok(())
}

/// Counts of a run so far.
#[derive(Debug, Default)]
struct Counts {
    read: u64,
    written: u64,
    rejected: u64,
    filtered: u64,
    rows: u64,
    methods: std::collections::BTreeMap<String, u64>,
    stages: Vec<(MethodId, StageTimes)>,
    connections: u64,
    lines_used: std::collections::BTreeSet<Option<u64>>,
    /// Lines of `input.connect`, when the run has a network.
    network: Option<u64>,
}

impl Counts {
    /// Counts one feature; under `on_error: fail` a rejection is the error.
    fn add(&mut self, f: &Feature, r: &FeatureRows, on_error: OnError) -> Result<(), RunError> {
        if let (OnError::Fail, Some(rej)) = (on_error, r.rows.rejected.first()) {
            return Err(RunError::Rejected {
                fid: f.fid.map_or_else(|| "(no fid)".into(), |x| x.to_string()),
                reason: rej.reason.clone(),
            });
        }
        for rej in &r.rows.rejected {
            tracing::warn!(fid = f.fid, reason = %rej.reason, "feature rejected");
        }
        match &r.status {
            Status::Rejected => self.rejected += f.source_count(),
            Status::Filtered => self.filtered += f.source_count(),
            Status::Written(methods) => {
                self.written += f.source_count();
                for m in methods {
                    *self.methods.entry(m.clone()).or_default() += 1;
                }
            }
        }
        self.rows += r.rows.skeletons.len() as u64;
        self.connections += r.rows.connections.len() as u64;
        self.lines_used
            .extend(r.rows.connections.iter().map(|c| c.line_fid));
        for (m, t) in &r.times {
            match self.stages.iter_mut().find(|(x, _)| x == m) {
                Some((_, total)) => *total += *t,
                None => self.stages.push((*m, *t)),
            }
        }
        Ok(())
    }
}

/// Progress: a bar on a terminal, otherwise a log line every
/// [`PROGRESS_EVERY`] (features done, rate, time left) so that a scheduled
/// job's log shows that a long run is alive.
struct Progress {
    bar: ProgressBar,
    log: bool,
    every: std::time::Duration,
    total: Option<u64>,
    done: u64,
    started: Instant,
    last: Instant,
}

/// How often a run without a terminal logs its progress.
pub const PROGRESS_EVERY: std::time::Duration = std::time::Duration::from_secs(10);

impl Progress {
    fn new(terminal: bool, total: Option<u64>, every: std::time::Duration) -> Self {
        let bar = match (terminal, total) {
            (false, _) => ProgressBar::hidden(),
            (true, Some(n)) => {
                let b = ProgressBar::new(n);
                b.set_style(
                    ProgressStyle::with_template(
                        "{spinner} {bar:40} {pos}/{len} features {elapsed_precise} (eta {eta})",
                    )
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
                );
                b
            }
            (true, None) => ProgressBar::new_spinner(),
        };
        let now = Instant::now();
        Self {
            bar,
            log: !terminal,
            every,
            total,
            done: 0,
            started: now,
            last: now,
        }
    }

    fn add(&mut self, n: u64) {
        self.done += n;
        self.bar.inc(n);
        if !self.log || self.last.elapsed() < self.every {
            return;
        }
        self.last = Instant::now();
        let secs = self.started.elapsed().as_secs_f64();
        let rate = self.done as f64 / secs.max(1e-9);
        let eta = self
            .total
            .filter(|_| rate > 0.0)
            .map(|t| format!("{:.0} s", t.saturating_sub(self.done) as f64 / rate))
            .unwrap_or_else(|| "unknown".into());
        let of = self.total.map_or_else(|| "?".into(), |t| t.to_string());
        tracing::info!(
            done = self.done,
            total = self.total,
            rate = format!("{rate:.1}"),
            "progress: {} of {of} features, {rate:.1}/s, {eta} left",
            self.done
        );
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Most worker threads a run may ask for: beyond a few per core they only
/// cost memory, and thousands make the thread pool's start crawl.
pub const MAX_THREADS: usize = 256;

/// The number of worker threads to run: `asked`, or one per core.
pub fn worker_threads(asked: Option<usize>) -> Result<usize, RunError> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match asked {
        None => Ok(rayon::current_num_threads()),
        Some(0) => Err(RunError::TooManyThreads { asked: 0, cores }),
        Some(n) if n > MAX_THREADS => Err(RunError::TooManyThreads { asked: n, cores }),
        Some(n) => Ok(n),
    }
}

/// What the reader thread hands over: a batch of features, or why reading
/// failed.
type Batch = Result<Vec<Feature>, IoError>;

/// Batches the reader may read ahead of the workers, and the workers ahead
/// of the writer: memory stays bounded by a few batches.
const QUEUE: usize = 2;

/// Runs a job: a reader thread reads batches, the worker threads process
/// each batch's features in parallel, a writer thread writes them in input
/// order — all three at once, so I/O overlaps the work and the output is the
/// same for any thread count.
pub fn run_job(job: &Job<'_>, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let started = chrono::Utc::now();
    let clock = Instant::now();
    let threads = worker_threads(opts.threads)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| RunError::Threads(threads))?;
    let batch = opts.batch_size.unwrap_or(256).max(1);
    let make_valid = job.params.prepare.make_valid;
    std::thread::scope(|scope| {
        // The reader opens the source on its own thread (GDAL handles stay on
        // the thread that made them) and reports what it found first.
        let (info_tx, info_rx) = mpsc::sync_channel::<Result<SourceInfo, IoError>>(1);
        let (batch_tx, batch_rx) = mpsc::sync_channel::<Batch>(QUEUE);
        let reader =
            scope.spawn(move || read_batches(job.input, batch, make_valid, info_tx, batch_tx));
        let info = match info_rx.recv() {
            Ok(Ok(info)) => info,
            Ok(Err(e)) => return Err(e.into()),
            Err(_) => return Err(reader_gone(reader)),
        };
        let mut params = job.params.clone();
        if let Some(c) = &job.input.connect {
            params.connect = Some(std::sync::Arc::new(read_network(c, &info)?));
        }
        let params = &params;
        let writer = Writer::create(&job.plan, job.output, &info, &job.protected())?;
        tracing::info!(
            pipeline = %job.name,
            source = %info.source,
            layer = %info.layer,
            crs = %info.crs_name,
            features = info.selected,
            total_features = info.total,
            threads,
            "run started"
        );
        let (rows_tx, rows_rx) = mpsc::sync_channel::<Rows>(QUEUE);
        let writing = scope.spawn(move || write_batches(writer, rows_rx));
        let every = opts.progress_every.unwrap_or(PROGRESS_EVERY);
        let mut progress = Progress::new(opts.progress, info.selected, every);
        let row_opts = RowOptions::of(&job.plan);
        let mut counts = Counts::default();
        let workers = Workers {
            job,
            params,
            pool: &pool,
            row_opts,
        };
        let result = workers.compute(&batch_rx, &rows_tx, &mut counts, &mut progress);
        progress.finish();
        // Stop the reader (if still reading) and let the writer drain.
        drop(batch_rx);
        drop(rows_tx);
        let written = writing.join().unwrap_or_else(|_| {
            Err(IoError::Output {
                path: job.output.path.clone(),
                reason: "the writer thread failed with an internal error; please report it".into(),
            })
        });
        let _ = reader.join();
        let writer = match (result, written) {
            (Err(e), Ok(mut w)) => {
                w.abort();
                return Err(e);
            }
            (Err(e), Err(_)) => return Err(e),
            (Ok(()), Err(e)) => return Err(e.into()),
            (Ok(()), Ok(w)) => w,
        };
        counts.network = params.connect.as_ref().map(|n| n.len() as u64);
        finish_run(job, &info, counts, threads, started, clock, writer)
    })
}

/// What the worker threads need for every batch.
struct Workers<'a> {
    job: &'a Job<'a>,
    params: &'a ProcessParams,
    pool: &'a rayon::ThreadPool,
    row_opts: RowOptions,
}

impl Workers<'_> {
    /// The workers' loop: every batch computed on the pool in parallel,
    /// counted, and handed to the writer in the order read. Up to
    /// [`IN_FLIGHT`] batches are computed at once, so a worker that has
    /// finished its share of one batch starts on the next instead of
    /// waiting for the batch's last feature; results are put back in input
    /// order before they are counted and written.
    fn compute(
        &self,
        batches: &mpsc::Receiver<Batch>,
        rows_tx: &mpsc::SyncSender<Rows>,
        counts: &mut Counts,
        progress: &mut Progress,
    ) -> Result<(), RunError> {
        let (job, params, row_opts) = (self.job, self.params, self.row_opts);
        let next = || batches.recv().ok().map(|b| b.map_err(RunError::from));
        let work = |features: &Vec<Feature>| -> Vec<FeatureRows> {
            features
                .par_iter()
                .map(|f| feature_rows(f, job.skeletons(f), params, row_opts))
                .collect()
        };
        in_order(self.pool, next, work, |features, done| {
            counts.read += features.iter().map(Feature::source_count).sum::<u64>();
            let mut rows = Rows::default();
            for (f, r) in features.iter().zip(done) {
                counts.add(f, &r, job.on_error)?;
                rows.append(r.rows);
            }
            // A closed channel: the writer stopped on an error; it says
            // which after the workers.
            let more = rows_tx.send(rows).is_ok();
            progress.add(features.len() as u64);
            Ok(more)
        })
    }
}

/// Computes `work` on every batch `next` yields, up to [`IN_FLIGHT`] batches
/// at once on `pool`, and gives each batch with its result to `take` in the
/// order `next` yielded them, on the calling thread. Stops at the first
/// error (from `next` or `take`) or when `take` returns false. A panic in
/// `work` is raised again on the calling thread, as `pool.install` would.
fn in_order<T: Send, U: Send>(
    pool: &rayon::ThreadPool,
    mut next: impl FnMut() -> Option<Result<T, RunError>>,
    work: impl Fn(&T) -> U + Sync,
    mut take: impl FnMut(T, U) -> Result<bool, RunError>,
) -> Result<(), RunError> {
    type Done<T, U> = (usize, T, std::thread::Result<U>);
    let (done_tx, done_rx) = mpsc::channel::<Done<T, U>>();
    let work = &work;
    // Runs on this thread (not a worker), so blocking on `next` or on the
    // results never takes a worker away from the batches.
    pool.in_place_scope(|scope| {
        let mut order = InOrder::new();
        let mut ended = false;
        loop {
            while !ended && order.in_flight() < IN_FLIGHT {
                match next() {
                    Some(batch) => {
                        let batch = batch?;
                        let (i, done_tx) = (order.start(), done_tx.clone());
                        scope.spawn(move |_| {
                            let done =
                                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                                    work(&batch)
                                }));
                            // The receiver outlives the scope.
                            let _ = done_tx.send((i, batch, done));
                        });
                    }
                    None => ended = true,
                }
            }
            if order.in_flight() == 0 {
                return Ok(());
            }
            // Every task sends before it ends, panic or not.
            let (i, batch, done) = done_rx.recv().expect("the sender is held here");
            let done = done.unwrap_or_else(|p| std::panic::resume_unwind(p));
            for (batch, done) in order.finish(i, (batch, done)) {
                if !take(batch, done)? {
                    return Ok(());
                }
            }
        }
    })
}

/// Batches computed at once: two, so the workers always have the next
/// batch's features to take while the last features of one are finishing
/// (and memory stays bounded by a few batches).
const IN_FLIGHT: usize = 2;

/// Puts batches finished in any order back in the order they were started.
struct InOrder<T> {
    /// Batches started so far (the next one's number).
    started: usize,
    /// The number of the next batch to hand on.
    next: usize,
    /// Finished batches waiting for an earlier one.
    waiting: std::collections::BTreeMap<usize, T>,
}

impl<T> InOrder<T> {
    /// None started yet.
    fn new() -> Self {
        Self {
            started: 0,
            next: 0,
            waiting: std::collections::BTreeMap::new(),
        }
    }

    /// Numbers a new batch.
    fn start(&mut self) -> usize {
        self.started += 1;
        self.started - 1
    }

    /// Batches started and not yet handed on.
    fn in_flight(&self) -> usize {
        self.started - self.next
    }

    /// Records batch `i` as finished; returns the batches that can now be
    /// handed on, in order.
    fn finish(&mut self, i: usize, batch: T) -> Vec<T> {
        self.waiting.insert(i, batch);
        let mut ready = Vec::new();
        while let Some(b) = self.waiting.remove(&self.next) {
            ready.push(b);
            self.next += 1;
        }
        ready
    }
}

/// The reader thread: opens the source, sends what it holds, then its
/// features batch by batch until the source ends, an error, or nobody
/// listens any more.
fn read_batches(
    input: &InputSpec,
    batch: usize,
    make_valid: bool,
    info_tx: mpsc::SyncSender<Result<SourceInfo, IoError>>,
    batch_tx: mpsc::SyncSender<Batch>,
) {
    let mut reader = match Reader::open(input) {
        Ok(r) => r,
        Err(e) => {
            let _ = info_tx.send(Err(e));
            return;
        }
    };
    if info_tx.send(Ok(reader.info().clone())).is_err() {
        return;
    }
    if input.merge_adjacent {
        return read_merged(&mut reader, input, batch, make_valid, batch_tx);
    }
    let r = reader.read::<Stop>(batch, make_valid, |features| {
        batch_tx.send(Ok(features)).map_err(|_| Stop::Gone)
    });
    if let Err(Stop::Failed(e)) = r {
        let _ = batch_tx.send(Err(e));
    }
}

/// The index of `input.merge_by` among the source's fields, or the error
/// naming the fields there are.
fn merge_field(input: &InputSpec, info: &SourceInfo) -> Result<Option<usize>, IoError> {
    let Some(name) = &input.merge_by else {
        return Ok(None);
    };
    let fields = &info.fields;
    fields
        .iter()
        .position(|f| &f.name == name)
        .map(Some)
        .ok_or_else(|| {
            let names: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
            IoError::Read {
                source_name: input.source.clone(),
                reason: format!(
                    "`input.merge_by`: the layer has no field `{name}`; its fields are {}",
                    names.join(", ")
                ),
            }
        })
}

/// The lines of `input.connect`, reprojected to the CRS the polygons are
/// handed out in (`polygons`); a layer without lines is an error.
fn read_network(
    c: &crate::config::ConnectSpec,
    polygons: &SourceInfo,
) -> Result<crate::connect::Network, RunError> {
    let mut reader =
        Reader::open(&c.input(polygons.srs_wkt.as_deref())).map_err(|e| connect_error(c, e))?;
    let mut lines = Vec::new();
    let mut features = 0;
    reader.read::<IoError>(1024, false, |batch| {
        features += batch.len();
        for f in batch {
            let mut ls = Vec::new();
            if let Some(g) = &f.geometry {
                crate::connect::lines_of(g, &mut ls);
            }
            lines.extend(ls.into_iter().map(|l| (f.fid, l)));
        }
        Ok(())
    })?;
    if lines.is_empty() {
        return Err(no_lines(c, reader.info(), features));
    }
    tracing::info!(source = %c.source, layer = %reader.info().layer, crs = %reader.info().crs_name, lines = lines.len(), "connect: line network read");
    Ok(crate::connect::Network::new(lines, c.snap))
}

/// An error opening `input.connect`, said to be about it.
fn connect_error(c: &crate::config::ConnectSpec, e: IoError) -> RunError {
    RunError::Io(IoError::Read {
        source_name: c.source.clone(),
        reason: format!("`input.connect`: {e}"),
    })
}

/// The error of a connect layer without lines.
fn no_lines(c: &crate::config::ConnectSpec, info: &SourceInfo, features: usize) -> RunError {
    RunError::Io(IoError::Read {
        source_name: c.source.clone(),
        reason: format!(
            "`input.connect`: layer `{}` has no lines ({features} features read, none a LINESTRING or MULTILINESTRING); give the layer of the line network (`input.connect.layer`)",
            info.layer
        ),
    })
}

/// `input.merge_adjacent`: every feature read first, the adjacent ones
/// dissolved into one per group, then sent in batches.
fn read_merged(
    reader: &mut Reader,
    input: &InputSpec,
    batch: usize,
    make_valid: bool,
    batch_tx: mpsc::SyncSender<Batch>,
) {
    let by = match merge_field(input, reader.info()) {
        Ok(by) => by,
        Err(e) => {
            let _ = batch_tx.send(Err(e));
            return;
        }
    };
    let mut all = Vec::new();
    let r = reader.read::<Stop>(batch, make_valid, |features| {
        all.extend(features);
        Ok(())
    });
    if let Err(Stop::Failed(e)) = r {
        let _ = batch_tx.send(Err(e));
        return;
    }
    let merged = crate::process::merge::merge_adjacent(all, by);
    for chunk in merged.chunks(batch) {
        if batch_tx.send(Ok(chunk.to_vec())).is_err() {
            return;
        }
    }
}

/// Why the reader thread stops before the end of the source.
enum Stop {
    /// Nobody takes batches any more (the run stopped).
    Gone,
    /// Reading failed.
    Failed(IoError),
}

impl From<IoError> for Stop {
    fn from(e: IoError) -> Self {
        Stop::Failed(e)
    }
}

/// The writer thread: writes each batch of rows as it comes, in order.
/// Returns the writer (to finish) or the first error (the file discarded).
fn write_batches(mut writer: Writer, rows: mpsc::Receiver<Rows>) -> Result<Writer, IoError> {
    for r in rows.iter() {
        if let Err(e) = writer.write_batch(&r) {
            writer.abort();
            return Err(e);
        }
    }
    Ok(writer)
}

/// The reader thread ended without a word: it panicked.
fn reader_gone(reader: std::thread::ScopedJoinHandle<'_, ()>) -> RunError {
    let _ = reader.join();
    RunError::Io(IoError::Output {
        path: String::new(),
        reason: "the reader thread failed with an internal error; please report it".into(),
    })
}

/// Records the run in the output and renames it into place.
fn finish_run(
    job: &Job<'_>,
    info: &SourceInfo,
    mut counts: Counts,
    threads: usize,
    started: chrono::DateTime<chrono::Utc>,
    clock: Instant,
    writer: Writer,
) -> Result<RunSummary, RunError> {
    // What `where` and `bbox` kept back (unknown when the driver cannot count).
    counts.filtered += info.total.map_or(0, |t| t.saturating_sub(counts.read));
    let elapsed_s = clock.elapsed().as_secs_f64();
    let record = RunRecord {
        name: job.name.clone(),
        started_utc: started.to_rfc3339(),
        finished_utc: chrono::Utc::now().to_rfc3339(),
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        pipeline: job.provenance.clone(),
        input: format!("{} (layer {})", info.source, info.layer),
        input_source: crate::io::reader::absolute_source(&info.source),
        input_layer: info.layer.clone(),
        input_reproject: job.input.reproject.clone(),
        skeleton_layer: job.output.layer.clone(),
        read: counts.read,
        written: counts.written,
        rejected: counts.rejected,
        filtered: counts.filtered,
        elapsed_s,
        threads,
        stage_seconds: stage_json(&counts.stages),
    };
    let out = writer.finish(&record)?;
    Ok(RunSummary {
        read: counts.read,
        written: counts.written,
        rows: counts.rows,
        rejected: counts.rejected,
        filtered: counts.filtered,
        elapsed_s,
        output: out.display().to_string(),
        methods: counts.methods.into_iter().collect(),
        stages: counts.stages,
        report: None,
        connect: counts.network.map(|lines| ConnectCounts {
            lines,
            lines_used: counts.lines_used.len() as u64,
            connections: counts.connections,
        }),
    })
}

/// Step times as JSON for `skeletonise_runs.stage_seconds`:
/// `{"MA": {"skeleton": 1.2, "prune_extend": 0.3, "score": 0.4}, …}`.
fn stage_json(stages: &[(MethodId, StageTimes)]) -> String {
    let map: serde_json::Map<String, serde_json::Value> = stages
        .iter()
        .map(|(m, t)| {
            (
                m.to_string(),
                serde_json::json!({
                    "skeleton": round_ms(t.skeleton),
                    "prune_extend": round_ms(t.prune_extend),
                    "score": round_ms(t.score),
                }),
            )
        })
        .collect();
    serde_json::Value::Object(map).to_string()
}

/// Seconds, to the millisecond.
fn round_ms(d: std::time::Duration) -> f64 {
    (d.as_secs_f64() * 1000.0).round() / 1000.0
}

#[cfg(test)]
mod tests {
    use super::{in_order, InOrder, RunError};

    /// Batches finished out of order are held back until every earlier one
    /// has finished, then handed on in the order they were started.
    #[test]
    fn batches_finished_out_of_order_are_handed_on_in_order() {
        let mut order = InOrder::new();
        let ids: Vec<usize> = (0..4).map(|_| order.start()).collect();
        assert_eq!(ids, [0, 1, 2, 3]);
        assert_eq!(order.in_flight(), 4);
        assert!(order.finish(2, "c").is_empty());
        assert!(order.finish(1, "b").is_empty());
        assert_eq!(order.in_flight(), 4, "held batches still count");
        assert_eq!(order.finish(0, "a"), ["a", "b", "c"]);
        assert_eq!(order.in_flight(), 1);
        assert_eq!(order.finish(3, "d"), ["d"]);
        assert_eq!(order.in_flight(), 0);
    }

    /// Batches come out in input order whatever order they finish in, and a
    /// panic in the work is raised on the calling thread instead of leaving
    /// it waiting for a result that never comes.
    #[test]
    fn in_order_keeps_the_order_and_raises_a_panic() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let mut items = (0..20u64).map(Ok::<u64, RunError>);
        let mut seen = Vec::new();
        let slow_first = |&i: &u64| {
            // Earlier batches finish later.
            std::thread::sleep(std::time::Duration::from_millis(20 - i));
            i * 10
        };
        in_order(
            &pool,
            || items.next(),
            slow_first,
            |i, r| {
                seen.push((i, r));
                Ok(true)
            },
        )
        .unwrap();
        assert_eq!(seen, (0..20).map(|i| (i, i * 10)).collect::<Vec<_>>());

        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let mut items = (0..5u64).map(Ok::<u64, RunError>);
                let boom = |&i: &u64| if i == 3 { panic!("boom") } else { i };
                in_order(&pool, || items.next(), boom, |_, _| Ok(true))
            }));
            let _ = tx.send(r.is_err());
        });
        let panicked = rx
            .recv_timeout(std::time::Duration::from_secs(60))
            .expect("a panic in the work must not hang the run");
        assert!(panicked, "the panic is raised again");
    }
}
