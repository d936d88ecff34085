//! The dashpot of `damping = "restitution"` sized so that a binary impact rebounds with the
//! restitution coefficient the scene gives, for the law as it runs: Hertz or linear spring,
//! with or without the no-pull clamp.
//!
//! The dashpot keeps LIGGGHTS' shape, `eta = 2 sqrt(5/6) beta sqrt(S_n m_eff)` with
//! `S_n = 2 V_eff sqrt(R_eff h)` (Hertz) and `eta = 2 beta sqrt(k_n m_eff)` (linear), but its
//! ratio `beta` is found by inverting the restitution of that very law instead of taken from
//! the linear oscillator's closed form `|ln e| / sqrt(ln^2 e + pi^2)`. Scaled by the impact
//! speed, the overlap obeys one equation per law, with no other parameter:
//!
//! ```text
//! Hertz:  y'' = -(y^(3/2) + sqrt(5) beta y^(1/4) y'),   linear:  y'' = -(y + 2 beta y'),
//! y(0) = 0, y'(0) = 1, the bracket held at zero or more under the clamp,
//! ```
//!
//! (`h = A y`, `t = (A / v) s` with `A^(5/2) = m_eff v^2 / k`, `F_el = k h^(3/2)`, for Hertz; `t
//! = s sqrt(m_eff / k_n)` for the linear spring), so `e(beta)` depends neither on the impact
//! speed nor on the sizes, masses or moduli, sphere-sphere or sphere-wall alike. Unclamped,
//! the contact ends where the overlap returns to zero, the dashpot pulling until then; clamped,
//! where the force first reaches zero on the way out (from there the grains fly apart: the
//! elastic force falls faster than the pull it would have to beat). Each `e(beta)` is one
//! classical Runge-Kutta integration; `beta` is bracketed and bisected.
//!
//! The linear spring without the clamp is the damped oscillator whose closed form
//! [`oscillator_beta`] is; the tests check the integration against it.
//!
//! Scene: `damping = "restitution"`, no keys of its own; every material in contact gives its
//! `restitution`.

use std::sync::Mutex;

use super::DampingLaw;
use crate::model::keys::{KeyProblem, LawInput};
use crate::model::registry::Entry;

/// The registry's row: every material in contact needs its restitution coefficient, and every
/// material and `[[pair]]` one of at least [`MIN_RESTITUTION`] (the dashpot is sized for each
/// pair of them).
pub(super) const ENTRY: Entry<DampingLaw<f64>> = Entry {
    name: "restitution",
    keys: &[],
    parse: |input: &LawInput| {
        if let Some(i) = input.materials.iter().position(|m| m.in_contact && m.restitution.is_none()) {
            return Err(KeyProblem::new(format!("material[{i}].restitution"), "(missing)", "damping = \"restitution\" needs it", "add `restitution` in (0, 1] to the material"));
        }
        if let Some((i, e)) = input.materials.iter().enumerate().find_map(|(i, m)| m.restitution.filter(|&e| e < MIN_RESTITUTION).map(|e| (i, e))) {
            return Err(KeyProblem::new(
                format!("material[{i}].restitution"),
                e,
                format!("is below {MIN_RESTITUTION}, where the dashpot would set the contact's time scale and the time step, picked from the elastic contact time, would not resolve it"),
                format!("give a restitution of at least {MIN_RESTITUTION}"),
            ));
        }
        if let Some((k, e)) = input.pairs.iter().enumerate().find(|(_, p)| p.restitution < MIN_RESTITUTION).map(|(k, p)| (k, p.restitution)) {
            return Err(KeyProblem::new(format!("pair[{k}].restitution"), e, format!("is below {MIN_RESTITUTION} (see the materials' limit)"), format!("give a restitution of at least {MIN_RESTITUTION}")));
        }
        Ok(DampingLaw::Restitution)
    },
};

/// Steps of the classical Runge-Kutta integration per unit of scaled time (the undamped
/// contact lasts 3.22 units for Hertz, `pi` for the linear spring): the restitution comes out
/// to about 1e-7 (the Hertz dashpot's `y^(1/4)` is rough only at the first step).
const STEPS_PER_UNIT: f64 = 4000.0;

/// Scaled time after which a contact that has not ended is taken to hold for good
/// (restitution 0): an unclamped dashpot at or above critical never lets the grains part.
const NEVER_ENDS: f64 = 400.0;

/// Bisection steps on `beta`: its bracket shrinks to `2^-36` (1.5e-11) of its width.
const BISECTIONS: usize = 36;

/// The smallest restitution coefficient a scene may ask for (-). Below it the dashpot ratio
/// passes 15 under the clamp: the dashpot then sets the contact's time scale, which the time
/// step picked from the elastic contact time no longer resolves.
pub const MIN_RESTITUTION: f64 = 1.0e-3;

/// What one inversion is of: the restitution's bits, the spring and the clamp.
type Inversion = (u64, Spring, bool);

/// The normal spring the dashpot is sized for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spring {
    /// Hertz, `F_el = 4/3 V_eff sqrt(R_eff) h^(3/2)`.
    Hertz,
    /// Linear, `F_el = k_n h`.
    Linear,
}

impl Spring {
    /// The scaled normal force `F / (k A)` at scaled overlap `y > 0` and rate `u`.
    fn force(self, beta: f64, y: f64, u: f64) -> f64 {
        match self {
            Spring::Hertz => y * y.sqrt() + 5f64.sqrt() * beta * y.sqrt().sqrt() * u,
            Spring::Linear => y + 2.0 * beta * u,
        }
    }
}

/// The dashpot ratio `beta` (-) that makes a binary impact under `spring`, with the no-pull
/// clamp when `limit_damping`, rebound with restitution `e` in `[MIN_RESTITUTION, 1]`; 0 for
/// `e = 1`.
pub fn dashpot_ratio(e: f64, spring: Spring, limit_damping: bool) -> f64 {
    assert!((MIN_RESTITUTION..=1.0).contains(&e), "restitution {e} outside [{MIN_RESTITUTION}, 1]: the scene's validation refuses it");
    if e == 1.0 {
        return 0.0;
    }
    if spring == Spring::Linear && !limit_damping {
        return oscillator_beta(e);
    }
    // Scenes are set up many times over (engines, checks, sweeps): each inversion is made once.
    static SOLVED: Mutex<Vec<(Inversion, f64)>> = Mutex::new(Vec::new());
    let key = (e.to_bits(), spring, limit_damping);
    if let Some(&(_, beta)) = SOLVED.lock().unwrap_or_else(|p| p.into_inner()).iter().find(|(k, _)| *k == key) {
        return beta;
    }
    // e(beta) falls from 1 at beta = 0: widen the bracket until it passes below e.
    let mut hi = 1.0;
    while restitution_of(spring, limit_damping, hi) > e {
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if restitution_of(spring, limit_damping, mid) > e {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let beta = 0.5 * (lo + hi);
    SOLVED.lock().unwrap_or_else(|p| p.into_inner()).push((key, beta));
    beta
}

/// The damped linear oscillator's `|beta| = |ln e| / sqrt(ln^2 e + pi^2)` for `e` in (0, 1]:
/// exact for a linear spring-dashpot that may pull (LIGGGHTS' `coefficientRestitution`, which
/// uses it for Hertz too).
pub fn oscillator_beta(e: f64) -> f64 {
    if e >= 1.0 || e <= 0.0 {
        return 0.0;
    }
    let l = e.ln();
    l.abs() / (l * l + std::f64::consts::PI * std::f64::consts::PI).sqrt()
}

/// The restitution (-) of a binary impact under `spring` with dashpot ratio `beta`, the
/// no-pull clamp when `limit_damping`: the scaled equation integrated by classical
/// Runge-Kutta from touch to the contact's end.
pub fn restitution_of(spring: Spring, limit_damping: bool, beta: f64) -> f64 {
    let force = |y: f64, u: f64| {
        let f = spring.force(beta, y.max(0.0), u);
        if limit_damping { f.max(0.0) } else { f }
    };
    // Acceleration of the overlap. The stages of the step that crosses zero see the law carried
    // on past it (smooth there), not cut off: cut, the linear dashpot's pull would jump within
    // the step and cost it its order.
    let acc = |y: f64, u: f64| -force(y, u);
    let dt = 1.0 / STEPS_PER_UNIT;
    let (mut y, mut u, mut t) = (0.0f64, 1.0f64, 0.0);
    while t < NEVER_ENDS {
        let (k1y, k1u) = (u, acc(y, u));
        let (k2y, k2u) = (u + 0.5 * dt * k1u, acc(y + 0.5 * dt * k1y, u + 0.5 * dt * k1u));
        let (k3y, k3u) = (u + 0.5 * dt * k2u, acc(y + 0.5 * dt * k2y, u + 0.5 * dt * k2u));
        let (k4y, k4u) = (u + dt * k3u, acc(y + dt * k3y, u + dt * k3u));
        let y_next = y + dt / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
        let u_next = u + dt / 6.0 * (k1u + 2.0 * k2u + 2.0 * k3u + k4u);
        t += dt;
        if y_next <= 0.0 {
            // The overlap closes within the step: the rate where it crosses zero.
            let s = y / (y - y_next);
            return -(u + s * (u_next - u));
        }
        if limit_damping && u_next < 0.0 && force(y_next, u_next) == 0.0 {
            // On the way out at zero force: the grains fly apart at this speed.
            return -u_next;
        }
        (y, u) = (y_next, u_next);
    }
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The integration against the closed form where there is one (the linear spring that may
    /// pull), to this absolute error in e.
    const CLOSED_FORM: f64 = 1.0e-6;

    #[test]
    fn the_integration_gives_the_oscillators_closed_form() {
        for e in [0.05, 0.1, 0.3, 0.5, 0.8, 0.95] {
            let got = restitution_of(Spring::Linear, false, oscillator_beta(e));
            assert!((got - e).abs() < CLOSED_FORM, "e = {e}: integrated {got}");
        }
    }

    #[test]
    fn each_law_gives_back_the_restitution_it_was_sized_for() {
        for spring in [Spring::Hertz, Spring::Linear] {
            for limit in [true, false] {
                let mut last = 0.0;
                for k in 1..=10 {
                    let e = 0.1 * k as f64;
                    let beta = dashpot_ratio(e, spring, limit);
                    assert!((restitution_of(spring, limit, beta) - e).abs() < CLOSED_FORM, "{spring:?} clamp {limit}: e = {e}, beta = {beta}");
                    if k > 1 {
                        assert!(beta < last, "a larger e needs a weaker dashpot");
                    }
                    last = beta;
                }
            }
        }
        assert!(dashpot_ratio(MIN_RESTITUTION, Spring::Hertz, true) < 20.0);
    }

    /// The clamp cuts the dashpot's pull at the end of a contact, so the same dashpot gives a
    /// larger restitution clamped (the figures docs/physics.md quotes: e = 0.2 sized as LIGGGHTS
    /// sizes it gives 0.32 under the clamp).
    #[test]
    fn the_clamp_raises_the_restitution_of_a_given_dashpot() {
        let beta = oscillator_beta(0.2);
        let (clamped, free) = (restitution_of(Spring::Hertz, true, beta), restitution_of(Spring::Hertz, false, beta));
        println!("LIGGGHTS' dashpot for e = 0.2 under Hertz: {clamped:.4} clamped, {free:.4} unclamped");
        assert!(clamped > 0.3 && clamped < 0.35, "{clamped}");
        assert!((free - 0.2).abs() < 0.01, "LIGGGHTS' sizing is near right for Hertz that may pull: {free}");
    }
}
