//! `reorder`: renumbers the grains' slots in the order of the cells that hold them, as LAMMPS'
//! `atom_modify sort` does, so that grains that touch sit near each other in memory and the
//! pair pass's partner loads hit the cache. The cells are taken along a Z-order (Morton)
//! curve, not row by row: a row-major order puts a grain's neighbours in the next layer a
//! whole layer of cells away, which at 10^5 grains no longer fits the cache. Every per-grain
//! array, the pair list and the per-contact history move with their grains; the permanent id
//! moves too, and every order that reaches a result is taken in permanent ids, so a run gives
//! the same bits however its slots are numbered.

use crate::state::CellGrid;
use crate::state::PairList;
use crate::state::reduce::chunked;
use crate::state::Body;
use crate::real::Real;
use rayon::prelude::*;

/// The slots in Z order of their cells (slot order within a cell): the `from` of a
/// [`Renumbering`] into cell order.
pub fn z_order<T: Real>(grid: &CellGrid<T>, body: &[Body<T>]) -> Vec<u32> {
    let mut keyed: Vec<(u64, u32)> = body.par_iter().with_min_len(crate::state::reduce::PAR_MIN_ITEMS).enumerate().map(|(i, b)| (morton(grid.coords(b.pos)), i as u32)).collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// The Z-order (Morton) key of cell coordinates: their bits interleaved, x lowest (21 bits
/// per axis; grids are far smaller).
fn morton(c: [u32; 3]) -> u64 {
    let spread = |v: u32| {
        let mut x = (v as u64) & 0x1f_ffff;
        x = (x | x << 32) & 0x1f_0000_0000_ffff;
        x = (x | x << 16) & 0x1f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        (x | x << 2) & 0x1249_2492_4924_9249
    };
    spread(c[0]) | spread(c[1]) << 1 | spread(c[2]) << 2
}

/// A renumbering of slots.
pub struct Renumbering {
    /// The old slot of each new slot.
    pub from: Vec<u32>,
    /// The new slot of each old slot.
    pub to: Vec<u32>,
}

impl Renumbering {
    /// The renumbering that puts old slot `from[s]` at new slot `s` (`from` is a permutation).
    pub fn new(from: Vec<u32>) -> Self {
        let mut to = vec![0; from.len()];
        for (s, &o) in from.iter().enumerate() {
            to[o as usize] = s as u32;
        }
        Renumbering { from, to }
    }

    /// True when no slot moves.
    pub fn is_identity(&self) -> bool {
        self.from.iter().enumerate().all(|(s, &o)| s == o as usize)
    }

    /// Moves one item per slot (an empty array, for a quantity the scene does not have, stays
    /// empty).
    pub fn apply<X: Copy + Send + Sync>(&self, v: &mut Vec<X>) {
        self.apply_blocks(v, 1);
    }

    /// Moves `width` items per slot.
    pub fn apply_blocks<X: Copy + Send + Sync>(&self, v: &mut Vec<X>, width: usize) {
        if v.is_empty() || width == 0 {
            return;
        }
        let old = &*v;
        let moved: Vec<X> = self.from.par_iter().with_min_len(crate::state::reduce::PAR_MIN_ITEMS).flat_map_iter(|&o| old[o as usize * width..(o as usize + 1) * width].iter().copied()).collect();
        *v = moved;
    }

    /// The pair list and its history (`stride` reals per pair) in the new slots: each owner's
    /// pairs move with it, in the same order (ascending partner id), and partners are
    /// renamed. The reverse lists are left empty for [`PairList::build_reverse`].
    pub fn apply_pairs<T: Real>(&self, list: &PairList, hist: &[T], stride: usize) -> (PairList, Vec<T>) {
        let n = self.from.len();
        let mut owner_start = Vec::with_capacity(n + 1);
        owner_start.push(0u32);
        for &o in &self.from {
            let o = o as usize;
            owner_start.push(owner_start.last().copied().unwrap_or(0) + list.owner_start[o + 1] - list.owner_start[o]);
        }
        let parts = chunked(n, |r| {
            let (mut partner, mut h) = (Vec::new(), Vec::new());
            for s in r {
                let o = self.from[s] as usize;
                let (a, b) = (list.owner_start[o] as usize, list.owner_start[o + 1] as usize);
                partner.extend(list.partner[a..b].iter().map(|&j| self.to[j as usize]));
                h.extend_from_slice(&hist[a * stride..b * stride]);
            }
            (partner, h)
        });
        let mut moved = PairList { partner: Vec::with_capacity(list.len()), ..Default::default() };
        let mut moved_hist = Vec::with_capacity(hist.len());
        for (partner, h) in parts {
            moved.partner.extend(partner);
            moved_hist.extend(h);
        }
        moved.owner_start = owner_start;
        (moved, moved_hist)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_the_axes_bits() {
        assert_eq!(morton([1, 0, 0]), 0b001);
        assert_eq!(morton([0, 1, 0]), 0b010);
        assert_eq!(morton([0, 0, 1]), 0b100);
        assert_eq!(morton([3, 0, 0]), 0b001_001);
        assert_eq!(morton([0x1f_ffff, 0x1f_ffff, 0x1f_ffff]), (1u64 << 63) - 1);
    }

    #[test]
    fn pairs_follow_their_owners_and_partners_are_renamed() {
        // Three grains with permanent ids = old slots; pairs 0-1, 0-2, 1-2.
        let mut list = PairList { owner_start: vec![0, 2, 3, 3], partner: vec![1, 2, 2], ..Default::default() };
        list.build_reverse(&[0, 1, 2]);
        let hist: Vec<f64> = vec![1.0, 1.5, 2.0, 2.5, 3.0, 3.5];
        // New slots: old 2, old 0, old 1.
        let r = Renumbering::new(vec![2, 0, 1]);
        assert_eq!(r.to, vec![1, 2, 0]);
        let (moved, h) = r.apply_pairs(&list, &hist, 2);
        assert_eq!(moved.owner_start, vec![0, 0, 2, 3]);
        assert_eq!(moved.owners_of(0..3).collect::<Vec<_>>(), vec![1, 1, 2]);
        assert_eq!(moved.partner, vec![2, 0, 0]);
        assert_eq!(h, hist);
        let mut v = vec![10, 11, 12];
        r.apply(&mut v);
        assert_eq!(v, vec![12, 10, 11]);
    }
}
