//! The twisting slot: a torque against the grains' relative spin about the normal
//! ([`oquendo`]: Oquendo et al. eq. 2). WGSL twin: `shaders/shared/model/twisting.wgsl`.

mod oquendo;

pub use oquendo::twisting_torque;

use super::keys::LawInput;
use super::registry::{Entry, Slot};

/// Twisting law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TwistingLaw {
    /// No twisting torque.
    None,
    /// Oquendo et al. eq. 2: `tau_i = -4 pi gamma_nt m_eff R_eff h w_n`.
    Oquendo,
}

/// The twisting laws, in the order of their WGSL codes (`TWISTING_<NAME>`).
pub const SLOT: Slot<TwistingLaw> = Slot { name: "twisting", laws: &[Entry { name: "none", keys: &[], parse: |_: &LawInput| Ok(TwistingLaw::None) }, oquendo::ENTRY] };

impl TwistingLaw {
    /// The law's name in scenes (its registry row's).
    pub fn name(&self) -> &'static str {
        match self {
            TwistingLaw::None => "none",
            TwistingLaw::Oquendo => oquendo::ENTRY.name,
        }
    }

    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        SLOT.code(self.name())
    }

    /// The law, for reports.
    pub fn describe(&self) -> &'static str {
        match self {
            TwistingLaw::None => "none",
            TwistingLaw::Oquendo => "oquendo(gamma_nt)",
        }
    }
}
