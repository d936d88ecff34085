//! How a distributed run cuts the domain into boxes, one per process: a grid of `n_x x n_y x
//! n_z` boxes, each axis cut into slabs of its own ([`Slabs`]) at the quantiles of the grains'
//! positions along it. Of the ways to write the process count as such a product, the grid
//! takes the one whose narrowest cut slab is widest (the boxes nearest to cubes), so one or
//! two processes cut slabs along the widest axis, and four a bed wider than tall into columns.

use super::slabs::Slabs;
use crate::scene::Scene;

/// A grain count at which the cuts move, as a multiple of the mean: a rebuild that finds a
/// process owning more cuts every cut axis anew at the quantiles of the grains' positions.
pub const REBALANCE_ABOVE: f64 = 1.2;

/// Boxes, one per process: process `r` owns the box of slab indices `(i_x, i_y, i_z)` with
/// `r = i_x + n_x (i_y + n_y i_z)`, and holds as ghosts the grains of other boxes within the
/// reach of its own along every axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// The slabs along x, y and z (an axis cut into one slab is not cut).
    pub axes: [Slabs; 3],
}

impl Grid {
    /// The grid of `scene` for `ranks` processes.
    pub fn new(scene: &Scene, ranks: usize) -> anyhow::Result<Self> {
        let file = scene.path.display();
        let n = scene.grains.len();
        if ranks > n {
            anyhow::bail!("{file}: {ranks} processes for {n} grains; fix: run on at most {n} processes");
        }
        let uncut = [0, 1, 2].map(|a| Slabs::uncut(scene, a));
        let extent = uncut.clone().map(|s| s.extent(scene));
        let mut best: Option<(f64, Grid)> = None;
        for n_x in (1..=ranks).filter(|&d| ranks.is_multiple_of(d)) {
            for n_y in (1..=ranks / n_x).filter(|&d| (ranks / n_x).is_multiple_of(d)) {
                let dims = [n_x, n_y, ranks / (n_x * n_y)];
                let cut: Result<Vec<Slabs>, f64> = (0..3).map(|a| Slabs::cut(scene, a, dims[a])).collect();
                let Ok(axes) = cut else { continue };
                let narrowest = (0..3).filter(|&a| dims[a] > 1).map(|a| extent[a] / dims[a] as f64).fold(f64::INFINITY, f64::min);
                if best.as_ref().is_none_or(|(w, _)| narrowest > *w) {
                    best = Some((narrowest, Grid { axes: [axes[0].clone(), axes[1].clone(), axes[2].clone()] }));
                }
            }
        }
        if let Some((_, grid)) = best {
            return Ok(grid);
        }
        // No grid fits: say what the slabs along the widest axis would be.
        let widest = (0..3).max_by(|&a, &b| extent[a].total_cmp(&extent[b])).unwrap_or(0);
        let w = Slabs::cut(scene, widest, ranks).err().unwrap_or(0.0);
        let (s, name) = (&uncut[widest], ["x", "y", "z"][widest]);
        anyhow::bail!(
            "{file}: {ranks} processes cut the grains into slabs along {name} as narrow as {w:.3e} m, below the {:.3e} m a slab needs (the neighbour reach 2 r_max + skin = {:.3e} m plus the skin), and no grid of boxes fits them either; fix: run on fewer processes",
            s.reach + s.skin,
            s.reach
        )
    }

    /// Processes (boxes).
    pub fn ranks(&self) -> usize {
        self.axes.iter().map(Slabs::count).product()
    }

    /// The process of the box of slab indices `i`.
    fn rank_of(&self, i: [usize; 3]) -> usize {
        i[0] + self.axes[0].count() * (i[1] + self.axes[1].count() * i[2])
    }

    /// The slab indices of process `r`'s box.
    fn index_of(&self, r: usize) -> [usize; 3] {
        let (n_x, n_y) = (self.axes[0].count(), self.axes[1].count());
        [r % n_x, (r / n_x) % n_y, r / (n_x * n_y)]
    }

    /// The process that owns a grain at `p` (m).
    pub fn owner(&self, p: [f64; 3]) -> usize {
        self.rank_of([0, 1, 2].map(|a| self.axes[a].owner(p[a])))
    }

    /// True when a grain at `p` (m) lies within the reach of process `r`'s box along every
    /// axis (in it or not).
    pub fn near(&self, p: [f64; 3], r: usize) -> bool {
        let i = self.index_of(r);
        (0..3).all(|a| self.axes[a].near(p[a], i[a]))
    }

    /// The processes that hold a grain at `p` (m): its owner first, then, in ascending order,
    /// the boxes it is a ghost of (a neighbour of the owner's box along each axis).
    pub fn holders(&self, p: [f64; 3]) -> Vec<usize> {
        let [x, y, z] = [0, 1, 2].map(|a| self.axes[a].holders(p[a]));
        let owner = self.owner(p);
        let mut others = Vec::new();
        for &i in &x {
            for &j in &y {
                others.extend(z.iter().map(|&k| self.rank_of([i, j, k])).filter(|&r| r != owner));
            }
        }
        others.sort_unstable();
        others.dedup();
        [owner].into_iter().chain(others).collect()
    }

    /// Cuts every cut axis anew at the quantiles of `positions` (m; an axis whose slabs would
    /// be too narrow keeps its cuts).
    pub fn recut(&mut self, positions: &[[f64; 3]]) {
        for s in &mut self.axes {
            let count = s.count();
            if count > 1 {
                let _ = s.cut_at_quantiles(positions.iter().map(|p| p[s.axis]).collect(), count);
            }
        }
    }
}
