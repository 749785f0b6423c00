//! A run: read in batches → process features in parallel (rayon) → write in
//! input order, so the output is identical for any thread count.
//!
//! GDAL is used only on the calling thread (reader and writer); workers run
//! [`crate::process::feature_rows`] on owned data. `run` and `score` are the
//! same [`Job`]: they differ only in where the skeletons come from.

use crate::config::{InputSpec, OnError, OutputSpec, Pipeline};
use crate::feature::Feature;
use crate::io::reader::Reader;
use crate::io::writer::{check_output, Writer};
use crate::io::IoError;
use crate::output::{Rows, RunRecord};
use crate::process::{feature_rows, FeatureRows, ProcessParams, RowOptions, Skeletons, Status};
use crate::reporting::{check_path, write_report, ReportError, ReportJob, ReportSummary};
use geo::MultiLineString;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::collections::HashMap;
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
    /// The report written after the run (`output.report`).
    pub report: Option<ReportSummary>,
}

/// Why a run failed.
#[derive(Debug, Error)]
pub enum RunError {
    /// Reading or writing failed.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A feature was rejected under `on_error: fail` (exit 65).
    #[error("feature {fid} was rejected: {reason} (on_error: fail stops the run; no output was written; use `on_error: reject` to list such features in the `rejected` layer instead)")]
    Rejected {
        /// Source FID.
        fid: String,
        /// The reason.
        reason: String,
    },
    /// The thread pool could not be created.
    #[error("cannot start {0} worker threads")]
    Threads(usize),
    /// The run's output was written but its report was not.
    #[error("the report failed ({0}); the GeoPackage was written, `skeletonise report` makes the report from it")]
    Report(#[from] ReportError),
}

/// Checks everything `run` checks before processing: the input opens, the
/// layer exists, the CRS is projected (or reprojected), the filter is valid
/// and the output can be written. Returns what the source holds.
pub fn validate(p: &Pipeline) -> Result<crate::io::SourceInfo, RunError> {
    let reader = Reader::open(&p.file.input)?;
    check_output(&p.file.output)?;
    if let Some(html) = p.file.output.report_path() {
        check_path(&html)?;
    }
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
        }
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
    let report = p
        .file
        .output
        .report
        .as_ref()
        .zip(p.file.output.report_path());
    if let Some((_, html)) = &report {
        check_path(html)?;
    }
    let mut summary = run_job(&Job::of(p), opts)?;
    if let Some((spec, html)) = report {
        summary.report = Some(write_report(&ReportJob {
            gpkg: summary.output.clone().into(),
            html,
            selection: spec.features.clone(),
            polygons: None,
        })?);
    }
    Ok(summary)
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
            Status::Rejected => self.rejected += 1,
            Status::Filtered => self.filtered += 1,
            Status::Written(methods) => {
                self.written += 1;
                for m in methods {
                    *self.methods.entry(m.clone()).or_default() += 1;
                }
            }
        }
        self.rows += r.rows.skeletons.len() as u64;
        Ok(())
    }
}

fn progress_bar(show: bool, len: u64) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(len);
    b.set_style(
        ProgressStyle::with_template(
            "{spinner} {bar:40} {pos}/{len} features {elapsed_precise} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b
}

/// Runs a job: read in batches → process each batch's features in parallel
/// → write in input order.
pub fn run_job(job: &Job<'_>, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let started = chrono::Utc::now();
    let clock = Instant::now();
    let mut reader = Reader::open(job.input)?;
    let info = reader.info().clone();
    let mut writer = Writer::create(job.output, &info)?;
    let threads = opts.threads.unwrap_or_else(rayon::current_num_threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| RunError::Threads(threads))?;
    tracing::info!(
        pipeline = %job.name,
        source = %info.source,
        layer = %info.layer,
        crs = %info.crs_name,
        features = info.selected,
        filtered_by_source = info.total.saturating_sub(info.selected),
        threads,
        "run started"
    );
    let bar = progress_bar(opts.progress, info.selected);
    let row_opts = RowOptions::from(job.output);
    let mut counts = Counts::default();
    let batch = opts.batch_size.unwrap_or(256).max(1);
    let result = reader.read::<RunError>(batch, job.params.prepare.make_valid, |features| {
        let done: Vec<FeatureRows> = pool.install(|| {
            features
                .par_iter()
                .map(|f| feature_rows(f, job.skeletons(f), &job.params, row_opts))
                .collect()
        });
        counts.read += features.len() as u64;
        let mut rows = Rows::default();
        for (f, r) in features.iter().zip(done) {
            counts.add(f, &r, job.on_error)?;
            rows.append(r.rows);
        }
        writer.write_batch(&rows)?;
        bar.inc(features.len() as u64);
        Ok(())
    });
    bar.finish_and_clear();
    if let Err(e) = result {
        writer.abort();
        return Err(e);
    }
    counts.filtered += info.total.saturating_sub(info.selected);
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
        report: None,
    })
}
