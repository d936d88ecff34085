//! How a distributed run cuts one axis of the domain (see [`super::Grid`], which cuts each
//! axis so): into slabs, each holding about as many grains as the others, cut at the start
//! and again at a rebuild when the counts have drifted apart. Along a wrapping axis the slabs
//! form a ring: the last one borders the first across the period.

use crate::scene::Scene;

/// Slabs along `axis`: slab `r` holds the grains with `cuts[r - 1] <= x < cuts[r]` (the first
/// and last slabs reach to infinity, or, along a wrapping axis, to the period's ends,
/// positions taken within the period), and its neighbours' grains within `reach` of it as
/// ghosts.
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
    /// The axis's wrapping interval `[lo, hi)` (m) when it is periodic: the slabs then form a
    /// ring, `[lo, cuts[0])` to `[cuts[K - 2], hi)`, and distances go round it.
    pub period: Option<[f64; 2]>,
}

impl Slabs {
    /// One slab along `axis` of `scene` (uncut), with the scene's reach, skin and period.
    pub fn uncut(scene: &Scene, axis: usize) -> Self {
        let r_max = scene.grains.radius.iter().copied().fold(0.0, f64::max);
        Slabs { axis, cuts: Vec::new(), reach: 2.0 * r_max + scene.skin + scene.bridges.reach, skin: scene.skin, period: scene.periodic[axis] }
    }

    /// How far the grains of `scene` spread along the axis (m): a wrapping axis spans its
    /// period.
    pub fn extent(&self, scene: &Scene) -> f64 {
        match self.period {
            Some([lo, hi]) => hi - lo,
            None => {
                let (lo, hi) = scene.grains.position.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[self.axis]), hi.max(p[self.axis])));
                hi - lo
            }
        }
    }

    /// Slabs along the axis (0 = x) cut into `slabs` at the quantiles of `scene`'s starting
    /// positions; the narrowest slab (m) when one would be too narrow (see
    /// [`Self::cut_at_quantiles`]).
    pub fn cut(scene: &Scene, axis: usize, slabs: usize) -> Result<Self, f64> {
        let mut s = Slabs::uncut(scene, axis);
        s.cut_at_quantiles(scene.grains.position.iter().map(|p| p[axis]).collect(), slabs)?;
        Ok(s)
    }

    /// Slabs along the axis.
    pub fn count(&self) -> usize {
        self.cuts.len() + 1
    }

    /// `x` (m) brought into the period along a wrapping axis; `x` itself otherwise.
    fn wrap(&self, x: f64) -> f64 {
        match self.period {
            Some([lo, hi]) => {
                let y = x - (hi - lo) * ((x - lo) / (hi - lo)).floor();
                if y >= hi { lo } else { y }
            }
            None => x,
        }
    }

    /// Cuts at the quantiles of the positions `x` (m) along the axis, so that each of `ranks`
    /// processes owns as many grains (within one); leaves the cuts as they were and returns
    /// the narrowest slab (m) when one would be narrower than `reach + skin` (an inner one;
    /// along a wrapping axis, any one).
    pub fn cut_at_quantiles(&mut self, x: Vec<f64>, ranks: usize) -> Result<(), f64> {
        if ranks <= 1 {
            self.cuts.clear();
            return Ok(());
        }
        let mut x: Vec<f64> = x.into_iter().map(|x| self.wrap(x)).collect();
        x.sort_by(f64::total_cmp);
        let n = x.len();
        let cuts: Vec<f64> = (1..ranks).map(|k| 0.5 * (x[k * n / ranks - 1] + x[k * n / ranks])).collect();
        let bounds: Vec<f64> = match self.period {
            Some([lo, hi]) => [lo].into_iter().chain(cuts.iter().copied()).chain([hi]).collect(),
            _ => cuts.clone(),
        };
        if let Some(w) = bounds.windows(2).map(|c| c[1] - c[0]).min_by(f64::total_cmp).filter(|&w| !(w >= self.reach + self.skin)) {
            return Err(w);
        }
        self.cuts = cuts;
        Ok(())
    }

    /// The process that owns a grain at `x` along the axis (m).
    pub fn owner(&self, x: f64) -> usize {
        let x = self.wrap(x);
        self.cuts.partition_point(|&c| c <= x)
    }

    /// True when a grain at `x` (m) lies within the reach of process `r`'s slab (in it or not),
    /// round the ring along a wrapping axis.
    pub fn near(&self, x: f64, r: usize) -> bool {
        let (lo, hi) = (self.period.map_or(f64::NEG_INFINITY, |p| p[0]), self.period.map_or(f64::INFINITY, |p| p[1]));
        let a = if r == 0 { lo } else { self.cuts[r - 1] };
        let b = self.cuts.get(r).copied().unwrap_or(hi);
        let gap = |x: f64| (a - x).max(x - b);
        let gap = match self.period {
            Some([lo, hi]) => {
                let x = self.wrap(x);
                gap(x).min(gap(x - (hi - lo))).min(gap(x + (hi - lo)))
            }
            None => gap(x),
        };
        gap < self.reach
    }

    /// The processes that hold a grain at `x` (m): its owner first, then the neighbours it is
    /// a ghost of (a grain farther than a slab from its owner is a ghost of no one else).
    pub fn holders(&self, x: f64) -> Vec<usize> {
        let (o, k) = (self.owner(x), self.cuts.len() + 1);
        let mut h = vec![o];
        let beside = match self.period {
            Some(_) => [(o + k - 1) % k, (o + 1) % k],
            None => [o.wrapping_sub(1), o + 1],
        };
        for r in beside {
            if r < k && !h.contains(&r) && self.near(x, r) {
                h.push(r);
            }
        }
        h
    }
}
