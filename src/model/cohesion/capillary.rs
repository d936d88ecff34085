//! Capillary cohesion of a liquid bridge (Richefeu et al. (2009) eqs. 1-8, docs/physics.md), derived from the
//! paper: the force is `f0 = -kappa R` while the grains touch, decays as `f0 exp(-delta/lambda)`
//! across the gap `delta`, and vanishes beyond the rupture distance `delta_max`.
//!
//! Scene: `cohesion = "capillary"`, with `surface_tension`, `contact_angle` and
//! `liquid_density` (the last read by the stages' `water_content`).

use super::CohesionLaw;
use crate::model::keys::{positive_or, KeyProblem, LawInput};
use crate::model::registry::Entry;
use crate::real::Real;

/// Water's surface tension (N/m), the default of `model.surface_tension`.
pub const DEFAULT_SURFACE_TENSION: f64 = 0.0728;
/// Richefeu et al.'s decay-length constant `c` (its eq. 6).
pub const CAPILLARY_C: f64 = 0.9;
/// Default liquid density (kg/m^3).
pub const DEFAULT_LIQUID_DENSITY: f64 = 1000.0;

/// The registry's row: `kappa = 2 pi gamma_s cos(theta)` from the surface tension and the
/// contact angle (degrees in the scene, in [0, 90) for an attractive bridge).
pub(super) const ENTRY: Entry<CohesionLaw<f64>> = Entry {
    name: "capillary",
    keys: &["surface_tension", "contact_angle", "liquid_density"],
    parse: |input: &LawInput| {
        let gamma_s = positive_or(input.keys, "surface_tension", DEFAULT_SURFACE_TENSION, "give the surface tension in N/m, e.g. 0.0728 for water")?;
        let theta = input.keys.number("contact_angle").unwrap_or(0.0);
        if !(0.0..90.0).contains(&theta) {
            return Err(KeyProblem::new("model.contact_angle", theta, "must lie in [0, 90) degrees for an attractive bridge", "give the contact angle in degrees, e.g. 0"));
        }
        let theta = theta.to_radians();
        Ok(CohesionLaw::Capillary { kappa: 2.0 * std::f64::consts::PI * gamma_s * theta.cos(), theta, c: CAPILLARY_C })
    },
};

/// `delta_max = (1 + theta/2) V_b^(1/3)` (m), `theta` the contact angle (rad), `V_b` the
/// bridge volume (m^3) (Richefeu et al. (2009) eq. 5).
#[inline(always)]
pub fn rupture_distance<T: Real>(theta: T, v_b: T) -> T {
    (T::ONE + theta * T::of(0.5)) * v_b.powf(T::of(1.0 / 3.0))
}

/// Whether a gap `delta` (m) lies within the rupture distance of a bridge of volume `v_b`
/// (m^3) at contact angle `theta` (rad): `delta <= delta_max`, tested as `delta^3 <=
/// (1 + theta/2)^3 V_b` so that the check, made for every bridge at every evaluation, needs no
/// cube root.
#[inline(always)]
pub fn within_rupture<T: Real>(theta: T, v_b: T, delta: T) -> bool {
    let k = T::ONE + theta * T::of(0.5);
    delta <= T::ZERO || delta * delta * delta <= k * k * k * v_b
}

/// `lambda = c / sqrt(2) sqrt((1/R_i + 1/R_j) / max(R_i/R_j, R_j/R_i) V_b)` (m), the decay
/// length of the force across the gap (Richefeu et al. (2009) eq. 8).
#[inline(always)]
pub fn decay_length<T: Real>(c: T, r_i: T, r_j: T, v_b: T) -> T {
    let ratio = (r_i / r_j).max(r_j / r_i);
    c * T::of(std::f64::consts::FRAC_1_SQRT_2) * ((T::ONE / r_i + T::ONE / r_j) / ratio * v_b).sqrt()
}

/// The capillary normal force (N, tensile negative) of a bridge of volume `v_b` between grains
/// of radii `r_i`, `r_j` at gap `delta = -h` (m), with `kappa = 2 pi gamma_s cos(theta)` (N/m):
/// `f0 = -kappa sqrt(R_i R_j)` in contact (`delta < 0`), `f0 exp(-delta/lambda)` up to
/// `delta_max`, 0 beyond or without liquid.
#[inline(always)]
pub fn capillary_force<T: Real>(kappa: T, theta: T, c: T, r_i: T, r_j: T, v_b: T, delta: T) -> T {
    if v_b <= T::ZERO {
        return T::ZERO;
    }
    let f0 = -kappa * (r_i * r_j).sqrt();
    if delta < T::ZERO {
        f0
    } else if within_rupture(theta, v_b, delta) {
        f0 * (-(delta / decay_length(c, r_i, r_j, v_b))).exp()
    } else {
        T::ZERO
    }
}

/// The potential energy (J, zero at rupture, negative while the bridge pulls) of the bridge
/// of [`capillary_force`] at gap `delta` (m): `U(delta) = int_delta^delta_max f ds`, so that
/// `f = -dU/d(delta)`: `f0 lambda (e^(-delta/lambda) - e^(-delta_max/lambda))` across the gap,
/// plus `-f0 delta` in contact (`delta < 0`). A bridge that forms lowers it at once (the
/// liquid's own energy is not counted); one that ruptures leaves it continuous.
#[inline(always)]
pub fn capillary_potential<T: Real>(kappa: T, theta: T, c: T, r_i: T, r_j: T, v_b: T, delta: T) -> T {
    let delta_max = rupture_distance(theta, v_b);
    if v_b <= T::ZERO || delta > delta_max {
        return T::ZERO;
    }
    let f0 = -kappa * (r_i * r_j).sqrt();
    let lambda = decay_length(c, r_i, r_j, v_b);
    let tail = (-(delta_max / lambda)).exp();
    if delta < T::ZERO {
        f0 * lambda * (T::ONE - tail) - f0 * delta
    } else {
        f0 * lambda * ((-(delta / lambda)).exp() - tail)
    }
}

/// How a volume of liquid (m^3) wets a sample: pairs within their rupture distance share it
/// in proportion to their reduced diameter `d = 2 R_i R_j / (R_i + R_j)` (m), each share
/// capped at `cap` (m^3); pairs beyond the rupture distance of their share drop out and raise
/// the others' shares, until none drops. `pairs` are each pair's radii and surface gap
/// `(R_i, R_j, gap)` (m), `theta` the contact angle (rad). Returns each wetted pair's
/// `(index, volume)` and the volume left over, which waits on the grains (Richefeu et al. (2009),
/// docs/physics.md).
pub fn share_liquid(volume: f64, pairs: &[(f64, f64, f64)], cap: f64, theta: f64) -> (Vec<(usize, f64)>, f64) {
    let d: Vec<f64> = pairs.iter().map(|&(ri, rj, _)| 2.0 * ri * rj / (ri + rj)).collect();
    let gaps: Vec<f64> = pairs.iter().map(|p| p.2).collect();
    let mut eligible: Vec<usize> = (0..d.len()).collect();
    loop {
        let total: f64 = eligible.iter().map(|&k| d[k]).sum();
        let share = |k: usize| (volume * d[k] / total).min(cap);
        let before = eligible.len();
        eligible.retain(|&k| within_rupture(theta, share(k), gaps[k]));
        if eligible.len() == before || eligible.is_empty() {
            break;
        }
    }
    let total: f64 = eligible.iter().map(|&k| d[k]).sum();
    let shares: Vec<(usize, f64)> = eligible.iter().map(|&k| (k, (volume * d[k] / total).min(cap))).collect();
    let placed: f64 = shares.iter().map(|s| s.1).sum();
    (shares, volume - placed)
}
