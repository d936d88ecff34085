//! The step's split of the slots among the pool's threads: one contiguous part per thread,
//! the same for the pair pass, the gather sweep and the kick-and-drift, so that the thread
//! that writes a grain's owner sum in the pair pass finds it (and the grain's body, and most
//! of the shares it gathers) in its own cache in the next two passes. Parts start at
//! multiples of [`ALIGN`] slots, so that each is a whole number of the pair pass's owner
//! blocks, and are balanced by an estimate of each pass's cost ([`slot_cost`]).
//!
//! Which thread runs which part never changes a result: each part writes its own outputs,
//! per-grain results do not depend on their neighbours' part, and what is summed across
//! grains (wall reactions, the largest displacement) is summed in an order that does not
//! depend on the split.
//!
//! Measured on the 2-core Intel host (10^4 grains, f64, two threads, the pool kept warm),
//! against tasks of 2,048-grain chunks for the sweeps and of 1,024 pairs or more for the pair
//! pass: the gather sweep 15.7 -> 11.3 ns per particle-step, the whole step +9%.
//!
//! Computed afresh by each pass that uses it (a bisection per part over the pair list's
//! prefix sums, far below a microsecond), so that it follows the list and the pool's size
//! without being kept in step with them.

use super::pair_force::OWNERS;
use crate::state::PairList;
use crate::state::reduce::PAR_MIN_PAIRS;

/// Parts start at multiples of this many slots: the pair pass's owner blocks.
pub const ALIGN: usize = OWNERS;

/// Relative costs of an owned pair (the pair pass), a partnered pair (the gather) and a grain
/// (gravity, the gather's and the kick-and-drift's per-grain work), from the one-thread
/// profile of the bench bed (f64, 10^4 grains, 4.67 contacts a grain): about 35, 4 and 7 ns.
const OWNED_COST: u64 = 9;
const PARTNERED_COST: u64 = 1;
const GRAIN_COST: u64 = 2;

/// The estimated cost of slots `0..end` (`end` at most the number of grains).
fn slot_cost(pairs: &PairList, end: usize) -> u64 {
    OWNED_COST * pairs.owner_start[end] as u64 + PARTNERED_COST * pairs.rev_start[end] as u64 + GRAIN_COST * end as u64
}

/// The parts wanted for a pool of `threads`: one per thread, or two per thread when the pool
/// has more threads than the machine has cores, so that threads sharing a core can still hand
/// work to each other (3 threads on the 2-core host, 10^4 grains: one part each ran 1.08e7
/// particle-steps/s, two each 1.41e7-1.59e7, the chunked tasks before the split 1.49e7-1.54e7;
/// on 2 threads, two parts each cost 2-4%, so a pool that fits keeps one).
pub fn parts_for(threads: usize) -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    let cores = *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |c| c.get()));
    if threads > cores { 2 * threads } else { threads }
}

/// The least cost of a part: [`PAR_MIN_PAIRS`] pairs' (a smaller part costs more to hand
/// over than it saves), or that of some 5,000 grains with no pair.
const MIN_PART_COST: u64 = PAR_MIN_PAIRS as u64 * (OWNED_COST + PARTNERED_COST);

/// The boundaries of the parts of `n` grains' slots (`parts + 1` of them, from 0 to `n`):
/// `wanted` parts ([`parts_for`]), but none below [`MIN_PART_COST`].
pub fn split(pairs: &PairList, n: usize, wanted: usize) -> Vec<usize> {
    if pairs.owner_start.len() != n + 1 || pairs.rev_start.len() != n + 1 {
        return vec![0, n];
    }
    let total = slot_cost(pairs, n);
    let parts = wanted.min((total / MIN_PART_COST) as usize).max(1);
    let blocks = n.div_ceil(ALIGN);
    let mut bounds = vec![0];
    for p in 1..parts {
        let target = total * p as u64 / parts as u64;
        // The block boundary nearest the target: the first whose cost reaches it (by
        // bisection; costs grow with the slot), or the one before.
        let end = |b: usize| (b * ALIGN).min(n);
        let (mut lo, mut hi) = (0, blocks);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if slot_cost(pairs, end(mid)) < target {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        if lo > 0 && target - slot_cost(pairs, end(lo - 1)) < slot_cost(pairs, end(lo)) - target {
            lo -= 1;
        }
        bounds.push(end(lo).max(bounds[p - 1]));
    }
    bounds.push(n);
    bounds
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A list where grain `i` owns `owned(i)` pairs and partners none.
    fn list(n: usize, owned: impl Fn(usize) -> u32) -> PairList {
        let mut owner_start = vec![0];
        for i in 0..n {
            owner_start.push(owner_start[i] + owned(i));
        }
        let partner = vec![0; owner_start[n] as usize];
        PairList { owner_start, partner, rev_start: vec![0; n + 1], ..Default::default() }
    }

    /// Parts are aligned, ordered, cover every slot, and each carries its even share of the
    /// cost to within one block's (each boundary is within half a block of its target); a
    /// list too small for two parts gets one.
    #[test]
    fn parts_are_aligned_and_balanced() {
        // The first half of the grains own 8 pairs each, the second half 2: the split falls
        // well before the middle.
        let n = 10_000;
        let pairs = list(n, |i| if i < n / 2 { 8 } else { 2 });
        for threads in [2, 3, 4] {
            let b = split(&pairs, n, threads);
            assert_eq!((b.len(), b[0], b[threads]), (threads + 1, 0, n));
            assert!(b[1..threads].iter().all(|&x| x % ALIGN == 0), "{b:?}");
            let costs: Vec<u64> = b.windows(2).map(|w| slot_cost(&pairs, w[1]) - slot_cost(&pairs, w[0])).collect();
            let block_cost = ALIGN as u64 * (8 * OWNED_COST + GRAIN_COST);
            let even = slot_cost(&pairs, n) / threads as u64;
            assert!(costs.iter().all(|&c| c.abs_diff(even) <= block_cost), "{threads} threads: costs {costs:?}, even {even}");
        }
        assert!(split(&pairs, n, 2)[1] < n / 2);
        // Too little work for two parts: 300 pairs; but 20,000 grains with none make two.
        assert_eq!(split(&list(100, |_| 3), 100, 2), vec![0, 100]);
        assert_eq!(split(&list(20_000, |_| 0), 20_000, 2).len(), 3);
    }
}
