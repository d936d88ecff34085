//! The tangential slot: friction at the contact point, one module per law with history
//! ([`oquendo`]: Oquendo et al.'s sliding / rolling / static regimes; [`mindlin`]: the
//! standard Hertz-Mindlin history law), the springs' shared geometry below. WGSL twin:
//! `shaders/shared/model/tangential.wgsl`.

mod mindlin;
mod oquendo;

pub use mindlin::mindlin_tangential;
pub use oquendo::{oquendo_tangential, OquendoLaw, RollingFriction, TangentialOut};

use super::keys::{required_positive, KeyProblem, LawInput};
use super::registry::{Entry, Slot};
use super::{Geometry, History, Kinematics, NormalSetup};
use crate::real::{Real, Vec3};

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

/// How the tangential spring stiffness `k_t` (N/m) is set (`kt_ratio`, read by both laws with
/// a spring).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TangentialStiffness<T> {
    /// Mindlin: `k_t = 8 G_eff sqrt(R_eff h)` (Hertz normal law only).
    Mindlin,
    /// A fixed ratio to the normal secant stiffness `F_elastic / h`.
    RatioToNormal(T),
}

/// The tangential laws, in the order of their WGSL codes (`TANGENTIAL_<NAME>`).
pub const SLOT: Slot<TangentialLaw<f64>> = Slot {
    name: "tangential",
    laws: &[Entry { name: "none", keys: &[], parse: |_: &LawInput| Ok(TangentialLaw::None) }, oquendo::ENTRY, mindlin::ENTRY],
};

/// The spring's stiffness a law with one reads (`kt_ratio` is both laws' key): `kt_ratio` times
/// the normal secant stiffness when the scene sets it, else the normal law's default.
fn stiffness_of(input: &LawInput) -> Result<TangentialStiffness<f64>, KeyProblem> {
    match input.keys.number("kt_ratio") {
        Some(_) => Ok(TangentialStiffness::RatioToNormal(required_positive(input.keys, "kt_ratio", "give a ratio such as 2/7")?)),
        None => Ok(input.normal.map_or(TangentialStiffness::Mindlin, |n| n.default_tangential_stiffness())),
    }
}

/// The stiffnesses' WGSL codes, `STIFFNESS_<NAME>` (`params.kt_law`).
pub const STIFFNESS_CODES: &[(&str, u32)] = &[("STIFFNESS_MINDLIN", 0), ("STIFFNESS_RATIO", 1)];

impl<T> TangentialLaw<T> {
    /// The law's name in scenes (its registry row's).
    pub fn name(&self) -> &'static str {
        match self {
            TangentialLaw::None => "none",
            TangentialLaw::Oquendo(_) => oquendo::ENTRY.name,
            TangentialLaw::Mindlin { .. } => mindlin::ENTRY.name,
        }
    }

    /// The law's WGSL code.
    pub fn code(&self) -> u32 {
        SLOT.code(self.name())
    }
}

impl<T> TangentialStiffness<T> {
    /// The stiffness's WGSL code, a row of [`STIFFNESS_CODES`].
    pub fn code(&self) -> u32 {
        match self {
            TangentialStiffness::Mindlin => STIFFNESS_CODES[0].1,
            TangentialStiffness::RatioToNormal(_) => STIFFNESS_CODES[1].1,
        }
    }
}

impl TangentialStiffness<f64> {
    /// The same stiffness in another precision.
    pub fn cast<U: Real>(&self) -> TangentialStiffness<U> {
        match *self {
            TangentialStiffness::Mindlin => TangentialStiffness::Mindlin,
            TangentialStiffness::RatioToNormal(r) => TangentialStiffness::RatioToNormal(U::of(r)),
        }
    }

    /// `k_t=mindlin` or `k_t=<ratio>*k_n`, for reports.
    pub fn describe(&self) -> String {
        match *self {
            TangentialStiffness::Mindlin => "k_t=mindlin".to_string(),
            TangentialStiffness::RatioToNormal(r) => format!("k_t={r}*k_n"),
        }
    }

    /// The ratio the kernels read (`params.tangential.x`), 0 for Mindlin's stiffness.
    fn gpu_ratio(&self) -> f32 {
        match *self {
            TangentialStiffness::RatioToNormal(r) => r as f32,
            TangentialStiffness::Mindlin => 0.0,
        }
    }
}

impl TangentialLaw<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> TangentialLaw<U> {
        match *self {
            TangentialLaw::None => TangentialLaw::None,
            TangentialLaw::Oquendo(l) => TangentialLaw::Oquendo(l.cast()),
            TangentialLaw::Mindlin { damping_ratio, stiffness } => TangentialLaw::Mindlin { damping_ratio: U::of(damping_ratio), stiffness: stiffness.cast() },
        }
    }

    /// The law and its constants, for reports.
    pub fn describe(&self) -> String {
        match *self {
            TangentialLaw::None => "none".to_string(),
            TangentialLaw::Oquendo(l) => format!("oquendo(static_damping={}, rolling_friction={}, {})", l.static_damping, l.rolling_friction.name(), l.stiffness.describe()),
            TangentialLaw::Mindlin { damping_ratio, stiffness } => format!("mindlin(damping_ratio={damping_ratio}, {})", stiffness.describe()),
        }
    }

    /// `params.tangential` (WGSL): `[k_t ratio, Hertz-Mindlin damping ratio, Oquendo et al.'s
    /// spring damping, 0]`.
    pub fn gpu_block(&self) -> glam::Vec4 {
        match *self {
            TangentialLaw::None => glam::Vec4::ZERO,
            TangentialLaw::Oquendo(l) => glam::Vec4::new(l.stiffness.gpu_ratio(), 0.0, l.static_damping as f32, 0.0),
            TangentialLaw::Mindlin { damping_ratio, stiffness } => glam::Vec4::new(stiffness.gpu_ratio(), damping_ratio as f32, 0.0, 0.0),
        }
    }
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

/// The time (s) the springs of a contact advance by at this evaluation: `elapsed`, the time
/// since the previous one, unless the contact is new (its springs all zero, as a contact that
/// was open at the previous evaluation has them) and its surfaces met within `elapsed`: then
/// the time since they met, the overlap `h` over the approach speed `-v_n` (m/s, `v_n < 0`
/// approaching), so that a contact that starts late in a step does not count a whole step of
/// slip (LAMMPS does). A contact whose springs are zero for another reason (no tangential
/// motion yet) has an overlap of more than a step's approach, and keeps `elapsed`.
#[inline(always)]
pub fn since_touch<T: Real>(hist: &History<T>, h: T, v_n: T, elapsed: T) -> T {
    let approach = -v_n;
    let new = hist.tangential == Vec3::ZERO && hist.rolling == Vec3::ZERO;
    if new && approach * elapsed > h { h / approach } else { elapsed }
}

/// Tangential velocity of the contact points, `v_t = v_p - (v_p.n) n` with Oquendo et al. eq. 4
/// `v_p = v_i - v_j - (R'_i w_i + R'_j w_j) x n`.
#[inline(always)]
pub fn contact_tangential_velocity<T: Real>(g: &Geometry<T>, k: &Kinematics<T>) -> Vec3<T> {
    let v_p = k.v_i - k.v_j - (k.w_i * g.rp_i + k.w_j * g.rp_j).cross(g.n);
    v_p - g.n * v_p.dot(g.n)
}
