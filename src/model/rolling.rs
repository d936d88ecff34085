//! Elastic-plastic spring-dashpot rolling resistance (the momentum-conserving alternative to
//! Oquendo et al.'s rolling regime; as LAMMPS `rolling sds`).

use super::tangential::rotate_into_plane;
use super::{Geometry, Kinematics};
use crate::real::{Real, Vec3};

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
