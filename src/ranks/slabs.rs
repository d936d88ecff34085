//! How a distributed run cuts the domain: slabs along one axis, one per process, each
//! holding about as many grains as the others: cut at the start, and again at a rebuild when
//! the counts have drifted apart.

use crate::scene::Scene;

/// Slabs along `axis`: process `r` owns the grains with `cuts[r - 1] <= x < cuts[r]` (the
/// first and last slabs reach to infinity), and holds as ghosts the grains of its neighbours
/// within `reach` of its slab.
#[derive(Clone, Debug, PartialEq)]
pub struct Slabs {
    /// The axis cut (0 = x).
    pub axis: usize,
    /// The cuts (m), ascending; one fewer than the processes.
    pub cuts: Vec<f64>,
    /// How far beyond its slab a process holds ghosts (m): the neighbour reach
    /// `2 r_max + skin`, within which any grain it owns may list a pair.
    pub reach: f64,
    /// The skin (m): an inner slab is at least `reach + skin` wide, so that a grain's pairs
    /// and its moves between two rebuilds (at most half the skin) stay within the neighbouring
    /// slabs.
    pub skin: f64,
}

/// A grain count at which the slabs are cut anew, as a multiple of the mean: a rebuild that
/// finds a process owning more moves the cuts to the quantiles of the grains' positions.
pub const REBALANCE_ABOVE: f64 = 1.2;

impl Slabs {
    /// The slabs of `scene` for `ranks` processes: along the non-periodic axis over which the
    /// grains spread widest, cut at the quantiles of the grains' starting positions.
    pub fn new(scene: &Scene, ranks: usize) -> anyhow::Result<Self> {
        let file = scene.path.display();
        let g = &scene.grains;
        let extent = |a: usize| {
            let (lo, hi) = g.position.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[a]), hi.max(p[a])));
            hi - lo
        };
        let Some(axis) = (0..3).filter(|&a| scene.periodic[a].is_none()).max_by(|&a, &b| extent(a).total_cmp(&extent(b))) else {
            anyhow::bail!("{file}: periodic = every axis: a run over several processes cuts the domain into slabs along an axis that does not wrap, and this scene has none; fix: run it on one process");
        };
        let r_max = g.radius.iter().copied().fold(0.0, f64::max);
        let n = g.len();
        if ranks > n {
            anyhow::bail!("{file}: {ranks} processes for {n} grains; fix: run on at most {n} processes");
        }
        let mut slabs = Slabs { axis, cuts: Vec::new(), reach: 2.0 * r_max + scene.skin + scene.bridges.reach, skin: scene.skin };
        let x: Vec<f64> = g.position.iter().map(|p| p[axis]).collect();
        if let Err(w) = slabs.cut_at_quantiles(x, ranks) {
            let (name, need) = (["x", "y", "z"][axis], slabs.reach + slabs.skin);
            anyhow::bail!(
                "{file}: {ranks} processes cut the grains into slabs along {name} as narrow as {w:.3e} m, below the {need:.3e} m a slab needs (the neighbour reach 2 r_max + skin = {:.3e} m plus the skin); fix: run on fewer processes",
                slabs.reach
            );
        }
        Ok(slabs)
    }

    /// Cuts at the quantiles of the positions `x` (m) along the axis, so that each of `ranks`
    /// processes owns as many grains (within one); leaves the cuts as they were and returns
    /// the narrowest inner slab (m) when one would be narrower than `reach + skin`.
    pub fn cut_at_quantiles(&mut self, mut x: Vec<f64>, ranks: usize) -> Result<(), f64> {
        x.sort_by(f64::total_cmp);
        let n = x.len();
        let cuts: Vec<f64> = (1..ranks).map(|k| 0.5 * (x[k * n / ranks - 1] + x[k * n / ranks])).collect();
        if let Some(w) = cuts.windows(2).map(|c| c[1] - c[0]).min_by(f64::total_cmp).filter(|&w| !(w >= self.reach + self.skin)) {
            return Err(w);
        }
        self.cuts = cuts;
        Ok(())
    }

    /// The process that owns a grain at `x` along the axis (m).
    pub fn owner(&self, x: f64) -> usize {
        self.cuts.partition_point(|&c| c <= x)
    }

    /// True when a grain at `x` (m) lies within the reach of process `r`'s slab (in it or not).
    pub fn near(&self, x: f64, r: usize) -> bool {
        let lo = if r == 0 { f64::NEG_INFINITY } else { self.cuts[r - 1] };
        let hi = self.cuts.get(r).copied().unwrap_or(f64::INFINITY);
        (lo - x).max(x - hi) < self.reach
    }

    /// The processes that hold a grain at `x` (m): its owner first, then the neighbours it is
    /// a ghost of (a grain farther than a slab from its owner is a ghost of no one else).
    pub fn holders(&self, x: f64) -> Vec<usize> {
        let o = self.owner(x);
        let mut h = vec![o];
        h.extend([o.wrapping_sub(1), o + 1].into_iter().filter(|&r| r <= self.cuts.len() && self.near(x, r)));
        h
    }
}
