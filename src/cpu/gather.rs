//! `gather`: one invocation sums the load on one grain in a fixed order (gravity, the pairs
//! it owns, the pairs where it is partner, its wall contacts). No float atomics, so the result
//! does not depend on scheduling.

use super::pairs::PairList;
use super::state::{Load, Props};
use crate::model::ContactForce;
use crate::real::{Real, Vec3};

/// `gather` for grain `i`.
#[inline(always)]
pub fn gather<T: Real>(i: usize, pairs: &PairList, out: &[ContactForce<T>], wall: &Load<T>, p: &Props<T>, gravity: Vec3<T>) -> Load<T> {
    let mut force = gravity * p.mass;
    let mut torque = Vec3::ZERO;
    for o in &out[pairs.owner_start[i] as usize..pairs.owner_start[i + 1] as usize] {
        force += o.f_i;
        torque += o.t_i;
    }
    for &k in &pairs.rev_pair[pairs.rev_start[i] as usize..pairs.rev_start[i + 1] as usize] {
        force += out[k as usize].f_j;
        torque += out[k as usize].t_j;
    }
    Load { force: force + wall.force, torque: torque + wall.torque }
}

super::simd::dispatch! {
    /// `gather` for grains `first..first + loads.len()`.
    pub fn gather_block<T: Real>(first: usize, loads: &mut [Load<T>], pairs: &PairList, out: &[ContactForce<T>], wall: &[Load<T>], prop: &[Props<T>], gravity: Vec3<T>) => gather_block_portable
}

/// [`gather_block`] for whatever instruction set the caller is compiled for.
#[inline(always)]
fn gather_block_portable<T: Real>(first: usize, loads: &mut [Load<T>], pairs: &PairList, out: &[ContactForce<T>], wall: &[Load<T>], prop: &[Props<T>], gravity: Vec3<T>) {
    for (m, l) in loads.iter_mut().enumerate() {
        let i = first + m;
        *l = gather(i, pairs, out, &wall[i], &prop[i], gravity);
    }
}
