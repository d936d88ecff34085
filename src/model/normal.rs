//! Normal force: elastic law, damping law, no-pull clamp (Oquendo et al. eq. 1, docs/physics.md).

use super::{DampingLaw, Geometry, NormalLaw, PairCoeffs};
use crate::real::Real;

/// Elastic normal force magnitude (N, repulsive positive) and the secant stiffness
/// `F / h` (N/m) that ratio-based tangential springs scale from.
#[inline(always)]
pub fn normal_elastic<T: Real>(law: &NormalLaw<T>, c: &PairCoeffs<T>, g: &Geometry<T>) -> (T, T) {
    match *law {
        NormalLaw::Hertz => {
            let k = T::of(4.0 / 3.0) * c.v_eff * (g.r_eff * g.h).sqrt();
            (k * g.h, k)
        }
        NormalLaw::Linear { k_n } => (k_n * g.h, k_n),
    }
}

/// Damping coefficient `eta` (kg/s) such that the damping force on i is `-eta v_n n`, with
/// `v_n = (v_i - v_j).n` (negative while approaching).
#[inline(always)]
pub fn normal_damping<T: Real>(law: &DampingLaw<T>, normal: &NormalLaw<T>, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
    match *law {
        DampingLaw::None => T::ZERO,
        DampingLaw::Papers => g.m_eff * c.gamma_n * g.h.sqrt(),
        DampingLaw::Restitution => match *normal {
            NormalLaw::Hertz => {
                let s_n = T::of(2.0) * c.v_eff * (g.r_eff * g.h).sqrt();
                T::of(2.0 * (5.0f64 / 6.0).sqrt()) * c.beta * (s_n * g.m_eff).sqrt()
            }
            NormalLaw::Linear { k_n } => T::of(2.0) * c.beta * (k_n * g.m_eff).sqrt(),
        },
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

/// Tangent stiffness `dF/dh` (N/m) of the elastic normal law: Hertz `2 V_eff sqrt(R_eff h)`
/// (3/2 of the secant), linear `k_n`.
#[inline(always)]
pub fn normal_stiffness<T: Real>(law: &NormalLaw<T>, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
    match *law {
        NormalLaw::Hertz => T::of(2.0) * c.v_eff * (g.r_eff * g.h).sqrt(),
        NormalLaw::Linear { k_n } => k_n,
    }
}
