//! The law of each slot (normal, damping, tangential, rolling, twisting, cohesion) with its
//! parameters, and the codes that name each law to the WGSL kernels.


/// The codes by which the WGSL kernels know each law (WGSL constants of the same names in
/// `shaders/shared/model.wgsl`, checked against these by `tests/shaders.rs`); each law's
/// `code()` gives its own.
pub mod code {
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

impl<T> CohesionLaw<T> {
    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        match self {
            CohesionLaw::None => code::COHESION_NONE,
            CohesionLaw::Capillary { .. } => code::COHESION_CAPILLARY,
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

impl RollingFriction {
    /// Name as written in scenes.
    pub fn name(self) -> &'static str {
        match self {
            RollingFriction::Torque => "torque",
            RollingFriction::AsWritten => "as_written",
        }
    }
}

// Each slot's constants as the kernels read them: a block of four f32 per slot (WGSL
// `params.<slot>`), so that a law's parameters never move the uniform's layout. Unused
// components are zero.

impl DampingLaw<f64> {
    /// `[c_n, 0, 0, 0]` for the viscous dashpot (N s/m).
    pub fn gpu_block(&self) -> glam::Vec4 {
        match *self {
            DampingLaw::Viscous { c_n } => glam::Vec4::new(c_n as f32, 0.0, 0.0, 0.0),
            _ => glam::Vec4::ZERO,
        }
    }
}

impl TangentialLaw<f64> {
    /// `[k_t ratio, Hertz-Mindlin damping ratio, Oquendo et al.'s spring damping, 0]`.
    pub fn gpu_block(&self) -> glam::Vec4 {
        let ratio = |s: TangentialStiffness<f64>| match s {
            TangentialStiffness::RatioToNormal(r) => r as f32,
            TangentialStiffness::Mindlin => 0.0,
        };
        match *self {
            TangentialLaw::None => glam::Vec4::ZERO,
            TangentialLaw::Oquendo(l) => glam::Vec4::new(ratio(l.stiffness), 0.0, l.static_damping as f32, 0.0),
            TangentialLaw::Mindlin { damping_ratio, stiffness } => glam::Vec4::new(ratio(stiffness), damping_ratio as f32, 0.0, 0.0),
        }
    }
}

impl RollingLaw<f64> {
    /// `[k_r, gamma_r, mu_r, 0]` of the sds law.
    pub fn gpu_block(&self) -> glam::Vec4 {
        match *self {
            RollingLaw::None => glam::Vec4::ZERO,
            RollingLaw::Sds { k_r, gamma_r, mu_r } => glam::Vec4::new(k_r as f32, gamma_r as f32, mu_r as f32, 0.0),
        }
    }
}

impl CohesionLaw<f64> {
    /// `[kappa, theta, c, volume_cap]` of capillary bridges, `volume_cap` (m^3) the largest
    /// bridge's volume (the scene's).
    pub fn gpu_block(&self, volume_cap: f64) -> glam::Vec4 {
        match *self {
            CohesionLaw::None => glam::Vec4::new(0.0, 0.0, 0.0, volume_cap as f32),
            CohesionLaw::Capillary { kappa, theta, c } => glam::Vec4::new(kappa as f32, theta as f32, c as f32, volume_cap as f32),
        }
    }
}
