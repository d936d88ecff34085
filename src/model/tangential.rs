//! Tangential laws: seed 000's sliding / rolling / static regimes and the standard
//! Hertz-Mindlin history law.

use super::{Bodies, Geometry, Kinematics, PairCoeffs};
use crate::real::{Real, Vec3};

/// Forces and torques of seed 000's tangential regimes on both partners.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentialOut<T> {
    /// Force on i (N).
    pub f_i: Vec3<T>,
    /// Force on j (N).
    pub f_j: Vec3<T>,
    /// Torque on i (N m).
    pub t_i: Vec3<T>,
    /// Torque on j (N m).
    pub t_j: Vec3<T>,
}

/// Rotates a world-frame spring into the tangent plane of `n`, keeping its length (LAMMPS'
/// and DEM-Engine's convention: the stored displacement follows the contact as it rolls).
#[inline(always)]
pub fn rotate_into_plane<T: Real>(s: Vec3<T>, n: Vec3<T>) -> Vec3<T> {
    let len2 = s.norm2();
    if len2 == T::ZERO {
        return s;
    }
    let p = s - n * s.dot(n);
    let p2 = p.norm2();
    if p2 == T::ZERO { Vec3::ZERO } else { p * (len2 / p2).sqrt() }
}

/// Tangential velocity of the contact points, `v_t = v_p - (v_p.n) n` with seed 000 eq. 4
/// `v_p = v_i - v_j - (R'_i w_i + R'_j w_j) x n`.
#[inline(always)]
pub fn contact_tangential_velocity<T: Real>(g: &Geometry<T>, k: &Kinematics<T>) -> Vec3<T> {
    let v_p = k.v_i - k.v_j - (k.w_i * g.rp_i + k.w_j * g.rp_j).cross(g.n);
    v_p - g.n * v_p.dot(g.n)
}

/// Seed 000's three regimes (PHYSICS.md "Tangential force"):
/// 1. sliding when `|v_t| > v_slip`: `F_t = -mu_k |F_n| t`, `t = v_t / |v_t|`;
/// 2. rolling when `|v_r| > v_roll`, `v_r = R'_eff (w_i - w_j) x n`: eqs. 8-9 on each grain
///    with its own `m, I, R'` (this force does not conserve the pair's linear momentum);
/// 3. static otherwise: damped spring `F_t = -k_t xi - eta_t v_t` up to `mu_s |F_n|`,
///    slipping at `mu_k |F_n|`.
///
/// The spring `xi` (history) is rotated into the tangent plane and grows by `v_t elapsed` in
/// the rolling and static regimes; a sliding contact sets it to the sliding force so that the
/// force is continuous when the contact sticks again. The paper's static friction cancels the
/// applied tangential force outright (eq. 10); the spring realises it, and its optional
/// dashpot `eta_t` (0 by default, as in the paper) damps the spring's own oscillation.
#[inline]
pub fn oquendo_tangential<T: Real>(
    c: &PairCoeffs<T>,
    g: &Geometry<T>,
    k: &Kinematics<T>,
    b: &Bodies<T>,
    f_n: T,
    k_t: T,
    v_slip: T,
    v_roll: T,
    eta_t: T,
    xi: &mut Vec3<T>,
    elapsed: T,
) -> TangentialOut<T> {
    let v_t = contact_tangential_velocity(g, k);
    let speed = v_t.norm();
    if speed > v_slip {
        let f_t = v_t * (-c.mu_k * f_n / speed);
        *xi = if k_t > T::ZERO { f_t * (-T::ONE / k_t) } else { Vec3::ZERO };
        return TangentialOut {
            f_i: f_t,
            f_j: -f_t,
            t_i: -(g.n.cross(f_t) * g.rp_i),
            t_j: -(g.n.cross(f_t) * g.rp_j),
        };
    }
    *xi = rotate_into_plane(*xi, g.n) + v_t * elapsed;
    let v_r = (k.w_i - k.w_j).cross(g.n) * g.rp_eff;
    let roll_speed = v_r.norm();
    if roll_speed > v_roll {
        let t = v_r * (T::ONE / roll_speed);
        let fr = f_n * c.tan_roll;
        // Eqs. 8-9 for grain i (normal n) and for grain j (normal -n); v_r is the same
        // vector seen from either grain.
        let (f_i, t_i) = rolling_regime(fr, b.m_i, b.inertia_i, g.rp_i, t, g.n);
        let (f_j, t_j) =
            if b.j_is_wall { (-f_i, Vec3::ZERO) } else { rolling_regime(fr, b.m_j, b.inertia_j, g.rp_j, t, -g.n) };
        return TangentialOut { f_i, f_j, t_i, t_j };
    }
    let damp = v_t * eta_t;
    let mut f_t = -(*xi * k_t) - damp;
    let limit = c.mu_s * f_n;
    let mag = f_t.norm();
    if mag > limit {
        // Slip: the force drops to the kinetic limit and the spring to match it.
        f_t = f_t * (c.mu_k * f_n / mag);
        *xi = if k_t > T::ZERO { (f_t + damp) * (-T::ONE / k_t) } else { Vec3::ZERO };
    }
    TangentialOut {
        f_i: f_t,
        f_j: -f_t,
        t_i: -(g.n.cross(f_t) * g.rp_i),
        t_j: -(g.n.cross(f_t) * g.rp_j),
    }
}

/// Seed 000 eqs. 8-9 for one grain: force `-fr / (1 + I/(m R'^2)) t` and torque
/// `R' fr / (1 + m R'^2 / I) t x n`, `fr = |F_n| tan(theta_r)`.
#[inline(always)]
fn rolling_regime<T: Real>(fr: T, m: T, inertia: T, rp: T, t: Vec3<T>, n: Vec3<T>) -> (Vec3<T>, Vec3<T>) {
    let mr2 = m * rp * rp;
    let force = t * (-fr / (T::ONE + inertia / mr2));
    let torque = t.cross(n) * (rp * fr / (T::ONE + mr2 / inertia));
    (force, torque)
}

/// Hertz-Mindlin tangential force on i with history and one Coulomb coefficient `mu`:
/// `F_t = -k_t xi - eta_t v_t`, capped at `mu F_n`; on the cap the spring is set to
/// `-(F_t + eta_t v_t) / k_t` (LAMMPS `tangential mindlin`).
#[inline(always)]
pub fn mindlin_tangential<T: Real>(
    mu: T,
    g: &Geometry<T>,
    k: &Kinematics<T>,
    f_n: T,
    k_t: T,
    eta_t: T,
    xi: &mut Vec3<T>,
    elapsed: T,
) -> Vec3<T> {
    let v_t = contact_tangential_velocity(g, k);
    *xi = rotate_into_plane(*xi, g.n) + v_t * elapsed;
    let damp = v_t * eta_t;
    let mut f_t = -(*xi * k_t) - damp;
    let limit = mu * f_n;
    let mag2 = f_t.norm2();
    if mag2 > limit * limit {
        f_t = f_t * (limit / mag2.sqrt());
        *xi = if k_t > T::ZERO { (f_t + damp) * (-T::ONE / k_t) } else { Vec3::ZERO };
    }
    f_t
}
