//! Whether a run's steps go on the whole thread pool or on the calling thread alone, chosen by
//! timing both. On a quiet machine the pool is faster (1.9x on two threads, the bench bed).
//! Beside another program that keeps a core busy, it can be slower than one thread: each of
//! a step's parallel loops waits for all of its tasks, and a task the kernel has parked with
//! its thread (for a time slice, milliseconds, against a step of a millisecond) holds every
//! other thread at the loop's end; one thread on the core the other program leaves it loses
//! nothing. Which threads run a step never changes a result (see `cpu::split`), so the
//! choice is free to follow the machine.
//!
//! The choice is remade by trying both: [`PROBE`] of steps on each (after [`SETTLE`]), then
//! the pool if it was [`FASTER`], else the caller, for [`HOLD`] times as long, or until the
//! pool's steps slow by [`SLOWED`] against its probe (a program started beside the run).
//! Steps that rebuild the neighbour list are not timed: they cost several ordinary steps and
//! come at no fixed interval. Contact dynamics times its solves alone (the rest of its step runs
//! on one thread either way), per contact sweep ([`Crew::step_ends_with`]).
//!
//! Measured (the bench bed, 10^4 grains, f64, the 2-core Intel KVM guest, beside `sh -c
//! 'while :; do :; done'`): the pool's probes gave 1.3-2.3 ms a step, the caller's 1.24 ms
//! where the kernel left it a core and 1.8-2.0 ms in the first milliseconds after the pool's
//! probe (hence [`SETTLE`]). The bench (`--busy 0,1`), interleaved rounds: two threads beside
//! the busy loop 4.9e6 and 5.6e6 particle-steps/s without the choice, 7.8e6 and 7.8e6 with it,
//! one thread 7.8e6-7.9e6; quiet, the pool won every probe (0.72-0.81 ms a step against the
//! caller's 1.23-1.47).

use std::time::{Duration, Instant};

/// The least wall time of a probe of one way of running (and at least [`PROBE_STEPS`] timed
/// steps): several of the kernel's time slices, so that it sees how the kernel shares the
/// cores.
const PROBE: Duration = Duration::from_millis(20);

/// The least timed steps of a probe.
const PROBE_STEPS: u32 = 3;

/// How much longer than its two probes together the faster way then runs before the next
/// probe: the probe of the slower way costs at most about 1/HOLD of the run (on two quiet
/// threads the calling thread alone runs at half the pool's speed, and its probe costs 0.7%).
/// Each probe in a row that the pool wins doubles the hold, up to [`MAX_STRETCH`] times (a
/// slowing pool is probed again at once all the same: [`SLOWED`]).
const HOLD: u32 = 50;

/// The most a hold on the pool is stretched.
const MAX_STRETCH: u32 = 16;

/// How long after the steps change hands they are not timed: the kernel's balancing of the
/// threads over the cores (every few milliseconds) and the helpers' falling asleep.
const SETTLE: Duration = Duration::from_millis(10);

/// How much faster per step the pool must be to run the steps: beside a busy program the two
/// come out within a few percent of each other in turn, and the caller alone leaves the other
/// cores to it.
const FASTER: f64 = 1.1;

/// A hold on the pool ends early when a window of [`PROBE`] runs this much slower per step
/// than the pool's probe.
const SLOWED: f64 = 1.3;

/// Who runs a step's parallel loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Who {
    /// Every thread of the pool.
    Pool,
    /// The thread that calls the step, alone.
    Caller,
}

/// The choice between [`Who::Pool`] and [`Who::Caller`] and what it rests on.
#[derive(Clone, Debug)]
pub struct Crew {
    /// Who runs the steps now.
    who: Who,
    /// What the current steps are for.
    stage: Stage,
    /// Timed steps and their wall time in the current window.
    window: Window,
    /// Seconds per unit of work of the last probe of each way (`[pool, caller]`).
    probed: [f64; 2],
    /// Wall seconds of the last probes' timed steps.
    probing: f64,
    /// What the next hold on the pool is stretched by: doubled by each probe in a row the pool
    /// wins.
    stretch: u32,
    /// When the current step started.
    step_started: Option<Instant>,
    /// Steps that end before this are not timed ([`SETTLE`]).
    timed_from: Option<Instant>,
}

/// What the current window of steps is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Timing the pool, then the caller.
    ProbePool,
    ProbeCaller,
    /// Running the faster way until the given wall time.
    Hold(Instant),
}

#[derive(Clone, Copy, Debug, Default)]
struct Window {
    steps: u32,
    seconds: f64,
    /// The steps' work, in the caller's units (1 a step where steps cost alike).
    work: f64,
}

impl Window {
    fn full(&self) -> bool {
        self.steps >= PROBE_STEPS && self.seconds >= PROBE.as_secs_f64()
    }
    /// Seconds per unit of work.
    fn per_work(&self) -> f64 {
        self.seconds / self.work
    }
}

impl Default for Crew {
    fn default() -> Self {
        Crew { who: Who::Pool, stage: Stage::ProbePool, window: Window::default(), probed: [0.0; 2], probing: 0.0, stretch: 1, step_started: None, timed_from: None }
    }
}

impl Crew {
    /// Who runs the steps now.
    pub fn who(&self) -> Who {
        self.who
    }

    /// A step starts.
    pub fn step_starts(&mut self) {
        self.step_started = Some(Instant::now());
    }

    /// The step started last ended; it rebuilt the neighbour list if `rebuilt` (and is not
    /// timed). Steps that cost alike.
    pub fn step_ends(&mut self, rebuilt: bool) {
        self.step_ends_with((!rebuilt).then_some(1.0));
    }

    /// The step started last ended, having done `work` (in units of the caller's choosing,
    /// the same for both ways: contact dynamics' contacts times sweeps); `None`: not timed.
    pub fn step_ends_with(&mut self, work: Option<f64>) {
        if let Some(started) = self.step_started.take() {
            let now = Instant::now();
            self.step_took(now.duration_since(started).as_secs_f64(), work, now);
        }
    }

    /// A step took `seconds` for `work` (untimed when `None`), ending at `now`.
    fn step_took(&mut self, seconds: f64, work: Option<f64>, now: Instant) {
        let Some(work) = work.filter(|&w| w > 0.0) else { return };
        if self.timed_from.is_some_and(|t| now < t) {
            return;
        }
        self.window.steps += 1;
        self.window.seconds += seconds;
        self.window.work += work;
        if !self.window.full() {
            return;
        }
        let per_work = self.window.per_work();
        match self.stage {
            Stage::ProbePool => {
                self.probed[0] = per_work;
                self.probing = self.window.seconds;
                self.begin(Who::Caller, Stage::ProbeCaller, now);
            }
            Stage::ProbeCaller => {
                self.probed[1] = per_work;
                self.probing += self.window.seconds;
                let (who, stretch) = if self.probed[0] * FASTER < self.probed[1] { (Who::Pool, self.stretch) } else { (Who::Caller, 1) };
                self.stretch = if who == Who::Pool { (2 * stretch).min(MAX_STRETCH) } else { 1 };
                self.begin(who, Stage::Hold(now + Duration::from_secs_f64((HOLD * stretch) as f64 * self.probing)), now);
            }
            Stage::Hold(until) => {
                let slowed = self.who == Who::Pool && per_work > SLOWED * self.probed[0];
                if slowed || now >= until {
                    self.begin(Who::Pool, Stage::ProbePool, now);
                } else {
                    self.window = Window::default();
                }
            }
        }
    }

    /// Runs the steps from `now` on `who`, for `stage`; a change of hands is timed after
    /// [`SETTLE`].
    fn begin(&mut self, who: Who, stage: Stage, now: Instant) {
        if who != self.who {
            self.timed_from = Some(now + SETTLE);
        }
        self.who = who;
        self.stage = stage;
        self.window = Window::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `steps` steps of `pool` seconds each on the pool and `caller` on the caller alone
    /// (a rebuild every tenth, untimed), from `now`; returns the steps each ran and the end.
    fn run(crew: &mut Crew, steps: u32, pool: f64, caller: f64, mut now: Instant) -> ([u32; 2], Instant) {
        let mut ran = [0; 2];
        for k in 0..steps {
            let (who, took) = match crew.who() {
                Who::Pool => (0, pool),
                Who::Caller => (1, caller),
            };
            ran[who] += 1;
            now += Duration::from_secs_f64(took);
            crew.step_took(took, (k % 10 != 9).then_some(1.0), now);
        }
        (ran, now)
    }

    /// On a quiet machine (the pool twice as fast) the caller runs less than 1/HOLD of the
    /// steps, its probes; beside a busy program (the pool slower) the pool runs only its
    /// probes; a pool that slows down during a hold is probed again at once.
    #[test]
    fn the_faster_way_runs_the_steps() {
        let start = Instant::now();
        let (ran, _) = run(&mut Crew::default(), 100_000, 0.5e-3, 1e-3, start);
        let caller_share = ran[1] as f64 / 100_000.0;
        assert!(caller_share > 0.0 && caller_share < 1.0 / HOLD as f64, "quiet: {ran:?}");
        let (ran, _) = run(&mut Crew::default(), 100_000, 1.5e-3, 1e-3, start);
        let pool_share = ran[0] as f64 / 100_000.0;
        assert!(pool_share < 1.0 / HOLD as f64, "busy: {ran:?}");
        // Quiet, then the pool slows to twice the caller's time: within two windows of the
        // slowdown the caller takes over.
        let mut crew = Crew::default();
        let (_, now) = run(&mut crew, 1000, 0.5e-3, 1e-3, start);
        assert_eq!(crew.who(), Who::Pool);
        let window_steps = (PROBE.as_secs_f64() / 2e-3).ceil() as u32 + PROBE_STEPS;
        run(&mut crew, 3 * window_steps, 2e-3, 1e-3, now);
        assert_eq!(crew.who(), Who::Caller);
    }
}
