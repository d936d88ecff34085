//! The damping slot's dashpot and the no-pull clamp on the normal force (Oquendo et al. eq. 1,
//! docs/physics.md).

use super::{DampingLaw, Geometry, NormalLaw, NormalModel, PairCoeffs};
use crate::real::Real;

/// Damping coefficient `eta` (kg/s) such that the damping force on i is `-eta v_n n`, with
/// `v_n = (v_i - v_j).n` (negative while approaching).
#[inline(always)]
pub fn normal_damping<T: Real>(law: &DampingLaw<T>, normal: &NormalLaw<T>, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
    match *law {
        DampingLaw::None => T::ZERO,
        DampingLaw::Papers => g.m_eff * c.gamma_n * g.h.sqrt(),
        DampingLaw::Restitution => normal.restitution_damping(c, g),
        DampingLaw::Viscous { c_n } => c_n,
    }
}

/// Total normal force magnitude `F_el - eta v_n` (N, compressive positive), with the no-pull
/// clamp when `limit_damping`: then held at zero where the dashpot would pull (docs/physics.md
/// ruling; LAMMPS' `limit_damping`). Returns the force and whether the clamp acted.
#[inline(always)]
pub fn normal_force<T: Real>(f_elastic: T, eta: T, v_n: T, limit_damping: bool) -> (T, bool) {
    let f = f_elastic - eta * v_n;
    if limit_damping && f < T::ZERO { (T::ZERO, true) } else { (f, false) }
}
