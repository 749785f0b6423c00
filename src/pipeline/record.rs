//! The counts of a run, and its record in the output
//! (`skeletonise_runs`), written before the file is renamed into place.

use super::{ConnectCounts, Job, RunError, RunSummary};
use crate::io::writer::Writer;
use crate::io::SourceInfo;
use crate::methods::MethodId;
use crate::output::RunRecord;
use crate::process::{RunCounts, StageTimes};
use std::time::Instant;

/// Records the run in the output and renames it into place.
pub(super) fn finish_run(
    job: &Job<'_>,
    info: &SourceInfo,
    mut counts: RunCounts,
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
        stage_seconds: stage_json(&counts.stages, &counts.step_times),
        area_held: counts.figure(crate::output::name::run::AREA_HELD),
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
/// each step after `select` that has a time of its own by its name
/// (`"partition": 0.8`, `"label": 0.2`).
fn stage_json(
    stages: &[(MethodId, StageTimes)],
    steps: &[(&'static str, std::time::Duration)],
) -> String {
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
    for (name, t) in steps {
        map.insert((*name).into(), serde_json::json!(round_ms(*t)));
    }
    serde_json::Value::Object(map).to_string()
}

/// Seconds, to the millisecond.
fn round_ms(d: std::time::Duration) -> f64 {
    (d.as_secs_f64() * 1000.0).round() / 1000.0
}
