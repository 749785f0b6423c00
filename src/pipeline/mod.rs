//! A run: read in batches → process features in parallel (rayon) → write in
//! input order, so the output is identical for any thread count.
//!
//! GDAL is used only on the calling thread (reader and writer); workers run
//! [`crate::process::feature_rows`] on owned data. `run` and `score` are the
//! same [`Job`]: they differ only in where the skeletons come from.

mod order;
mod progress;
mod record;
mod source;

pub use progress::PROGRESS_EVERY;

use crate::config::{InputSpec, OnError, OutputSpec, Pipeline};
use crate::feature::Feature;
use crate::io::guard::Protected;
use crate::io::reader::Reader;
use crate::io::writer::{check_output, Writer};
use crate::io::{IoError, SourceInfo};
use crate::methods::MethodId;
use crate::output::Rows;
use crate::process::{feature_rows, FeatureRows, ProcessParams, RowOptions, Skeletons, StageTimes};
use crate::reporting::{check_path, write_report, ReportError, ReportJob, ReportSummary};
use geo::MultiLineString;
use order::in_order;
use progress::Progress;
use rayon::prelude::*;
use record::finish_run;
use source::{merge_field, read_batches, read_neighbours, read_network, reader_gone, Merge};
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
    /// The work after the last feature failed — a registered step's finish
    /// failed, such as a unit of a partitioned coverage that could not be
    /// written valid — (exit 65: the output is not written).
    #[error(transparent)]
    Finish(#[from] crate::process::FinishError),
    /// The run's output was written but its report was not.
    #[error("the report failed ({0}); the GeoPackage was written, `skeletonise report` makes the report from it")]
    Report(#[from] ReportError),
}

/// Checks everything `run` checks before processing: the input opens, the
/// layer exists, the CRS is projected (or reprojected), the filter is valid,
/// the line network and the coverage (read whole, as `run` reads them) hold
/// what their steps need, and the output can be written. Returns what the source holds.
pub fn validate(p: &Pipeline) -> Result<crate::io::SourceInfo, RunError> {
    let input = &p.file.input;
    let mut reader = Reader::open(input)?;
    reader.probe()?;
    if let Some(reason) = merge_field(input, reader.info()).err() {
        return Err(RunError::Io(reason));
    }
    // The second inputs are read whole, as `run` reads them before any
    // feature: whatever `run` would refuse in them, `validate` refuses.
    if let Some(c) = &input.connect {
        read_network(c, reader.info())?;
    }
    if let Some(n) = &input.neighbours {
        read_neighbours(n, reader.info())?;
    }
    read_step_sides(&mut p.process_params(), reader.info())?;
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
            // The registered steps' side inputs are read too: never written over.
            other_inputs: p
                .process_params()
                .extra
                .iter()
                .filter_map(|e| {
                    Some((
                        "a registered step's side input",
                        e.side_source()?.1.ok()?.source,
                    ))
                })
                .collect(),
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
        if let Some(n) = &self.input.neighbours {
            p.push(Protected::new("the neighbours source", &n.source));
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
        let merge = merge_of(job);
        // The reader checks a large polygon's validity on several threads
        // (`PackedTree::first_pair`): as many as the run's, in a pool of its
        // own (the workers' pool waits on the reader's batches), so that a
        // run with `--threads 1` stays on one core.
        let reader_pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("skeletonise-read-{i}"))
            .build()
            .map_err(|_| RunError::Threads(threads))?;
        let reader = scope.spawn(move || {
            reader_pool
                .install(|| read_batches(job.input, merge, batch, make_valid, info_tx, batch_tx))
        });
        let info = match info_rx.recv() {
            Ok(Ok(info)) => info,
            Ok(Err(e)) => return Err(e.into()),
            Err(_) => return Err(reader_gone(reader)),
        };
        let (params, neighbours) = params_for(job, &info)?;
        let params = &params;
        let writer = Writer::create(
            &job.plan,
            job.output,
            &info,
            neighbours.as_ref(),
            &job.protected(),
        )?;
        log_start(job, &info, threads);
        let (rows_tx, rows_rx) = mpsc::sync_channel::<Rows>(QUEUE);
        let writing = scope.spawn(move || write_batches(writer, rows_rx));
        let every = opts.progress_every.unwrap_or(PROGRESS_EVERY);
        let mut progress = Progress::new(opts.progress, info.selected, every);
        let row_opts = RowOptions::of(&job.plan);
        let workers = Workers {
            job,
            params,
            pool: &pool,
            row_opts,
        };
        let (result, counts) = workers.run(&batch_rx, &rows_tx, &mut progress);
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
        let writer = settled(result, written)?;
        finish_run(job, &info, counts, threads, started, clock, writer)
    })
}

/// The writer to finish the run with, when the work and the writing both
/// succeeded; otherwise the first error (the output is then abandoned).
fn settled(
    result: Result<(), RunError>,
    written: Result<Writer, IoError>,
) -> Result<Writer, RunError> {
    match (result, written) {
        (Err(e), Ok(mut w)) => {
            w.abort();
            Err(e)
        }
        (Err(e), Err(_)) => Err(e),
        (Ok(()), Err(e)) => Err(e.into()),
        (Ok(()), Ok(w)) => Ok(w),
    }
}

/// How the reader treats adjacent polygons: merged exactly (every vertex
/// kept) for a step that [needs it](crate::process::step::Needs::merge),
/// dissolved with `merge_adjacent`.
fn merge_of(job: &Job<'_>) -> Merge {
    if job.params.needs().merge {
        Merge::Exactly
    } else if job.input.merge_adjacent {
        Merge::Dissolve
    } else {
        Merge::None
    }
}

/// The run's parameters for the source found: longitude and latitude for
/// the registered steps, the network and the coverage read (with the
/// coverage's source, for the writer).
fn params_for(
    job: &Job<'_>,
    info: &SourceInfo,
) -> Result<(ProcessParams, Option<SourceInfo>), RunError> {
    let mut params = job.params.clone();
    if params.extra.iter().any(|e| e.entry.needs.lonlat) {
        params.lonlat = info
            .srs_wkt
            .as_deref()
            .and_then(crate::io::lonlat::lonlat_of);
    }
    read_step_sides(&mut params, info)?;
    let neighbours = second_inputs(job, info, &mut params)?;
    Ok((params, neighbours))
}

/// Reads the side input layer of every registered step whose options name
/// one (`steps.<step>.<key>`), reprojected to the polygons' CRS (`info`).
fn read_step_sides(params: &mut ProcessParams, info: &SourceInfo) -> Result<(), RunError> {
    for e in &mut params.extra {
        if let Some((key, src)) = e.side_source() {
            let key = format!("steps.{}.{key}", e.entry.name);
            let src = src.map_err(|why| {
                RunError::Io(crate::io::IoError::Read {
                    source_name: key.clone(),
                    reason: format!(
                        "`{key}` is no layer: {why}; give `{{ source: …, layer: …, where: … }}`"
                    ),
                })
            })?;
            e.side = Some(std::sync::Arc::new(source::read_step_side(
                &src, &key, info,
            )?));
        }
    }
    Ok(())
}

/// The run's second inputs, read before any feature: the line network of
/// `input.connect` and the coverage of `input.neighbours` (whose source,
/// when there is one, the writer records).
fn second_inputs(
    job: &Job<'_>,
    info: &SourceInfo,
    params: &mut ProcessParams,
) -> Result<Option<SourceInfo>, RunError> {
    if let Some(c) = &job.input.connect {
        params.connect = Some(std::sync::Arc::new(read_network(c, info)?));
    }
    let Some(n) = &job.input.neighbours else {
        return Ok(None);
    };
    let (coverage, source) = read_neighbours(n, info)?;
    params.neighbours = Some(std::sync::Arc::new(coverage));
    Ok(Some(source))
}

fn log_start(job: &Job<'_>, info: &SourceInfo, threads: usize) {
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
}

/// What the worker threads need for every batch.
struct Workers<'a> {
    job: &'a Job<'a>,
    params: &'a ProcessParams,
    pool: &'a rayon::ThreadPool,
    row_opts: RowOptions,
}

impl Workers<'_> {
    /// Every feature through the run driver ([`crate::process::Run`]),
    /// then the rows it makes once after the last feature — the network's
    /// lines split where they met the polygons, the registered steps'
    /// finish (the coverage a partition grows) — handed to the writer too;
    /// the result and the counts.
    fn run(
        &self,
        batches: &mpsc::Receiver<Batch>,
        rows_tx: &mpsc::SyncSender<Rows>,
        progress: &mut Progress,
    ) -> (Result<(), RunError>, crate::process::RunCounts) {
        let mut run = crate::process::Run::new(self.params, self.job.on_error == OnError::Fail);
        let result = self.compute(batches, rows_tx, &mut run, progress);
        progress.finish();
        match result.map(|()| run.finish()) {
            Ok(Ok((rows, counts))) => {
                // A closed channel: the writer stopped on an error; it
                // says which after the workers.
                let _ = rows_tx.send(rows);
                (Ok(()), counts)
            }
            Ok(Err(e)) => (Err(RunError::Finish(e)), Default::default()),
            Err(e) => (Err(e), Default::default()),
        }
    }

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
        run: &mut crate::process::Run<'_>,
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
            let mut rows = Rows::default();
            for (f, r) in features.iter().zip(done) {
                if job.on_error != OnError::Fail {
                    for rej in &r.rows.rejected {
                        tracing::warn!(fid = rej.src_fid, reason = %rej.reason, "feature rejected");
                    }
                }
                let kept = run.add(f, r).map_err(|e| RunError::Rejected {
                    fid: e.fid,
                    reason: e.reason,
                })?;
                rows.append(kept);
            }
            // A closed channel: the writer stopped on an error; it says
            // which after the workers.
            let more = rows_tx.send(rows).is_ok();
            progress.add(features.len() as u64);
            Ok(more)
        })
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
