//! The CPU twin of `find_bridge_events` and `update_bridges`: liquid bridges rupture past their
//! rupture distance and form at new contacts, the liquid conserved to round-off.

use super::*;

impl<T: Real> CpuEngine<T> {
    /// Gap (m) between the surfaces of grains `i` and `j` (negative when they overlap).
    pub(super) fn gap(&self, i: usize, j: usize) -> T {
        self.separation(i, j).norm() - self.prop[i].radius - self.prop[j].radius
    }

    /// `update_bridges`: ruptures bridges stretched past their rupture distance, returning
    /// their liquid to the two grains in equal halves, and forms bridges at new contacts from
    /// half of each grain's liquid (capped at the largest bridge volume). Liquid is conserved
    /// to round-off.
    ///
    /// Whether a pair ruptures or may form a bridge depends on its own gap and volume alone,
    /// so a parallel pass finds those events ([`Self::bridge_events`]); the liquid then moves
    /// serially, in canonical order, so that a grain forming several bridges in one step gives
    /// its liquid out in a fixed order (the same bits as one serial walk over every pair, which
    /// cost a quarter of a wet scene's step on two threads).
    pub(super) fn update_bridges(&mut self) {
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        for (k, event) in self.bridge_events() {
            let k = k as usize;
            let (i, j) = self.pairs.grains_of(k);
            let (mut l_i, mut l_j) = (self.liquid[i], self.liquid[j]);
            self.hist[k * stride + b] = move_liquid(event, self.hist[k * stride + b], self.bridge_cap, &mut l_i, &mut l_j);
            (self.liquid[i], self.liquid[j]) = (l_i, l_j);
        }
    }

    /// The pairs whose bridge ruptures or may form at this evaluation, in canonical order
    /// (owner id, then partner id: the pair order within an owner); none without cohesion.
    pub(super) fn bridge_events(&self) -> Vec<(u32, BridgeEvent)> {
        let CohesionLaw::Capillary { theta, .. } = self.model.cohesion else { return Vec::new() };
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        let events: Vec<Vec<(u32, BridgeEvent)>> = chunked(self.pairs.len(), |range| {
            range
                .clone()
                .zip(self.pairs.owners_of(range))
                .filter_map(|(k, i)| {
                    let (v, gap) = (self.hist[k * stride + b], self.gap(i, self.pairs.partner[k] as usize));
                    let event = if v > T::ZERO {
                        (!within_rupture(theta, v, gap)).then_some(BridgeEvent::Rupture)
                    } else {
                        (gap < T::ZERO).then_some(BridgeEvent::Touch)
                    };
                    event.map(|e| (k as u32, e))
                })
                .collect()
        });
        // Pair order by slot follows the numbering; the liquid moves in canonical order.
        let mut events: Vec<(u32, BridgeEvent)> = events.into_iter().flatten().collect();
        events.sort_by_key(|&(k, _)| (self.id[self.pairs.owner_of(k as usize)], k));
        events
    }
}

/// What `update_bridges` does to one pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum BridgeEvent {
    /// Its bridge is stretched past its rupture distance.
    Rupture,
    /// It touches without a bridge: one forms if its grains hold liquid.
    Touch,
}

/// The bridge volume (m^3) a pair holds after `event`, from its volume before it, `bridge`, and
/// the liquid waiting on its two grains (m^3), which the event changes: a rupture returns the
/// bridge to them in halves; a touch forms a bridge from half of each one's liquid, scaled down
/// to `cap` when more.
#[inline]
pub(crate) fn move_liquid<T: Real>(event: BridgeEvent, bridge: T, cap: T, liquid_i: &mut T, liquid_j: &mut T) -> T {
    let half = T::of(0.5);
    match event {
        BridgeEvent::Rupture => {
            *liquid_i += bridge * half;
            *liquid_j += bridge * half;
            T::ZERO
        }
        BridgeEvent::Touch if *liquid_i > T::ZERO || *liquid_j > T::ZERO => {
            let (mut a, mut c) = (*liquid_i * half, *liquid_j * half);
            if a + c > cap {
                let s = cap / (a + c);
                a *= s;
                c *= s;
            }
            *liquid_i -= a;
            *liquid_j -= c;
            a + c
        }
        BridgeEvent::Touch => bridge,
    }
}
