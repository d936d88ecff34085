//! `pair_force`: one invocation computes the force of one listed pair, once, in canonical
//! order (owner = lower permanent id = i), and reads and writes its history.
//!
//! The pass runs in tasks of [`OWNERS`] owner grains, each compiled for the widest instruction
//! set the CPU has (see `simd`); under the standard Hertz-Mindlin model their pairs run in
//! vector lanes (see `lanes`), with the same bits, and otherwise one at a time. Of each pair's
//! force only the partner's share and a small report go back to memory: the owner's share is
//! summed into the owner's load on the spot, in the order the gather used to sum it. Dry, the
//! lanes hand each pair over as they store it; in capillary scenes, whose lanes take a
//! window's open pairs first, [`BLOCK`] pairs at a time go through a scratch record that stays
//! in cache and are handed over from it in pair order.

use crate::state::{Body, ForceContext, Load, PairFlags, PairList, Props};
use super::lanes::PairSink;
use crate::model::{capillary_force, contact_force, parted_normal_force, Bodies, CohesionLaw, ContactForce, Geometry, KickWindow, Kinematics};
use crate::real::{Real, Vec3};

/// `pair_force` for pair `k`, owned by grain `i`. A listed pair that does not touch forgets
/// its springs and exerts only the capillary force of its liquid bridge, if it has one within
/// reach, and the end of a contact that parted within the window ([`parted_normal_force`]).
#[inline(always)]
pub fn pair_force<T: Real>(i: usize, k: usize, pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>, hist: &mut [T]) -> ContactForce<T> {
    let j = pairs.partner[k] as usize;
    let (bi, bj, pi, pj) = (&body[i], &body[j], &prop[i], &prop[j]);
    let d = ctx.separation(body, i, j);
    let dist2 = d.norm2();
    let reach = pi.radius + pj.radius;
    if dist2 >= reach * reach {
        ctx.slots.clear_springs(hist);
        let mut f = match ctx.model.cohesion {
            CohesionLaw::Capillary { kappa, theta, c } if ctx.slots.layout.bridge && hist[ctx.slots.bridge] > T::ZERO => {
                let dist = dist2.sqrt();
                let f_c = capillary_force(kappa, theta, c, pi.radius, pj.radius, hist[ctx.slots.bridge], dist - reach);
                let n = d * (T::ONE / dist);
                ContactForce { f_i: n * f_c, f_j: n * (-f_c), f_c, ..Default::default() }
            }
            _ => ContactForce::default(),
        };
        if ctx.ends_pull() {
            let geo = Geometry::grain_grain(d, dist2.sqrt(), pi.radius, pj.radius, pi.mass, pj.mass);
            let f_n = parted_normal_force(ctx.model, ctx.pair_coeffs(i, j), &geo, (bi.vel - bj.vel).dot(geo.n), ctx.window);
            f.f_n = f_n;
            f.f_i += geo.n * f_n;
            f.f_j -= geo.n * f_n;
        }
        return f;
    }
    let geo = Geometry::grain_grain(d, dist2.sqrt(), pi.radius, pj.radius, pi.mass, pj.mass);
    let kin = Kinematics { v_i: bi.vel, v_j: bj.vel, w_i: bi.omega, w_j: bj.omega };
    let bodies = Bodies { m_i: pi.mass, inertia_i: pi.inertia, m_j: pj.mass, inertia_j: pj.inertia, j_is_wall: false };
    let c = ctx.pair_coeffs(i, j);
    let mut h = ctx.slots.load(hist);
    let f = contact_force(ctx.model, c, &geo, &kin, &bodies, &mut h, ctx.elapsed, KickWindow::centred(ctx.window));
    ctx.slots.store(&h, hist);
    f
}

/// Pairs the lane kernel computes at a time into a task's scratch record in capillary scenes,
/// before each is split into the owner's share (summed into its load), the partner's share and
/// the report.
pub const BLOCK: usize = 256;

/// What a thread of the pair pass keeps from task to task (made when first needed; its
/// contents are overwritten by each task).
#[derive(Default)]
pub struct TaskScratch<T> {
    /// The lane kernel's output in capillary scenes, [`BLOCK`] records.
    records: Vec<ContactForce<T>>,
    /// The lane kernel's working arrays.
    lanes: Option<Box<super::lanes::Scratch<T>>>,
}

/// Owner grains per task of the pair pass: a task takes every pair these grains own, so each
/// owner's share is summed within one task, in pair order.
pub const OWNERS: usize = 64;

/// What one task of the pair pass writes, for the owner grains `first..first + load.len()`
/// and the pairs they own (`pairs.owner_start[first]..`).
pub struct OwnerBlock<'a, T> {
    /// First owner grain.
    pub first: usize,
    /// The owners' loads: gravity plus the owner's share of each pair it owns, summed in
    /// pair order (the gather adds the partners' shares and the walls' afterwards).
    pub load: &'a mut [Load<T>],
    /// The partner's share of each pair: force (N) and torque (N m) on the partner.
    pub share: &'a mut [Load<T>],
    /// Each pair's normal force after the clamp (N; [`super::PairReports`]).
    pub f_n: &'a mut [T],
    /// Each pair's capillary force (N); empty without cohesion.
    pub f_c: &'a mut [T],
    /// Each pair's [`PairFlags`].
    pub flags: &'a mut [u8],
    /// The force on the owner of each pair (N), kept only where it is not the partner's
    /// force reversed (see [`ContactModel::keeps_both_forces`]); empty otherwise.
    pub force_i: &'a mut [Vec3<T>],
    /// The pairs' history slots (empty when the model keeps none).
    pub hist: &'a mut [T],
}

super::simd::dispatch! {
    /// `pair_force` for every pair the grains of `block` own, with each owner's share summed
    /// into its load from `gravity * m` in pair order: the bits the gather got when it read
    /// whole per-pair records, with a third of the bytes.
    /// `scratch` is the lane kernel's working arrays and output, reused from task to task.
    pub fn owner_block<T: Real>(block: OwnerBlock<'_, T>, scratch: &mut TaskScratch<T>, pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>, gravity: Vec3<T>) => owner_block_portable
}

/// [`owner_block`] for whatever instruction set the caller is compiled for.
#[inline(always)]
fn owner_block_portable<T: Real>(mut block: OwnerBlock<'_, T>, scratch: &mut TaskScratch<T>, pairs: &PairList, body: &[Body<T>], prop: &[Props<T>], ctx: &ForceContext<T>, gravity: Vec3<T>) {
    let first = block.first;
    for (m, l) in block.load.iter_mut().enumerate() {
        let p = &prop[first + m];
        // A grain out of play feels no gravity (WGSL gather's twin).
        *l = Load { force: if p.in_play() { gravity * p.mass } else { Vec3::ZERO }, torque: Vec3::ZERO };
    }
    let first_pair = pairs.owner_start[first] as usize;
    let (stride, n_pairs) = (ctx.slots.stride, block.f_n.len());
    let hist = std::mem::take(&mut block.hist);
    let mut sink = Deposit::new(&mut block);
    match super::lanes::hertz_mindlin(ctx.model) {
        // Without cohesion the lanes hand the touching pairs over in pair order.
        Some(model) if matches!(ctx.model.cohesion, CohesionLaw::None) => {
            let lanes = scratch.lanes.get_or_insert_with(super::lanes::Scratch::new);
            super::lanes::hertz_mindlin_block(&model, lanes, first_pair, n_pairs, &mut sink, hist, pairs, body, prop, ctx)
        }
        Some(model) => {
            let TaskScratch { records, lanes } = scratch;
            let lanes = lanes.get_or_insert_with(super::lanes::Scratch::new);
            records.resize(BLOCK, ContactForce::default());
            for start in (0..n_pairs).step_by(BLOCK) {
                let n = BLOCK.min(n_pairs - start);
                let h = &mut hist[start * stride..(start + n) * stride];
                super::lanes::hertz_mindlin_block(&model, lanes, first_pair + start, n, &mut records[..n], h, pairs, body, prop, ctx);
                let owners = pairs.owners_of(first_pair + start..first_pair + start + n);
                for ((q, f), i) in records[..n].iter().enumerate().zip(owners) {
                    sink.put(start + q, i, f);
                }
            }
        }
        None => {
            for (k, i) in pairs.owners_of(first_pair..first_pair + n_pairs).enumerate() {
                sink.put(k, i, &pair_force(i, first_pair + k, pairs, body, prop, ctx, &mut hist[k * stride..(k + 1) * stride]));
            }
        }
    }
    sink.finish();
}

/// Hands out a block's pair forces, taken in pair order: the owner's share summed into a
/// running load (kept out of memory while the owner stays the same, so each addition does not
/// wait on the previous one's store), the rest stored per pair.
struct Deposit<'b, 'a, T> {
    block: &'b mut OwnerBlock<'a, T>,
    /// The owner being summed, as an index into the block's loads.
    current: usize,
    /// Its load so far.
    sum: Load<T>,
}

impl<'b, 'a, T: Real> Deposit<'b, 'a, T> {
    fn new(block: &'b mut OwnerBlock<'a, T>) -> Self {
        let sum = block.load.first().copied().unwrap_or_default();
        Deposit { block, current: 0, sum }
    }

    /// Stores the load being summed.
    #[inline(always)]
    fn finish(&mut self) {
        if let Some(l) = self.block.load.get_mut(self.current) {
            *l = self.sum;
        }
    }
}

impl<T: Real> PairSink<T> for Deposit<'_, '_, T> {
    #[inline(always)]
    fn put(&mut self, k: usize, owner: usize, f: &ContactForce<T>) {
        let owner = owner - self.block.first;
        if owner != self.current {
            self.finish();
            self.current = owner;
            self.sum = self.block.load[owner];
        }
        self.sum.force += f.f_i;
        self.sum.torque += f.t_i;
        self.block.deposit(k, f);
    }

    /// A zero force leaves the owner's sum as it is: adding `+0` changes the bits of no sum
    /// but `-0`, which a sum starting from `gravity * m` only is where gravity is written `-0`.
    /// A pair still open since the last evaluation ([`PairFlags::OPEN`]) keeps its zeros.
    #[inline(always)]
    fn skip(&mut self, k: usize) -> bool {
        if self.block.flags[k] == PairFlags::OPEN.0 {
            return false;
        }
        self.block.deposit(k, &ContactForce::default());
        self.block.flags[k] = PairFlags::OPEN.0;
        true
    }
}

impl<T: Real> OwnerBlock<'_, T> {
    /// Stores all but the owner's share of the force of the block's pair `k` (counted from
    /// its first pair).
    #[inline(always)]
    fn deposit(&mut self, k: usize, f: &ContactForce<T>) {
        // Field by field: a whole-struct store is assembled on the stack and read back in
        // wider words than it was written, which stalls store forwarding (a tenth of the
        // oedometer's step).
        let sh = &mut self.share[k];
        sh.force = f.f_j;
        sh.torque = f.t_j;
        self.f_n[k] = f.f_n;
        self.flags[k] = PairFlags::new(f.regime, f.clamped).0;
        if !self.f_c.is_empty() {
            self.f_c[k] = f.f_c;
        }
        if !self.force_i.is_empty() {
            self.force_i[k] = f.f_i;
        }
    }
}
