//! How the CPU engine runs a step's operations: a kick right after a force evaluation runs in
//! the evaluation's last sweep (each grain kicked as soon as its load is whole), and a kick
//! followed by a drift runs in the drift's sweep. Each grain sees the same operations in the
//! same order, so the bits are those of the operations run one by one; the grains' arrays are
//! read and written twice less per step of velocity Verlet.

use crate::schedule::Op;

/// One sweep of the engine over the grains (or none, for the rebuild check).
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

/// The sweep that starts at operation `k` of `ops`, and how many operations it covers.
pub fn sweep_at(ops: &[Op], k: usize) -> (Sweep, usize) {
    match (ops[k], ops.get(k + 1)) {
        (Op::Forces { elapsed }, Some(&Op::Kick { tau })) => (Sweep::ForcesKick { elapsed, tau }, 2),
        (Op::Kick { tau: kick }, Some(&Op::Drift { tau })) => (Sweep::KickDrift { kick, tau }, 2),
        (op, _) => (Sweep::Op(op), 1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Integrator;
    use crate::schedule::Schedule;

    /// Velocity Verlet's step is two merged sweeps around the rebuild check; the optimised
    /// velocity Verlet's kicks merge into the evaluations before them.
    #[test]
    fn kicks_merge_into_the_sweeps_next_to_them() {
        let all = |ops: &[Op]| {
            let (mut k, mut out) = (0, Vec::new());
            while k < ops.len() {
                let (s, n) = sweep_at(ops, k);
                out.push(s);
                k += n;
            }
            out
        };
        let dt = 1.0e-6;
        let vv = all(&Schedule::new(Integrator::VelocityVerlet, dt).step);
        assert_eq!(vv, vec![Sweep::KickDrift { kick: 0.5 * dt, tau: dt }, Sweep::Op(Op::RebuildIfNeeded), Sweep::ForcesKick { elapsed: dt, tau: 0.5 * dt }]);
        let ovv = all(&Schedule::new(Integrator::OptimizedVerlet, dt).step);
        let merged = ovv.iter().filter(|s| matches!(s, Sweep::ForcesKick { .. })).count();
        assert_eq!((ovv.len(), merged), (7, 2), "{ovv:?}");
    }
}
