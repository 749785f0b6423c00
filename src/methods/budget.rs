//! A budget per method and polygon — time (`skeleton.timeout_s`) and memory
//! (`skeleton.max_memory_mb`) — so that one pathological polygon cannot
//! stall an unattended run or exhaust the machine.
//!
//! The per-feature path runs each method inside [`with_budget`], which
//! starts the method's clock and hands it a [`MethodContext`]: the budget
//! travels as an argument of [`super::SkeletonMethod::skeletonise`], not in
//! global or thread-local state. A method with a long loop calls
//! [`MethodContext::check`] in it (the straight skeleton does, on its event
//! queue) and stops with [`MethodError::TimedOut`] once the deadline has
//! passed. A method that cannot be interrupted is judged when it returns:
//! its skeleton is dropped with the same error if it took too long. A method
//! whose cost grows faster than its input (the straight skeleton) predicts
//! its cost first and declines a polygon it cannot finish within the budget
//! ([`MethodContext::afford`], [`MethodError::OverBudget`]), and keeps its
//! memory under [`MethodContext::memory_limit`]. Either way only that method
//! fails for that feature; the others still run.

use super::{MethodError, MethodId};
use std::time::{Duration, Instant};

/// What one method may spend on one polygon part.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Budget {
    /// Wall time (`None`: no limit).
    pub time: Option<Duration>,
    /// Bytes of the method's own working memory (`None`: no limit).
    pub memory: Option<u64>,
}

/// The context of one method's run on one polygon part: its budget, with
/// the clock started. [`MethodContext::default`] has no limits (every check
/// passes), for a method called outside the per-feature path.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MethodContext {
    budget: Budget,
    deadline: Option<Instant>,
}

impl MethodContext {
    /// `budget`, its clock starting now.
    pub fn start(budget: Budget) -> Self {
        Self {
            budget,
            deadline: budget.time.map(|t| Instant::now() + t),
        }
    }

    /// The budget.
    pub fn budget(&self) -> Budget {
        self.budget
    }

    /// Fails with [`MethodError::TimedOut`] (for `method`) when the deadline
    /// has passed (free when no deadline is set).
    pub fn check(&self, method: MethodId) -> Result<(), MethodError> {
        match self.deadline {
            Some(d) if Instant::now() > d => {
                Err(timed_out(method, self.budget.time.unwrap_or_default()))
            }
            _ => Ok(()),
        }
    }

    /// True once the deadline has passed (never without one).
    pub fn expired(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() > d)
    }

    /// Time left before the deadline (`None`: no deadline).
    pub fn remaining(&self) -> Option<Duration> {
        self.deadline
            .map(|d| d.saturating_duration_since(Instant::now()))
    }

    /// The memory budget in bytes (`None`: no limit).
    pub fn memory_limit(&self) -> Option<u64> {
        self.budget.memory
    }

    /// Declines the polygon (for `method`) when `seconds` (predicted)
    /// exceeds the time left or `bytes` (predicted) the memory budget: the
    /// reason names the prediction and the option to raise.
    pub fn afford(&self, method: MethodId, seconds: f64, bytes: f64) -> Result<(), MethodError> {
        if let Some(left) = self.remaining() {
            if seconds > left.as_secs_f64() {
                return Err(MethodError::OverBudget {
                    method,
                    reason: format!(
                        "would need about {} s on this polygon, more than the {} s left of `skeleton.timeout_s`",
                        seconds_text(seconds),
                        seconds_text(left.as_secs_f64())
                    ),
                });
            }
        }
        if let Some(max) = self.memory_limit() {
            if bytes > max as f64 {
                return Err(MethodError::OverBudget {
                    method,
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
}

/// Runs `f` (method `id`) with a [`MethodContext`] of `budget` started now;
/// a result that came after the deadline becomes [`MethodError::TimedOut`].
pub fn with_budget<T>(
    id: MethodId,
    budget: Budget,
    f: impl FnOnce(&MethodContext) -> Result<T, MethodError>,
) -> Result<T, MethodError> {
    within(id, &MethodContext::start(budget), f)
}

/// Runs `f` (method `id`) in `ctx`, whose clock may have started before (a
/// method's budget covers its pruning, extension and scores too); a result
/// that came after the deadline becomes [`MethodError::TimedOut`].
pub fn within<T>(
    id: MethodId,
    ctx: &MethodContext,
    f: impl FnOnce(&MethodContext) -> Result<T, MethodError>,
) -> Result<T, MethodError> {
    match f(ctx) {
        Ok(_) if ctx.deadline.is_some_and(|d| Instant::now() > d) => {
            Err(timed_out(id, ctx.budget.time.unwrap_or_default()))
        }
        other => other,
    }
}

impl MethodContext {
    /// After (or before) a later stage of the method's work on the polygon
    /// — `stage` says which, e.g. "pruning and extending" — fails with
    /// [`MethodError::StageTimedOut`] once the deadline has passed: the
    /// budget is the method's whole work on the polygon, not its raw
    /// skeleton alone.
    pub fn check_stage(&self, method: MethodId, stage: &'static str) -> Result<(), MethodError> {
        match self.deadline {
            Some(d) if Instant::now() > d => Err(MethodError::StageTimedOut {
                method,
                seconds: self.budget.time.unwrap_or_default().as_secs_f64(),
                stage,
            }),
            _ => Ok(()),
        }
    }

    /// Declines a later stage (`stage`, e.g. "scoring") of the method's work
    /// that would need about `bytes` of working memory, more than
    /// `skeleton.max_memory_mb` ([`MethodError::OverBudget`]).
    pub fn afford_stage(
        &self,
        method: MethodId,
        stage: &'static str,
        bytes: f64,
    ) -> Result<(), MethodError> {
        match self.memory_limit() {
            Some(max) if bytes > max as f64 => Err(MethodError::OverBudget {
                method,
                reason: format!(
                    "would need about {:.0} MB for {stage} this polygon, more than `skeleton.max_memory_mb` = {:.0}",
                    bytes / 1e6,
                    max as f64 / 1e6
                ),
            }),
            _ => Ok(()),
        }
    }
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
        let slow = |ctx: &MethodContext| -> Result<(), MethodError> {
            loop {
                ctx.check(MethodId::STSK)?;
            }
        };
        let b = Budget {
            time: Some(Duration::from_millis(20)),
            memory: None,
        };
        let e = with_budget(MethodId::STSK, b, slow).unwrap_err();
        assert!(e.to_string().contains("skeleton.timeout_s"), "{e}");
        // No budget: check is free and never fails.
        assert!(MethodContext::default().check(MethodId::STSK).is_ok());
        assert_eq!(
            with_budget(MethodId::MA, Budget::default(), |_| Ok(3)),
            Ok(3)
        );
        // A method that cannot be interrupted is judged when it returns.
        let late = with_budget(MethodId::CDT, b, |_| {
            std::thread::sleep(Duration::from_millis(30));
            Ok(())
        });
        assert!(
            matches!(late, Err(MethodError::TimedOut { method, .. }) if method == MethodId::CDT)
        );
    }

    #[test]
    fn a_predicted_cost_over_the_budget_is_declined_with_the_reason() {
        let r = with_budget(MethodId::STSK, seconds(60), |ctx| {
            ctx.afford(MethodId::STSK, 5.0, 1e12)?;
            ctx.afford(MethodId::STSK, 600.0, 0.0)
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
        let e = with_budget(MethodId::STSK, mem, |ctx| {
            ctx.afford(MethodId::STSK, 1e9, 5e6)
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("5 MB") && e.contains("max_memory_mb"), "{e}");
        // Without a budget everything is affordable.
        assert!(MethodContext::default()
            .afford(MethodId::STSK, 1e9, 1e18)
            .is_ok());
        assert_eq!(MethodContext::start(mem).memory_limit(), Some(1_000_000));
    }

    #[test]
    fn later_stages_are_judged_against_the_same_deadline() {
        let ctx = MethodContext::start(Budget {
            time: Some(Duration::from_millis(5)),
            memory: Some(1_000_000),
        });
        assert!(ctx.check_stage(MethodId::MA, "scoring").is_ok());
        let e = ctx
            .afford_stage(MethodId::MA, "scoring", 3e6)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("about 3 MB for scoring this polygon") && e.contains("max_memory_mb"),
            "{e}"
        );
        assert!(ctx.afford_stage(MethodId::MA, "scoring", 5e5).is_ok());
        std::thread::sleep(Duration::from_millis(10));
        let e = ctx
            .check_stage(MethodId::MA, "pruning and extending")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("while pruning and extending") && e.contains("skeleton.timeout_s"),
            "{e}"
        );
        // No limits: every stage passes.
        let free = MethodContext::default();
        assert!(free.check_stage(MethodId::MA, "scoring").is_ok());
        assert!(free.afford_stage(MethodId::MA, "scoring", 1e15).is_ok());
    }
}
