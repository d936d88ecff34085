//! One time step as a list of operations, derived once from the integrator. The CPU engine
//! executes the list and the GPU engine encodes it, so the kernel sequence, the kick and drift
//! durations and the time the contact springs advance by at each force evaluation are written
//! once, here.

use crate::scene::Integrator;

/// Oquendo et al.'s optimised velocity Verlet parameter (eqs. 11-15).
pub const OVV_XI: f64 = 0.1931833275037836;

/// One operation of a step. Durations are seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// Velocities (grains and piston) advance by `tau` under the last loads.
    Kick {
        /// s.
        tau: f64,
    },
    /// Positions (grains, orientations, piston, servo walls) advance by `tau`.
    Drift {
        /// s.
        tau: f64,
    },
    /// The neighbour list is rebuilt if a grain has moved half the skin since the last build.
    RebuildIfNeeded,
    /// Forces are evaluated; the contact springs advance by `elapsed`, the time since the
    /// previous evaluation.
    Forces {
        /// s.
        elapsed: f64,
    },
}

/// The operations of the scene's integrator.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Makes the loads valid where nothing has evaluated them yet (before the first step, and
    /// before statistics are read): the springs do not advance.
    pub prologue: Vec<Op>,
    /// Whether a step needs valid loads before its first operation (it starts with a kick).
    pub needs_loads: bool,
    /// Whether each evaluation's forces stand for the kicks half a step either side of it
    /// (velocity Verlet): the contact laws then take their mean over that window of one step
    /// ([`crate::model::window`]), whose length is the evaluation's elapsed time.
    pub centred_kicks: bool,
    /// The first step: its first evaluation counts the springs' time from the start.
    pub first: Vec<Op>,
    /// Every later step.
    pub step: Vec<Op>,
    /// `first`'s sweeps ([`sweeps`]).
    first_sweeps: Vec<Sweep>,
    /// `step`'s sweeps.
    step_sweeps: Vec<Sweep>,
}

impl Schedule {
    /// The schedule of `integrator` at step `dt` (s).
    pub fn new(integrator: Integrator, dt: f64) -> Self {
        use Op::{Drift, Kick};
        let forces = [Op::RebuildIfNeeded, Op::Forces { elapsed: f64::NAN }];
        let mut step = Vec::new();
        match integrator {
            Integrator::VelocityVerlet => {
                step.extend([Kick { tau: 0.5 * dt }, Drift { tau: dt }]);
                step.extend(forces);
                step.push(Kick { tau: 0.5 * dt });
            }
            Integrator::OptimizedVerlet => {
                let xi = OVV_XI;
                step.push(Drift { tau: xi * dt });
                step.extend(forces);
                step.extend([Kick { tau: 0.5 * dt }, Drift { tau: (1.0 - 2.0 * xi) * dt }]);
                step.extend(forces);
                step.extend([Kick { tau: 0.5 * dt }, Drift { tau: xi * dt }]);
            }
        }
        // The springs advance by the drifts since the previous evaluation: in the first step
        // counted from the start, in later ones across the end of the step before.
        let drifts_after_last = step.iter().rev().take_while(|op| !matches!(op, Op::Forces { .. })).map(Op::drift).sum();
        let first = with_elapsed(&step, 0.0);
        let step = with_elapsed(&step, drifts_after_last);
        let (first_sweeps, step_sweeps) = (sweeps(&first), sweeps(&step));
        let centred_kicks = centred_kicks(integrator);
        Schedule { prologue: vec![Op::RebuildIfNeeded, Op::Forces { elapsed: 0.0 }], needs_loads: matches!(step[0], Kick { .. }), centred_kicks, first, step, first_sweeps, step_sweeps }
    }

    /// The window (s) of kicks an evaluation `elapsed` (s) after the previous one stands for
    /// ([`Self::centred_kicks`]; 0 where the kicks are not centred on it).
    pub fn window(&self, elapsed: f64) -> f64 {
        if self.centred_kicks { elapsed } else { 0.0 }
    }

    /// The kick and drift (s) of a later step's first sweep where a run of steps may run it in
    /// the last sweep of the step before: that sweep evaluates forces and kicks, the first
    /// kicks and drifts, and only the step's end comes between them (velocity Verlet).
    pub fn carried(&self) -> Option<(f64, f64)> {
        match (self.step_sweeps.last(), self.step_sweeps.first()) {
            (Some(Sweep::ForcesKick { .. }), Some(&Sweep::KickDrift { kick, tau })) => Some((kick, tau)),
            _ => None,
        }
    }

    /// The sweeps of step number `step` (0 = the first): its operations, each kick merged
    /// into the sweep next to it ([`sweeps`]).
    pub fn sweeps(&self, step: u64) -> &[Sweep] {
        if step == 0 { &self.first_sweeps } else { &self.step_sweeps }
    }
}

impl Op {
    /// The drift's duration (s); 0 for every other operation.
    fn drift(&self) -> f64 {
        if let Op::Drift { tau } = self { *tau } else { 0.0 }
    }
}

/// `ops` with each evaluation's elapsed time set from the drifts before it, starting from
/// `carried` (s) of drift before the list.
fn with_elapsed(ops: &[Op], carried: f64) -> Vec<Op> {
    let mut since = carried;
    ops.iter()
        .map(|op| match op {
            Op::Forces { .. } => {
                let elapsed = since;
                since = 0.0;
                Op::Forces { elapsed }
            }
            other => {
                since += other.drift();
                *other
            }
        })
        .collect()
}

/// Whether `integrator`'s force evaluations each stand for the kicks half a step either side
/// of them (velocity Verlet): [`Schedule::centred_kicks`].
pub fn centred_kicks(integrator: Integrator) -> bool {
    matches!(integrator, Integrator::VelocityVerlet)
}

/// A record of the operations an engine ran, for checking both engines walk one schedule.
#[derive(Clone, Debug, Default)]
pub struct Trace(Option<Vec<Op>>);

impl Trace {
    /// Starts recording (and forgets what was recorded).
    pub fn start(&mut self) {
        self.0 = Some(Vec::new());
    }
    /// Records `op` while recording.
    #[inline]
    pub fn record(&mut self, op: Op) {
        if let Some(v) = &mut self.0 {
            v.push(op);
        }
    }
    /// What was recorded.
    pub fn ops(&self) -> &[Op] {
        self.0.as_deref().unwrap_or(&[])
    }
    /// Forgets what was recorded after the first `kept` operations (an engine that goes back
    /// over operations it had encoded but not run).
    pub fn keep_first(&mut self, kept: usize) {
        if let Some(v) = &mut self.0 {
            v.truncate(kept);
        }
    }
}

/// One pass of an engine over the grains: an operation alone, or a kick merged into the sweep
/// next to it (a kick right after a force evaluation runs in the evaluation's last sweep, each
/// grain kicked as soon as its load is whole; a kick followed by a drift runs in the drift's
/// sweep). Each grain sees the same operations in the same order, so the bits are those of
/// the operations run one by one, with fewer passes over the grains: the CPU engine runs its
/// sweeps this way and the GPU engine encodes them as its dispatches (`gpu::plan`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sweep {
    /// One operation alone.
    Op(Op),
    /// A kick by `kick` (s), then a drift by `tau` (s).
    KickDrift {
        /// s.
        kick: f64,
        /// s.
        tau: f64,
    },
    /// A force evaluation whose springs advance by `elapsed` (s), then a kick by `tau` (s).
    ForcesKick {
        /// s.
        elapsed: f64,
        /// s.
        tau: f64,
    },
}

/// The sweeps that run `ops`, in order: a kick right after a force evaluation merged into it,
/// a kick right before a drift merged into the drift, every other operation alone.
pub fn sweeps(ops: &[Op]) -> Vec<Sweep> {
    let (mut out, mut k) = (Vec::new(), 0);
    while k < ops.len() {
        let (sweep, covers) = match (ops[k], ops.get(k + 1)) {
            (Op::Forces { elapsed }, Some(&Op::Kick { tau })) => (Sweep::ForcesKick { elapsed, tau }, 2),
            (Op::Kick { tau: kick }, Some(&Op::Drift { tau })) => (Sweep::KickDrift { kick, tau }, 2),
            (op, _) => (Sweep::Op(op), 1),
        };
        out.push(sweep);
        k += covers;
    }
    out
}

impl Sweep {
    /// The operations the sweep runs, in order.
    pub fn ops(self) -> impl Iterator<Item = Op> {
        let (a, b) = match self {
            Sweep::Op(op) => (op, None),
            Sweep::KickDrift { kick, tau } => (Op::Kick { tau: kick }, Some(Op::Drift { tau })),
            Sweep::ForcesKick { elapsed, tau } => (Op::Forces { elapsed }, Some(Op::Kick { tau })),
        };
        std::iter::once(a).chain(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each step drifts `dt` in all and kicks `dt` in all; every evaluation but the first
    /// step's advances the springs by the drift since the one before it, across step ends.
    #[test]
    fn durations_add_up_for_each_integrator() {
        let dt = 1e-6;
        for integrator in [Integrator::VelocityVerlet, Integrator::OptimizedVerlet] {
            let s = Schedule::new(integrator, dt);
            let total = |ops: &[Op], f: fn(&Op) -> f64| ops.iter().map(f).sum::<f64>();
            let kick = |op: &Op| if let Op::Kick { tau } = op { *tau } else { 0.0 };
            let elapsed = |op: &Op| if let Op::Forces { elapsed } = op { *elapsed } else { 0.0 };
            for ops in [&s.first, &s.step] {
                assert!((total(ops, Op::drift) - dt).abs() < 1e-18, "{integrator:?}: drifts sum to dt");
                assert!((total(ops, kick) - dt).abs() < 1e-18, "{integrator:?}: kicks sum to dt");
                assert!(ops.iter().zip(ops.iter().skip(1)).all(|(a, b)| !matches!(b, Op::Forces { .. }) || *a == Op::RebuildIfNeeded), "{integrator:?}: every evaluation follows a rebuild check");
            }
            // Springs advance by exactly the time that passed: in a steady step, dt.
            assert!((total(&s.step, elapsed) - dt).abs() < 1e-18, "{integrator:?}: springs advance dt per step");
            assert_eq!(s.needs_loads, integrator == Integrator::VelocityVerlet);
        }
    }

    /// Velocity Verlet's step is two merged sweeps around the rebuild check; the optimised
    /// velocity Verlet's kicks merge into the evaluations before them.
    #[test]
    fn kicks_merge_into_the_sweeps_next_to_them() {
        let dt = 1.0e-6;
        let vv = Schedule::new(Integrator::VelocityVerlet, dt).sweeps(1).to_vec();
        assert_eq!(vv, vec![Sweep::KickDrift { kick: 0.5 * dt, tau: dt }, Sweep::Op(Op::RebuildIfNeeded), Sweep::ForcesKick { elapsed: dt, tau: 0.5 * dt }]);
        let ovv = Schedule::new(Integrator::OptimizedVerlet, dt).sweeps(1).to_vec();
        let merged = ovv.iter().filter(|s| matches!(s, Sweep::ForcesKick { .. })).count();
        assert_eq!((ovv.len(), merged), (7, 2), "{ovv:?}");
    }
}
