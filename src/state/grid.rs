//! `hash_cells` and `detect_pairs`: cell hashing by counting sort and Verlet-list pair
//! detection. One invocation of `detect_pairs` lists the pairs one grain owns.

use super::reduce::chunked;
use super::arrays::{Body, Props};
use crate::periodic::Periodic;
use crate::position;
use crate::real::{Real, Vec3};

/// A uniform grid over the grains' bounding box (or the period, along a wrapping axis) with
/// grains sorted by cell.
#[derive(Clone, Debug, Default)]
pub struct CellGrid<T> {
    /// Lower corner (m).
    pub origin: Vec3<T>,
    /// Cell edges (m), each at least the largest pair cut-off.
    pub cell: [T; 3],
    /// Cells per axis.
    pub dims: [u32; 3],
    /// Axes that wrap around.
    pub wraps: [bool; 3],
    /// `cell_start[c]..cell_start[c + 1]` indexes `cell_grains` for cell `c`.
    pub cell_start: Vec<u32>,
    /// Grain indices sorted by cell, ascending within a cell.
    pub cell_grains: Vec<u32>,
}

/// Most cells per grain the grid may have; a sparse scene gets larger cells instead.
pub const MAX_CELLS_PER_GRAIN: f64 = 8.0;

impl<T: Real> CellGrid<T> {
    /// Cell coordinates of a position, clamped to the grid.
    #[inline(always)]
    pub fn coords(&self, p: Vec3<T>) -> [u32; 3] {
        let q = [(p.x - self.origin.x) / self.cell[0], (p.y - self.origin.y) / self.cell[1], (p.z - self.origin.z) / self.cell[2]];
        let mut c = [0u32; 3];
        for a in 0..3 {
            // `as` saturates: NaN -> 0, +inf -> u32::MAX, then clamped.
            c[a] = (q[a].floor().f64() as u32).min(self.dims[a] - 1);
        }
        c
    }
    /// Linear cell index of cell coordinates.
    #[inline(always)]
    pub fn index(&self, c: [u32; 3]) -> usize {
        (c[0] as usize) + self.dims[0] as usize * ((c[1] as usize) + self.dims[1] as usize * c[2] as usize)
    }
}

/// `hash_cells`: sizes the grid to the grains' bounding box (the period along a wrapping
/// axis, where positions must already be wrapped) with cells at least `cutoff` wide, and
/// sorts grain indices by cell (counting sort: count, exclusive scan, stable scatter).
/// Returns `false` when a position is not finite.
pub fn hash_cells<T: Real>(body: &[Body<T>], cutoff: T, periodic: &Periodic<T>, grid: &mut CellGrid<T>) -> bool {
    let Some(bounds) = bounds_of(body, None, periodic) else { return false };
    place(body, None, bounds, cutoff, periodic, grid);
    true
}

/// The bounding box of the grains of slots `members` (every grain when `None`), lower and
/// upper corners (m; the period along a wrapping axis), or `None` when a position is not
/// finite.
pub(super) fn bounds_of<T: Real>(body: &[Body<T>], members: Option<&[u32]>, periodic: &Periodic<T>) -> Option<([f64; 3], [f64; 3])> {
    let bounds = chunked(members.map_or(body.len(), |m| m.len()), |r| {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut finite = true;
        for k in r {
            let b = &body[members.map_or(k, |m| m[k] as usize)];
            finite &= b.pos.is_finite();
            let p = b.pos.f64();
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        (lo, hi, finite)
    });
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for (l, h, finite) in bounds {
        if !finite {
            return None;
        }
        for a in 0..3 {
            lo[a] = lo[a].min(l[a]);
            hi[a] = hi[a].max(h[a]);
        }
    }
    if lo[0] > hi[0] {
        // No grain: a grid of one cell at the origin.
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    for a in 0..3 {
        if periodic.on[a] {
            lo[a] = periodic.lo[a].f64();
            hi[a] = lo[a] + periodic.len[a].f64();
        }
    }
    Some((lo, hi))
}

/// Sizes `grid` to the box `(lo, hi)` with cells at least `cutoff` wide and sorts by cell the
/// slots of `members` (every grain when `None`), ascending within a cell.
pub(super) fn place<T: Real>(body: &[Body<T>], members: Option<&[u32]>, (lo, hi): ([f64; 3], [f64; 3]), cutoff: T, periodic: &Periodic<T>, grid: &mut CellGrid<T>) {
    let count = members.map_or(body.len(), |m| m.len());
    let mut cell = cutoff.f64();
    let cap = (MAX_CELLS_PER_GRAIN * count as f64).max(64.0);
    let dims = loop {
        // A wrapping axis has a whole number of cells over its period, each at least `cell`.
        let d: Vec<f64> = (0..3).map(|a| if periodic.on[a] { ((hi[a] - lo[a]) / cell).floor().max(1.0) } else { ((hi[a] - lo[a]) / cell).floor() + 1.0 }).collect();
        if d[0] * d[1] * d[2] <= cap {
            break [d[0] as u32, d[1] as u32, d[2] as u32];
        }
        cell *= 1.25;
    };
    grid.origin = Vec3::of(lo);
    grid.cell = [0, 1, 2].map(|a| T::of(if periodic.on[a] { (hi[a] - lo[a]) / dims[a] as f64 } else { cell }));
    grid.dims = dims;
    grid.wraps = periodic.on;
    let n_cells = (dims[0] * dims[1] * dims[2]) as usize;
    let cells: Vec<u32> = {
        let g = &*grid;
        match members {
            None => chunked(body.len(), |r| body[r].iter().map(|b| g.index(g.coords(b.pos)) as u32).collect::<Vec<u32>>()).concat(),
            Some(m) => m.iter().map(|&i| g.index(g.coords(body[i as usize].pos)) as u32).collect(),
        }
    };
    grid.cell_start.clear();
    grid.cell_start.resize(n_cells + 1, 0);
    for &c in &cells {
        grid.cell_start[c as usize + 1] += 1;
    }
    for c in 0..n_cells {
        grid.cell_start[c + 1] += grid.cell_start[c];
    }
    let mut cursor = grid.cell_start[..n_cells].to_vec();
    grid.cell_grains.clear();
    grid.cell_grains.resize(count, 0);
    for (k, &c) in cells.iter().enumerate() {
        grid.cell_grains[cursor[c as usize] as usize] = members.map_or(k as u32, |m| m[k]);
        cursor[c as usize] += 1;
    }
}

impl<T: Real> CellGrid<T> {
    /// The distinct coordinates along axis `a` within `h` cells of `c` (itself included),
    /// wrapped on a periodic axis, clipped otherwise, in increasing offset: `(first, count)`,
    /// coordinate `k` being `first + k`, less `dims[a]` where that reaches it (`first` is
    /// below `dims[a]` and `count` at most `dims[a]`).
    #[inline(always)]
    pub(super) fn within(&self, c: u32, a: usize, h: u32) -> (u32, u32) {
        let d = self.dims[a];
        if self.wraps[a] {
            if 2 * h + 1 >= d { (0, d) } else { ((c + d - h) % d, 2 * h + 1) }
        } else {
            let lo = c.saturating_sub(h);
            (lo, (c + h).min(d - 1) - lo + 1)
        }
    }
}

/// `detect_pairs` for grain `i`: appends to `out` every grain `j` with a higher permanent id
/// whose surface is within `skin` of i's (`|r_i - r_j| < R_i + R_j + skin`, minimum image,
/// residuals included: the grid bins by `pos`, which is within a rounding of the position),
/// in ascending id order, so that the list does not depend on the grid.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn detect_pairs<T: Real>(
    i: usize,
    body: &[Body<T>],
    residual: &[Vec3<T>],
    prop: &[Props<T>],
    id: &[u32],
    grid: &CellGrid<T>,
    periodic: &Periodic<T>,
    skin: T,
    out: &mut Vec<u32>,
) {
    let start = out.len();
    scan_cells(i, [1; 3], body, residual, prop, id, grid, periodic, skin, out);
    out[start..].sort_unstable_by_key(|&j| id[j as usize]);
}

/// Appends to `out`, unsorted, the grains `grain i` owns (a higher permanent id and a surface
/// within `skin` of i's) among those of `grid` within `h[a]` cells of i's along each axis `a`
/// ([`CellGrid::within`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn scan_cells<T: Real>(
    i: usize,
    h: [u32; 3],
    body: &[Body<T>],
    residual: &[Vec3<T>],
    prop: &[Props<T>],
    id: &[u32],
    grid: &CellGrid<T>,
    periodic: &Periodic<T>,
    skin: T,
    out: &mut Vec<u32>,
) {
    let c = grid.coords(body[i].pos);
    let span = [0, 1, 2].map(|a| grid.within(c[a], a, h[a]));
    let at = |a: usize, k: u32| {
        let x = span[a].0 + k;
        if x >= grid.dims[a] { x - grid.dims[a] } else { x }
    };
    for kz in 0..span[2].1 {
        for ky in 0..span[1].1 {
            let row = grid.index([0, at(1, ky), at(2, kz)]);
            for kx in 0..span[0].1 {
                let cell = row + at(0, kx) as usize;
                for &j in &grid.cell_grains[grid.cell_start[cell] as usize..grid.cell_start[cell + 1] as usize] {
                    let j = j as usize;
                    if id[j] <= id[i] {
                        continue;
                    }
                    let reach = prop[i].radius + prop[j].radius + skin;
                    if position::separation_of(periodic, |k| body[k].pos, residual, i, j).norm2() < reach * reach {
                        out.push(j as u32);
                    }
                }
            }
        }
    }
}
