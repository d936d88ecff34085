//! `pair_force`: one invocation computes the force of one listed pair, once, in canonical
//! order (owner = lower permanent id = i), and reads and writes its history.
//!
//! The pass runs in blocks of [`BLOCK`] pairs, each compiled for the widest instruction set
//! the CPU has (see `simd`); under the standard Hertz-Mindlin model a block runs in vector
//! lanes (see `lanes`), with the same bits.

use super::pairs::PairList;
use super::state::{Body, HistorySlots, Props};
use crate::model::{capillary_force, contact_force, Bodies, CohesionLaw, ContactForce, ContactModel, Geometry, Kinematics, PairCoeffs};
use crate::periodic::Periodic;
use crate::real::Real;

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
    /// Wrapping axes.
    pub periodic: Periodic<T>,
}

/// `pair_force` for pair `k`. A listed pair that does not touch forgets its springs and
/// exerts only the capillary force of its liquid bridge, if it has one within reach.
#[inline(always)]
pub fn pair_force<T: Real>(k: usize, pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>, hist: &mut [T]) -> ContactForce<T> {
    let i = pairs.owner[k] as usize;
    let j = pairs.partner[k] as usize;
    let (bi, bj, pi, pj) = (&body[i], &body[j], &prop[i], &prop[j]);
    let d = ctx.periodic.min_image(bi.pos - bj.pos);
    let dist2 = d.norm2();
    let reach = pi.radius + pj.radius;
    if dist2 >= reach * reach {
        ctx.slots.clear_springs(hist);
        return match ctx.model.cohesion {
            CohesionLaw::Capillary { kappa, theta, c } if ctx.slots.layout.bridge && hist[ctx.slots.bridge] > T::ZERO => {
                let dist = dist2.sqrt();
                let f_c = capillary_force(kappa, theta, c, pi.radius, pj.radius, hist[ctx.slots.bridge], dist - reach);
                let n = d * (T::ONE / dist);
                ContactForce { f_i: n * f_c, f_j: n * (-f_c), f_c, ..Default::default() }
            }
            _ => ContactForce::default(),
        };
    }
    let geo = Geometry::grain_grain(d, dist2.sqrt(), pi.radius, pj.radius, pi.mass, pj.mass);
    let kin = Kinematics { v_i: bi.vel, v_j: bj.vel, w_i: bi.omega, w_j: bj.omega };
    let bodies = Bodies { m_i: pi.mass, inertia_i: pi.inertia, m_j: pj.mass, inertia_j: pj.inertia, j_is_wall: false };
    let c = &ctx.coeffs[pi.material as usize * ctx.n_materials + pj.material as usize];
    let mut h = ctx.slots.load(hist);
    let f = contact_force(ctx.model, c, &geo, &kin, &bodies, &mut h, ctx.elapsed);
    ctx.slots.store(&h, hist);
    f
}

/// Pairs per block of the pair pass.
pub const BLOCK: usize = 256;

super::simd::dispatch! {
    /// `pair_force` for pairs `first..first + out.len()`; `hist` holds their history slots
    /// (empty when the model keeps none).
    pub fn pair_block<T: Real>(first: usize, out: &mut [ContactForce<T>], hist: &mut [T], pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>) => pair_block_portable
}

/// [`pair_block`] for whatever instruction set the caller is compiled for.
#[inline(always)]
fn pair_block_portable<T: Real>(first: usize, out: &mut [ContactForce<T>], hist: &mut [T], pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>) {
    let stride = ctx.slots.stride;
    if let Some(model) = super::lanes::hertz_mindlin(ctx.model) {
        debug_assert!(!ctx.slots.layout.sliding && !ctx.slots.layout.rolling, "Hertz-Mindlin keeps one spring per pair");
        return super::lanes::hertz_mindlin_block(&model, first, out, hist, pairs, body, prop, ctx);
    }
    for (m, o) in out.iter_mut().enumerate() {
        *o = pair_force(first + m, pairs, body, prop, ctx, &mut hist[m * stride..(m + 1) * stride]);
    }
}
