//! The grain pairs a step's contacts are drawn from: every pair within the gap allowance plus a
//! skin, found by the cell search and kept while no grain has moved half the skin since (a
//! Verlet list). Two grains then cannot have come within the allowance without being in the
//! list, so the pairs of the list within the allowance, tested as the cell search tests them
//! and in the list's canonical order, are the pairs a search of the allowance alone would find,
//! in its order: the list changes when the search runs, never a result.

use crate::periodic::Periodic;
use crate::real::{Real, Vec3};
use crate::state::{Body, Grids, PairList, Props};

/// The candidate pairs and the positions they were found at.
#[derive(Default)]
pub(super) struct Near<T> {
    /// Pairs within `allowance + skin`, owner by owner in id order, partners in id order.
    pub pairs: PairList,
    /// Each grain's position when the pairs were found (m; the compensated residual left out:
    /// it is below a position's last bit, far below any skin).
    found_at: Vec<Vec3<T>>,
    /// The skin the pairs were found with (m).
    skin: T,
    /// Searches run since the start.
    pub searches: u64,
}

impl<T: Real> Near<T> {
    /// Whether the pairs still hold every pair within the allowance: no grain has moved half
    /// the skin since they were found.
    fn holds(&self, body: &[Body<T>]) -> bool {
        let half = self.skin * T::of(0.5);
        self.found_at.len() == body.len() && body.iter().zip(&self.found_at).all(|(b, &at)| (b.pos - at).norm2() < half * half)
    }

    /// The pairs, searched again with a skin of `skin` (m) when a grain has moved half the
    /// last one since they were found.
    pub fn update(&mut self, body: &[Body<T>], residual: &[Vec3<T>], prop: &[Props<T>], id: &[u32], r_max: T, allowance: T, skin: T) -> &PairList {
        if self.skin == skin && self.holds(body) {
            return &self.pairs;
        }
        self.pairs = search(body, residual, prop, id, r_max, allowance + skin);
        self.found_at = body.iter().map(|b| b.pos).collect();
        self.skin = skin;
        self.searches += 1;
        &self.pairs
    }

    /// What a checkpoint keeps: where the pairs were found (m), the skin (m), the searches.
    pub fn saved(&self) -> (&[Vec3<T>], T, u64) {
        (&self.found_at, self.skin, self.searches)
    }

    /// The pairs of a resumed run, which searches again at the steps the uninterrupted run
    /// does (`found_at`, `skin` and `searches` as [`Self::saved`] gave them). Until then every
    /// grain stays within half the skin of `found_at`, as it is now, so within a skin of where
    /// it is now: the pairs are searched now with twice the skin, which holds every pair that
    /// can come within the allowance before the next search.
    #[allow(clippy::too_many_arguments)]
    pub fn resumed(found_at: Vec<Vec3<T>>, skin: T, searches: u64, body: &[Body<T>], residual: &[Vec3<T>], prop: &[Props<T>], id: &[u32], r_max: T, allowance: T) -> Self {
        let pairs = if found_at.len() == body.len() { search(body, residual, prop, id, r_max, allowance + skin * T::of(2.0)) } else { PairList::default() };
        Near { pairs, found_at, skin, searches }
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        use crate::state::allocated;
        allocated(&self.pairs.owner_start) + allocated(&self.pairs.partner) + allocated(&self.found_at)
    }
}

/// Every pair within `reach` (m) of each other's surfaces, by the cell search. Non-finite
/// positions find no pairs (the step's own check reports them).
fn search<T: Real>(body: &[Body<T>], residual: &[Vec3<T>], prop: &[Props<T>], id: &[u32], r_max: T, reach: T) -> PairList {
    let periodic = Periodic::<T>::of(&[None, None, None]);
    let grids = Grids::hash(body, prop, r_max * T::of(2.0) + reach, reach, &periodic).unwrap_or_default();
    PairList::detect(body, residual, prop, id, &grids, &periodic, reach, |_| usize::MAX).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pairs of a fresh search within `reach`, as (owner, partner) slots.
    fn fresh(body: &[Body<f64>], prop: &[Props<f64>], id: &[u32], r_max: f64, reach: f64) -> Vec<(usize, u32)> {
        let p = search(body, &[], prop, id, r_max, reach);
        p.owners_of(0..p.len()).zip(p.partner.iter().copied()).collect()
    }

    /// The kept pairs' members within the allowance, tested as the contacts' detection tests
    /// them, in the list's order.
    fn within(near: &Near<f64>, body: &[Body<f64>], prop: &[Props<f64>], allowance: f64) -> Vec<(usize, u32)> {
        let p = &near.pairs;
        p.owners_of(0..p.len())
            .zip(p.partner.iter().copied())
            .filter(|&(a, b)| {
                let reach = prop[a].radius + prop[b as usize].radius + allowance;
                (body[b as usize].pos - body[a].pos).norm2() < reach * reach
            })
            .collect()
    }

    /// 2,000 grains of radii 0.5-1 mm scattered in a 20 mm box, moving at random speeds of up
    /// to a fifth of the skin a step for 60 steps: at every step the kept pairs within the
    /// allowance are a fresh search's, in its order; the list is searched again only every few
    /// steps; and a list resumed from a checkpoint's record searches at the same steps and
    /// finds the same pairs.
    #[test]
    fn the_kept_pairs_within_the_allowance_are_a_fresh_searchs() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = 2000;
        let (allowance, skin) = (5e-5, 5e-5);
        let mut body: Vec<Body<f64>> = (0..n).map(|_| Body { pos: Vec3::of([0.02 * next(), 0.02 * next(), 0.02 * next()]), ..Default::default() }).collect();
        let prop: Vec<Props<f64>> = (0..n).map(|_| Props { radius: 5e-4 * (1.0 + next()), mass: 1.0, inertia: 1.0 }).collect();
        let step: Vec<Vec3<f64>> = (0..n).map(|_| Vec3::of([next() - 0.5, next() - 0.5, next() - 0.5]) * (0.2 * skin / 0.87)).collect();
        let id: Vec<u32> = (0..n as u32).collect();
        let r_max = 1e-3;
        let (mut near, mut resumed) = (Near::default(), None::<Near<f64>>);
        for k in 0..60 {
            near.update(&body, &[], &prop, &id, r_max, allowance, skin);
            let expected = fresh(&body, &prop, &id, r_max, allowance);
            assert!(expected.len() > 1000, "a dense enough scatter: {} pairs", expected.len());
            assert_eq!(within(&near, &body, &prop, allowance), expected, "step {k}");
            if let Some(r) = &mut resumed {
                r.update(&body, &[], &prop, &id, r_max, allowance, skin);
                assert_eq!(within(r, &body, &prop, allowance), expected, "resumed, step {k}");
                assert_eq!(r.searches, near.searches, "resumed, step {k}");
            }
            if k == 20 {
                let (found_at, skin, searches) = near.saved();
                resumed = Some(Near::resumed(found_at.to_vec(), skin, searches, &body, &[], &prop, &id, r_max, allowance));
            }
            for (b, &d) in body.iter_mut().zip(&step) {
                b.pos += d;
            }
        }
        assert!((10..=30).contains(&near.searches), "searched {} times in 60 steps", near.searches);
    }
}
