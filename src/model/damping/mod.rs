//! The damping slot: normal dissipation, added to the elastic force before the no-pull clamp
//! (Oquendo et al. eq. 1, docs/physics.md). The registry below, one row per law, names each
//! law and its keys; `none` and `papers` read none, `restitution` sizes its dashpot from the
//! materials ([`restitution`]), `viscous` reads `c_n` ([`viscous`]). WGSL twin:
//! `shaders/shared/model/damping.wgsl`.

mod papers;
pub mod restitution;
mod viscous;

use super::keys::LawInput;
use super::registry::{Entry, Slot};
use super::{Geometry, NormalLaw, NormalModel, PairCoeffs};
use crate::real::Real;

/// Normal dissipation law, added to the elastic force before the no-pull clamp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DampingLaw<T> {
    /// No normal dissipation.
    None,
    /// The papers' nonlinear damping `-m_eff gamma_n sqrt(h) v_n` (Oquendo et al. eq. 1),
    /// `gamma_n` (s^-1 m^-1/2) from the materials.
    Papers,
    /// Viscous damping that gives a binary impact the restitution coefficient `e` of the
    /// materials, shaped as LIGGGHTS' `coefficientRestitution` (Hertz:
    /// `eta = 2 sqrt(5/6) beta sqrt(S_n m_eff)`, `S_n = 2 V_eff sqrt(R_eff h)`; linear:
    /// `eta = 2 beta sqrt(k_n m_eff)`), its ratio `beta` found for the law as it runs, with or
    /// without the clamp ([`restitution::dashpot_ratio`]).
    Restitution,
    /// Constant viscous coefficient `c_n` (N s/m): `-c_n v_n`.
    Viscous {
        /// Dashpot coefficient (N s/m).
        c_n: T,
    },
}

/// The damping laws, in the order of their WGSL codes (`DAMPING_<NAME>`).
pub const SLOT: Slot<DampingLaw<f64>> = Slot {
    name: "damping",
    laws: &[
        Entry { name: "none", keys: &[], parse: |_: &LawInput| Ok(DampingLaw::None) },
        papers::ENTRY,
        restitution::ENTRY,
        viscous::ENTRY,
    ],
};

impl<T> DampingLaw<T> {
    /// The law's name in scenes (its registry row's).
    pub fn name(&self) -> &'static str {
        match self {
            DampingLaw::None => "none",
            DampingLaw::Papers => papers::ENTRY.name,
            DampingLaw::Restitution => restitution::ENTRY.name,
            DampingLaw::Viscous { .. } => viscous::ENTRY.name,
        }
    }

    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        SLOT.code(self.name())
    }
}

impl DampingLaw<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> DampingLaw<U> {
        match *self {
            DampingLaw::None => DampingLaw::None,
            DampingLaw::Papers => DampingLaw::Papers,
            DampingLaw::Restitution => DampingLaw::Restitution,
            DampingLaw::Viscous { c_n } => DampingLaw::Viscous { c_n: U::of(c_n) },
        }
    }

    /// The law and its constants, for reports.
    pub fn describe(&self) -> String {
        match *self {
            DampingLaw::None => "none".to_string(),
            DampingLaw::Papers => "papers(gamma_n)".to_string(),
            DampingLaw::Restitution => "restitution(e)".to_string(),
            DampingLaw::Viscous { c_n } => format!("viscous(c_n={c_n:e} N s/m)"),
        }
    }

    /// `params.damping` (WGSL): `[c_n, 0, 0, 0]` for the viscous dashpot (N s/m).
    pub fn gpu_block(&self) -> glam::Vec4 {
        match *self {
            DampingLaw::Viscous { c_n } => glam::Vec4::new(c_n as f32, 0.0, 0.0, 0.0),
            _ => glam::Vec4::ZERO,
        }
    }
}

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
