//! Optional wall-clock time per phase of the step, for `grains bench`. Off by default: a run
//! that does not ask pays one branch per phase.

use std::marker::PhantomData;
use std::time::Instant;

/// A step's phases: their names in step order, and each one's place among them.
pub trait Phases: Copy {
    /// Names, indexed by [`Phases::index`].
    const NAMES: &'static [&'static str];
    /// This phase's index into [`Phases::NAMES`].
    fn index(self) -> usize;
}

/// The phases, in step order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// `hash_cells` (and wrapping grains into the periodic box).
    Hash,
    /// `detect_pairs` and the pair list's assembly.
    Detect,
    /// `remap_history` and, every few rebuilds, `reorder`.
    Remap,
    /// `pair_force` (and `update_bridges` in capillary scenes).
    Force,
    /// `gather` and `wall_contacts` (one sweep over the grains).
    Gather,
    /// Kicks, drifts and the displacement check.
    Integrate,
}

/// The phases' names, indexed by `Phase as usize`.
pub const PHASE_NAMES: [&str; 6] = ["hash", "detect", "remap", "force", "gather", "integrate"];

impl Phases for Phase {
    const NAMES: &'static [&'static str] = &PHASE_NAMES;
    fn index(self) -> usize {
        self as usize
    }
}

/// Accumulated seconds per phase of `P`.
#[derive(Clone, Debug)]
pub struct PhaseClock<P> {
    on: bool,
    seconds: Vec<f64>,
    phases: PhantomData<P>,
}

impl<P: Phases> Default for PhaseClock<P> {
    fn default() -> Self {
        PhaseClock { on: false, seconds: vec![0.0; P::NAMES.len()], phases: PhantomData }
    }
}

impl<P: Phases> PhaseClock<P> {
    /// Starts or stops timing (the totals are kept).
    pub fn enable(&mut self, on: bool) {
        self.on = on;
    }
    /// The start of a timed phase, when timing is on.
    #[inline]
    pub fn start(&self) -> Option<Instant> {
        self.on.then(Instant::now)
    }
    /// Books the time since `start` to `phase`.
    #[inline]
    pub fn stop(&mut self, phase: P, start: Option<Instant>) {
        if let Some(t) = start {
            self.seconds[phase.index()] += t.elapsed().as_secs_f64();
        }
    }
    /// Seconds per phase, by name.
    pub fn totals(&self) -> Vec<(&'static str, f64)> {
        P::NAMES.iter().copied().zip(self.seconds.iter().copied()).collect()
    }
}
