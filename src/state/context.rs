//! What every invocation of a force pass shares: the contact law per slot, the pairs'
//! coefficients by material, the history's layout, the time the springs advance by, the
//! window the forces stand for, wrapping and compensated positions.

use super::{material_at, Body, HistorySlots};
use crate::model::{ContactModel, PairCoeffs};
use crate::periodic::Periodic;
use crate::real::{Real, Vec3};

/// What every invocation of a force pass shares.
#[derive(Clone, Copy, Debug)]
pub struct ForceContext<'a, T> {
    /// Contact law per slot.
    pub model: &'a ContactModel<T>,
    /// Pair coefficients, `[material_i * n_materials + material_j]`.
    pub coeffs: &'a [PairCoeffs<T>],
    /// Number of materials.
    pub n_materials: usize,
    /// History block layout.
    pub slots: HistorySlots,
    /// Time since the previous force evaluation (s).
    pub elapsed: T,
    /// The span of kicks (s) the evaluation's forces stand for, centred on it: the step
    /// under velocity Verlet, 0 otherwise ([`crate::model::window`]).
    pub window: T,
    /// Wrapping axes.
    pub periodic: Periodic<T>,
    /// The positions' residuals by slot ([`crate::position`]; empty in f64).
    pub residual: &'a [Vec3<T>],
    /// Material index by slot; empty in a scene of one material, whose grains are all 0.
    pub material: &'a [u32],
    /// The mesh walls' surfaces, by [`crate::walls::WallGeom::Mesh`]'s index.
    pub meshes: &'a [crate::mesh::MeshSurface<T>],
}

impl<'a, T: Real> ForceContext<'a, T> {
    /// Material index of slot `i`.
    #[inline(always)]
    pub fn material(&self, i: usize) -> usize {
        material_at(self.material, i)
    }

    /// The coefficients of slots `i` and `j`'s materials.
    #[inline(always)]
    pub fn pair_coeffs(&self, i: usize, j: usize) -> &'a PairCoeffs<T> {
        coeffs_of(self.coeffs, self.n_materials, self.material(i), self.material(j))
    }

    /// The coefficients of a wall of material `wall` against a grain of material `grain`.
    #[inline(always)]
    pub fn wall_coeffs(&self, wall: u32, grain: usize) -> &'a PairCoeffs<T> {
        coeffs_of(self.coeffs, self.n_materials, wall as usize, grain)
    }

    /// Whether a contact that has parted can still pull ([`crate::model::window::ends_pull`]).
    #[inline(always)]
    pub fn ends_pull(&self) -> bool {
        crate::model::window::ends_pull(self.model, self.window)
    }

    /// The separation `r_i - r_j` of slots `i` and `j` (m, minimum image, residuals included).
    #[inline(always)]
    pub fn separation(&self, body: &[Body<T>], i: usize, j: usize) -> Vec3<T> {
        crate::position::separation_of(&self.periodic, |k| body[k].pos, self.residual, i, j)
    }
}

/// The coefficients of materials `a` and `b` in a table of `n_materials` squared
/// (`[a * n_materials + b]`).
#[inline(always)]
pub fn coeffs_of<T>(coeffs: &[PairCoeffs<T>], n_materials: usize, a: usize, b: usize) -> &PairCoeffs<T> {
    &coeffs[a * n_materials + b]
}
