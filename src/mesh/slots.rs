//! Which of a grain's [`MESH_CONTACTS`] slots with a mesh each of its contacts takes: the
//! slot whose last normal is nearest to its own (within the merge angle), so that its history
//! follows it from triangle to triangle; a new contact takes the first slot left, with its
//! history cleared. A slot's reals are the contact's history (`stride`) then its normal (3).

use super::surface::MeshContact;
use super::MESH_CONTACTS;
use crate::real::{Real, Vec3};

/// Reals a slot keeps beyond the contact's history: its normal.
pub const NORMAL_REALS: usize = 3;

/// Reals of one slot with `stride` reals of history.
pub fn slot_reals(stride: usize) -> usize {
    stride + NORMAL_REALS
}

/// Reals a grain keeps for one mesh: [`MESH_CONTACTS`] slots.
pub fn mesh_reals(stride: usize) -> usize {
    MESH_CONTACTS * slot_reals(stride)
}

/// What becomes of a slot this evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SlotUse {
    /// No contact: its history and normal are cleared.
    #[default]
    Free,
    /// Contact `k` carries on from this slot's history.
    Carried(usize),
    /// Contact `k` starts here from zero history.
    New(usize),
}

/// The slots' uses for `contacts` given each slot's last normal (`last[j]`, zero for a free
/// slot); `cos` the cosine of the merge angle.
#[inline(always)]
pub fn assign<T: Real>(contacts: &[MeshContact<T>], last: &[Vec3<T>; MESH_CONTACTS], cos: T) -> [SlotUse; MESH_CONTACTS] {
    let mut uses = [SlotUse::Free; MESH_CONTACTS];
    let mut placed = [false; MESH_CONTACTS];
    for (k, c) in contacts.iter().enumerate() {
        let mut best: Option<(usize, T)> = None;
        for (j, m) in last.iter().enumerate() {
            if uses[j] != SlotUse::Free || *m == Vec3::ZERO {
                continue;
            }
            let d = m.dot(c.normal);
            if d > cos && best.is_none_or(|(_, b)| d > b) {
                best = Some((j, d));
            }
        }
        if let Some((j, _)) = best {
            uses[j] = SlotUse::Carried(k);
            placed[k] = true;
        }
    }
    for (k, _) in placed.iter().enumerate().take(contacts.len()).filter(|(_, p)| !**p) {
        let j = uses.iter().position(|u| *u == SlotUse::Free).expect("at most MESH_CONTACTS contacts");
        uses[j] = SlotUse::New(k);
    }
    uses
}
