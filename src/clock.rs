//! CPU time of the calling thread: what a step cost, whatever else the
//! machine was doing (a wall clock on a busy machine counts the waits).

use std::time::Duration;

/// Thread CPU time one method spent on one feature, step by step (summed over
/// polygon parts). Measurements, not results: any two compare equal, so
/// that two runs' results can be compared whatever the clock said.
#[derive(Debug, Clone, Copy, Default)]
pub struct StageTimes {
    /// The raw skeleton.
    pub skeleton: std::time::Duration,
    /// Pruning and extension (for the reference method: also the structure
    /// every other method is pruned to; for the others: conforming to it).
    pub prune_extend: std::time::Duration,
    /// Bars, hits, sides and metrics (the rays all methods share are split
    /// evenly between them).
    pub score: std::time::Duration,
}

impl PartialEq for StageTimes {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::ops::AddAssign for StageTimes {
    fn add_assign(&mut self, o: Self) {
        self.skeleton += o.skeleton;
        self.prune_extend += o.prune_extend;
        self.score += o.score;
    }
}

/// A stopwatch of the calling thread's CPU time.
#[derive(Debug, Clone, Copy)]
pub struct CpuClock(Duration);

impl CpuClock {
    /// Starts now.
    pub fn start() -> Self {
        Self(thread_cpu_time())
    }

    /// CPU time this thread spent since the start.
    pub fn elapsed(&self) -> Duration {
        thread_cpu_time().saturating_sub(self.0)
    }

    /// CPU time since the start or the last lap, and a new lap starts: one
    /// reading of the clock per stage (a reading is a system call that takes
    /// a lock; on a small polygon they add up to several per cent of a run).
    pub fn lap(&mut self) -> Duration {
        let now = thread_cpu_time();
        let lap = now.saturating_sub(self.0);
        self.0 = now;
        lap
    }
}

/// The stopwatch of a feature's stages. A feature split between threads
/// ([`Stopwatch::Cpu`]) is timed by each thread's CPU clock; a feature
/// worked on one thread ([`Stopwatch::Wall`]) by the wall clock (a vDSO
/// read, 30 times cheaper than a CPU clock reading), its stages scaled
/// afterwards by the thread's CPU time over the whole feature against its
/// wall time ([`Stopwatch::scale`]): the stages then add up to at most that
/// CPU time (the untimed steps between them take the rest), and each is
/// exact unless the thread was preempted more in one stage than in another.
#[derive(Debug, Clone, Copy)]
pub enum Stopwatch {
    /// Thread CPU time.
    Cpu(CpuClock),
    /// Wall time, to be scaled.
    Wall(std::time::Instant),
}

impl Stopwatch {
    /// Starts now: on the CPU clock when `cpu`, else on the wall clock.
    pub fn start(cpu: bool) -> Self {
        if cpu {
            Self::Cpu(CpuClock::start())
        } else {
            Self::Wall(std::time::Instant::now())
        }
    }

    /// Time since the start.
    pub fn elapsed(&self) -> Duration {
        match self {
            Self::Cpu(c) => c.elapsed(),
            Self::Wall(w) => w.elapsed(),
        }
    }

    /// Time since the start or the last lap, and a new lap starts.
    pub fn lap(&mut self) -> Duration {
        match self {
            Self::Cpu(c) => c.lap(),
            Self::Wall(w) => {
                let now = std::time::Instant::now();
                let lap = now.saturating_duration_since(*w);
                *w = now;
                lap
            }
        }
    }

    /// The factor that turns wall-clock stage times of one thread into CPU
    /// time: `cpu` (the thread's CPU time over the whole feature) over
    /// `wall` (its wall time), at most 1.
    pub fn scale(cpu: Duration, wall: Duration) -> f64 {
        if wall.is_zero() {
            return 1.0;
        }
        (cpu.as_secs_f64() / wall.as_secs_f64()).min(1.0)
    }
}

/// CPU time the calling thread has used (zero where the clock is missing).
fn thread_cpu_time() -> Duration {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec to write to.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } == 0;
    if !ok {
        return Duration::ZERO;
    }
    Duration::new(
        t.tv_sec.max(0) as u64,
        t.tv_nsec.clamp(0, 999_999_999) as u32,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_work_not_sleep() {
        let c = CpuClock::start();
        std::thread::sleep(Duration::from_millis(30));
        assert!(c.elapsed() < Duration::from_millis(20));
        let c = CpuClock::start();
        let mut x = 0u64;
        let wall = std::time::Instant::now();
        while wall.elapsed() < Duration::from_millis(30) {
            x = x.wrapping_add(std::hint::black_box(1));
        }
        assert!(x > 0 && c.elapsed() > Duration::from_millis(5));
    }

    #[test]
    fn laps_add_up_to_the_elapsed_time() {
        // Busy until this thread has used `d` of CPU time since `from`.
        let spin = |from: CpuClock, d: Duration| {
            let mut x = 0u64;
            while from.elapsed() < d {
                x = x.wrapping_add(std::hint::black_box(1));
            }
            x
        };
        let start = CpuClock::start();
        let mut lap = start;
        assert!(spin(start, Duration::from_millis(20)) > 0);
        let first = lap.lap();
        std::thread::sleep(Duration::from_millis(30));
        let idle = lap.lap();
        assert!(spin(lap, Duration::from_millis(10)) > 0);
        let third = lap.lap();
        let total = start.elapsed();
        assert!(first >= Duration::from_millis(20) && idle < Duration::from_millis(10));
        assert!(third >= Duration::from_millis(10));
        assert!(
            first + idle + third <= total
                && total - (first + idle + third) < Duration::from_millis(5)
        );
    }

    #[test]
    fn a_wall_stopwatch_counts_sleep_and_the_scale_takes_it_out() {
        let cpu = CpuClock::start();
        let mut wall = Stopwatch::start(false);
        std::thread::sleep(Duration::from_millis(30));
        let slept = wall.lap();
        let c = cpu.elapsed();
        assert!(slept >= Duration::from_millis(30) && c < Duration::from_millis(10));
        let k = Stopwatch::scale(c, slept);
        assert!(k < 0.4 && slept.mul_f64(k) < Duration::from_millis(10));
        assert_eq!(
            Stopwatch::scale(Duration::from_millis(9), Duration::from_millis(8)),
            1.0
        );
        assert_eq!(Stopwatch::scale(Duration::ZERO, Duration::ZERO), 1.0);
        assert!(matches!(Stopwatch::start(true), Stopwatch::Cpu(_)));
    }
}
