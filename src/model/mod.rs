//! Contact sub-models as pure functions, composed in a fixed order:
//! geometry -> normal (elastic + damping, no-pull clamp, an adhesive law's pull-off) ->
//! tangential -> rolling -> twisting -> cohesion.
//!
//! Every law follows docs/physics.md. Conventions: the normal `n` points from partner `j` to grain
//! `i`; the overlap `h > 0` in contact; forces and torques are "on i" unless named `_j`.
//! A wall is a partner with infinite radius and mass (`R_eff = R_i`, `m_eff = m_i`) that does
//! not spin.
//!
//! A scene picks one law per slot ([`ContactModel`]); a slot set to `None` is skipped before
//! any arithmetic, and its history is not allocated (see [`HistoryLayout`]).

mod coeffs;
pub mod cohesion;
mod contact;
pub mod damping;
mod geometry;
pub mod keys;
pub mod normal;
pub mod registry;
pub mod rolling;
pub mod tangential;
pub mod twisting;
pub mod window;

pub use coeffs::{History, HistoryLayout, MaterialConstants, Mixed, MixedConstants, MixedOverride, PairCoeffs};
pub use cohesion::{capillary_force, capillary_potential, decay_length, rupture_distance, share_liquid, within_rupture, CohesionLaw};
pub use contact::{contact_force, ContactForce, Regime};
pub use damping::{normal_damping, normal_force, restitution, DampingLaw};
pub use geometry::{Bodies, Geometry, Kinematics};
pub use normal::{hertz_collision_time, Hertz, Linear, NormalLaw, NormalModel, NormalSetup};
pub use rolling::{rolling_sds, RollingLaw};
pub use tangential::{contact_tangential_velocity, mindlin_tangential, oquendo_tangential, rotate_into_plane, since_touch, OquendoLaw, RollingFriction, TangentialLaw, TangentialOut, TangentialStiffness};
pub use twisting::{twisting_torque, TwistingLaw};
pub use window::{at_edge, driven_normal_velocity, parted_normal_force, windowed_normal_force, KickWindow};

use crate::real::{Real, Vec3};

/// The law chosen for each slot of a scene's contacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactModel<T> {
    /// Elastic normal law.
    pub normal: NormalLaw<T>,
    /// Normal dissipation.
    pub damping: DampingLaw<T>,
    /// Tangential law.
    pub tangential: TangentialLaw<T>,
    /// Rolling resistance.
    pub rolling: RollingLaw<T>,
    /// Twisting torque.
    pub twisting: TwistingLaw,
    /// Cohesion.
    pub cohesion: CohesionLaw<T>,
    /// The no-pull clamp: the elastic and damping normal force together is held at zero
    /// where the dashpot would pull (docs/physics.md ruling; LAMMPS' `limit_damping`). Off, the
    /// dashpot pulls at the end of a contact (as in LIGGGHTS, EDEM and MercuryDPM) and the
    /// friction limits take the force's magnitude.
    pub limit_damping: bool,
}

impl<T: Real> ContactModel<T> {
    /// The per-contact history this model needs.
    pub fn history_layout(&self) -> HistoryLayout {
        HistoryLayout {
            tangential: !matches!(self.tangential, TangentialLaw::None),
            sliding: matches!(self.tangential, TangentialLaw::Oquendo(_)),
            rolling: !matches!(self.rolling, RollingLaw::None) || matches!(self.tangential, TangentialLaw::Oquendo(_)),
            normal: !matches!(self.damping, DampingLaw::None),
            bridge: !matches!(self.cohesion, CohesionLaw::None),
        }
    }

    /// True when a pair's force on its owner is not always its force on the partner reversed,
    /// bit for bit, so that an engine must keep both: Oquendo et al.'s rolling regime moves both
    /// grains along their own rolling directions. Every other law applies `f` to i and `-f`
    /// to j (a negation commutes with rounding, so `-f` is exact).
    pub fn keeps_both_forces(&self) -> bool {
        matches!(self.tangential, TangentialLaw::Oquendo(_))
    }
}

impl ContactModel<f64> {
    /// The same model in another precision.
    pub fn cast<U: Real>(&self) -> ContactModel<U> {
        ContactModel {
            normal: self.normal.cast(),
            damping: self.damping.cast(),
            tangential: self.tangential.cast(),
            rolling: self.rolling.cast(),
            twisting: self.twisting,
            cohesion: self.cohesion.cast(),
            limit_damping: self.limit_damping,
        }
    }

    /// One line naming the law in each slot, for reports.
    pub fn describe(&self) -> String {
        let clamp = if self.limit_damping { "on" } else { "off" };
        format!(
            "normal={} damping={} no-pull clamp={clamp} tangential={} rolling={} twisting={} cohesion={}",
            self.normal.describe(),
            self.damping.describe(),
            self.tangential.describe(),
            self.rolling.describe(),
            self.twisting.describe(),
            self.cohesion.describe()
        )
    }
}

/// Every WGSL constant naming a law or a tangential stiffness, with its code: each slot's
/// registry rows ([`registry::Slot::codes`]) and [`tangential::STIFFNESS_CODES`].
pub fn law_codes() -> Vec<(String, u32)> {
    let mut codes: Vec<(String, u32)> = normal::SLOT.codes().collect();
    codes.extend(damping::SLOT.codes());
    codes.extend(tangential::SLOT.codes());
    codes.extend(rolling::SLOT.codes());
    codes.extend(twisting::SLOT.codes());
    codes.extend(cohesion::SLOT.codes());
    codes.extend(tangential::STIFFNESS_CODES.iter().map(|&(name, code)| (name.to_string(), code)));
    codes
}

/// [`law_codes`] as WGSL, `const <NAME>: u32 = <code>u;`, written into the kernels' prelude
/// before the contact model's files.
pub fn wgsl_codes() -> String {
    law_codes().iter().map(|(name, code)| format!("const {name}: u32 = {code}u;\n")).collect()
}

#[cfg(test)]
mod tests {
    //! The laws against values computed by hand from docs/physics.md.
    use super::*;

    /// Relative tolerance for hand-computed values (f64 round-off and printed digits).
    const HAND: f64 = 1e-9;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= HAND * b.abs().max(1e-300)
    }

    fn sand() -> MaterialConstants {
        MaterialConstants { youngs_modulus: 7.0e7, poisson_ratio: 0.3, mu_s: 0.5, mu_k: 0.4, rolling_angle: 0.1, gamma_n: 1.0e5, gamma_nt: 20.0, restitution: 0.5 }
    }

    /// The standard Hertz-Mindlin model with restitution damping, clamped or not.
    fn restitution_model(normal: NormalLaw<f64>, limit_damping: bool) -> ContactModel<f64> {
        let tangential = TangentialLaw::Mindlin { damping_ratio: 0.0, stiffness: TangentialStiffness::Mindlin };
        ContactModel { normal, damping: DampingLaw::Restitution, tangential, rolling: RollingLaw::None, twisting: TwistingLaw::None, cohesion: CohesionLaw::None, limit_damping }
    }

    /// Two 0.5 mm grains of 1.3875e-6 kg along x, overlapping by 1 um.
    fn pair() -> (PairCoeffs<f64>, Geometry<f64>) {
        let c = PairCoeffs::of(&sand(), &sand(), &MixedConstants::rule(&sand(), &sand()), &restitution_model(NormalLaw::Hertz(Hertz), true));
        let g = Geometry::grain_grain(Vec3::new(0.999e-3, 0.0, 0.0), 0.999e-3, 5.0e-4, 5.0e-4, 1.3875e-6, 1.3875e-6);
        (c, g)
    }

    #[test]
    fn pair_coefficients_combine_as_physics_md_rules() {
        let (c, _) = pair();
        // V = 7e7 / 0.91 = 7.6923e7 Pa, V_eff = V / 2; G = 7e7 / 2.6, G_eff = G / (2 (2 - 0.3)).
        assert!(close(c.v_eff, 7.0e7 / 0.91 / 2.0));
        assert!(close(c.g_eff, 7.0e7 / 2.6 / 3.4));
        assert!(close(c.tan_roll, 0.1f64.tan()));
        // The dashpot ratio is the law's own: the clamped Hertz inversion; the linear spring
        // that may pull has the oscillator's ln 2 / sqrt(ln^2 2 + pi^2).
        assert!(close(c.beta, restitution::dashpot_ratio(0.5, restitution::Spring::Hertz, true)));
        let (ln2, pi) = (std::f64::consts::LN_2, std::f64::consts::PI);
        let linear: PairCoeffs<f64> = PairCoeffs::of(&sand(), &sand(), &MixedConstants::rule(&sand(), &sand()), &restitution_model(NormalLaw::Linear(Linear { k_n: 1.0e3 }), false));
        assert!(close(linear.beta, ln2 / (ln2 * ln2 + pi * pi).sqrt()));
        let papers = ContactModel { damping: DampingLaw::Papers, ..restitution_model(NormalLaw::Hertz(Hertz), true) };
        assert_eq!(PairCoeffs::<f64>::of(&sand(), &sand(), &MixedConstants::rule(&sand(), &sand()), &papers).beta, 0.0, "no dashpot ratio without restitution damping");
    }

    #[test]
    fn geometry_puts_the_contact_point_per_oquendo_eq_3() {
        let (_, g) = pair();
        assert!(close(g.h, 1.0e-6));
        assert!(close(g.r_eff, 2.5e-4) && close(g.m_eff, 1.3875e-6 / 2.0));
        // Equal grains: z = h/2 each, R' = R - h/2, R'_eff = R'/2.
        assert!(close(g.rp_i, 5.0e-4 - 0.5e-6) && close(g.rp_j, 5.0e-4 - 0.5e-6) && close(g.rp_eff, (5.0e-4 - 0.5e-6) / 2.0));
        assert_eq!(g.n, Vec3::new(1.0, 0.0, 0.0));
        let w = Geometry::grain_wall(Vec3::new(0.0, 0.0, 1.0), 4.99e-4, 5.0e-4, 1.0);
        assert!(close(w.h, 1.0e-6) && close(w.rp_i, 4.99e-4) && w.rp_j == 0.0 && close(w.r_eff, 5.0e-4));
    }

    #[test]
    fn hertz_force_damping_and_clamp() {
        let (c, g) = pair();
        let (f, k) = Hertz.elastic(&c, &g);
        // 4/3 sqrt(2.5e-4) 3.846153846e7 (1e-6)^1.5
        let hand = 4.0 / 3.0 * 0.015811388300841896 * (7.0e7 / 0.91 / 2.0) * 1.0e-9;
        assert!(close(f, hand) && close(k, hand / 1.0e-6));
        // m_eff gamma_n sqrt(h) = 6.9375e-7 * 1e5 * 1e-3
        assert!(close(normal_damping(&DampingLaw::Papers, &NormalLaw::Hertz(Hertz), &c, &g), 6.9375e-7 * 1.0e5 * 1.0e-3));
        assert_eq!(normal_force(1.0, 2.0, -0.25, true), (1.5, false));
        assert_eq!(normal_force(1.0, 2.0, 1.0, true), (0.0, true));
        assert_eq!(normal_force(1.0, 2.0, 1.0, false), (-1.0, false), "unclamped, the dashpot pulls");
        assert!(close(Hertz.potential(&c, g.r_eff, g.h), 0.4 * hand * 1.0e-6));
    }

    #[test]
    fn twisting_torque_opposes_the_relative_spin_about_the_normal() {
        let (c, g) = pair();
        let k = Kinematics { w_i: Vec3::new(3.0, 5.0, 0.0), w_j: Vec3::new(-1.0, 0.0, 7.0), ..Default::default() };
        let t = twisting_torque(c.gamma_nt, &g, &k);
        // -4 pi gamma_nt m_eff R_eff h (w_i - w_j).n n, (w_i - w_j).n = 4
        let hand = -4.0 * std::f64::consts::PI * 20.0 * 6.9375e-7 * 2.5e-4 * 1.0e-6 * 4.0;
        assert!(close(t.x, hand) && t.y == 0.0 && t.z == 0.0);
    }

    #[test]
    fn a_spring_rotated_into_the_tangent_plane_keeps_its_length() {
        let n = Vec3::new(0.6, 0.8, 0.0);
        let s = rotate_into_plane(Vec3::new(1.0, 2.0, 3.0), n);
        assert!(s.dot(n).abs() < 1e-15);
        assert!(close(s.norm(), 14f64.sqrt()));
    }

    #[test]
    fn mindlin_caps_at_coulomb_and_resets_the_spring_to_the_cap() {
        let (c, g) = pair();
        let k = Kinematics::default();
        let mut xi = Vec3::new(0.0, 1.0e-3, 0.0); // far beyond the Coulomb limit
        let (f, slid) = mindlin_tangential(c.mu_s, &g, &k, 2.0e-3, 1.0e3, 0.0, &mut xi, 0.0);
        assert!(close(f.norm(), 0.5 * 2.0e-3) && slid);
        assert!(f.y < 0.0, "opposes the spring");
        assert!(close(xi.norm() * 1.0e3, 0.5 * 2.0e-3));
    }

    #[test]
    fn oquendo_slides_on_the_springs_coulomb_test_and_sticks_when_it_unloads() {
        let (c, g) = pair();
        let b = Bodies { m_i: 1.3875e-6, inertia_i: 0.4 * 1.3875e-6 * 2.5e-7, m_j: 1.3875e-6, inertia_j: 0.4 * 1.3875e-6 * 2.5e-7, j_is_wall: false };
        let law = OquendoLaw { static_damping: 0.0, stiffness: TangentialStiffness::Mindlin, rolling_friction: RollingFriction::Torque };
        let (f_n, k_t) = (1.0e-3, 1.0e3);
        let spring = |y: f64| History { tangential: Vec3::new(0.0, y, 0.0), ..Default::default() };
        // Static: a spring below mu_s F_n gives -k_t xi.
        let mut h = spring(4.0e-7);
        let o = oquendo_tangential(&c, &g, &Kinematics::default(), &b, f_n, k_t, &law, &mut h, 1.0e-6);
        assert!(close(o.f_i.y, -4.0e-4) && !h.sliding && o.regime == Regime::Static);
        // Past mu_s F_n = 5e-4 N the contact slides at mu_k F_n, the spring on the cap.
        let mut h = spring(6.0e-7);
        let o = oquendo_tangential(&c, &g, &Kinematics::default(), &b, f_n, k_t, &law, &mut h, 1.0e-6);
        assert!(close(o.f_i.y, -0.4 * f_n) && o.f_j == -o.f_i && h.sliding && o.regime == Regime::Sliding);
        assert!(close(h.tangential.y * k_t, 0.4 * f_n));
        // Still slipping along the spring: stays on the mu_k cap (not mu_s).
        let slip = Kinematics { v_i: Vec3::new(0.0, 0.01, 0.0), ..Default::default() };
        let o = oquendo_tangential(&c, &g, &slip, &b, f_n, k_t, &law, &mut h, 1.0e-6);
        assert!(close(o.f_i.y, -0.4 * f_n) && h.sliding);
        // The slip reverses: the spring unloads below mu_k F_n and the contact sticks.
        let back = Kinematics { v_i: Vec3::new(0.0, -0.01, 0.0), ..Default::default() };
        let o = oquendo_tangential(&c, &g, &back, &b, f_n, k_t, &law, &mut h, 1.0e-6);
        assert!(close(o.f_i.y, -(0.4 * f_n - k_t * 0.01 * 1.0e-6)) && !h.sliding && o.regime == Regime::Static);
    }

    #[test]
    fn oquendo_rolling_friction_holds_below_tan_theta_f_n_and_is_eqs_8_9_on_the_cap() {
        let (c, g) = pair();
        let (m, inertia) = (1.3875e-6, 0.4 * 1.3875e-6 * 2.5e-7);
        let b = Bodies { m_i: m, inertia_i: inertia, m_j: m, inertia_j: inertia, j_is_wall: false };
        let (f_n, k_t) = (1.0e-3, 1.0e3);
        let cap = f_n * c.tan_roll;
        let rp = g.rp_i;
        // Counter-spinning grains, no slip at the contact: v_r = R'_eff 20 rad/s along +y.
        let k = Kinematics { w_i: Vec3::new(0.0, 0.0, 10.0), w_j: Vec3::new(0.0, 0.0, -10.0), ..Default::default() };
        let v_r = 20.0 * g.rp_eff;
        // A rolling spring below the cap holds: torque R'_eff k_t psi, no force.
        let law = OquendoLaw { static_damping: 0.0, stiffness: TangentialStiffness::Mindlin, rolling_friction: RollingFriction::Torque };
        let mut h = History { rolling: Vec3::new(0.0, -0.5 * cap / k_t, 0.0), ..Default::default() };
        let o = oquendo_tangential(&c, &g, &Kinematics::default(), &b, f_n, k_t, &law, &mut h, 1.0e-6);
        assert!(close(o.t_i.norm(), g.rp_eff * 0.5 * cap) && o.t_j == -o.t_i && o.f_i == Vec3::ZERO && o.regime == Regime::Static);
        // Rolling for long enough loads it to the cap: the torque pair R'_eff tan(theta_r) F_n.
        let mut h = History::default();
        let o = oquendo_tangential(&c, &g, &k, &b, f_n, k_t, &law, &mut h, 1.0);
        assert!(close(o.t_i.norm(), g.rp_eff * cap) && o.t_j == -o.t_i && o.regime == Regime::Rolling, "torque {:?}", o.t_i);
        assert!(o.t_i.z < 0.0, "opposes w_i - w_j");
        assert!(close(h.rolling.norm() * k_t, cap) && h.rolling.y > 0.0, "the spring on the cap, along v_r = {v_r:e} y");
        // As written: eq. 8 on both grains, same direction, and eq. 9's torque on each.
        let written = OquendoLaw { rolling_friction: RollingFriction::AsWritten, ..law };
        let mut h = History::default();
        let o = oquendo_tangential(&c, &g, &k, &b, f_n, k_t, &written, &mut h, 1.0);
        let each = cap / (1.0 + inertia / (m * rp * rp));
        let torque = rp * cap / (1.0 + m * rp * rp / inertia);
        assert!(close(o.f_i.y, -each), "eq. 8 against v_r: {:?}", o.f_i);
        assert!(o.f_i.y == o.f_j.y && close(o.t_i.norm(), torque) && close(o.t_j.norm(), torque), "eqs. 8-9 on both grains");
        // A sliding contact drops its rolling spring.
        let mut h = History { tangential: Vec3::new(0.0, 0.0, 1.0), rolling: Vec3::new(0.0, 1.0e-9, 0.0), ..Default::default() };
        let o = oquendo_tangential(&c, &g, &k, &b, f_n, k_t, &law, &mut h, 0.0);
        assert!(o.regime == Regime::Sliding && h.rolling == Vec3::ZERO);
    }
}
