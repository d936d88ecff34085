//! Twisting torque of Oquendo et al. eq. 2, its `gamma_nt` the materials'. Scene:
//! `twisting = "oquendo"`, no keys of its own.

use super::TwistingLaw;
use crate::model::keys::LawInput;
use crate::model::registry::Entry;
use crate::model::{Geometry, Kinematics};
use crate::real::{Real, Vec3};

/// The registry's row.
pub(super) const ENTRY: Entry<TwistingLaw> = Entry { name: "oquendo", keys: &[], parse: |_: &LawInput| Ok(TwistingLaw::Oquendo) };

/// Twisting torque on i (N m), `-4 pi gamma_nt m_eff R_eff h w_n` with
/// `w_n = ((w_i - w_j).n) n`; the torque on j is its opposite.
#[inline(always)]
pub fn twisting_torque<T: Real>(gamma_nt: T, g: &Geometry<T>, k: &Kinematics<T>) -> Vec3<T> {
    let w_n = g.n * (k.w_i - k.w_j).dot(g.n);
    w_n * (-T::of(4.0 * std::f64::consts::PI) * gamma_nt * g.m_eff * g.r_eff * g.h)
}
