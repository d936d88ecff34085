//! The normal slot: a contact's elastic normal force, one module per law. Each law's module owns
//! its scene keys and their checks (its registry [`Entry`]), its physics ([`NormalModel`], generic over
//! the precision), what the scene's setup asks of it ([`NormalSetup`]: its description, time
//! scale, dashpot shape, GPU parameter block) and its WGSL (`shaders/shared/model/normal.wgsl`,
//! which mirrors this folder). The registry below, one row per law, builds [`NormalLaw`], its
//! dispatch and [`SLOT`]; a law's WGSL code is its row's index, written into the kernels'
//! prelude ([`crate::model::wgsl_codes`]). Adding a law: docs/architecture.md, "Adding a
//! contact law".

mod dmt;
mod hertz;
mod linear;

pub use dmt::Dmt;
pub use hertz::{hertz_collision_time, Hertz};
pub use linear::Linear;

use super::registry::{Entry, Slot};
use super::{restitution, Geometry, PairCoeffs, TangentialStiffness};
use crate::real::Real;

/// A normal law's physics, in either precision. `h > 0` in contact; forces are compressive
/// positive.
pub trait NormalModel<T: Real> {
    /// Elastic force magnitude `F_el` (N, repulsive positive) at overlap `g.h`, and the secant
    /// stiffness `F_el / h` (N/m) that ratio-based tangential springs scale from.
    fn elastic(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> (T, T);
    /// Tangent stiffness `dF_el/dh` (N/m).
    fn stiffness(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T;
    /// The coefficient `eta` (kg/s) of `damping = "restitution"`'s dashpot, shaped to this law
    /// from the pair's dashpot ratio `c.beta`.
    fn restitution_damping(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T;
    /// Elastic potential energy (J) at overlap `h` (m), reduced radius `r_eff` (m), zero at
    /// touch: `F_el = dU/dh` (adhesion included).
    fn potential(&self, c: &PairCoeffs<T>, r_eff: T, h: T) -> T;
    /// The exponent `p` of the overlap in `F_el ~ h^p` (the window means of
    /// [`super::window`]).
    fn exponent(&self) -> T;
    /// An adhesive law's pull-off force (N, positive), subtracted from the normal force after
    /// the no-pull clamp while the surfaces touch; `None` for a law that never pulls.
    #[inline(always)]
    fn pull_off(&self, _g: &Geometry<T>) -> Option<T> {
        None
    }
}

/// What a scene's setup asks of a normal law (in f64, before the engines cast it).
pub trait NormalSetup {
    /// One phrase naming the law and its constants, for reports.
    fn describe(&self) -> String;
    /// The spring the restitution dashpot's ratio is found for ([`restitution::dashpot_ratio`]).
    fn spring(&self) -> restitution::Spring;
    /// The collision time (s) of a pair of reduced mass `m_eff` (kg) and radius `r_eff` (m),
    /// mixed modulus `v_eff` (Pa), meeting at `v` (m/s): the automatic time step's scale.
    fn collision_time(&self, m_eff: f64, r_eff: f64, v_eff: f64, v: f64) -> f64;
    /// Whether the law's stiffness is the materials' moduli (so that the Rayleigh time bounds
    /// the step) rather than a constant of its own.
    fn uses_moduli(&self) -> bool;
    /// The tangential spring's stiffness when the scene gives no `kt_ratio`.
    fn default_tangential_stiffness(&self) -> TangentialStiffness<f64>;
    /// Whether the law pulls grains in contact together ([`NormalModel::pull_off`]): contact
    /// dynamics' rigid contacts refuse it.
    fn adhesive(&self) -> bool {
        false
    }
    /// The law's constants as the kernels read them, `params.normal` (WGSL): a block of fixed
    /// size, so that a law's parameters never move the uniform's layout.
    fn gpu_block(&self) -> glam::Vec4;
}

/// The registry: one row per law, `Variant(Type) in module`. It declares [`NormalLaw`], its
/// dispatch to the law's traits, its cast between precisions and [`SLOT`], in this order
/// (a law's WGSL code is its index).
macro_rules! normal_laws {
    ($($variant:ident($ty:ty) in $module:ident),* $(,)?) => {
        /// The elastic normal law of a scene's contacts.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum NormalLaw<T> {
            $(
                #[doc = concat!("See [`", stringify!($module), "`].")]
                $variant($ty),
            )*
        }

        /// The normal laws, in the order of their WGSL codes (`NORMAL_<NAME>`).
        pub const SLOT: Slot<NormalLaw<f64>> = Slot { name: "normal", laws: &[$($module::ENTRY),*] };

        impl<T: Real> NormalModel<T> for NormalLaw<T> {
            #[inline(always)]
            fn elastic(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> (T, T) {
                match self { $(NormalLaw::$variant(l) => l.elastic(c, g)),* }
            }
            #[inline(always)]
            fn stiffness(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
                match self { $(NormalLaw::$variant(l) => l.stiffness(c, g)),* }
            }
            #[inline(always)]
            fn restitution_damping(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
                match self { $(NormalLaw::$variant(l) => l.restitution_damping(c, g)),* }
            }
            #[inline(always)]
            fn potential(&self, c: &PairCoeffs<T>, r_eff: T, h: T) -> T {
                match self { $(NormalLaw::$variant(l) => l.potential(c, r_eff, h)),* }
            }
            #[inline(always)]
            fn exponent(&self) -> T {
                match self { $(NormalLaw::$variant(l) => l.exponent()),* }
            }
            #[inline(always)]
            fn pull_off(&self, g: &Geometry<T>) -> Option<T> {
                match self { $(NormalLaw::$variant(l) => l.pull_off(g)),* }
            }
        }

        impl NormalSetup for NormalLaw<f64> {
            fn describe(&self) -> String {
                match self { $(NormalLaw::$variant(l) => l.describe()),* }
            }
            fn spring(&self) -> restitution::Spring {
                match self { $(NormalLaw::$variant(l) => l.spring()),* }
            }
            fn collision_time(&self, m_eff: f64, r_eff: f64, v_eff: f64, v: f64) -> f64 {
                match self { $(NormalLaw::$variant(l) => l.collision_time(m_eff, r_eff, v_eff, v)),* }
            }
            fn uses_moduli(&self) -> bool {
                match self { $(NormalLaw::$variant(l) => l.uses_moduli()),* }
            }
            fn default_tangential_stiffness(&self) -> TangentialStiffness<f64> {
                match self { $(NormalLaw::$variant(l) => l.default_tangential_stiffness()),* }
            }
            fn adhesive(&self) -> bool {
                match self { $(NormalLaw::$variant(l) => l.adhesive()),* }
            }
            fn gpu_block(&self) -> glam::Vec4 {
                match self { $(NormalLaw::$variant(l) => l.gpu_block()),* }
            }
        }

        impl NormalLaw<f64> {
            /// The same law in another precision.
            pub fn cast<U: Real>(&self) -> NormalLaw<U> {
                match self { $(NormalLaw::$variant(l) => NormalLaw::$variant(l.cast())),* }
            }

            /// The law's row in [`SLOT`]: its WGSL code.
            pub fn code(&self) -> u32 {
                let mut code = 0u32;
                $(
                    if let NormalLaw::$variant(_) = self {
                        return code;
                    }
                    code += 1;
                )*
                unreachable!("every law has a row, code {code}")
            }
        }
    };
}

normal_laws! {
    Hertz(Hertz) in hertz,
    Linear(Linear<T>) in linear,
    Dmt(Dmt<T>) in dmt,
}
