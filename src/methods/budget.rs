//! A time budget per method and polygon (`skeleton.timeout_s`), so that one
//! pathological polygon cannot stall an unattended run.
//!
//! The per-feature path runs each method inside [`with_deadline`]; a method
//! with a long loop calls [`check`] in it (the straight skeleton does, on
//! its event queue) and stops with [`MethodError::TimedOut`] once the
//! deadline has passed. A method that cannot be interrupted is judged when
//! it returns: its skeleton is dropped with the same error if it took too
//! long. Either way only that method fails for that feature; the others
//! still run.

use super::{MethodError, MethodId};
use std::cell::Cell;
use std::time::{Duration, Instant};

thread_local! {
    static DEADLINE: Cell<Option<(Instant, MethodId, Duration)>> = const { Cell::new(None) };
}

/// Runs `f` (method `id`) with a deadline `budget` from now on this thread;
/// a result that came after the deadline becomes [`MethodError::TimedOut`].
pub fn with_deadline<T>(
    id: MethodId,
    budget: Option<Duration>,
    f: impl FnOnce() -> Result<T, MethodError>,
) -> Result<T, MethodError> {
    let Some(budget) = budget else {
        return f();
    };
    let start = Instant::now();
    let before = DEADLINE.with(|d| d.replace(Some((start + budget, id, budget))));
    let r = f();
    DEADLINE.with(|d| d.set(before));
    match r {
        Ok(_) if start.elapsed() > budget => Err(timed_out(id, budget)),
        other => other,
    }
}

/// Fails with [`MethodError::TimedOut`] when the current method's deadline
/// has passed (free when no deadline is set).
pub fn check() -> Result<(), MethodError> {
    match DEADLINE.with(Cell::get) {
        Some((deadline, id, budget)) if Instant::now() > deadline => Err(timed_out(id, budget)),
        _ => Ok(()),
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

    #[test]
    fn a_method_past_its_deadline_stops_with_the_reason() {
        let slow = || -> Result<(), MethodError> {
            loop {
                check()?;
            }
        };
        let e = with_deadline(MethodId::STSK, Some(Duration::from_millis(20)), slow).unwrap_err();
        assert!(e.to_string().contains("skeleton.timeout_s"), "{e}");
        // No deadline: check is free and never fails.
        assert!(check().is_ok());
        assert_eq!(with_deadline(MethodId::MA, None, || Ok(3)), Ok(3));
    }
}
