//! A budget per method and polygon — time (`skeleton.timeout_s`) and memory
//! (`skeleton.max_memory_mb`) — so that one pathological polygon cannot
//! stall an unattended run or exhaust the machine.
//!
//! The per-feature path runs each method inside [`with_budget`]. A method
//! with a long loop calls [`check`] in it (the straight skeleton does, on
//! its event queue) and stops with [`MethodError::TimedOut`] once the
//! deadline has passed. A method that cannot be interrupted is judged when
//! it returns: its skeleton is dropped with the same error if it took too
//! long. A method whose cost grows faster than its input (the straight
//! skeleton) predicts its cost first and declines a polygon it cannot finish
//! within the budget ([`MethodError::OverBudget`]), and keeps its memory
//! under [`memory_limit`]. Either way only that method fails for that
//! feature; the others still run.

use super::{MethodError, MethodId};
use std::cell::Cell;
use std::time::{Duration, Instant};

/// What one method may spend on one polygon part.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Budget {
    /// Wall time (`None`: no limit).
    pub time: Option<Duration>,
    /// Bytes of the method's own working memory (`None`: no limit).
    pub memory: Option<u64>,
}

#[derive(Clone, Copy)]
struct Current {
    id: MethodId,
    deadline: Option<Instant>,
    budget: Budget,
}

thread_local! {
    static CURRENT: Cell<Option<Current>> = const { Cell::new(None) };
}

/// Runs `f` (method `id`) under `budget` on this thread; a result that came
/// after the deadline becomes [`MethodError::TimedOut`].
pub fn with_budget<T>(
    id: MethodId,
    budget: Budget,
    f: impl FnOnce() -> Result<T, MethodError>,
) -> Result<T, MethodError> {
    let start = Instant::now();
    let current = Current {
        id,
        deadline: budget.time.map(|t| start + t),
        budget,
    };
    let before = CURRENT.with(|c| c.replace(Some(current)));
    let r = f();
    CURRENT.with(|c| c.set(before));
    match (r, budget.time) {
        (Ok(_), Some(t)) if start.elapsed() > t => Err(timed_out(id, t)),
        (other, _) => other,
    }
}

/// Fails with [`MethodError::TimedOut`] when the current method's deadline
/// has passed (free when no deadline is set).
pub fn check() -> Result<(), MethodError> {
    match CURRENT.with(Cell::get) {
        Some(Current {
            id,
            deadline: Some(d),
            budget,
        }) if Instant::now() > d => Err(timed_out(id, budget.time.unwrap_or_default())),
        _ => Ok(()),
    }
}

/// Time left before the current method's deadline (`None`: no deadline).
pub fn remaining() -> Option<Duration> {
    CURRENT
        .with(Cell::get)
        .and_then(|c| c.deadline)
        .map(|d| d.saturating_duration_since(Instant::now()))
}

/// The current method's memory budget in bytes (`None`: no limit).
pub fn memory_limit() -> Option<u64> {
    CURRENT.with(Cell::get).and_then(|c| c.budget.memory)
}

/// Declines the current polygon when `seconds` (predicted) exceeds the time
/// left or `bytes` (predicted) the memory budget: the reason names the
/// prediction and the option to raise.
pub fn afford(id: MethodId, seconds: f64, bytes: f64) -> Result<(), MethodError> {
    if let Some(left) = remaining() {
        if seconds > left.as_secs_f64() {
            return Err(MethodError::OverBudget {
                method: id,
                reason: format!(
                    "would need about {} s on this polygon, more than the {} s left of `skeleton.timeout_s`",
                    seconds_text(seconds),
                    seconds_text(left.as_secs_f64())
                ),
            });
        }
    }
    if let Some(max) = memory_limit() {
        if bytes > max as f64 {
            return Err(MethodError::OverBudget {
                method: id,
                reason: format!(
                    "would need about {:.0} MB on this polygon, more than `skeleton.max_memory_mb` = {:.0}",
                    bytes / 1e6,
                    max as f64 / 1e6
                ),
            });
        }
    }
    Ok(())
}

/// Whole seconds from 10 s, tenths from 1 s, milliseconds below.
fn seconds_text(s: f64) -> String {
    if s >= 10.0 {
        format!("{s:.0}")
    } else if s >= 1.0 {
        format!("{s:.1}")
    } else {
        format!("{s:.3}")
    }
}

fn timed_out(method: MethodId, budget: Duration) -> MethodError {
    MethodError::TimedOut {
        method,
        seconds: budget.as_secs_f64(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seconds(s: u64) -> Budget {
        Budget {
            time: Some(Duration::from_secs(s)),
            memory: None,
        }
    }

    #[test]
    fn a_method_past_its_deadline_stops_with_the_reason() {
        let slow = || -> Result<(), MethodError> {
            loop {
                check()?;
            }
        };
        let b = Budget {
            time: Some(Duration::from_millis(20)),
            memory: None,
        };
        let e = with_budget(MethodId::STSK, b, slow).unwrap_err();
        assert!(e.to_string().contains("skeleton.timeout_s"), "{e}");
        // No budget: check is free and never fails.
        assert!(check().is_ok());
        assert_eq!(
            with_budget(MethodId::MA, Budget::default(), || Ok(3)),
            Ok(3)
        );
    }

    #[test]
    fn a_predicted_cost_over_the_budget_is_declined_with_the_reason() {
        let r = with_budget(MethodId::STSK, seconds(60), || {
            afford(MethodId::STSK, 5.0, 1e12)?;
            afford(MethodId::STSK, 600.0, 0.0)
        });
        let e = r.unwrap_err().to_string();
        assert!(
            e.contains("about 600 s") && e.contains("skeleton.timeout_s"),
            "{e}"
        );
        let mem = Budget {
            time: None,
            memory: Some(1_000_000),
        };
        let e = with_budget(MethodId::STSK, mem, || afford(MethodId::STSK, 1e9, 5e6))
            .unwrap_err()
            .to_string();
        assert!(e.contains("5 MB") && e.contains("max_memory_mb"), "{e}");
        // Outside any budget everything is affordable.
        assert!(afford(MethodId::STSK, 1e9, 1e18).is_ok());
    }
}
