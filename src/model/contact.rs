//! One contact's force: the slots' laws composed in their fixed order (normal, damping,
//! tangential, rolling, twisting), the tangential regime it ends in, and the elastic energy.

use super::*;

/// The force and torque one contact exerts on its two partners.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce<T> {
    /// Force on i (N).
    pub f_i: Vec3<T>,
    /// Force on j (N); `-f_i` except in Oquendo et al.'s rolling regime.
    pub f_j: Vec3<T>,
    /// Torque on i (N m).
    pub t_i: Vec3<T>,
    /// Torque on j (N m).
    pub t_j: Vec3<T>,
    /// Elastic + damping normal force after the no-pull clamp, less an adhesive normal law's
    /// pull-off (N, compressive positive).
    pub f_n: T,
    /// Capillary normal force (N, tensile negative; 0 without a bridge).
    pub f_c: T,
    /// True when the no-pull clamp removed an attractive damping force.
    pub clamped: bool,
    /// The tangential regime.
    pub regime: Regime,
}

/// The tangential regime of a contact at one force evaluation.
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Regime {
    /// Sticking (or frictionless): the spring holds below its Coulomb limit.
    #[default]
    Static = 0,
    /// On the Coulomb limit.
    Sliding = 1,
    /// Oquendo et al.'s rolling friction at full strength.
    Rolling = 2,
}

impl Regime {
    /// The regime whose `as u8` code is `code` (unknown codes read as static).
    pub fn from_code(code: u8) -> Self {
        match code {
            1 => Regime::Sliding,
            2 => Regime::Rolling,
            _ => Regime::Static,
        }
    }
}

/// Composes the sub-models for one touching contact (`geo.h > 0`), updating its history.
///
/// `elapsed` is the time (s) since the previous force evaluation: the tangential and rolling
/// springs grow by the relative velocity times `elapsed`, or, on the evaluation that finds the
/// contact new, times the time since the surfaces met ([`since_touch`]). `window` is the span
/// of kicks the force stands for, centred on this evaluation: the normal force is its mean
/// over it ([`windowed_normal_force`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn contact_force<T: Real>(
    model: &ContactModel<T>,
    c: &PairCoeffs<T>,
    geo: &Geometry<T>,
    kin: &Kinematics<T>,
    bodies: &Bodies<T>,
    hist: &mut History<T>,
    elapsed: T,
    window: KickWindow<T>,
) -> ContactForce<T> {
    let v_rel = kin.v_i - kin.v_j;
    let v_n = v_rel.dot(geo.n);
    let (f_el, k_secant) = model.normal.elastic(c, geo);
    let eta_n = normal_damping(&model.damping, &model.normal, c, geo);
    let driven = driven_normal_velocity(kin.v_i, kin.v_j, geo.n, bodies.j_is_wall);
    let (f_n, clamped) = windowed_normal_force(model, c, geo, f_el, eta_n, v_n, driven - hist.v_n, window);
    hist.v_n = driven;
    // The friction limits take the normal force's magnitude (unclamped, the dashpot can pull);
    // under an adhesive law, LAMMPS' |F_el - F_po + 2 F_po| (the dashpot left out).
    let (f_n, friction_load) = match model.normal.pull_off(geo) {
        None => (f_n, f_n.abs()),
        Some(pull) => (f_n - pull, (f_el + pull).abs()),
    };
    let mut out = ContactForce { f_i: geo.n * f_n, f_j: geo.n * (-f_n), f_n, clamped, ..Default::default() };
    let f_n = friction_load;
    let elapsed = since_touch(hist, geo.h, v_n, elapsed);

    match model.tangential {
        TangentialLaw::None => {}
        TangentialLaw::Oquendo(law) => {
            let k_t = tangential_stiffness(&law.stiffness, c, geo, k_secant);
            let t = oquendo_tangential(c, geo, kin, bodies, f_n, k_t, &law, hist, elapsed);
            out.f_i += t.f_i;
            out.f_j += t.f_j;
            out.t_i += t.t_i;
            out.t_j += t.t_j;
            out.regime = t.regime;
        }
        TangentialLaw::Mindlin { damping_ratio, stiffness } => {
            let k_t = tangential_stiffness(&stiffness, c, geo, k_secant);
            let (f_t, slid) = mindlin_tangential(c.mu_s, geo, kin, f_n, k_t, eta_n * damping_ratio, &mut hist.tangential, elapsed);
            out.f_i += f_t;
            out.f_j -= f_t;
            // Lever arms to the contact point: -R'_i n on i, +R'_j n on j (force -f_t).
            out.t_i -= geo.n.cross(f_t) * geo.rp_i;
            out.t_j -= geo.n.cross(f_t) * geo.rp_j;
            out.regime = if slid { Regime::Sliding } else { Regime::Static };
        }
    }
    if let RollingLaw::Sds { k_r, gamma_r, mu_r } = model.rolling {
        let tau = rolling_sds(k_r, gamma_r, mu_r, geo, kin, f_n, &mut hist.rolling, elapsed);
        out.t_i += tau;
        out.t_j -= tau;
    }
    if let TwistingLaw::Oquendo = model.twisting {
        let tau = twisting_torque(c.gamma_nt, geo, kin);
        out.t_i += tau;
        out.t_j -= tau;
    }
    if let CohesionLaw::Capillary { kappa, theta, c } = model.cohesion {
        let f_c = capillary_force(kappa, theta, c, geo.r_i(), geo.r_j(), hist.bridge, -geo.h);
        out.f_c = f_c;
        out.f_i += geo.n * f_c;
        out.f_j -= geo.n * f_c;
    }
    out
}

/// `k_t` (N/m) for the current overlap.
#[inline(always)]
pub(super) fn tangential_stiffness<T: Real>(s: &TangentialStiffness<T>, c: &PairCoeffs<T>, geo: &Geometry<T>, k_secant: T) -> T {
    match *s {
        TangentialStiffness::Mindlin => T::of(8.0) * c.g_eff * (geo.r_eff * geo.h).sqrt(),
        TangentialStiffness::RatioToNormal(r) => r * k_secant,
    }
}
