//! Keeps the rayon pool's threads awake through a run of steps. A step is a few parallel
//! loops (the pair pass, the gather, the kick-and-drift) with short serial work between them;
//! a rayon worker that finds no work spins briefly and then sleeps, and waking it again costs
//! tens of microseconds on a virtual machine, which at 10^4 grains is a sizeable part of a
//! step (three such waits per step of about 0.6 ms on two threads; measured below). Here each
//! other worker runs a job that steals and runs the pool's pending work ([`rayon::yield_now`]),
//! spinning while there is none, so that it takes its share of each parallel loop at once,
//! until the run is over or it has found no work for [`HELPER_IDLE`] (then it sleeps, and the
//! next step sends it again). Which thread runs which task never changes a result (each task
//! writes its own outputs and reductions combine fixed chunks in order), so the bits are the
//! same with and without it.
//!
//! Measured (a rayon probe on the 2-core KVM guest, Intel Xeon): a join of two 100 us tasks
//! took a median 107 us straight after another, 132 us after 20 us of serial work and 165 us
//! after 100 us.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Runs `f` with the current pool's other threads kept awake (see the module's note) until it
/// returns; `f` calls [`Warm::rearm`] where a helper that went to sleep should wake again (at
/// the start of each step). With one thread, only `f`.
pub fn with_warm_pool<R: Send>(f: impl FnOnce(&Warm) -> R + Send) -> R {
    let helpers = rayon::current_num_threads().saturating_sub(1);
    let state = &WarmState { stop: AtomicBool::new(false), awake: AtomicUsize::new(0) };
    if helpers == 0 {
        return f(&Warm { send: None, helpers });
    }
    rayon::scope(|s| {
        let leader = rayon::current_thread_index();
        let send = move || s.spawn(move |_| keep_warm(state, leader));
        let warm = Warm { send: Some((&send, state)), helpers };
        warm.rearm();
        // Set on the way out, however `f` leaves (a panic included), so the scope ends.
        let _stop = StopOnDrop(&state.stop);
        f(&warm)
    })
}

/// The helpers of a warm run ([`with_warm_pool`]).
pub struct Warm<'a> {
    /// Sends one more helper, and what the helpers share; none with one thread.
    send: Option<(&'a (dyn Fn() + Sync), &'a WarmState)>,
    /// Helpers wanted awake: the pool's other threads.
    helpers: usize,
}

/// What the helpers of a warm run share.
struct WarmState {
    /// Set when the run is over.
    stop: AtomicBool,
    /// Helpers sent and not yet left.
    awake: AtomicUsize,
}

impl Warm<'_> {
    /// Sends helpers again in place of those that left, idle for [`HELPER_IDLE`] (on a busy
    /// machine: see [`keep_warm`]).
    pub fn rearm(&self) {
        let Some((send, state)) = self.send else { return };
        while state.awake.load(Ordering::Acquire) < self.helpers {
            state.awake.fetch_add(1, Ordering::AcqRel);
            send();
        }
    }
}

/// A helper's job: runs the pool's pending work until the run is over, or until it has found
/// none for [`HELPER_IDLE`]. It leaves then, and rayon lets its thread sleep: on a machine
/// where another program wants the cores, a helper that spun on would keep its core from the
/// thread it waits for (the one running the step's serial work, or a task it has not
/// finished), which the kernel moves onto a core that falls idle. On the thread running the
/// scope's body (`leader`, which may pick the job up itself while it waits on a parallel
/// loop) it returns at once: spinning there would never let the body reach `stop`.
fn keep_warm(state: &WarmState, leader: Option<usize>) {
    if rayon::current_thread_index() != leader {
        run_pending_until(|| state.stop.load(Ordering::Acquire), HELPER_IDLE);
    }
    state.awake.fetch_sub(1, Ordering::AcqRel);
}

/// How long a helper spins without finding work before it leaves: far above the serial gaps
/// between a step's parallel loops on a quiet machine (a few microseconds; the serial parts of
/// a rebuild at 10^4 grains, a few hundred), below the kernel's time slice (milliseconds).
const HELPER_IDLE: Duration = Duration::from_millis(1);

/// Where the tasks of one parallel loop end together. The thread that calls the loop runs
/// tasks and, finishing before the others, waits in the loop's join, where rayon lets it
/// sleep; waking it when the last task ended cost 20 us on the 2-core KVM guest (the pair pass
/// at 10^4 grains, f64, two threads: 494 us from the loop's start to its return, the caller's
/// task done after 457 us, the helper's after 471). Each task that ends here waits for the
/// others, running the pool's pending work meanwhile (the loop's other tasks among it), until
/// it has found none for [`TOGETHER_IDLE`], so the caller is awake when the last ends (the
/// pair pass then 471 us; the bench, interleaved runs, f64, two threads: 10^4 grains 1.611e7
/// -> 1.647e7 particle-steps/s, means of five; 10^6 1.20e7 -> 1.25e7).
pub struct Together {
    done: AtomicUsize,
    tasks: usize,
}

impl Together {
    /// For a loop of `tasks` tasks.
    pub fn new(tasks: usize) -> Self {
        Together { done: AtomicUsize::new(0), tasks }
    }

    /// The end of one task: waits for the others (see [`Together`]).
    pub fn finish(&self) {
        self.done.fetch_add(1, Ordering::AcqRel);
        run_pending_until(|| self.done.load(Ordering::Acquire) >= self.tasks, TOGETHER_IDLE);
    }
}

/// How long [`Together::finish`] spins without finding work: a few wake-ups' worth.
const TOGETHER_IDLE: Duration = Duration::from_micros(100);

/// Runs the pool's pending work ([`rayon::yield_now`]), spinning while there is none, until
/// `over()` or until none has been found for `idle`.
fn run_pending_until(over: impl Fn() -> bool, idle: Duration) {
    let mut last_work = Instant::now();
    while !over() {
        if rayon::yield_now() == Some(rayon::Yield::Executed) {
            last_work = Instant::now();
        } else if last_work.elapsed() >= idle {
            return;
        } else {
            std::hint::spin_loop();
        }
    }
}

/// Sets its flag when dropped.
struct StopOnDrop<'a>(&'a AtomicBool);

impl Drop for StopOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Parallel loops inside the warm run give the serial loop's results, on pools of one to
    /// four threads, and the run returns (every helper leaves).
    #[test]
    fn loops_inside_a_warm_run_give_the_same_sums() {
        let v: Vec<f64> = (0..100_000).map(|i| (i as f64).sqrt()).collect();
        let serial: Vec<f64> = v.chunks(1000).map(|c| c.iter().sum()).collect();
        for threads in 1..=4 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let runs: Vec<Vec<f64>> = pool.install(|| with_warm_pool(|_| (0..50).map(|_| v.par_chunks(1000).map(|c| c.iter().sum()).collect()).collect()));
            assert!(runs.iter().all(|r| *r == serial), "{threads} threads");
        }
    }

    /// Tasks that end together ([`Together`]), more of them than threads, in a warm run and
    /// outside one: every loop returns, with the serial loop's results and every task counted.
    #[test]
    fn tasks_that_end_together_give_the_same_sums() {
        let v: Vec<f64> = (0..100_000).map(|i| (i as f64).sqrt()).collect();
        let serial: Vec<f64> = v.chunks(10_000).map(|c| c.iter().sum()).collect();
        let sums = || {
            let together = Together::new(serial.len());
            let r: Vec<f64> = v
                .par_chunks(10_000)
                .map(|c| {
                    let s = c.iter().sum();
                    together.finish();
                    s
                })
                .collect();
            (r, together.done.load(Ordering::Acquire))
        };
        for threads in 1..=4 {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let runs: Vec<(Vec<f64>, usize)> = pool.install(|| (0..10).map(|_| sums()).chain(with_warm_pool(|_| (0..10).map(|_| sums()).collect::<Vec<_>>())).collect());
            assert!(runs.iter().all(|(r, done)| *r == serial && *done == serial.len()), "{threads} threads");
        }
    }
}
