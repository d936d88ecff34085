//! The cohesion slot: attraction across and beyond a contact ([`capillary`]: liquid bridges,
//! Richefeu et al. (2009)). WGSL twin: `shaders/shared/model/cohesion.wgsl`.

mod capillary;

pub use capillary::{capillary_force, capillary_potential, decay_length, rupture_distance, share_liquid, within_rupture, DEFAULT_LIQUID_DENSITY};

use super::keys::LawInput;
use super::registry::{Entry, Slot};
use crate::real::Real;

/// Cohesion law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CohesionLaw<T> {
    /// No cohesion.
    None,
    /// Capillary bridges (Richefeu et al. (2009) eqs. 1-8), per-pair liquid volume as history.
    Capillary {
        /// `kappa = 2 pi gamma_s cos(theta)` (N/m).
        kappa: T,
        /// Contact angle (rad).
        theta: T,
        /// The decay-length constant `c` (0.9 in Richefeu et al. (2009)).
        c: T,
    },
}

/// The cohesion laws, in the order of their WGSL codes (`COHESION_<NAME>`).
pub const SLOT: Slot<CohesionLaw<f64>> = Slot { name: "cohesion", laws: &[Entry { name: "none", keys: &[], parse: |_: &LawInput| Ok(CohesionLaw::None) }, capillary::ENTRY] };

impl<T> CohesionLaw<T> {
    /// The law's name in scenes (its registry row's).
    pub fn name(&self) -> &'static str {
        match self {
            CohesionLaw::None => "none",
            CohesionLaw::Capillary { .. } => capillary::ENTRY.name,
        }
    }

    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        SLOT.code(self.name())
    }
}

impl CohesionLaw<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> CohesionLaw<U> {
        match *self {
            CohesionLaw::None => CohesionLaw::None,
            CohesionLaw::Capillary { kappa, theta, c } => CohesionLaw::Capillary { kappa: U::of(kappa), theta: U::of(theta), c: U::of(c) },
        }
    }

    /// The law and its constants, for reports.
    pub fn describe(&self) -> String {
        match *self {
            CohesionLaw::None => "none".to_string(),
            CohesionLaw::Capillary { kappa, theta, c } => format!("capillary(kappa={kappa:e} N/m, theta={:.1} deg, c={c})", theta.to_degrees()),
        }
    }

    /// `params.cohesion` (WGSL): `[kappa, theta, c, volume_cap]` of capillary bridges,
    /// `volume_cap` (m^3) the largest bridge's volume (the scene's).
    pub fn gpu_block(&self, volume_cap: f64) -> glam::Vec4 {
        match *self {
            CohesionLaw::None => glam::Vec4::new(0.0, 0.0, 0.0, volume_cap as f32),
            CohesionLaw::Capillary { kappa, theta, c } => glam::Vec4::new(kappa as f32, theta as f32, c as f32, volume_cap as f32),
        }
    }
}
