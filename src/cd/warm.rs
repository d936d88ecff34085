//! The warm start: each contact's impulse of the last step, carried to the contact between the
//! same two bodies, by grain id and partner (grain id or wall). Kept in detection order (the
//! grain pairs by first and second grain, then the wall contacts by grain and wall, each run
//! ascending), so that a step's contacts, detected in that order, find theirs by walking the
//! two runs alongside (a hash map's lookups were a tenth of a step).

use super::{Contact, Partner};
use crate::real::{Real, Vec3};

/// One carried impulse: first grain's id, the partner's code ([`code`]), the impulse (N s).
pub(super) type Entry<T> = (u32, u64, Vec3<T>);

/// A partner as a sortable code: a grain's id, or [`WALL_TAG`] plus a wall's index.
pub(super) fn code(b: Partner) -> u64 {
    match b {
        Partner::Grain(j) => j as u64,
        Partner::Wall(w) => WALL_TAG + w as u64,
    }
}

/// Partner codes at and above this are walls (above every grain id).
pub(super) const WALL_TAG: u64 = 1 << 32;

/// The last step's nonzero impulses, in detection order.
#[derive(Clone, Debug, Default)]
pub(super) struct WarmStart<T> {
    entries: Vec<Entry<T>>,
}

impl<T: Real> WarmStart<T> {
    /// From entries in any order (a checkpoint's).
    pub fn of(mut entries: Vec<Entry<T>>) -> Self {
        entries.sort_by_key(|&(a, b, _)| (b >= WALL_TAG, a, b));
        WarmStart { entries }
    }

    /// The entries, in detection order.
    pub fn entries(&self) -> &[Entry<T>] {
        &self.entries
    }

    /// Sets each contact's impulse (`contacts` in detection order; grain slots to ids by `id`)
    /// to the one carried for its two bodies, zero where none.
    pub fn start(&self, contacts: &mut [Contact<T>], id: &[u32]) {
        let mut at = 0;
        for c in contacts {
            let key = (matches!(c.b, Partner::Wall(_)), id[c.a as usize], code(c.b));
            let order = |&(a, b, _): &Entry<T>| (b >= WALL_TAG, a, b);
            while at < self.entries.len() && order(&self.entries[at]) < key {
                at += 1;
            }
            c.r = match self.entries.get(at) {
                Some(e) if order(e) == key => e.2,
                _ => Vec3::ZERO,
            };
        }
    }

    /// The record of a step's solved contacts (in solve order; `order[k]` is contact `k`'s
    /// index in detection order).
    pub fn record(contacts: &[Contact<T>], order: &[u32], id: &[u32]) -> Self {
        let mut detected = vec![None; contacts.len()];
        for (c, &k) in contacts.iter().zip(order) {
            detected[k as usize] = (c.r != Vec3::ZERO).then(|| (id[c.a as usize], code(c.b), c.r));
        }
        WarmStart { entries: detected.into_iter().flatten().collect() }
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        (self.entries.capacity() * std::mem::size_of::<Entry<T>>()) as u64
    }
}
