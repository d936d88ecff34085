//! DMT adhesion (Derjaguin, Muller & Toporov 1975, doi:10.1016/0021-9797(75)90018-1), as LAMMPS'
//! `pair granular` normal model `dmt`: Hertz's elastic force less a constant pull-off
//! `F_po = 4 pi gamma R_eff` while the surfaces touch,
//! `F_ne = 4/3 V_eff sqrt(R_eff) h^(3/2) - 4 pi gamma R_eff`, with `gamma` the surface energy
//! (J/m^2). It acts only in contact (`h > 0`): the pull drops to zero as the surfaces part.
//! Scene: `normal = "dmt"`, `surface_energy` required.
//!
//! As in LAMMPS, the friction limits take `|F_ne + 2 F_po|` (the elastic force plus the
//! pull-off, without the dashpot), and the dashpot and its restitution are Hertz's. Beyond
//! LAMMPS, which refuses `limit_damping` with `dmt` (clamping the sum would cancel the
//! adhesion): the no-pull clamp holds the Hertz and damping force at zero where the dashpot
//! would pull, and the pull-off is added after it, as a capillary bridge's pull is. Without
//! the clamp the two agree.

use super::{Entry, Hertz, NormalLaw, NormalModel, NormalSetup};
use crate::model::keys::{required_positive, LawInput};
use crate::model::{restitution, Geometry, PairCoeffs, TangentialStiffness};
use crate::real::Real;

/// The DMT law's surface energy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dmt<T> {
    /// Surface energy `gamma` (J/m^2): the pull-off force is `4 pi gamma R_eff`.
    pub surface_energy: T,
}

/// The registry's row.
pub(super) const ENTRY: Entry<NormalLaw<f64>> = Entry {
    name: "dmt",
    keys: &["surface_energy"],
    parse: |input: &LawInput| Ok(NormalLaw::Dmt(Dmt { surface_energy: required_positive(input.keys, "surface_energy", "give the surface energy gamma in J/m^2, e.g. 0.05")? })),
};

impl Dmt<f64> {
    /// The same law in another precision.
    pub fn cast<U: Real>(&self) -> Dmt<U> {
        Dmt { surface_energy: U::of(self.surface_energy) }
    }
}

impl<T: Real> Dmt<T> {
    /// The pull-off force `4 pi gamma R_eff` (N) at reduced radius `r_eff` (m).
    #[inline(always)]
    fn pull_off_at(&self, r_eff: T) -> T {
        T::of(4.0 * std::f64::consts::PI) * self.surface_energy * r_eff
    }
}

impl<T: Real> NormalModel<T> for Dmt<T> {
    #[inline(always)]
    fn elastic(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> (T, T) {
        Hertz.elastic(c, g)
    }

    #[inline(always)]
    fn stiffness(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
        Hertz.stiffness(c, g)
    }

    #[inline(always)]
    fn restitution_damping(&self, c: &PairCoeffs<T>, g: &Geometry<T>) -> T {
        Hertz.restitution_damping(c, g)
    }

    /// Hertz's energy less the pull-off's work, `-F_po h`: zero at touch, so the energy jumps
    /// by nothing when the surfaces meet or part.
    #[inline(always)]
    fn potential(&self, c: &PairCoeffs<T>, r_eff: T, h: T) -> T {
        Hertz.potential(c, r_eff, h) - self.pull_off_at(r_eff) * h
    }

    #[inline(always)]
    fn exponent(&self) -> T {
        <Hertz as NormalModel<T>>::exponent(&Hertz)
    }

    #[inline(always)]
    fn pull_off(&self, g: &Geometry<T>) -> Option<T> {
        Some(self.pull_off_at(g.r_eff))
    }
}

impl NormalSetup for Dmt<f64> {
    fn describe(&self) -> String {
        format!("dmt(surface_energy={:e} J/m^2)", self.surface_energy)
    }

    fn spring(&self) -> restitution::Spring {
        restitution::Spring::Hertz
    }

    fn collision_time(&self, m_eff: f64, r_eff: f64, v_eff: f64, v: f64) -> f64 {
        Hertz.collision_time(m_eff, r_eff, v_eff, v)
    }

    fn uses_moduli(&self) -> bool {
        true
    }

    fn default_tangential_stiffness(&self) -> TangentialStiffness<f64> {
        TangentialStiffness::Mindlin
    }

    fn adhesive(&self) -> bool {
        true
    }

    fn gpu_block(&self) -> glam::Vec4 {
        glam::Vec4::new(self.surface_energy as f32, 0.0, 0.0, 0.0)
    }
}
