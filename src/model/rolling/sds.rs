//! Elastic-plastic spring-dashpot rolling resistance (the momentum-conserving alternative to
//! Oquendo et al.'s rolling regime; as LAMMPS `rolling sds`). Scene: `rolling = "sds"`, with
//! `rolling_k` and `rolling_mu` required, `rolling_gamma` optional.

use super::RollingLaw;
use crate::model::keys::{non_negative_or, required_positive, LawInput};
use crate::model::registry::Entry;
use crate::model::tangential::rotate_into_plane;
use crate::model::{Geometry, Kinematics};
use crate::real::{Real, Vec3};

/// The registry's row.
pub(super) const ENTRY: Entry<RollingLaw<f64>> = Entry {
    name: "sds",
    keys: &["rolling_k", "rolling_gamma", "rolling_mu"],
    parse: |input: &LawInput| {
        Ok(RollingLaw::Sds {
            k_r: required_positive(input.keys, "rolling_k", "give the rolling stiffness in N/m")?,
            gamma_r: non_negative_or(input.keys, "rolling_gamma", 0.0, "give the rolling damping in N s/m")?,
            mu_r: required_positive(input.keys, "rolling_mu", "give the rolling friction coefficient, e.g. 0.05")?,
        })
    },
};

/// Rolling torque on i (N m); the torque on j is its opposite, so linear and angular
/// momentum are conserved.
///
/// The rolling displacement `psi` (history, m) is rotated into the tangent plane and grows by
/// `v_rl elapsed`, `v_rl = R_eff (w_i - w_j) x n`. The rolling force
/// `F_r = -k_r psi - gamma_r v_rl` is capped at `mu_r F_n` (the plastic limit, where `psi` is
/// reset to match the cap), and the torque on i is `R_eff n x F_r`, which dissipates
/// `F_r . v_rl` per unit time.
#[inline]
pub fn rolling_sds<T: Real>(
    k_r: T,
    gamma_r: T,
    mu_r: T,
    g: &Geometry<T>,
    k: &Kinematics<T>,
    f_n: T,
    psi: &mut Vec3<T>,
    elapsed: T,
) -> Vec3<T> {
    let v_rl = (k.w_i - k.w_j).cross(g.n) * g.r_eff;
    *psi = rotate_into_plane(*psi, g.n) + v_rl * elapsed;
    let damp = v_rl * gamma_r;
    let mut f_r = -(*psi * k_r) - damp;
    let limit = mu_r * f_n;
    let mag2 = f_r.norm2();
    if mag2 > limit * limit {
        f_r = f_r * (limit / mag2.sqrt());
        *psi = if k_r > T::ZERO { (f_r + damp) * (-T::ONE / k_r) } else { Vec3::ZERO };
    }
    g.n.cross(f_r) * g.r_eff
}
