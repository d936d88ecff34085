//! The rolling slot: rolling resistance, the momentum-conserving alternative to Oquendo et
//! al.'s rolling regime ([`sds`]: LAMMPS' `rolling sds`). WGSL twin:
//! `shaders/shared/model/rolling.wgsl`.

mod sds;

pub use sds::rolling_sds;

use super::keys::LawInput;
use super::registry::{Entry, Slot};
use crate::real::Real;

/// Rolling-resistance law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RollingLaw<T> {
    /// No rolling resistance.
    None,
    /// Elastic-plastic spring-dashpot on the rolling displacement (as LAMMPS `rolling sds`):
    /// `F_r = -k_r psi - gamma_r v_rl`, capped at `mu_r F_n`; torque on i `R_eff n x F_r`.
    Sds {
        /// Rolling stiffness (N/m).
        k_r: T,
        /// Rolling damping (N s/m).
        gamma_r: T,
        /// Rolling friction coefficient (-).
        mu_r: T,
    },
}

/// The rolling laws, in the order of their WGSL codes (`ROLLING_<NAME>`).
pub const SLOT: Slot<RollingLaw<f64>> = Slot { name: "rolling", laws: &[Entry { name: "none", keys: &[], parse: |_: &LawInput| Ok(RollingLaw::None) }, sds::ENTRY] };

impl<T> RollingLaw<T> {
    /// The law's name in scenes (its registry row's).
    pub fn name(&self) -> &'static str {
        match self {
            RollingLaw::None => "none",
            RollingLaw::Sds { .. } => sds::ENTRY.name,
        }
    }

    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        SLOT.code(self.name())
    }
}

impl RollingLaw<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> RollingLaw<U> {
        match *self {
            RollingLaw::None => RollingLaw::None,
            RollingLaw::Sds { k_r, gamma_r, mu_r } => RollingLaw::Sds { k_r: U::of(k_r), gamma_r: U::of(gamma_r), mu_r: U::of(mu_r) },
        }
    }

    /// The law and its constants, for reports.
    pub fn describe(&self) -> String {
        match *self {
            RollingLaw::None => "none".to_string(),
            RollingLaw::Sds { k_r, gamma_r, mu_r } => format!("sds(k_r={k_r:e}, gamma_r={gamma_r:e}, mu_r={mu_r})"),
        }
    }

    /// `params.rolling` (WGSL): `[k_r, gamma_r, mu_r, 0]` of the sds law.
    pub fn gpu_block(&self) -> glam::Vec4 {
        match *self {
            RollingLaw::None => glam::Vec4::ZERO,
            RollingLaw::Sds { k_r, gamma_r, mu_r } => glam::Vec4::new(k_r as f32, gamma_r as f32, mu_r as f32, 0.0),
        }
    }
}
