//! The pair list (CSR by owner, with the reverse index the gather reads) and
//! `remap_history`, which carries per-contact history across a rebuild.

use super::levels::{detect_pairs_in, Grids};
use super::reduce::chunked;
use super::arrays::{Body, Props};
use crate::periodic::Periodic;
use crate::real::{Real, Vec3};

/// Candidate pairs, each listed once under its owner (the lower permanent id).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PairList {
    /// `owner_start[i]..owner_start[i + 1]` are the pairs grain `i` owns (no per-pair owner
    /// array: 4 bytes a pair; the passes walk the owners, [`Self::owner_of`] finds one).
    pub owner_start: Vec<u32>,
    /// Partner grain of each pair (higher permanent id), ascending id within an owner.
    pub partner: Vec<u32>,
    /// `rev_start[j]..rev_start[j + 1]` index `rev_pair` for the pairs where `j` is partner.
    pub rev_start: Vec<u32>,
    /// Pair indices grouped by partner, ascending within a partner.
    pub rev_pair: Vec<u32>,
}

impl PairList {
    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.partner.len()
    }
    /// True when there are no pairs.
    pub fn is_empty(&self) -> bool {
        self.partner.is_empty()
    }
    /// The owner of pair `k`, by bisection of `owner_start` (for the passes that visit a few
    /// pairs or run between steps; the per-step passes walk the owners).
    #[inline]
    pub fn owner_of(&self, k: usize) -> usize {
        self.owner_start.partition_point(|&s| s as usize <= k) - 1
    }
    /// Pair `k`'s two grains (owner, partner), the owner by [`Self::owner_of`].
    #[inline]
    pub fn grains_of(&self, k: usize) -> (usize, usize) {
        (self.owner_of(k), self.partner[k] as usize)
    }
    /// The owner of every pair in `range`, in order, walking `owner_start` once.
    pub fn owners_of(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = usize> + '_ {
        let mut i = if range.is_empty() { 0 } else { self.owner_of(range.start) };
        range.map(move |k| {
            while self.owner_start[i + 1] as usize <= k {
                i += 1;
            }
            i
        })
    }

    /// Runs `detect_pairs` for every grain and assembles the list, without the reverse lists
    /// ([`Self::build_reverse`]). Of the grains that own more pairs than `capacity` gives for
    /// their slot, returns the one with the lowest permanent id (slot, count).
    pub fn detect<T: Real>(
        body: &[Body<T>],
        residual: &[Vec3<T>],
        prop: &[Props<T>],
        id: &[u32],
        grids: &Grids<T>,
        periodic: &Periodic<T>,
        skin: T,
        capacity: impl Fn(usize) -> usize,
    ) -> Result<Self, (usize, usize)> {
        let n = body.len();
        let parts = chunked(n, |r| {
            let mut counts = Vec::with_capacity(r.len());
            let mut partners = Vec::new();
            for i in r {
                let before = partners.len();
                // A grain out of play owns no pair (and no grid holds it to be found).
                if prop[i].in_play() {
                    detect_pairs_in(i, body, residual, prop, id, grids, periodic, skin, &mut partners);
                }
                counts.push((partners.len() - before) as u32);
            }
            (counts, partners)
        });
        // Exact sizes: a pair list of 10^6 grains is tens of megabytes, so no growth slack.
        let total = parts.iter().map(|(_, partners)| partners.len()).sum();
        let mut list = PairList { owner_start: Vec::with_capacity(n + 1), partner: Vec::with_capacity(total), ..Default::default() };
        list.owner_start.push(0);
        let mut over: Option<(usize, usize)> = None;
        for (counts, partners) in parts {
            for c in counts {
                let i = list.owner_start.len() - 1;
                if c as usize > capacity(i) && over.is_none_or(|(o, _)| id[i] < id[o]) {
                    over = Some((i, c as usize));
                }
                list.owner_start.push(list.owner_start[i] + c);
            }
            list.partner.extend(partners);
        }
        match over {
            Some(o) => Err(o),
            None => Ok(list),
        }
    }

    /// The reverse lists: pair indices grouped by partner, and within a partner in ascending
    /// permanent id of the owner (the owners walked in id order, `slot[id]` being the slot of
    /// permanent id `id`), so that the gather's sums do not depend on how slots are numbered.
    pub fn build_reverse(&mut self, slot: &[u32]) {
        let n = slot.len();
        self.rev_start = vec![0; n + 1];
        for &j in &self.partner {
            self.rev_start[j as usize + 1] += 1;
        }
        for j in 0..n {
            self.rev_start[j + 1] += self.rev_start[j];
        }
        let mut cursor = self.rev_start[..n].to_vec();
        self.rev_pair = vec![0; self.partner.len()];
        for &s in slot {
            for k in self.owner_start[s as usize]..self.owner_start[s as usize + 1] {
                let j = self.partner[k as usize] as usize;
                self.rev_pair[cursor[j] as usize] = k;
                cursor[j] += 1;
            }
        }
    }

    /// `(owner, pair)` for every pair in canonical order: owners by ascending permanent id,
    /// then the owner's pairs in list order (ascending partner id). `slot[id]` is the slot of
    /// permanent id `id`. The owner comes along so that no pass bisects for it (at 10^6 grains
    /// the bisections took 0.36 s of a statistics read's 0.84, two steps' worth).
    pub fn in_id_order(&self, slot: &[u32]) -> Vec<(u32, u32)> {
        let mut order = Vec::with_capacity(self.len());
        for &s in slot {
            order.extend((self.owner_start[s as usize]..self.owner_start[s as usize + 1]).map(|k| (s, k)));
        }
        order
    }

    /// Index of the pair (owner `i`, partner with permanent id `partner_id`), if listed.
    #[inline]
    pub fn find(&self, i: usize, partner_id: u32, id: &[u32]) -> Option<usize> {
        if i + 1 >= self.owner_start.len() {
            return None;
        }
        let (a, b) = (self.owner_start[i] as usize, self.owner_start[i + 1] as usize);
        self.partner[a..b].binary_search_by_key(&partner_id, |&j| id[j as usize]).ok().map(|k| a + k)
    }
}

/// The most pairs a grain of `radius` may own (m; f32, as the GPU holds it) in a scene whose
/// smallest grain has radius `r_min`: `max_neighbours` for a grain of the smallest size, times
/// 4 for each doubling the grain's `radius + r_min` needs to reach past `2 r_min` (the centres
/// of its smallest neighbours lie on a sphere of radius `radius + r_min`, whose area grows as
/// its square): a 20 mm ball among 2 mm grains may own 64 times as many. At most 8 doublings.
/// A guard against a list that explodes (a skin far too large, grains collapsing into each
/// other), not a size the list is allocated to; computed with exact doublings and one correctly
/// rounded f32 sum, so that `detect_count.wgsl`'s twin gives the same bits.
pub fn owner_capacity(max_neighbours: usize, r_min: f32, radius: f32) -> usize {
    let reach = radius + r_min;
    let (mut edge, mut capacity) = (2.0 * r_min, max_neighbours);
    for _ in 0..OWNER_DOUBLINGS {
        if edge >= reach {
            break;
        }
        edge *= 2.0;
        capacity *= 4;
    }
    capacity
}

/// The most doublings [`owner_capacity`] takes (WGSL `OWNER_DOUBLINGS`).
pub const OWNER_DOUBLINGS: u32 = 8;

/// `(owner, pair)` for every pair of a list whose owners' pairs start at `starts` (the
/// `owner_start` a saved state holds), in pair order.
pub fn owned_pairs(starts: &[u64]) -> impl Iterator<Item = (usize, usize)> + '_ {
    starts.windows(2).enumerate().flat_map(|(i, w)| (w[0] as usize..w[1] as usize).map(move |k| (i, k)))
}

/// `remap_history` for new pair `k`, owned by `i`: copies the history block of the same pair
/// (owner and partner's permanent id, as DEM-Engine's persistent map matches them) from the
/// old list, or zeroes it for a pair that is new.
#[inline]
pub fn remap_history<T: Real>(i: usize, k: usize, new: &PairList, old: &PairList, old_hist: &[T], id: &[u32], stride: usize, out: &mut [T]) {
    let j = new.partner[k] as usize;
    match old.find(i, id[j], id) {
        Some(o) => out.copy_from_slice(&old_hist[o * stride..(o + 1) * stride]),
        None => out.fill(T::ZERO),
    }
}

/// Runs `remap_history` over every new pair.
pub fn remap_all<T: Real>(new: &PairList, old: &PairList, old_hist: &[T], id: &[u32], stride: usize) -> Vec<T> {
    if stride == 0 {
        return Vec::new();
    }
    // Owner by owner, in chunks of owners whose blocks are joined in order.
    let n = new.owner_start.len().saturating_sub(1);
    chunked(n, |owners| {
        let pairs = new.owner_start[owners.start] as usize..new.owner_start[owners.end] as usize;
        let mut hist = vec![T::ZERO; pairs.len() * stride];
        for (m, (k, i)) in pairs.clone().zip(new.owners_of(pairs)).enumerate() {
            remap_history(i, k, new, old, old_hist, id, stride, &mut hist[m * stride..(m + 1) * stride]);
        }
        hist
    })
    .concat()
}
