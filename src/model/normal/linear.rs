//! A linear spring: `F_el = k_n h`, `k_n` (N/m) from the scene. Scene: `normal = "linear"`,
//! `k_n` required.

use super::{Entry, NormalLaw, NormalModel, NormalSetup};
use crate::model::keys::{required_positive, LawInput};
use crate::model::{restitution, Geometry, PairCoeffs, TangentialStiffness};
use crate::real::Real;

/// `k_t / k_n` of a linear law's tangential spring when the scene gives no `kt_ratio` (-):
/// 2/7, the ratio at which a sphere's tangential and normal oscillations share one period.
pub const DEFAULT_KT_RATIO: f64 = 2.0 / 7.0;

/// The linear law's stiffness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear<T> {
    /// Spring stiffness (N/m).
    pub k_n: T,
}

/// The registry's row.
pub(super) const ENTRY: Entry<NormalLaw<f64>> = Entry {
    name: "linear",
    keys: &["k_n"],
    parse: |input: &LawInput| Ok(NormalLaw::Linear(Linear { k_n: required_positive(input.keys, "k_n", "give the linear stiffness k_n in N/m")? })),
};

impl Linear<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> Linear<U> {
        Linear { k_n: U::of(self.k_n) }
    }
}

impl<T: Real> NormalModel<T> for Linear<T> {
    #[inline(always)]
    fn elastic(&self, _: &PairCoeffs<T>, g: &Geometry<T>) -> (T, T) {
        (self.k_n * g.h, self.k_n)
    }

    #[inline(always)]
    fn stiffness(&self, _: &PairCoeffs<T>, _: &Geometry<T>) -> T {
        self.k_n
    }

    #[inline(always)]
    fn restitution_damping(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
        // The damped oscillator's: eta = 2 beta sqrt(k_n m_eff).
        T::of(2.0) * c.beta * (self.k_n * g.m_eff).sqrt()
    }

    #[inline(always)]
    fn potential(&self, _: &PairCoeffs<T>, _: T, h: T) -> T {
        T::of(0.5) * self.k_n * h * h
    }

    #[inline(always)]
    fn exponent(&self) -> T {
        T::ONE
    }
}

impl NormalSetup for Linear<f64> {
    fn describe(&self) -> String {
        format!("linear(k_n={:e} N/m)", self.k_n)
    }

    fn spring(&self) -> restitution::Spring {
        restitution::Spring::Linear
    }

    fn collision_time(&self, m_eff: f64, _: f64, _: f64, _: f64) -> f64 {
        std::f64::consts::PI * (m_eff / self.k_n).sqrt()
    }

    fn uses_moduli(&self) -> bool {
        false
    }

    fn default_tangential_stiffness(&self) -> TangentialStiffness<f64> {
        TangentialStiffness::RatioToNormal(DEFAULT_KT_RATIO)
    }

    fn gpu_block(&self) -> glam::Vec4 {
        glam::Vec4::new(self.k_n as f32, 0.0, 0.0, 0.0)
    }
}
