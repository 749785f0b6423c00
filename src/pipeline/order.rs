//! The workers' batches put back in the order they were read: up to
//! [`IN_FLIGHT`] batches are computed at once, and handed on in order.

use super::RunError;
use std::sync::mpsc;

/// Computes `work` on every batch `next` yields, up to [`IN_FLIGHT`] batches
/// at once on `pool`, and gives each batch with its result to `take` in the
/// order `next` yielded them, on the calling thread. Stops at the first
/// error (from `next` or `take`) or when `take` returns false. A panic in
/// `work` is raised again on the calling thread, as `pool.install` would.
pub(super) fn in_order<T: Send, U: Send>(
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

#[cfg(test)]
mod tests {
    use super::{in_order, InOrder};
    use crate::pipeline::RunError;

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
