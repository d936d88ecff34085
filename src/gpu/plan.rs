//! How the GPU engine encodes the schedule: each of its sweeps ([`Sweep`]) is one entry (a
//! kick and the drift after it in `integrate`; an evaluation's gather and the kick after it in
//! `gather`), with the arithmetic of running them apart, so the step costs fewer dispatches and
//! gives the same bits. Inside a run of steps, each step's first sweep (a kick and a drift)
//! runs in the dispatches of the step before's last (a force evaluation and a kick), where
//! the schedule allows it ([`Schedule::carried`]): one dispatch and one pass over the grains
//! fewer per step, each grain still kicked, kicked and drifted in that order.

use super::layout::Phase;
use crate::schedule::{sweeps, Op, Schedule, Sweep};

/// What one entry of a plan encodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dispatch {
    /// `integrate` (a kick and/or a drift), then `servo_move` after a drift in servo scenes.
    Integrate,
    /// `decide_rebuild` and the rebuild kernels (zero workgroups when the list is good).
    RebuildIfNeeded,
    /// `find_bridge_events` and `update_bridges` (capillary scenes), `pair_force`, `gather`
    /// (with the wall contacts) and `wall_reduce`, which kick too when the phase has a kick
    /// (and run the next step's kick and drift when it has a drift, then `servo_move` in servo
    /// scenes).
    Forces,
    /// Nothing: operations the step before's last entry ran.
    Carried,
}

/// One entry of a plan: the dispatches, their phase uniform and the operations they run.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// What is encoded.
    pub dispatch: Dispatch,
    /// Durations it runs with.
    pub phase: Phase,
    /// The schedule's operations it covers, in order.
    pub ops: Vec<Op>,
}

/// The plan of `ops`.
pub fn plan(ops: &[Op]) -> Vec<Entry> {
    let mut out = Vec::new();
    for sweep in sweeps(ops) {
        let (dispatch, phase) = match sweep {
            Sweep::KickDrift { kick, tau } => (Dispatch::Integrate, Phase { kick: kick as f32, drift: tau as f32, ..Default::default() }),
            Sweep::Op(Op::Kick { tau }) => (Dispatch::Integrate, Phase { kick: tau as f32, ..Default::default() }),
            Sweep::Op(Op::Drift { tau }) => (Dispatch::Integrate, Phase { drift: tau as f32, ..Default::default() }),
            Sweep::Op(Op::RebuildIfNeeded) => (Dispatch::RebuildIfNeeded, Phase::default()),
            Sweep::ForcesKick { elapsed, tau } => (Dispatch::Forces, Phase { elapsed: elapsed as f32, kick: tau as f32, ..Default::default() }),
            Sweep::Op(Op::Forces { elapsed }) => (Dispatch::Forces, Phase { elapsed: elapsed as f32, ..Default::default() }),
        };
        out.push(Entry { dispatch, phase, ops: sweep.ops().collect() });
    }
    out
}

/// The plans of a schedule: its prologue, its first step and every later step.
#[derive(Clone, Debug, PartialEq)]
pub struct Plans {
    /// Where the loads are not valid yet (see [`Schedule::prologue`]).
    pub prologue: Vec<Entry>,
    /// Whether a step needs valid loads before it starts ([`Schedule::needs_loads`]).
    pub needs_loads: bool,
    first: Vec<Entry>,
    later: Vec<Entry>,
    /// The kick and drift (s) a step's last entry runs for the next step in a run of steps
    /// ([`Schedule::carried`]).
    carry: Option<(f32, f32)>,
}

impl Plans {
    /// The plans of `schedule`.
    pub fn of(schedule: &Schedule) -> Self {
        let carry = schedule.carried().map(|(kick, drift)| (kick as f32, drift as f32));
        Plans { prologue: plan(&schedule.prologue), needs_loads: schedule.needs_loads, first: plan(&schedule.first), later: plan(&schedule.step), carry }
    }
    /// The plan of step number `step` (0 = the first), as [`Schedule::sweeps`].
    pub fn step(&self, step: u64) -> &[Entry] {
        if step == 0 { &self.first } else { &self.later }
    }
    /// The plan of step number `step` inside a run of steps: its first entry left to the
    /// step before (`carried_in`, [`Dispatch::Carried`]) and the next step's first entry run in
    /// its last (`carry_out`), where the schedule allows it.
    pub fn step_in_run(&self, step: u64, carried_in: bool, carry_out: bool) -> Vec<Entry> {
        let mut plan = self.step(step).to_vec();
        if let Some((kick, drift)) = self.carry {
            if carried_in {
                plan[0].dispatch = Dispatch::Carried;
            }
            if let Some(last) = plan.last_mut().filter(|_| carry_out) {
                (last.phase.then_kick, last.phase.drift) = (kick, drift);
            }
        }
        plan
    }

    /// Every entry of every plan, a run's included.
    pub fn entries(&self) -> Vec<Entry> {
        let runs = [0, 1].into_iter().flat_map(|step| self.step_in_run(step, step > 0, true));
        self.prologue.iter().chain(&self.first).chain(&self.later).cloned().chain(runs).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schedule::Schedule;
    use crate::scene::Integrator;

    /// A plan covers its operations exactly once and in order, and velocity Verlet's step is
    /// three dispatch groups: kick+drift, the rebuild check, forces+kick.
    #[test]
    fn a_plan_covers_the_schedule_in_order() {
        for integrator in [Integrator::VelocityVerlet, Integrator::OptimizedVerlet] {
            let s = Schedule::new(integrator, 1e-6);
            for ops in [&s.prologue, &s.first, &s.step] {
                let p = plan(ops);
                let covered: Vec<Op> = p.iter().flat_map(|e| e.ops.clone()).collect();
                assert_eq!(&covered, ops, "{integrator:?}");
            }
        }
        let vv = plan(&Schedule::new(Integrator::VelocityVerlet, 1e-6).step);
        assert_eq!(vv.iter().map(|e| e.dispatch).collect::<Vec<_>>(), [Dispatch::Integrate, Dispatch::RebuildIfNeeded, Dispatch::Forces]);
    }
}
