//! `gather`: one invocation adds to one grain's load, in a fixed order, the shares of the
//! pairs where it is partner (the pair pass left gravity plus the shares of the pairs the
//! grain owns there; the wall pass adds the walls' after). No float atomics, so the result
//! does not depend on scheduling.

use crate::state::PairList;
use crate::state::Load;
use crate::real::{Real, Vec3};

/// `gather` for grain `i`, whose load holds the pair pass's owner sum.
#[inline(always)]
pub fn gather<T: Real>(i: usize, pairs: &PairList, owned: &Load<T>, share: &[Load<T>]) -> Load<T> {
    let (mut force, mut torque) = (owned.force, owned.torque);
    for &k in &pairs.rev_pair[pairs.rev_start[i] as usize..pairs.rev_start[i + 1] as usize] {
        force += share[k as usize].force;
        torque += share[k as usize].torque;
    }
    // Adding zero turns a sum of -0 into +0, as the GPU's gather does by adding its zeroed wall
    // loads (the CPU's wall pass adds its own after): the twins keep the same bits.
    Load { force: force + Vec3::ZERO, torque: torque + Vec3::ZERO }
}

super::simd::dispatch! {
    /// `gather` for grains `first..first + loads.len()`, in place.
    pub fn gather_block<T: Real>(first: usize, loads: &mut [Load<T>], pairs: &PairList, share: &[Load<T>]) => gather_block_portable
}

/// [`gather_block`] for whatever instruction set the caller is compiled for.
#[inline(always)]
fn gather_block_portable<T: Real>(first: usize, loads: &mut [Load<T>], pairs: &PairList, share: &[Load<T>]) {
    for (m, l) in loads.iter_mut().enumerate() {
        *l = gather(first + m, pairs, l, share);
    }
}
