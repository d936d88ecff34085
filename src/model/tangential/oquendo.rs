//! Oquendo et al.'s tangential law: static, sliding and rolling regimes (docs/physics.md
//! "Tangential force"). Scene: `tangential = "oquendo"`, with `static_damping`,
//! `rolling_friction` and `kt_ratio`.

use super::{contact_tangential_velocity, rotate_into_plane, stiffness_of, TangentialLaw, TangentialStiffness};
use crate::model::keys::{non_negative_or, KeyProblem, LawInput};
use crate::model::registry::Entry;
use crate::model::{Bodies, Geometry, History, Kinematics, PairCoeffs, Regime};
use crate::real::{Real, Vec3};

/// Damping of the static and rolling springs as a fraction of their critical damping when the
/// scene gives no `static_damping` (-).
pub const DEFAULT_STATIC_DAMPING: f64 = 0.3;

/// The registry's row.
pub(super) const ENTRY: Entry<TangentialLaw<f64>> = Entry {
    name: "oquendo",
    keys: &["static_damping", "rolling_friction", "kt_ratio"],
    parse: |input: &LawInput| {
        let rolling_friction = match input.keys.text("rolling_friction").unwrap_or("torque") {
            "torque" => RollingFriction::Torque,
            "as_written" => RollingFriction::AsWritten,
            other => {
                return Err(KeyProblem::new("model.rolling_friction", format!("\"{other}\""), "unknown rolling friction", "use \"torque\" (momentum-conserving) or \"as_written\" (eqs. 8-9 on each grain)"));
            }
        };
        Ok(TangentialLaw::Oquendo(OquendoLaw {
            static_damping: non_negative_or(input.keys, "static_damping", DEFAULT_STATIC_DAMPING, "give a fraction of critical damping such as 0.3")?,
            stiffness: stiffness_of(input)?,
            rolling_friction,
        }))
    },
};

/// The parameters of Oquendo et al.'s tangential regimes (see [`oquendo_tangential`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OquendoLaw<T> {
    /// Damping of the static and rolling springs as a fraction of their critical damping (-).
    pub static_damping: T,
    /// Static spring stiffness (the rolling spring's too).
    pub stiffness: TangentialStiffness<T>,
    /// How rolling friction acts.
    pub rolling_friction: RollingFriction,
}

impl OquendoLaw<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> OquendoLaw<U> {
        OquendoLaw { static_damping: U::of(self.static_damping), stiffness: self.stiffness.cast(), rolling_friction: self.rolling_friction }
    }
}

/// How Oquendo et al.'s rolling friction (eqs. 8-9) is applied (see [`oquendo_tangential`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RollingFriction {
    /// A torque pair of magnitude `R'_eff |F_n| tan(theta_r)` when rolling: eqs. 8-9 for a
    /// grain rolling on a wall, with the static spring supplying eq. 8's force;
    /// momentum-conserving.
    #[default]
    Torque,
    /// Eqs. 8-9 on each grain as the paper writes them (force and torque per grain).
    AsWritten,
}

impl RollingFriction {
    /// Name as written in scenes.
    pub fn name(self) -> &'static str {
        match self {
            RollingFriction::Torque => "torque",
            RollingFriction::AsWritten => "as_written",
        }
    }
}

/// Forces and torques of Oquendo et al.'s tangential regimes on both partners.
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
    /// The regime the contact was in.
    pub regime: Regime,
}
/// Oquendo et al.'s three regimes (docs/physics.md "Tangential force"), realised so that a loaded
/// contact that should stick does stick at any `F_n dt / m*`:
///
/// - **static**: an elastic spring `xi` (history, m), rotated into the tangent plane and grown
///   by `v_t elapsed`, gives `F_t = -k_t xi - eta_t v_t`; it cancels the applied tangential
///   force (eq. 10) as long as `|F_t| <= mu_s |F_n|` (`max(mu_s, mu_k)`: see below). Its
///   dashpot `eta_t = 2 zeta sqrt(k_t m_t)` is the fraction `zeta` (`static_damping`) of the
///   critical damping of the contact's tangential mass `1/m_t = 1/m_i + R'_i^2/I_i + 1/m_j +
///   R'_j^2/I_j`, so that the spring, a stand-in for the paper's rigid constraint, does not
///   ring.
/// - **sliding**: once the spring's own Coulomb test fails, the contact slides: `F_t` is
///   capped at `mu_k |F_n|` (eq. 5) along the spring and the spring is rescaled to the cap.
///   The `sliding` flag (history) keeps the cap at `mu_k` until the spring unloads below it,
///   which happens when the slip stops or reverses: then the contact sticks again, with a
///   continuous force. Deciding by force rather than by `|v_t| > v_slip` is what keeps an
///   explicit step from jumping over the sticking band: the spring absorbs the overshoot.
///   The spring is only ever scaled down, so no regime switch creates energy; with
///   `mu_k > mu_s` (Oquendo et al.'s Table 3 at mu_s = 0.1, 0.2) a contact therefore holds up to
///   `mu_k |F_n|`, where the paper's speed threshold let it creep at `v_slip`.
/// - **rolling** (not sliding): the rolling velocity `v_r = R'_eff (w_i - w_j) x n` loads a
///   rolling spring `psi` (history, m) in the same way, `F_r = -k_t psi - eta_r v_r` (the
///   static spring's stiffness; `eta_r` the fraction `zeta` of critical for the rolling mass
///   `1/m_r = R'_eff^2 (1/I_i + 1/I_j)`), capped at the paper's rolling friction
///   `|F_n| tan(theta_r)`. On the cap the contact rolls: rolling friction of eqs. 8-9's
///   magnitude along `-t`, `t = v_r / |v_r|`; below it, the spring holds the rolling moment
///   as static friction holds the tangential force, so a loaded contact neither rolls nor
///   creeps. How the rolling force acts is `law.rolling_friction`:
///   - [`RollingFriction::Torque`] (default): a torque pair `+-R'_eff n x F_r` on i and j.
///     With the static spring holding the contact point, a sphere rolling on a plane then
///     feels exactly eqs. 8-9 (the spring supplies eq. 8's force, and eq. 9 is the net
///     torque); between two grains it conserves linear and angular momentum and dissipates
///     `|F_n| tan(theta_r) |v_r|` while rolling.
///   - [`RollingFriction::AsWritten`]: eqs. 8-9 with `|F_r|` on each grain with its own
///     `m, I, R'`, as if its partner were fixed. Both grains are pushed along `-t`, so the
///     pair's momentum is not conserved and a moving pair can gain energy (README: a loaded
///     packing does not settle with it).
///
/// Sliding and rolling are exclusive, as in the paper: a sliding contact drops its rolling
/// spring. The static spring acts in the rolling regime too.
#[inline]
pub fn oquendo_tangential<T: Real>(
    c: &PairCoeffs<T>,
    g: &Geometry<T>,
    k: &Kinematics<T>,
    b: &Bodies<T>,
    f_n: T,
    k_t: T,
    law: &OquendoLaw<T>,
    hist: &mut History<T>,
    elapsed: T,
) -> TangentialOut<T> {
    let v_t = contact_tangential_velocity(g, k);
    let xi = rotate_into_plane(hist.tangential, g.n) + v_t * elapsed;
    // Tangential mobility of the contact points: 1/m + R'^2/I per grain.
    let mobility_i = T::ONE / b.m_i + g.rp_i * g.rp_i / b.inertia_i;
    let mobility_j = if b.j_is_wall { T::ZERO } else { T::ONE / b.m_j + g.rp_j * g.rp_j / b.inertia_j };
    let eta_t = T::of(2.0) * law.static_damping * (k_t / (mobility_i + mobility_j)).sqrt();
    // A sticking contact holds up to mu_s, or up to mu_k where that is larger (a kinetic
    // friction above the static one would stop any slip at once: scaling the spring up to it
    // would create energy).
    let mu = if hist.sliding { c.mu_k } else { c.mu_s.max(c.mu_k) };
    let (f_t, xi, slips) = elastic_plastic(xi, v_t, k_t, eta_t, mu * f_n, c.mu_k * f_n);
    hist.tangential = xi;
    hist.sliding = slips;
    let mut out = TangentialOut {
        f_i: f_t,
        f_j: -f_t,
        t_i: -(g.n.cross(f_t) * g.rp_i),
        t_j: -(g.n.cross(f_t) * g.rp_j),
        // A frictionless contact (mu 0) slips without a force: it counts as static.
        regime: if slips && mu * f_n > T::ZERO { Regime::Sliding } else { Regime::Static },
    };
    if slips {
        hist.rolling = Vec3::ZERO;
        return out;
    }
    let v_r = (k.w_i - k.w_j).cross(g.n) * g.rp_eff;
    let psi = rotate_into_plane(hist.rolling, g.n) + v_r * elapsed;
    // Rolling mobility: R'_eff^2 / I per grain (the torque R'_eff F_r alone).
    let mobility_r = g.rp_eff * g.rp_eff * (T::ONE / b.inertia_i + if b.j_is_wall { T::ZERO } else { T::ONE / b.inertia_j });
    let eta_r = T::of(2.0) * law.static_damping * (k_t / mobility_r).sqrt();
    let limit_r = f_n * c.tan_roll;
    let (f_r, psi, rolls) = elastic_plastic(psi, v_r, k_t, eta_r, limit_r, limit_r);
    hist.rolling = psi;
    match law.rolling_friction {
        RollingFriction::Torque => {
            let tau = g.n.cross(f_r) * g.rp_eff;
            out.t_i += tau;
            out.t_j -= tau;
        }
        RollingFriction::AsWritten => {
            // Eqs. 8-9 for grain i (normal n) and for grain j (normal -n), along t = -F_r/|F_r|;
            // v_r is the same vector seen from either grain.
            let fr = -f_r;
            let (f_i, t_i) = rolling_regime(fr, b.m_i, b.inertia_i, g.rp_i, g.n);
            let (f_j, t_j) = if b.j_is_wall { (-f_i, Vec3::ZERO) } else { rolling_regime(fr, b.m_j, b.inertia_j, g.rp_j, -g.n) };
            out.f_i += f_i;
            out.f_j += f_j;
            out.t_i += t_i;
            out.t_j += t_j;
        }
    }
    if rolls && limit_r > T::ZERO {
        out.regime = Regime::Rolling;
    }
    out
}

/// An elastic-plastic spring `s` (m) with stiffness `k` (N/m) and dashpot `eta` (N s/m) at
/// relative velocity `v`: the force `-k s - eta v` while its magnitude stays within `stick`
/// (N); past it, the force drops to `slip` (N) along itself and the spring is rescaled to
/// match. Returns the force, the spring and whether it slipped.
#[inline(always)]
fn elastic_plastic<T: Real>(s: Vec3<T>, v: Vec3<T>, k: T, eta: T, stick: T, slip: T) -> (Vec3<T>, Vec3<T>, bool) {
    let damp = v * eta;
    let f = -(s * k) - damp;
    let mag = f.norm();
    if mag > stick {
        let f = f * (slip / mag);
        let s = if k > T::ZERO { (f + damp) * (-T::ONE / k) } else { Vec3::ZERO };
        (f, s, true)
    } else {
        (f, s, false)
    }
}

/// Oquendo et al. eqs. 8-9 for one grain: force `-fr / (1 + I/(m R'^2))` and torque
/// `R' / (1 + m R'^2 / I) fr x n`, `fr = |F_n| tan(theta_r) t` on the cap (the rolling
/// spring's force below it).
#[inline(always)]
fn rolling_regime<T: Real>(fr: Vec3<T>, m: T, inertia: T, rp: T, n: Vec3<T>) -> (Vec3<T>, Vec3<T>) {
    let mr2 = m * rp * rp;
    let force = fr * (-T::ONE / (T::ONE + inertia / mr2));
    let torque = fr.cross(n) * (rp / (T::ONE + mr2 / inertia));
    (force, torque)
}
