//! The GPU's workgroup shape and the order its fixed-order reductions add in, for the CPU
//! twins that must give the same bits: `wall_contacts` sums its [`WG`] lanes by a halving tree
//! into one row per workgroup, and `wall_reduce` has lane `l` add rows `l, l + WG, ...` in turn,
//! then sums its lanes by the same tree. Floating-point addition is commutative but not
//! associative, so a sum is reproduced bit for bit exactly when its parenthesisation is.

/// Invocations per workgroup of the per-item kernels (WGSL `WG`).
pub const WG: u32 = 64;

/// Workgroups along x and y that cover `n` items (at most 65535 along x).
pub fn groups(n: u64) -> (u32, u32) {
    let g = n.div_ceil(WG as u64);
    if g <= 65535 { (g as u32, 1) } else { (65535, g.div_ceil(65535) as u32) }
}

/// Workgroups dispatched for `n` items (at least one): the rows of a per-workgroup reduction.
pub fn rows(n: u64) -> u64 {
    let (x, y) = groups(n.max(1));
    x as u64 * y as u64
}

/// Sums [`WG`] lanes as a workgroup's halving tree does (lane `l` takes lane `l + s` for
/// `s = WG/2, ..., 1`); the sum is left in lane 0.
pub fn tree_sum<R: Copy>(lanes: &mut [R], add: impl Fn(R, R) -> R) -> R {
    debug_assert_eq!(lanes.len(), WG as usize);
    let mut stride = lanes.len() / 2;
    while stride > 0 {
        for l in 0..stride {
            lanes[l] = add(lanes[l], lanes[l + stride]);
        }
        stride /= 2;
    }
    lanes[0]
}

/// Sums per-workgroup rows as one workgroup of [`WG`] lanes does: lane `l` adds rows
/// `l, l + WG, ...` to `zero` in turn, then the lanes are summed by [`tree_sum`].
pub fn strided_sum<R: Copy>(rows: impl IntoIterator<Item = R>, zero: R, add: impl Fn(R, R) -> R) -> R {
    let mut lanes = vec![zero; WG as usize];
    for (r, row) in rows.into_iter().enumerate() {
        let l = r % WG as usize;
        lanes[l] = add(lanes[l], row);
    }
    tree_sum(&mut lanes, add)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree pairs lane 0 with lane 32 first: with 1 at lane 0, 2^-24 at lanes 1 and 33,
    /// the tree keeps the small terms together (1 + 2^-23) where a running sum rounds each away.
    #[test]
    fn the_tree_adds_in_the_gpus_order() {
        let mut lanes = vec![0.0f32; WG as usize];
        let tiny = 2.0f32.powi(-24);
        (lanes[0], lanes[1], lanes[33]) = (1.0, tiny, tiny);
        let running = lanes.iter().fold(0.0f32, |s, &x| s + x);
        assert_eq!(running, 1.0);
        assert_eq!(tree_sum(&mut lanes, |a, b| a + b), 1.0 + 2.0 * tiny);
    }

    /// Row r lands in lane r % WG: rows 0 and WG share a lane and are added before the tree.
    #[test]
    fn rows_are_dealt_to_lanes_in_turn() {
        let tiny = 2.0f32.powi(-24);
        let mut rows = vec![0.0f32; 2 * WG as usize];
        (rows[1], rows[WG as usize + 1], rows[0]) = (tiny, tiny, 1.0);
        assert_eq!(strided_sum(rows.iter().copied(), 0.0, |a, b| a + b), 1.0 + 2.0 * tiny);
    }

    #[test]
    fn rows_cover_every_item() {
        assert_eq!(rows(0), 1);
        assert_eq!(rows(64), 1);
        assert_eq!(rows(65), 2);
        assert_eq!(groups(65535 * 64 + 1), (65535, 2));
    }
}
