//! Hertz's elastic sphere contact (Oquendo et al. eq. 1): `F_el = 4/3 V_eff sqrt(R_eff) h^(3/2)`,
//! the materials' `V = E / (1 - nu^2)` mixed as docs/physics.md rules. Scene: `normal = "hertz"`
//! (the default), no keys of its own.

use super::{Entry, NormalLaw, NormalModel, NormalSetup};
use crate::model::keys::LawInput;
use crate::model::{restitution, Geometry, PairCoeffs, TangentialStiffness};
use crate::real::Real;

/// Hertz's law: its constants are the materials'.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hertz;

/// The registry's row.
pub(super) const ENTRY: Entry<NormalLaw<f64>> = Entry { name: "hertz", keys: &[], parse: |_: &LawInput| Ok(NormalLaw::Hertz(Hertz)) };

impl Hertz {
    /// The same law in another precision (it has no constants of its own).
    pub fn cast(&self) -> Hertz {
        Hertz
    }
}

impl<T: Real> NormalModel<T> for Hertz {
    #[inline(always)]
    fn elastic(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> (T, T) {
        let k = T::of(4.0 / 3.0) * c.v_eff * (g.r_eff * g.h).sqrt();
        (k * g.h, k)
    }

    #[inline(always)]
    fn stiffness(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
        T::of(2.0) * c.v_eff * (g.r_eff * g.h).sqrt()
    }

    #[inline(always)]
    fn restitution_damping(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
        // LIGGGHTS' coefficientRestitution: eta = 2 sqrt(5/6) beta sqrt(S_n m_eff), S_n = dF/dh.
        let s_n = T::of(2.0) * c.v_eff * (g.r_eff * g.h).sqrt();
        T::of(2.0 * (5.0f64 / 6.0).sqrt()) * c.beta * (s_n * g.m_eff).sqrt()
    }

    #[inline(always)]
    fn potential(&self, c: &PairCoeffs<T>, r_eff: T, h: T) -> T {
        T::of(8.0 / 15.0) * r_eff.sqrt() * c.v_eff * h * h * h.sqrt()
    }

    #[inline(always)]
    fn exponent(&self) -> T {
        T::of(1.5)
    }
}

impl NormalSetup for Hertz {
    fn describe(&self) -> String {
        "hertz".to_string()
    }

    fn spring(&self) -> restitution::Spring {
        restitution::Spring::Hertz
    }

    fn collision_time(&self, m_eff: f64, r_eff: f64, v_eff: f64, v: f64) -> f64 {
        hertz_collision_time(m_eff, r_eff, v_eff, v)
    }

    fn uses_moduli(&self) -> bool {
        true
    }

    fn default_tangential_stiffness(&self) -> TangentialStiffness<f64> {
        TangentialStiffness::Mindlin
    }

    fn gpu_block(&self) -> glam::Vec4 {
        glam::Vec4::ZERO
    }
}

/// Hertz collision time (s) of a pair of reduced mass `m_eff` (kg), radius `r_eff` (m) and
/// modulus `v_eff` (Pa) meeting at relative speed `v` (m/s).
pub fn hertz_collision_time(m_eff: f64, r_eff: f64, v_eff: f64, v: f64) -> f64 {
    2.868 * (m_eff * m_eff / (r_eff * v_eff * v_eff * v)).powf(0.2)
}
