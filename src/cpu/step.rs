//! One step: the schedule's operations (kicks, drifts with the walls' controllers, the rebuild
//! check, force evaluations) run in order, with a driver's hooks between them.

use super::*;
use super::forces::{take_front, Carry};

impl<T: Real> CpuEngine<T> {
    /// Kick of every grain and of the piston by `tau` (s).
    pub(super) fn kick(&mut self, tau: T) {
        let t = self.clock.start();
        let (load, prop) = (&self.load, &self.prop);
        self.body.par_iter_mut().with_min_len(PAR_MIN_ITEMS).enumerate().for_each(|(i, b)| integrate::kick(b, &load[i], &prop[i], tau));
        self.kick_piston(tau);
        self.clock.stop(Phase::Integrate, t);
    }

    /// Kick of the piston by `tau` (s) under the grains' push and its pressure.
    pub(super) fn kick_piston(&mut self, tau: T) {
        if let Some(p) = self.piston {
            let push = self.wall_reaction[p.wall].z - p.pressure * p.area;
            self.walls[p.wall].velocity.z += push * tau / p.mass;
        }
    }

    /// Drift of every grain (and orientation, piston and servo walls) by `tau` (s), after a
    /// [`Self::kick`] by `kick` (s) when given: in one sweep over the grains, each kicked and
    /// then drifted (the same operations on each grain in the same order as a kick and a
    /// drift, with one pass over the grains' arrays instead of two). Notes how far the grains
    /// have moved since the last build.
    pub(super) fn drift(&mut self, kick: Option<T>, tau: T) {
        let t = self.clock.start();
        let bounds = self.split();
        let (mut body, mut residual) = (&mut self.body[..], &mut self.residual[..]);
        let parts: Vec<_> = bounds
            .windows(2)
            .map(|w| {
                let grains = w[0]..w[1];
                let r = if T::COMPENSATED { take_front(&mut residual, grains.len()) } else { &mut [] };
                (take_front(&mut body, grains.len()), r, &self.built_at[grains.clone()], &self.load[grains.clone()], &self.prop[grains])
            })
            .collect();
        let together = warm::Together::new(parts.len());
        let moved: Vec<T> = parts
            .into_par_iter()
            .with_max_len(1)
            .map(|(b, r, at, l, p)| {
                let moved = integrate::kick_drift(b, r, at, l, p, kick, tau);
                together.finish();
                moved
            })
            .collect();
        self.drift_rest(kick, tau, moved.into_iter().fold(T::ZERO, T::max));
        self.clock.stop(Phase::Integrate, t);
    }

    /// What a drift does besides kicking and drifting the grains (which read neither the
    /// walls nor the orientations, so the order does not matter): the piston kicked by `kick`
    /// (s) when given, the orientations, the piston and the servo walls drifted by `tau` (s),
    /// and `moved`, the grains' largest squared displacement since the last build, noted.
    pub(super) fn drift_rest(&mut self, kick: Option<T>, tau: T, moved: T) {
        if let Some(k) = kick {
            self.kick_piston(k);
        }
        if let Some(q) = &mut self.orientation {
            let body = &self.body;
            q.par_iter_mut().with_min_len(PAR_MIN_ITEMS).enumerate().for_each(|(i, q)| *q = crate::turn::rotate(*q, body[i].omega, tau));
        }
        if let Some(p) = self.piston {
            let wall = &mut self.walls[p.wall];
            let dz = wall.velocity.z * tau;
            if let WallGeom::Piston { z } = &mut wall.geom {
                *z += dz;
            }
            self.external_work -= (p.pressure * p.area * dz).f64();
        }
        self.servo_drift(tau);
        self.drive_walls(tau);
        self.max_moved2 = built_at::with_margin(moved, self.built_margin);
    }

    /// Runs one operation of the schedule, with `hooks` around it.
    pub(super) fn run(&mut self, op: Op, hooks: &mut impl StepHooks<T>) -> Result<(), SimError> {
        self.trace.record(op);
        match op {
            Op::Kick { tau } => self.kick(T::of(tau)),
            Op::Drift { tau } => {
                self.drift(None, T::of(tau));
                hooks.drifted(self)?;
            }
            Op::RebuildIfNeeded => hooks.rebuild_if_needed(self)?,
            Op::Forces { elapsed } => {
                self.forces(elapsed, None, None, hooks)?;
            }
        }
        Ok(())
    }

    /// A force evaluation ([`Op::Forces`]) with `hooks` around it, and with the grains kicked by
    /// `kick` (s) in its last sweep when given (and by `carry`, see [`Self::evaluate_forces`]).
    /// Returns what the carried drift found.
    pub(super) fn forces(&mut self, elapsed: f64, kick: Option<T>, carry: Option<Carry<T>>, hooks: &mut impl StepHooks<T>) -> Result<T, SimError> {
        if self.slots.layout.bridge {
            let t = self.clock.start();
            hooks.bridges(self)?;
            self.clock.stop(Phase::Force, t);
        }
        let moved = self.evaluate_forces(T::of(elapsed), kick, carry);
        if let Some(grain) = self.mesh_overflow {
            return Err(self.mesh_overflow_error(grain));
        }
        hooks.forces_evaluated(self)?;
        Ok(moved)
    }

    /// Makes the loads valid by the schedule's prologue, if nothing has evaluated them yet.
    pub(super) fn ensure_loads(&mut self) -> Result<(), SimError> {
        self.ensure_loads_with(&mut Alone)
    }

    /// [`Self::ensure_loads`] with `hooks` around each operation.
    pub(super) fn ensure_loads_with(&mut self, hooks: &mut impl StepHooks<T>) -> Result<(), SimError> {
        if !self.forces_valid {
            for k in 0..self.schedule.prologue.len() {
                self.run(self.schedule.prologue[k], hooks)?;
            }
        }
        Ok(())
    }

    /// Starts recording the operations run (see [`Trace`]).
    pub fn trace_schedule(&mut self) {
        self.trace.start();
    }

    /// The operations run since [`Self::trace_schedule`].
    pub fn traced(&self) -> &[Op] {
        self.trace.ops()
    }

    /// One time step of the scene's integrator.
    pub fn step(&mut self) -> Result<(), SimError> {
        self.step_in_run(false)
    }

    /// One time step of a run that goes on with another (`more`) inside the same `advance`.
    /// Velocity Verlet ends a step with a force evaluation and a kick and begins the next with
    /// a kick and a drift: such a next step's kick and drift then run in this step's gather
    /// sweep, each grain kicked, kicked again and drifted while it is in cache (as the GPU's
    /// runs of steps do), and the next step skips them. Each grain sees the same operations
    /// in the same order: the same bits. At 10^6 grains the kick-and-drift pass it saves
    /// streamed 228 B per grain from memory.
    pub(super) fn step_in_run(&mut self, more: bool) -> Result<(), SimError> {
        self.step_with(&mut Alone, more)
    }

    /// One time step with `hooks` around its operations (a hook may replace the engine; the
    /// step goes on with the one it leaves), carrying the next step's first sweep into this
    /// one's last where `carry` and the schedule allow ([`Self::step_in_run`]).
    pub(crate) fn step_with(&mut self, hooks: &mut impl StepHooks<T>, carry: bool) -> Result<(), SimError> {
        if self.schedule.needs_loads {
            self.ensure_loads_with(hooks)?;
        }
        let sweeps = self.schedule.sweeps(self.step).len();
        for s in std::mem::take(&mut self.carried) as usize..sweeps {
            let sweep = self.schedule.sweeps(self.step)[s];
            if !matches!(sweep, Sweep::Op(_)) {
                sweep.ops().for_each(|op| self.trace.record(op));
            }
            match sweep {
                Sweep::Op(op) => self.run(op, hooks)?,
                Sweep::ForcesKick { elapsed, tau } => {
                    let next = match self.schedule.sweeps(self.step + 1).first() {
                        Some(&next @ Sweep::KickDrift { kick, tau }) if carry && s + 1 == sweeps => Some((next, Carry { kick: T::of(kick), tau: T::of(tau) })),
                        _ => None,
                    };
                    let moved = self.forces(elapsed, Some(T::of(tau)), next.map(|n| n.1), hooks)?;
                    // The piston's kick reads the walls' sums, which the hooks complete.
                    self.kick_piston(T::of(tau));
                    if let Some((next, c)) = next {
                        next.ops().for_each(|op| self.trace.record(op));
                        self.drift_rest(Some(c.kick), c.tau, moved);
                        hooks.drifted(self)?;
                        self.carried = true;
                    }
                }
                Sweep::KickDrift { kick, tau } => {
                    self.drift(Some(T::of(kick)), T::of(tau));
                    hooks.drifted(self)?;
                }
            }
        }
        self.step += 1;
        self.time += self.dt.f64();
        Ok(())
    }
}

/// What a driver does between the operations of a step: the distributed engine exchanges
/// the grains other processes own after each drift, decides rebuilds over every process and
/// sums the walls' loads over them after each force evaluation ([`crate::cpu::ranks`]).
pub(crate) trait StepHooks<T: Real> {
    /// After each drift.
    fn drifted(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
    /// In place of the rebuild check.
    fn rebuild_if_needed(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
    /// In place of `update_bridges`, before each force evaluation of a capillary scene.
    fn bridges(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
    /// After each force evaluation.
    fn forces_evaluated(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
}

/// The hooks of an engine that holds every grain: the rebuild check alone.
pub(super) struct Alone;

impl<T: Real> StepHooks<T> for Alone {
    fn drifted(&mut self, _: &mut CpuEngine<T>) -> Result<(), SimError> {
        Ok(())
    }
    fn rebuild_if_needed(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        e.rebuild_if_needed()
    }
    fn bridges(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        e.update_bridges();
        Ok(())
    }
    fn forces_evaluated(&mut self, _: &mut CpuEngine<T>) -> Result<(), SimError> {
        Ok(())
    }
}

