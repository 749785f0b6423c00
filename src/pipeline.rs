//! A run: read in batches → process features in parallel (rayon) → write in
//! input order, so the output is identical for any thread count.
//!
//! GDAL is used only on the calling thread (reader and writer); workers run
//! [`crate::process::process`] on owned data.

use crate::config::{OnError, Pipeline};
use crate::io::reader::{InputFeature, Reader};
use crate::io::writer::{
    check_output, BarRow, CandidateRow, RejectedRow, RunRecord, ScoreColumns, SkeletonRow,
    WidthRow, Writer,
};
use crate::io::IoError;
use crate::process::{process, ProcessParams, Processed};
use crate::score::Scores;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
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
}

/// Checks everything `run` checks before processing: the input opens, the
/// layer exists, the CRS is projected (or reprojected), the filter is valid
/// and the output can be written. Returns what the source holds.
pub fn validate(p: &Pipeline) -> Result<crate::io::SourceInfo, RunError> {
    let reader = Reader::open(&p.file.input)?;
    check_output(&p.file.output)?;
    Ok(reader.info().clone())
}

/// The score columns of an output row.
pub fn columns(s: &Scores) -> ScoreColumns {
    ScoreColumns {
        bars: s.bars as i64,
        hits: s.hits as i64,
        coverage: s.coverage,
        deviation: s.deviation,
        deviation_parts: s.deviation_parts,
        distortion_sum: s.distortion_sum,
        distortion: s.distortion,
    }
}

/// Rows produced for one input feature.
#[derive(Default)]
struct Rows {
    skeletons: Vec<SkeletonRow>,
    candidates: Vec<CandidateRow>,
    bars: Vec<BarRow>,
    widths: Vec<WidthRow>,
    rejected: Vec<RejectedRow>,
    filtered: bool,
}

fn feature_rows(f: &InputFeature, params: &ProcessParams, p: &Pipeline) -> Rows {
    let mut rows = Rows::default();
    if let Some(e) = &f.geometry_error {
        rows.rejected.push(RejectedRow {
            src_fid: f.fid,
            reason: e.clone(),
            wkb: f.source_wkb.clone(),
        });
        return rows;
    }
    // With `explode`, every polygon part is its own unit of work and row.
    let units: Vec<(Option<usize>, Option<geo::Geometry<f64>>)> =
        match (&f.geometry, p.file.output.explode) {
            (Some(geo::Geometry::MultiPolygon(mp)), true) if !mp.0.is_empty() => {
                mp.0.iter()
                    .enumerate()
                    .map(|(i, poly)| (Some(i), Some(geo::Geometry::Polygon(poly.clone()))))
                    .collect()
            }
            (g, true) => vec![(Some(0), g.clone())],
            (g, false) => vec![(None, g.clone())],
        };
    let mut any_written = false;
    for (part, geom) in units {
        match process(geom.as_ref(), params) {
            Processed::Done(o) => {
                let (method, chosen) = o.chosen();
                rows.skeletons.push(SkeletonRow {
                    src_fid: f.fid,
                    part,
                    attributes: f.attributes.clone(),
                    geometry: chosen.geometry.clone(),
                    method: method.to_string(),
                    scores: chosen.scores.as_ref().map(columns),
                    components: chosen.components as i64,
                    legs: chosen.legs as i64,
                    repaired: f.repaired,
                });
                any_written = true;
                rows.widths.extend(chosen.widths.iter().map(|w| WidthRow {
                    src_fid: f.fid,
                    method: method.to_string(),
                    geometry: w.line,
                    width_start: w.width_start(),
                    width_end: w.width_end(),
                }));
                for (i, c) in o.candidates.iter().enumerate() {
                    if p.file.output.candidates {
                        rows.candidates.push(CandidateRow {
                            src_fid: f.fid,
                            part,
                            method: c.method.to_string(),
                            geometry: c.result.as_ref().ok().map(|s| s.geometry.clone()),
                            scores: c
                                .result
                                .as_ref()
                                .ok()
                                .and_then(|s| s.scores.as_ref())
                                .map(columns),
                            chosen: i == o.chosen,
                            components: c.result.as_ref().map(|s| s.components as i64).unwrap_or(0),
                            legs_raw: c.result.as_ref().map(|s| s.legs_raw as i64).unwrap_or(0),
                            legs: c.result.as_ref().map(|s| s.legs as i64).unwrap_or(0),
                            error: c.result.as_ref().err().cloned(),
                        });
                    }
                    if p.file.output.bars {
                        if let Ok(s) = &c.result {
                            for b in &s.bars {
                                let end = b.hit.map(|h| h.point).unwrap_or(b.origin);
                                rows.bars.push(BarRow {
                                    src_fid: f.fid,
                                    method: c.method.to_string(),
                                    geometry: geo::LineString(vec![b.origin, end]),
                                    d_left: b.hit.map(|h| h.d_left),
                                    d_right: b.hit.map(|h| h.d_right),
                                    delta_d: b.hit.map(|h| h.delta_d()),
                                    z: b.hit.map(|h| h.z()),
                                    part: b.hit.map(|h| h.part as i64),
                                });
                            }
                        }
                    }
                }
            }
            Processed::Filtered => {}
            Processed::Rejected(reason) => {
                let reason = match part {
                    Some(i) if p.file.output.explode => format!("part {i}: {reason}"),
                    _ => reason,
                };
                rows.rejected.push(RejectedRow {
                    src_fid: f.fid,
                    reason,
                    wkb: f.source_wkb.clone(),
                });
            }
        }
    }
    rows.filtered = !any_written && rows.rejected.is_empty();
    rows
}

/// Runs the pipeline end to end.
pub fn run(p: &Pipeline, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let started = chrono::Utc::now();
    let clock = Instant::now();
    let mut reader = Reader::open(&p.file.input)?;
    let info = reader.info().clone();
    let mut writer = Writer::create(&p.file.output, &info)?;
    let threads = opts.threads.unwrap_or_else(rayon::current_num_threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| RunError::Threads(threads))?;
    let params = p.process_params();
    tracing::info!(
        pipeline = p.file.name.as_deref().unwrap_or(&p.origin),
        source = %info.source,
        layer = %info.layer,
        crs = %info.crs_name,
        features = info.selected,
        filtered_by_source = info.total.saturating_sub(info.selected),
        threads,
        "run started"
    );
    let bar = if opts.progress {
        let b = ProgressBar::new(info.selected);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} {bar:40} {pos}/{len} features {elapsed_precise} (eta {eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let (mut read, mut written, mut rejected, mut filtered, mut rows_written) =
        (0u64, 0u64, 0u64, 0u64, 0u64);
    let mut methods: std::collections::BTreeMap<String, u64> = Default::default();
    let batch = opts.batch_size.unwrap_or(256).max(1);
    let result = reader.read::<RunError>(batch, params.prepare.make_valid, |features| {
        let rows: Vec<Rows> = pool.install(|| {
            features
                .par_iter()
                .map(|f| feature_rows(f, &params, p))
                .collect()
        });
        read += features.len() as u64;
        let mut sk = Vec::new();
        let mut ca = Vec::new();
        let mut ba = Vec::new();
        let mut rj = Vec::new();
        let mut wi = Vec::new();
        for (f, r) in features.iter().zip(rows) {
            if p.file.on_error == OnError::Fail {
                if let Some(rej) = r.rejected.first() {
                    return Err(RunError::Rejected {
                        fid: f
                            .fid
                            .map(|x| x.to_string())
                            .unwrap_or_else(|| "(no fid)".into()),
                        reason: rej.reason.clone(),
                    });
                }
            }
            for rej in &r.rejected {
                tracing::warn!(fid = f.fid, reason = %rej.reason, "feature rejected");
            }
            // Each feature counts once: rejected if any part was rejected,
            // else written if it has a row, else filtered (min_area).
            if !r.rejected.is_empty() {
                rejected += 1;
            } else if r.filtered {
                filtered += 1;
            } else {
                written += 1;
            }
            rows_written += r.skeletons.len() as u64;
            for s in &r.skeletons {
                *methods.entry(s.method.clone()).or_default() += 1;
            }
            sk.extend(r.skeletons);
            ca.extend(r.candidates);
            ba.extend(r.bars);
            rj.extend(r.rejected);
            wi.extend(r.widths);
        }
        writer.write_batch(&sk, &ca, &ba, &wi, &rj)?;
        bar.inc(features.len() as u64);
        Ok(())
    });
    bar.finish_and_clear();
    if let Err(e) = result {
        writer.abort();
        return Err(e);
    }
    filtered += info.total.saturating_sub(info.selected);
    let elapsed_s = clock.elapsed().as_secs_f64();
    let record = RunRecord {
        name: p.file.name.clone().unwrap_or_default(),
        started_utc: started.to_rfc3339(),
        finished_utc: chrono::Utc::now().to_rfc3339(),
        tool_version: env!("CARGO_PKG_VERSION").to_string(),
        pipeline: p.provenance_text(),
        input: format!("{} (layer {})", info.source, info.layer),
        read,
        written,
        rejected,
        filtered,
        elapsed_s,
        threads: threads as i64,
    };
    let out = writer.finish(&record)?;
    Ok(RunSummary {
        read,
        written,
        rows: rows_written,
        rejected,
        filtered,
        elapsed_s,
        output: out.display().to_string(),
        methods: methods.into_iter().collect(),
    })
}
