//! Progress: a bar on a terminal, otherwise a log line every so often.

use indicatif::{ProgressBar, ProgressStyle};
use std::time::Instant;

/// Progress: a bar on a terminal, otherwise a log line every
/// [`PROGRESS_EVERY`] (features done, rate, time left) so that a scheduled
/// job's log shows that a long run is alive.
pub(super) struct Progress {
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
    pub(super) fn new(terminal: bool, total: Option<u64>, every: std::time::Duration) -> Self {
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

    pub(super) fn add(&mut self, n: u64) {
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

    pub(super) fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
