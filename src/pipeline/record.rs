//! The counts of a run, and its record in the output
//! (`skeletonise_runs`), written before the file is renamed into place.

use super::{ConnectCounts, Job, RunError, RunSummary};
use crate::config::OnError;
use crate::feature::Feature;
use crate::io::writer::Writer;
use crate::io::SourceInfo;
use crate::methods::MethodId;
use crate::output::RunRecord;
use crate::process::{FeatureRows, StageTimes, Status};
use std::time::Instant;

/// Counts of a run so far.
#[derive(Debug, Default)]
pub(super) struct Counts {
    pub(super) read: u64,
    written: u64,
    rejected: u64,
    filtered: u64,
    rows: u64,
    methods: std::collections::BTreeMap<String, u64>,
    stages: Vec<(MethodId, StageTimes)>,
    connections: u64,
    lines_used: std::collections::BTreeSet<Option<u64>>,
    /// Lines of `input.connect`, when the run has a network.
    pub(super) network: Option<u64>,
    /// Units of the partitioned coverage written, when the run partitions.
    pub(super) units: Option<u64>,
    /// With a partition: the area the units held of the collapsed polygons.
    pub(super) area_held: f64,
    /// The `partition` step's CPU time: the polygons, and the coverage
    /// assembled at the end.
    pub(super) partition_time: std::time::Duration,
}

impl Counts {
    /// Counts one feature; under `on_error: fail` a rejection is the error.
    pub(super) fn add(
        &mut self,
        f: &Feature,
        r: &FeatureRows,
        on_error: OnError,
    ) -> Result<(), RunError> {
        if let (OnError::Fail, Some(rej)) = (on_error, r.rows.rejected.first()) {
            return Err(RunError::Rejected {
                fid: f.fid.map_or_else(|| "(no fid)".into(), |x| x.to_string()),
                reason: rej.reason.clone(),
            });
        }
        for rej in &r.rows.rejected {
            tracing::warn!(fid = rej.src_fid, reason = %rej.reason, "feature rejected");
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
        self.partition_time += r.partition_time;
        for (m, t) in &r.times {
            match self.stages.iter_mut().find(|(x, _)| x == m) {
                Some((_, total)) => *total += *t,
                None => self.stages.push((*m, *t)),
            }
        }
        Ok(())
    }
}

/// Records the run in the output and renames it into place.
pub(super) fn finish_run(
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
        stage_seconds: stage_json(&counts.stages, counts.units.map(|_| counts.partition_time)),
        area_held: counts.units.map(|_| counts.area_held),
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
/// `{"MA": {"skeleton": 1.2, "prune_extend": 0.3, "score": 0.4}, …}`, and
/// `"partition": 0.8` when the run partitions.
fn stage_json(stages: &[(MethodId, StageTimes)], partition: Option<std::time::Duration>) -> String {
    let mut map: serde_json::Map<String, serde_json::Value> = stages
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
    if let Some(p) = partition {
        map.insert("partition".into(), serde_json::json!(round_ms(p)));
    }
    serde_json::Value::Object(map).to_string()
}

/// Seconds, to the millisecond.
fn round_ms(d: std::time::Duration) -> f64 {
    (d.as_secs_f64() * 1000.0).round() / 1000.0
}
