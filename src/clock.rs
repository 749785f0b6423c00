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

/// A step of a method's work on one polygon, as [`StageTimes`] counts it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The raw skeleton.
    Skeleton,
    /// Pruning and extension (and the shared structure, or conforming to it).
    Prune,
}

/// The recorder of a method's stage times on one polygon: the work is done
/// in closures it times (`stages.time(Stage::Prune, || …)`), so that what
/// is computed reads apart from how long it took.
#[derive(Debug, Clone, Copy)]
pub struct Stages {
    cpu: bool,
    times: StageTimes,
}

impl Stages {
    /// An empty record, timed on the thread's CPU clock when `cpu` (a
    /// feature split between threads), else on the wall clock (scaled for
    /// the feature afterwards: [`Stopwatch::scale`]).
    pub fn new(cpu: bool) -> Self {
        Self {
            cpu,
            times: StageTimes::default(),
        }
    }

    /// Runs `f`, adding the time it took to `stage`.
    pub fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        let watch = Stopwatch::start(self.cpu);
        let out = f();
        self.add(stage, watch.elapsed());
        out
    }

    /// Adds `d` to `stage` (time taken elsewhere for this method).
    pub fn add(&mut self, stage: Stage, d: Duration) {
        match stage {
            Stage::Skeleton => self.times.skeleton += d,
            Stage::Prune => self.times.prune_extend += d,
        }
    }

    /// Takes `d` off `stage` (time counted there that another step's is).
    pub fn remove(&mut self, stage: Stage, d: Duration) {
        match stage {
            Stage::Skeleton => self.times.skeleton = self.times.skeleton.saturating_sub(d),
            Stage::Prune => self.times.prune_extend = self.times.prune_extend.saturating_sub(d),
        }
    }

    /// What was recorded.
    pub fn times(&self) -> StageTimes {
        self.times
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
    fn the_recorder_counts_each_stage_and_not_the_time_between() {
        // Busy until this thread has used `d` of CPU time.
        let spin = |d: Duration| {
            let from = CpuClock::start();
            let mut x = 0u64;
            while from.elapsed() < d {
                x = x.wrapping_add(std::hint::black_box(1));
            }
            x
        };
        let mut stages = Stages::new(true);
        assert!(stages.time(Stage::Skeleton, || spin(Duration::from_millis(20))) > 0);
        std::thread::sleep(Duration::from_millis(30));
        assert!(stages.time(Stage::Prune, || spin(Duration::from_millis(10))) > 0);
        stages.add(Stage::Prune, Duration::from_millis(5));
        let t = stages.times();
        assert!(t.skeleton >= Duration::from_millis(20) && t.skeleton < Duration::from_millis(30));
        assert!(t.prune_extend >= Duration::from_millis(15));
        assert_eq!(t.score, Duration::ZERO);
    }

    #[test]
    fn a_wall_stopwatch_counts_sleep_and_the_scale_takes_it_out() {
        let cpu = CpuClock::start();
        let wall = Stopwatch::start(false);
        std::thread::sleep(Duration::from_millis(30));
        let slept = wall.elapsed();
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
