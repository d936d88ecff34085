//! Contact sub-models as pure functions, composed in a fixed order:
//! geometry -> normal (elastic + damping, no-pull clamp) -> tangential -> rolling -> twisting.
//!
//! Every law follows docs/physics.md. Conventions: the normal `n` points from partner `j` to grain
//! `i`; the overlap `h > 0` in contact; forces and torques are "on i" unless named `_j`.
//! A wall is a partner with infinite radius and mass (`R_eff = R_i`, `m_eff = m_i`) that does
//! not spin.
//!
//! A scene picks one law per slot ([`ContactModel`]); a slot set to `None` is skipped before
//! any arithmetic, and its history is not allocated (see [`HistoryLayout`]).

mod capillary;
mod geometry;
mod normal;
pub mod restitution;
mod rolling;
mod tangential;
mod twisting;
pub mod window;

pub use capillary::{capillary_force, capillary_potential, decay_length, rupture_distance, share_liquid, within_rupture};
pub use geometry::{Bodies, Geometry, Kinematics};
pub use normal::{normal_damping, normal_elastic, normal_force, normal_stiffness};
pub use rolling::rolling_sds;
pub use tangential::{contact_tangential_velocity, mindlin_tangential, oquendo_tangential, rotate_into_plane, since_touch, TangentialOut};
pub use twisting::twisting_torque;
pub use window::{at_edge, driven_normal_velocity, parted_normal_force, windowed_normal_force, KickWindow};

use crate::real::{Real, Vec3};

/// The codes by which the WGSL kernels know each law (WGSL constants of the same names in
/// `shaders/shared/model.wgsl`, checked against these by `tests/shaders.rs`); each law's
/// `code()` gives its own.
pub mod code {
    /// [`super::NormalLaw::Hertz`].
    pub const NORMAL_HERTZ: u32 = 0;
    /// [`super::NormalLaw::Linear`].
    pub const NORMAL_LINEAR: u32 = 1;
    /// [`super::DampingLaw::None`].
    pub const DAMPING_NONE: u32 = 0;
    /// [`super::DampingLaw::Papers`].
    pub const DAMPING_PAPERS: u32 = 1;
    /// [`super::DampingLaw::Restitution`].
    pub const DAMPING_RESTITUTION: u32 = 2;
    /// [`super::DampingLaw::Viscous`].
    pub const DAMPING_VISCOUS: u32 = 3;
    /// [`super::TangentialLaw::None`].
    pub const TANGENTIAL_NONE: u32 = 0;
    /// [`super::TangentialLaw::Oquendo`].
    pub const TANGENTIAL_OQUENDO: u32 = 1;
    /// [`super::TangentialLaw::Mindlin`].
    pub const TANGENTIAL_MINDLIN: u32 = 2;
    /// [`super::TangentialStiffness::Mindlin`].
    pub const STIFFNESS_MINDLIN: u32 = 0;
    /// [`super::TangentialStiffness::RatioToNormal`].
    pub const STIFFNESS_RATIO: u32 = 1;
    /// [`super::RollingLaw::None`].
    pub const ROLLING_NONE: u32 = 0;
    /// [`super::RollingLaw::Sds`].
    pub const ROLLING_SDS: u32 = 1;
    /// [`super::TwistingLaw::None`].
    pub const TWISTING_NONE: u32 = 0;
    /// [`super::TwistingLaw::Oquendo`].
    pub const TWISTING_OQUENDO: u32 = 1;
    /// [`super::CohesionLaw::None`].
    pub const COHESION_NONE: u32 = 0;
    /// [`super::CohesionLaw::Capillary`].
    pub const COHESION_CAPILLARY: u32 = 1;
    /// Every code by its WGSL name.
    pub const ALL: &[(&str, u32)] = &[
        ("NORMAL_HERTZ", NORMAL_HERTZ),
        ("NORMAL_LINEAR", NORMAL_LINEAR),
        ("DAMPING_NONE", DAMPING_NONE),
        ("DAMPING_PAPERS", DAMPING_PAPERS),
        ("DAMPING_RESTITUTION", DAMPING_RESTITUTION),
        ("DAMPING_VISCOUS", DAMPING_VISCOUS),
        ("TANGENTIAL_NONE", TANGENTIAL_NONE),
        ("TANGENTIAL_OQUENDO", TANGENTIAL_OQUENDO),
        ("TANGENTIAL_MINDLIN", TANGENTIAL_MINDLIN),
        ("STIFFNESS_MINDLIN", STIFFNESS_MINDLIN),
        ("STIFFNESS_RATIO", STIFFNESS_RATIO),
        ("ROLLING_NONE", ROLLING_NONE),
        ("ROLLING_SDS", ROLLING_SDS),
        ("TWISTING_NONE", TWISTING_NONE),
        ("TWISTING_OQUENDO", TWISTING_OQUENDO),
        ("COHESION_NONE", COHESION_NONE),
        ("COHESION_CAPILLARY", COHESION_CAPILLARY),
    ];
}

impl<T> NormalLaw<T> {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            NormalLaw::Hertz => code::NORMAL_HERTZ,
            NormalLaw::Linear { .. } => code::NORMAL_LINEAR,
        }
    }
}

impl<T> DampingLaw<T> {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            DampingLaw::None => code::DAMPING_NONE,
            DampingLaw::Papers => code::DAMPING_PAPERS,
            DampingLaw::Restitution => code::DAMPING_RESTITUTION,
            DampingLaw::Viscous { .. } => code::DAMPING_VISCOUS,
        }
    }
}

impl<T> TangentialLaw<T> {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            TangentialLaw::None => code::TANGENTIAL_NONE,
            TangentialLaw::Oquendo(_) => code::TANGENTIAL_OQUENDO,
            TangentialLaw::Mindlin { .. } => code::TANGENTIAL_MINDLIN,
        }
    }
}

impl<T> TangentialStiffness<T> {
    /// The stiffness's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            TangentialStiffness::Mindlin => code::STIFFNESS_MINDLIN,
            TangentialStiffness::RatioToNormal(_) => code::STIFFNESS_RATIO,
        }
    }
}

impl<T> RollingLaw<T> {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            RollingLaw::None => code::ROLLING_NONE,
            RollingLaw::Sds { .. } => code::ROLLING_SDS,
        }
    }
}

impl TwistingLaw {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            TwistingLaw::None => code::TWISTING_NONE,
            TwistingLaw::Oquendo => code::TWISTING_OQUENDO,
        }
    }
}

impl<T> CohesionLaw<T> {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            CohesionLaw::None => code::COHESION_NONE,
            CohesionLaw::Capillary { .. } => code::COHESION_CAPILLARY,
        }
    }
}

/// Elastic normal law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NormalLaw<T> {
    /// Hertz: `F = 4/3 sqrt(R_eff) V_eff h^(3/2)` (Oquendo et al. eq. 1).
    Hertz,
    /// Linear spring: `F = k_n h`, `k_n` in N/m.
    Linear {
        /// Spring stiffness (N/m).
        k_n: T,
    },
}

/// Normal dissipation law, added to the elastic force before the no-pull clamp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DampingLaw<T> {
    /// No normal dissipation.
    None,
    /// The papers' nonlinear damping `-m_eff gamma_n sqrt(h) v_n` (Oquendo et al. eq. 1),
    /// `gamma_n` (s^-1 m^-1/2) from the materials.
    Papers,
    /// Viscous damping that gives a binary impact the restitution coefficient `e` of the
    /// materials, shaped as LIGGGHTS' `coefficientRestitution` (Hertz:
    /// `eta = 2 sqrt(5/6) beta sqrt(S_n m_eff)`, `S_n = 2 V_eff sqrt(R_eff h)`; linear:
    /// `eta = 2 beta sqrt(k_n m_eff)`), its ratio `beta` found for the law as it runs, with or
    /// without the clamp ([`restitution::dashpot_ratio`]).
    Restitution,
    /// Constant viscous coefficient `c_n` (N s/m): `-c_n v_n`.
    Viscous {
        /// Dashpot coefficient (N s/m).
        c_n: T,
    },
}

/// How the tangential spring stiffness `k_t` (N/m) is set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TangentialStiffness<T> {
    /// Mindlin: `k_t = 8 G_eff sqrt(R_eff h)` (Hertz normal law only).
    Mindlin,
    /// A fixed ratio to the normal secant stiffness `F_elastic / h`.
    RatioToNormal(T),
}

/// Tangential law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TangentialLaw<T> {
    /// Frictionless.
    None,
    /// Oquendo et al.'s three regimes: static (history spring up to `mu_s`), sliding (at `mu_k`
    /// once the spring's Coulomb test fails, until it unloads), rolling (eqs. 8-9's friction
    /// once a rolling spring reaches `tan(theta_r) |F_n|`, when not sliding); see
    /// [`oquendo_tangential`].
    Oquendo(OquendoLaw<T>),
    /// Standard Hertz-Mindlin with history and one Coulomb `mu` (the materials' `mu_s`), as
    /// LAMMPS `tangential mindlin` / LIGGGHTS `tangential history`.
    Mindlin {
        /// Tangential damping as a fraction of the normal damping coefficient (LAMMPS
        /// `x_gammat`; 0.9075 reproduces LIGGGHTS for nu = 0.3).
        damping_ratio: T,
        /// Spring stiffness.
        stiffness: TangentialStiffness<T>,
    },
}

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

/// Rolling-resistance law (the momentum-conserving alternative to Oquendo et al.'s rolling regime).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RollingLaw<T> {
    /// No rolling resistance.
    None,
    /// Elastic-plastic spring-dashpot on the rolling displacement (as LAMMPS `rolling sds`):
    /// `F_r = -k_r psi - gamma_r v_rl`, capped at `mu_r F_n`; torque on i `R_eff n x F_r`.
    Sds {
        /// Rolling stiffness (N/m).
        k_r: T,
        /// Rolling damping (N s/m).
        gamma_r: T,
        /// Rolling friction coefficient (-).
        mu_r: T,
    },
}

/// Twisting law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TwistingLaw {
    /// No twisting torque.
    None,
    /// Oquendo et al. eq. 2: `tau_i = -4 pi gamma_nt m_eff R_eff h w_n`.
    Oquendo,
}

/// Cohesion law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CohesionLaw<T> {
    /// No cohesion.
    None,
    /// Capillary bridges (Richefeu et al. (2009) eqs. 1-8), per-pair liquid volume as history.
    Capillary {
        /// `kappa = 2 pi gamma_s cos(theta)` (N/m).
        kappa: T,
        /// Contact angle (rad).
        theta: T,
        /// The decay-length constant `c` (0.9 in Richefeu et al. (2009)).
        c: T,
    },
}

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

/// Which per-contact history blocks exist: world-frame 3-vectors (m) and single reals; a
/// block a model does not use is not allocated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HistoryLayout {
    /// Accumulated tangential spring displacement `xi` (m).
    pub tangential: bool,
    /// The normal velocity at the previous evaluation (m/s), one real: damped laws, whose
    /// dashpot sees the velocity carried forward from it ([`window`]).
    pub normal: bool,
    /// Whether the contact is sliding (one real, 0 or 1): friction with two coefficients.
    pub sliding: bool,
    /// Accumulated rolling displacement `psi` (m): the rolling law's, or Oquendo et al.'s rolling
    /// spring.
    pub rolling: bool,
    /// Liquid bridge volume `V_b` (m^3), one real.
    pub bridge: bool,
}

impl HistoryLayout {
    /// Reals a contact's history holds: 3 per spring, 1 for the normal velocity, 1 for the
    /// sliding flag, 1 for a bridge.
    pub fn reals(&self) -> usize {
        3 * self.tangential as usize + self.normal as usize + self.sliding as usize + 3 * self.rolling as usize + self.bridge as usize
    }
}

/// Per-contact history, world frame, zero when a contact forms.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct History<T> {
    /// Tangential spring displacement `xi` (m).
    pub tangential: Vec3<T>,
    /// The normal velocity the contact forces drive at the previous evaluation (m/s,
    /// [`driven_normal_velocity`]); 0 in a new contact.
    pub v_n: T,
    /// Sliding at the last evaluation (Oquendo et al.'s regimes).
    pub sliding: bool,
    /// Rolling spring displacement `psi` (m).
    pub rolling: Vec3<T>,
    /// Liquid bridge volume (m^3); 0 without a bridge.
    pub bridge: T,
}

/// Coefficients of one pair of materials (see [`PairCoeffs::mix`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairCoeffs<T> {
    /// `V_eff = V_i V_j / (V_i + V_j)` (Pa), `V = E / (1 - nu^2)`.
    pub v_eff: T,
    /// Mindlin `G_eff`: `1/G_eff = (2 - nu_i)/G_i + (2 - nu_j)/G_j` (Pa).
    pub g_eff: T,
    /// Static friction coefficient (-).
    pub mu_s: T,
    /// Kinetic friction coefficient (-).
    pub mu_k: T,
    /// `tan(theta_r)` of the rolling angle (-).
    pub tan_roll: T,
    /// Papers' normal damping `gamma_n` (s^-1 m^-1/2).
    pub gamma_n: T,
    /// Twisting damping `gamma_nt` (s^-1).
    pub gamma_nt: T,
    /// Dashpot ratio `beta` (-) of `damping = "restitution"`, found for the mean restitution
    /// of the two materials ([`restitution::dashpot_ratio`]); 0 under other damping laws.
    pub beta: T,
}

/// The mechanical constants of one material, in SI units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialConstants {
    /// Young's modulus (Pa).
    pub youngs_modulus: f64,
    /// Poisson ratio (-).
    pub poisson_ratio: f64,
    /// Static friction coefficient (-).
    pub mu_s: f64,
    /// Kinetic friction coefficient (-).
    pub mu_k: f64,
    /// Rolling angle `theta_r` (rad).
    pub rolling_angle: f64,
    /// `gamma_n` (s^-1 m^-1/2).
    pub gamma_n: f64,
    /// `gamma_nt` (s^-1).
    pub gamma_nt: f64,
    /// Restitution coefficient (-), used by [`DampingLaw::Restitution`].
    pub restitution: f64,
}

impl MaterialConstants {
    /// `V = E / (1 - nu^2)` (Pa).
    pub fn stiffness(&self) -> f64 {
        self.youngs_modulus / (1.0 - self.poisson_ratio * self.poisson_ratio)
    }
    /// Shear modulus `G = E / (2 (1 + nu))` (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

impl<T: Real> PairCoeffs<T> {
    /// Coefficients for a contact between materials `a` and `b`. Elastic constants combine
    /// as docs/physics.md rules; friction coefficients and the rolling angle take the smaller of
    /// the two (as YADE does: a frictionless wall makes frictionless contacts); damping and
    /// restitution take the arithmetic mean. Equal materials give their own values. The
    /// dashpot ratio is sized for `model`'s normal law and clamp.
    pub fn mix(a: &MaterialConstants, b: &MaterialConstants, model: &ContactModel<f64>) -> Self {
        let (va, vb) = (a.stiffness(), b.stiffness());
        let g_inv = (2.0 - a.poisson_ratio) / a.shear_modulus() + (2.0 - b.poisson_ratio) / b.shear_modulus();
        let mean = |x: f64, y: f64| 0.5 * (x + y);
        PairCoeffs {
            v_eff: T::of(va * vb / (va + vb)),
            g_eff: T::of(1.0 / g_inv),
            mu_s: T::of(a.mu_s.min(b.mu_s)),
            mu_k: T::of(a.mu_k.min(b.mu_k)),
            tan_roll: T::of(a.rolling_angle.min(b.rolling_angle).tan()),
            gamma_n: T::of(mean(a.gamma_n, b.gamma_n)),
            gamma_nt: T::of(mean(a.gamma_nt, b.gamma_nt)),
            beta: T::of(match model.damping {
                DampingLaw::Restitution => {
                    let spring = match model.normal {
                        NormalLaw::Hertz => restitution::Spring::Hertz,
                        NormalLaw::Linear { .. } => restitution::Spring::Linear,
                    };
                    restitution::dashpot_ratio(mean(a.restitution, b.restitution), spring, model.limit_damping)
                }
                _ => 0.0,
            }),
        }
    }
}

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
    /// Elastic + damping normal force after the no-pull clamp (N, compressive positive).
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
    let (f_el, k_secant) = normal_elastic(&model.normal, c, geo);
    let eta_n = normal_damping(&model.damping, &model.normal, c, geo);
    let driven = driven_normal_velocity(kin.v_i, kin.v_j, geo.n, bodies.j_is_wall);
    let (f_n, clamped) = windowed_normal_force(model, c, geo, f_el, eta_n, v_n, driven - hist.v_n, window);
    hist.v_n = driven;
    let mut out = ContactForce { f_i: geo.n * f_n, f_j: geo.n * (-f_n), f_n, clamped, ..Default::default() };
    // The friction limits take the normal force's magnitude: unclamped, the dashpot can pull.
    let f_n = f_n.abs();
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
fn tangential_stiffness<T: Real>(s: &TangentialStiffness<T>, c: &PairCoeffs<T>, geo: &Geometry<T>, k_secant: T) -> T {
    match *s {
        TangentialStiffness::Mindlin => T::of(8.0) * c.g_eff * (geo.r_eff * geo.h).sqrt(),
        TangentialStiffness::RatioToNormal(r) => r * k_secant,
    }
}

/// Elastic potential energy (J) stored in the normal spring of a contact with overlap `h`:
/// Hertz `8/15 sqrt(R_eff) V_eff h^(5/2)`, linear `k_n h^2 / 2`.
#[inline]
pub fn normal_potential<T: Real>(law: &NormalLaw<T>, c: &PairCoeffs<T>, r_eff: T, h: T) -> T {
    match *law {
        NormalLaw::Hertz => T::of(8.0 / 15.0) * r_eff.sqrt() * c.v_eff * h * h * h.sqrt(),
        NormalLaw::Linear { k_n } => T::of(0.5) * k_n * h * h,
    }
}

impl ContactModel<f64> {
    /// The same model in another precision.
    pub fn cast<U: Real>(&self) -> ContactModel<U> {
        let u = U::of;
        let stiffness = |s: TangentialStiffness<f64>| match s {
            TangentialStiffness::Mindlin => TangentialStiffness::Mindlin,
            TangentialStiffness::RatioToNormal(r) => TangentialStiffness::RatioToNormal(u(r)),
        };
        ContactModel {
            normal: match self.normal {
                NormalLaw::Hertz => NormalLaw::Hertz,
                NormalLaw::Linear { k_n } => NormalLaw::Linear { k_n: u(k_n) },
            },
            damping: match self.damping {
                DampingLaw::None => DampingLaw::None,
                DampingLaw::Papers => DampingLaw::Papers,
                DampingLaw::Restitution => DampingLaw::Restitution,
                DampingLaw::Viscous { c_n } => DampingLaw::Viscous { c_n: u(c_n) },
            },
            tangential: match self.tangential {
                TangentialLaw::None => TangentialLaw::None,
                TangentialLaw::Oquendo(l) => TangentialLaw::Oquendo(OquendoLaw { static_damping: u(l.static_damping), stiffness: stiffness(l.stiffness), rolling_friction: l.rolling_friction }),
                TangentialLaw::Mindlin { damping_ratio, stiffness: s } => TangentialLaw::Mindlin { damping_ratio: u(damping_ratio), stiffness: stiffness(s) },
            },
            rolling: match self.rolling {
                RollingLaw::None => RollingLaw::None,
                RollingLaw::Sds { k_r, gamma_r, mu_r } => RollingLaw::Sds { k_r: u(k_r), gamma_r: u(gamma_r), mu_r: u(mu_r) },
            },
            twisting: self.twisting,
            cohesion: match self.cohesion {
                CohesionLaw::None => CohesionLaw::None,
                CohesionLaw::Capillary { kappa, theta, c } => CohesionLaw::Capillary { kappa: u(kappa), theta: u(theta), c: u(c) },
            },
            limit_damping: self.limit_damping,
        }
    }

    /// One line naming the law in each slot, for reports.
    pub fn describe(&self) -> String {
        let normal = match self.normal {
            NormalLaw::Hertz => "hertz".to_string(),
            NormalLaw::Linear { k_n } => format!("linear(k_n={k_n:e} N/m)"),
        };
        let damping = match self.damping {
            DampingLaw::None => "none".to_string(),
            DampingLaw::Papers => "papers(gamma_n)".to_string(),
            DampingLaw::Restitution => "restitution(e)".to_string(),
            DampingLaw::Viscous { c_n } => format!("viscous(c_n={c_n:e} N s/m)"),
        };
        let stiff = |s: TangentialStiffness<f64>| match s {
            TangentialStiffness::Mindlin => "k_t=mindlin".to_string(),
            TangentialStiffness::RatioToNormal(r) => format!("k_t={r}*k_n"),
        };
        let tangential = match self.tangential {
            TangentialLaw::None => "none".to_string(),
            TangentialLaw::Oquendo(l) => format!("oquendo(static_damping={}, rolling_friction={}, {})", l.static_damping, l.rolling_friction.name(), stiff(l.stiffness)),
            TangentialLaw::Mindlin { damping_ratio, stiffness } => format!("mindlin(damping_ratio={damping_ratio}, {})", stiff(stiffness)),
        };
        let rolling = match self.rolling {
            RollingLaw::None => "none".to_string(),
            RollingLaw::Sds { k_r, gamma_r, mu_r } => format!("sds(k_r={k_r:e}, gamma_r={gamma_r:e}, mu_r={mu_r})"),
        };
        let twisting = match self.twisting {
            TwistingLaw::None => "none",
            TwistingLaw::Oquendo => "oquendo(gamma_nt)",
        };
        let cohesion = match self.cohesion {
            CohesionLaw::None => "none".to_string(),
            CohesionLaw::Capillary { kappa, theta, c } => format!("capillary(kappa={kappa:e} N/m, theta={:.1} deg, c={c})", theta.to_degrees()),
        };
        let clamp = if self.limit_damping { "on" } else { "off" };
        format!("normal={normal} damping={damping} no-pull clamp={clamp} tangential={tangential} rolling={rolling} twisting={twisting} cohesion={cohesion}")
    }
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
        let c = PairCoeffs::mix(&sand(), &sand(), &restitution_model(NormalLaw::Hertz, true));
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
        let linear: PairCoeffs<f64> = PairCoeffs::mix(&sand(), &sand(), &restitution_model(NormalLaw::Linear { k_n: 1.0e3 }, false));
        assert!(close(linear.beta, ln2 / (ln2 * ln2 + pi * pi).sqrt()));
        let papers = ContactModel { damping: DampingLaw::Papers, ..restitution_model(NormalLaw::Hertz, true) };
        assert_eq!(PairCoeffs::<f64>::mix(&sand(), &sand(), &papers).beta, 0.0, "no dashpot ratio without restitution damping");
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
        let (f, k) = normal_elastic(&NormalLaw::Hertz, &c, &g);
        // 4/3 sqrt(2.5e-4) 3.846153846e7 (1e-6)^1.5
        let hand = 4.0 / 3.0 * 0.015811388300841896 * (7.0e7 / 0.91 / 2.0) * 1.0e-9;
        assert!(close(f, hand) && close(k, hand / 1.0e-6));
        // m_eff gamma_n sqrt(h) = 6.9375e-7 * 1e5 * 1e-3
        assert!(close(normal_damping(&DampingLaw::Papers, &NormalLaw::Hertz, &c, &g), 6.9375e-7 * 1.0e5 * 1.0e-3));
        assert_eq!(normal_force(1.0, 2.0, -0.25, true), (1.5, false));
        assert_eq!(normal_force(1.0, 2.0, 1.0, true), (0.0, true));
        assert_eq!(normal_force(1.0, 2.0, 1.0, false), (-1.0, false), "unclamped, the dashpot pulls");
        assert!(close(normal_potential(&NormalLaw::Hertz, &c, g.r_eff, g.h), 0.4 * hand * 1.0e-6));
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
