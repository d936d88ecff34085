//! The neighbour search for grains of very different sizes: a cell grid per size class, as
//! LAMMPS' `neigh_modify ... multi` bins each type by its own cut-off. One grid sized by the
//! largest grain puts hundreds of small grains in each cell when one grain is ten times the
//! others (a 20 mm ball among 2 mm grains: cells of 21 mm, some 1,500 grains each at the bed's
//! density); here each class has cells as wide as its own largest pair, and a grain searches
//! every class's grid as far as its reach into that class goes (the ball, about six of the
//! small grains' cells each way; a small grain, the ball's cells next to its own). The pair
//! list does not depend on the grids (each owner's partners in ascending permanent id, by the
//! same distance test), so it is the single grid's to the bit; a scene whose radii are within
//! [`CLASS_RATIO`] of each other keeps the single grid and its search.

use super::arrays::{Body, Props};
use super::grid::{bounds_of, detect_pairs, place, scan_cells, CellGrid};
use crate::periodic::Periodic;
use crate::real::{Real, Vec3};

/// Radii within this ratio share a size class: the class's smallest grains search cells at most
/// this many of their own diameters wide.
pub const CLASS_RATIO: f64 = 2.0;

/// The most size classes: radii beyond the last class's lower bound join it (WGSL
/// `MAX_CLASSES`, the length of `Params`' class tables).
pub const MAX_CLASSES: usize = 8;

/// The grids of a neighbour build: one over every grain, or one per size class.
#[derive(Clone, Debug, Default)]
pub struct Grids<T> {
    /// The grid of each class, smallest grains first, with the class's largest radius (m).
    pub classes: Vec<(CellGrid<T>, T)>,
}

impl<T: Real> Grids<T> {
    /// The grid over every grain, or the smallest class's (over the same box): what
    /// renumbering in cell order follows.
    pub fn finest(&self) -> &CellGrid<T> {
        &self.classes[0].0
    }

    /// Hashes the grains into grids: one (exactly `hash_cells` with cells of `cutoff`, the
    /// largest pair's reach, m) when the radii are within [`CLASS_RATIO`] of each other, else
    /// one per size class, each with cells of its largest pair plus `reach` (m: the skin and
    /// any bridge's rupture distance). Returns `None` when a position is not finite.
    pub fn hash(body: &[Body<T>], prop: &[Props<T>], cutoff: T, reach: T, periodic: &Periodic<T>) -> Option<Self> {
        // Grains out of play ([`Props::in_play`]) are in no grid: the slots of those in play,
        // when some are not.
        let playing: Option<Vec<u32>> = if prop.iter().all(Props::in_play) { None } else { Some((0..prop.len() as u32).filter(|&i| prop[i as usize].in_play()).collect()) };
        let bounds = bounds_of(body, playing.as_deref(), periodic)?;
        let tops = class_tops(prop.iter().filter(|p| p.in_play()).map(|p| p.radius.f64()));
        let mut grids = Grids { classes: Vec::with_capacity(tops.len()) };
        if tops.len() <= 1 {
            let mut grid = CellGrid::default();
            place(body, playing.as_deref(), bounds, cutoff, periodic, &mut grid);
            grids.classes.push((grid, T::of(tops.first().copied().unwrap_or(0.0))));
            return Some(grids);
        }
        let mut members = vec![Vec::new(); tops.len()];
        for (i, p) in prop.iter().enumerate().filter(|(_, p)| p.in_play()) {
            members[class_index(&tops, p.radius.f64())].push(i as u32);
        }
        for (m, &largest) in members.iter().zip(&tops) {
            let largest = T::of(largest);
            let mut grid = CellGrid::default();
            place(body, Some(m), bounds, largest + largest + reach, periodic, &mut grid);
            grids.classes.push((grid, largest));
        }
        Some(grids)
    }
}

/// The size classes of grains of `radii` (m): the largest radius of each class that holds a
/// grain, smallest first. A class spans a factor of [`CLASS_RATIO`]: the first from `r_min`
/// to `CLASS_RATIO r_min` inclusive, the next to `CLASS_RATIO^2 r_min`, ...; radii beyond the
/// [`MAX_CLASSES`]th join the last. Both backends class grains by these tops
/// ([`class_index`]; on the GPU `class_of` in `shaders/shared/grid.wgsl`).
pub fn class_tops(radii: impl Iterator<Item = f64> + Clone) -> Vec<f64> {
    let r_min = radii.clone().fold(f64::INFINITY, f64::min);
    let mut tops = [f64::NEG_INFINITY; MAX_CLASSES];
    for r in radii {
        let mut class = 0;
        let mut top = r_min * CLASS_RATIO;
        while top < r && class + 1 < MAX_CLASSES {
            top *= CLASS_RATIO;
            class += 1;
        }
        tops[class] = tops[class].max(r);
    }
    tops.into_iter().filter(|t| t.is_finite()).collect()
}

/// The class of a grain of `radius` (m) among classes of `tops` ([`class_tops`]): the first
/// whose top it does not exceed, the last when it exceeds them all.
pub fn class_index(tops: &[f64], radius: f64) -> usize {
    tops.iter().position(|&t| radius <= t).unwrap_or(tops.len() - 1)
}

/// `detect_pairs` over [`Grids`]: appends to `out` every grain `j` with a higher permanent id
/// whose surface is within `reach` of i's, in ascending id order (see [`detect_pairs`]; with
/// one grid, it is that search).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn detect_pairs_in<T: Real>(i: usize, body: &[Body<T>], residual: &[Vec3<T>], prop: &[Props<T>], id: &[u32], grids: &Grids<T>, periodic: &Periodic<T>, reach: T, out: &mut Vec<u32>) {
    if let [(grid, _)] = &grids.classes[..] {
        return detect_pairs(i, body, residual, prop, id, grid, periodic, reach, out);
    }
    let start = out.len();
    for (grid, largest) in &grids.classes {
        // How many of this grid's cells the farthest partner's centre may lie away.
        let far = prop[i].radius + *largest + reach;
        let h = [0, 1, 2].map(|a| ((far / grid.cell[a]).f64().ceil() as u32).max(1));
        scan_cells(i, h, body, residual, prop, id, grid, periodic, reach, out);
    }
    out[start..].sort_unstable_by_key(|&j| id[j as usize]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::{hash_cells, owner_capacity, PairList};

    /// A box of `n` grains (a deterministic scatter, overlaps allowed: the search is geometry
    /// alone) of radii from `radius(k)`, in a 40 x 40 x 40 mm box, periodic along x when
    /// `wrap`.
    fn scene(n: usize, radius: impl Fn(usize) -> f64, wrap: bool) -> (Vec<Body<f64>>, Vec<Props<f64>>, Periodic<f64>) {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let body = (0..n).map(|_| Body { pos: Vec3::of([0.04 * next(), 0.04 * next(), 0.04 * next()]), ..Default::default() }).collect();
        let prop = (0..n).map(|k| Props { radius: radius(k), mass: 1.0, inertia: 1.0 }).collect();
        (body, prop, Periodic::of(&[wrap.then_some([0.0, 0.04]), None, None]))
    }

    /// The list through the size classes, against the one grid sized by the largest grain
    /// (the search every other scene uses): the same pairs in the same order, for a few 10 mm
    /// balls among 1 mm grains and for radii spread evenly from 0.5 to 5 mm, with and without a
    /// periodic axis; a class for each factor of two the radii span that holds a grain.
    #[test]
    fn size_classes_find_the_single_grids_pairs() {
        let reach = 2e-4;
        let balls_in_a_bed = |k: usize| if k % 500 == 7 { 0.010 } else { 0.001 };
        let ratio_ten_spread = |k: usize| 0.0005 + 0.0045 * ((k * 7919) % 1000) as f64 / 999.0;
        let cases = [("balls in a bed", balls_in_a_bed as fn(usize) -> f64, 2), ("ratio-10 spread", ratio_ten_spread, 4)];
        for (name, radius, classes) in cases {
            for wrap in [false, true] {
                let (body, prop, periodic) = scene(3000, radius, wrap);
                let id: Vec<u32> = (0..body.len() as u32).rev().collect();
                let r_max = prop.iter().map(|p| p.radius).fold(0.0, f64::max);
                let cutoff = 2.0 * r_max + reach;
                let grids = Grids::hash(&body, &prop, cutoff, reach, &periodic).unwrap();
                assert_eq!(grids.classes.len(), classes, "{name}");
                let mut one = CellGrid::default();
                assert!(hash_cells(&body, cutoff, &periodic, &mut one));
                let single = Grids { classes: vec![(one, r_max)] };
                let by_classes = PairList::detect(&body, &[], &prop, &id, &grids, &periodic, reach, |_| usize::MAX).unwrap();
                let by_one = PairList::detect(&body, &[], &prop, &id, &single, &periodic, reach, |_| usize::MAX).unwrap();
                assert!(by_one.len() > body.len(), "{name}: {} pairs", by_one.len());
                assert_eq!(by_classes, by_one, "{name}, periodic {wrap}");
            }
        }
    }

    /// A grain of the smallest size may own `max_neighbours` pairs; one whose radius plus the
    /// smallest is 2, 4 or 5.5 times the smallest diameter, 4, 16 or 64 times as many.
    #[test]
    fn larger_grains_may_own_more_pairs() {
        let r = 0.001f32;
        assert_eq!(owner_capacity(32, r, r), 32);
        assert_eq!(owner_capacity(32, r, 3.0 * r), 128);
        assert_eq!(owner_capacity(32, r, 7.0 * r), 512);
        assert_eq!(owner_capacity(32, r, 10.0 * r), 2048);
    }
}
