//! The normal force one evaluation applies over the kicks it stands for.
//!
//! Velocity Verlet applies each evaluation's force over a window of one step centred on it
//! (half a kick either side), and evaluates it with the velocity of half a step before. For a
//! dashpot that leaves an error of first order in the step, largest at small restitution
//! (docs/restitution.md); three mends bring it to second order:
//!
//! 1. **The dashpot's velocity** is the normal velocity carried forward half a step, by half
//!    its change since the previous evaluation (`u = v_n + (v_n - v_prev) / 2`: the half-kicks
//!    between two evaluations add `dt` times the previous acceleration). Against a wall only
//!    the grain's own change counts: a wall's velocity is prescribed (a servo resets it every
//!    step), not the integral of a force.
//! 2. **A contact that starts inside the window** (its overlap less than the last drift's
//!    approach) applies the mean of its force over the window from the instant of touch: the
//!    overlap grows linearly from zero there, so each term of the law, a power `h^p` of the
//!    overlap, averages to its value at the window's end over `p + 1`.
//! 3. **A contact that ends inside it** (predicted to part before the window closes, at the
//!    separation speed of the next drift `2u - v_n`) applies its mean up to the parting; and
//!    a contact without the no-pull clamp, whose dashpot pulls until the overlap closes, adds
//!    on the evaluation after it parted the part of the contact that fell in that evaluation's
//!    window ([`parted_normal_force`]).
//!
//! The mends act on damped laws under velocity Verlet (a `window` of zero turns them off: the
//! optimised scheme's evaluations are not centred on their kicks).

use super::{normal_damping, ContactModel, DampingLaw, Geometry, NormalLaw, NormalModel, PairCoeffs};
use crate::real::Real;

/// Exponents `(p, q)` of the overlap in the elastic force `F_el ~ h^p` and the dashpot
/// coefficient `eta ~ h^q`: the restitution dashpot goes as the square root of the tangent
/// stiffness, `q = (p - 1) / 2`.
#[inline(always)]
pub fn overlap_exponents<T: Real>(normal: &NormalLaw<T>, damping: &DampingLaw<T>) -> (T, T) {
    let p = normal.exponent();
    let q = match damping {
        DampingLaw::Papers => T::of(0.5),
        DampingLaw::Restitution => (p - T::ONE) * T::of(0.5),
        _ => T::ZERO,
    };
    (p, q)
}

/// The mean over a window of `window` (s) of the normal force (N, compressive positive) of a
/// contact that lasts `span` (s) of it, its overlap falling linearly to zero from `h_far` (m)
/// at the far end, with dashpot velocity `u` (m/s, positive separating):
/// `span / window (F_el(h_far) / (p + 1) - eta(h_far) u / (q + 1))`.
#[inline(always)]
fn mean_over<T: Real>(model: &ContactModel<T>, c: &PairCoeffs<T>, geo: &Geometry<T>, h_far: T, span: T, u: T, window: T) -> T {
    let far = Geometry { h: h_far, ..*geo };
    let (f_el, _) = model.normal.elastic(c, &far);
    let eta = normal_damping(&model.damping, &model.normal, c, &far);
    let (p, q) = overlap_exponents(&model.normal, &model.damping);
    span / window * (f_el / (p + T::ONE) - eta * u / (q + T::ONE))
}

/// The window of kicks an evaluation's forces stand for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KickWindow<T> {
    /// Its span (s), centred on the evaluation: the step under velocity Verlet; 0 where the
    /// kicks are not centred on it (no mends).
    pub span: T,
    /// Whether a contact that starts or ends inside it applies its mean over the part it
    /// lasts. The lane kernel leaves this off, which gives every other contact's bits without
    /// the means' arithmetic in every lane, and redoes the few contacts [`at_edge`] one at a
    /// time.
    pub edges: bool,
}

impl<T: Real> KickWindow<T> {
    /// A window of `span` (s) with its mends at the edges.
    pub fn centred(span: T) -> Self {
        KickWindow { span, edges: true }
    }
}

/// Whether a contact's surfaces met within the last drift of a window of `window` (s): its
/// overlap `h` (m) less than the drift's approach (`v_n`, m/s, negative approaching).
#[inline(always)]
fn met_within<T: Real>(h: T, v_n: T, window: T) -> bool {
    -v_n * window > h
}

/// Whether a contact is predicted to part before a window of `window` (s) closes: at the
/// next drift's separation speed `v_n + dv` (m/s), its overlap `h` (m) gone within half of it.
#[inline(always)]
fn parts_within<T: Real>(h: T, v_n: T, dv: T, window: T) -> bool {
    (v_n + dv) * (T::of(0.5) * window) > h
}

/// Whether a touching contact of `model` starts or ends inside the window (s), so that its
/// normal force there is a mean over part of it ([`windowed_normal_force`]'s arguments).
#[inline(always)]
pub fn at_edge<T: Real>(model: &ContactModel<T>, h: T, v_n: T, dv: T, window: T) -> bool {
    !matches!(model.damping, DampingLaw::None) && window != T::ZERO && (met_within(h, v_n, window) || parts_within(h, v_n, dv, window))
}

/// The normal force (N, compressive positive) a touching contact (`geo.h > 0`) applies over
/// `window`, centred on this evaluation, with the no-pull clamp when the model has it, and
/// whether the clamp acted. `f_el` and `eta` are the law's at the overlap now, `v_n` the
/// normal velocity (m/s, `(v_i - v_j).n`, negative approaching) and `dv` its change since the
/// previous evaluation that forces made (m/s; [`driven_normal_velocity`]; any value where the
/// contact is new). See the module's mends; with no dashpot or no window, `F_el - eta v_n` as
/// [`normal_force`](super::normal_force) gives it.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn windowed_normal_force<T: Real>(model: &ContactModel<T>, c: &PairCoeffs<T>, geo: &Geometry<T>, f_el: T, eta: T, v_n: T, dv: T, window: KickWindow<T>) -> (T, bool) {
    let KickWindow { span: window, edges } = window;
    if matches!(model.damping, DampingLaw::None) || window == T::ZERO {
        return super::normal_force(f_el, eta, v_n, model.limit_damping);
    }
    let half = T::of(0.5) * window;
    let approach = -v_n;
    let u = v_n + T::of(0.5) * dv;
    let f = if edges && met_within(geo.h, v_n, window) {
        // Met within the last drift: the mean from the touch, overlap / approach before now.
        let span = geo.h / approach + half;
        mean_over(model, c, geo, approach * span, span, v_n, window)
    } else if edges && parts_within(geo.h, v_n, dv, window) {
        // Parts before the window closes, at the separation speed of the next drift (the
        // acceleration carried on): the mean up to the parting.
        let w = v_n + dv;
        let span = geo.h / w + half;
        mean_over(model, c, geo, w * span, span, u, window)
    } else {
        f_el - eta * u
    };
    if model.limit_damping && f < T::ZERO { (T::ZERO, true) } else { (f, false) }
}

/// The part of the normal velocity (m/s) that the contact forces drive, kept from one
/// evaluation to the next to carry the dashpot's velocity forward: `(v_i - v_j).n` between
/// grains, `v_i.n` against a wall.
#[inline(always)]
pub fn driven_normal_velocity<T: Real>(v_i: crate::real::Vec3<T>, v_j: crate::real::Vec3<T>, n: crate::real::Vec3<T>, j_is_wall: bool) -> T {
    if j_is_wall { v_i.dot(n) } else { (v_i - v_j).dot(n) }
}

/// Whether a contact of `model` that has parted can still pull within a window of `window`
/// (s): a damped law without the no-pull clamp, inside a window ([`parted_normal_force`]).
#[inline(always)]
pub fn ends_pull<T: Real>(model: &ContactModel<T>, window: T) -> bool {
    !model.limit_damping && !matches!(model.damping, DampingLaw::None) && window > T::ZERO
}

/// The normal force (N, compressive positive; negative: a pull) a contact without the no-pull
/// clamp applies on the evaluation after it parted, `h <= 0` (m) the overlap now: where the
/// last drift's separation `v_n` (m/s, positive separating) took it from touching at the
/// previous evaluation to parted after that evaluation's window had closed, the part of the
/// contact that fell in this evaluation's window of `window` (s), the force's mean over it.
/// Zero otherwise: with the clamp, with no dashpot, or with no window.
#[inline(always)]
pub fn parted_normal_force<T: Real>(model: &ContactModel<T>, c: &PairCoeffs<T>, geo: &Geometry<T>, v_n: T, window: T) -> T {
    let half = T::of(0.5) * window;
    if !ends_pull(model, window) || !(v_n * half > -geo.h) {
        return T::ZERO;
    }
    // The contact lasted `span` into this window, its overlap falling to zero at the parting.
    let span = geo.h / v_n + half;
    mean_over(model, c, geo, v_n * span, span, v_n, window)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{CohesionLaw, RollingLaw, TangentialLaw, TwistingLaw};
    use crate::real::Vec3;

    fn linear(limit_damping: bool) -> ContactModel<f64> {
        ContactModel {
            normal: NormalLaw::Linear(crate::model::Linear { k_n: 1.0 }),
            damping: DampingLaw::Restitution,
            tangential: TangentialLaw::None,
            rolling: RollingLaw::None,
            twisting: TwistingLaw::None,
            cohesion: CohesionLaw::None,
            limit_damping,
        }
    }

    fn geo(h: f64) -> Geometry<f64> {
        Geometry { n: Vec3::new(0.0, 0.0, 1.0), h, r_eff: 1.0, m_eff: 1.0, rp_i: 1.0, rp_j: 1.0, rp_eff: 0.5, r_i: 1.0, r_j: 1.0 }
    }

    /// A linear spring (k = 1 N/m, m = 1 kg) and dashpot (beta = 0.25: eta = 0.5 kg/s)
    /// touching 0.3 of the way into the last drift of 0.1 s at 1 m/s: overlap 0.07 m; the
    /// force's exact mean over the window from the touch, 0.12 s, the overlap growing to 0.12
    /// m: (0.12 / 0.1) (0.12 / 2 + 0.5 * 1) = 0.672 N.
    #[test]
    fn a_new_contact_applies_its_mean_since_the_touch() {
        let c = PairCoeffs { beta: 0.25, ..Default::default() };
        let (f, clamped) = windowed_normal_force(&linear(true), &c, &geo(0.07), 0.07, 0.5, -1.0, 0.0, KickWindow::centred(0.1));
        assert!((f - 0.672).abs() < 1e-12 && !clamped, "{f}");
    }

    /// The dashpot sees the velocity half a step on: -1 m/s now, -1.2 m/s at the previous
    /// evaluation (a change of 0.2 m/s), so -0.9 m/s; the force 1 + 0.5 * 0.9 N on an overlap
    /// of 1 m.
    #[test]
    fn the_dashpot_sees_the_velocity_carried_half_a_step_on() {
        let c = PairCoeffs { beta: 0.25, ..Default::default() };
        let (f, _) = windowed_normal_force(&linear(true), &c, &geo(1.0), 1.0, 0.5, -1.0, 0.2, KickWindow::centred(0.1));
        assert!((f - 1.45).abs() < 1e-12, "{f}");
    }

    /// Parting 0.02 s after the evaluation at 1 m/s (the velocity unchanged since the previous
    /// evaluation), overlap 0.02 m: the mean over the 0.07 s from the window's start to the
    /// parting, (0.07 / 0.1) (0.07 / 2 - 0.5 * 1) = -0.3255 N unclamped; clamped, zero. The
    /// evaluation after, 0.03 m parted (the parting 0.02 s into the window): unclamped, the
    /// mean over those 0.02 s, (0.02 / 0.1) (0.02 / 2 - 0.5) = -0.098 N.
    #[test]
    fn a_contact_that_parts_applies_its_mean_up_to_the_parting() {
        let c = PairCoeffs { beta: 0.25, ..Default::default() };
        let (f, _) = windowed_normal_force(&linear(false), &c, &geo(0.02), 0.02, 0.5, 1.0, 0.0, KickWindow::centred(0.1));
        assert!((f + 0.3255).abs() < 1e-12, "{f}");
        assert_eq!(windowed_normal_force(&linear(true), &c, &geo(0.02), 0.02, 0.5, 1.0, 0.0, KickWindow::centred(0.1)), (0.0, true));
        let f = parted_normal_force(&linear(false), &c, &geo(-0.03), 1.0, 0.1);
        assert!((f + 0.098).abs() < 1e-12, "{f}");
        assert_eq!(parted_normal_force(&linear(true), &c, &geo(-0.03), 1.0, 0.1), 0.0);
        // Parted before the window opened (the previous evaluation's window held it all),
        // and not touching at the previous evaluation: nothing.
        assert_eq!(parted_normal_force(&linear(false), &c, &geo(-0.06), 1.0, 0.1), 0.0);
        assert_eq!(parted_normal_force(&linear(false), &c, &geo(-0.12), 1.0, 0.1), 0.0);
    }
}
