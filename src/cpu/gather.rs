//! `gather`: one invocation completes the load on one grain in a fixed order: the pair pass
//! left gravity plus the shares of the pairs the grain owns in its load; the gather adds the
//! shares of the pairs where it is partner, then its wall contacts. No float atomics, so the
//! result does not depend on scheduling.

use super::pairs::PairList;
use super::state::Load;
use crate::real::Real;

/// `gather` for grain `i`, whose load holds the pair pass's owner sum.
#[inline(always)]
pub fn gather<T: Real>(i: usize, pairs: &PairList, owned: &Load<T>, share: &[Load<T>], wall: &Load<T>) -> Load<T> {
    let (mut force, mut torque) = (owned.force, owned.torque);
    for &k in &pairs.rev_pair[pairs.rev_start[i] as usize..pairs.rev_start[i + 1] as usize] {
        force += share[k as usize].force;
        torque += share[k as usize].torque;
    }
    Load { force: force + wall.force, torque: torque + wall.torque }
}

super::simd::dispatch! {
    /// `gather` for grains `first..first + loads.len()`, in place.
    pub fn gather_block<T: Real>(first: usize, loads: &mut [Load<T>], pairs: &PairList, share: &[Load<T>], wall: &[Load<T>]) => gather_block_portable
}

/// [`gather_block`] for whatever instruction set the caller is compiled for.
#[inline(always)]
fn gather_block_portable<T: Real>(first: usize, loads: &mut [Load<T>], pairs: &PairList, share: &[Load<T>], wall: &[Load<T>]) {
    for (m, l) in loads.iter_mut().enumerate() {
        let i = first + m;
        *l = gather(i, pairs, l, share, &wall[i]);
    }
}
