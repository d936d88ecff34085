//! Optional wall-clock time per phase of the step, for `grains bench`. Off by default: a run
//! that does not ask pays one branch per phase.

use std::time::Instant;

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

/// Accumulated seconds per phase.
#[derive(Clone, Debug, Default)]
pub struct PhaseClock {
    on: bool,
    seconds: [f64; 6],
}

impl PhaseClock {
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
    pub fn stop(&mut self, phase: Phase, start: Option<Instant>) {
        if let Some(t) = start {
            self.seconds[phase as usize] += t.elapsed().as_secs_f64();
        }
    }
    /// Seconds per phase, by name.
    pub fn totals(&self) -> Vec<(&'static str, f64)> {
        PHASE_NAMES.iter().copied().zip(self.seconds).collect()
    }
}
