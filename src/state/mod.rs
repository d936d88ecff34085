//! The state the engines share, beneath them all: the grains' arrays ([`Body`], [`Props`],
//! loads, periodic image counts), the per-contact history's slots, the pair list with the
//! cell grid and pair detection that build it, the force evaluation's context with the
//! grain-wall contact it evaluates, deterministic chunked reductions, the per-phase clock, and
//! the choice of threads for a run's steps (`crew`).
//!
//! The CPU engine (`crate::cpu`) runs the step on these; the GPU engine reads its state back
//! into them for frames and reports; contact dynamics (`crate::cd`) detects its contacts with
//! the same grid. Nothing here imports an engine.

mod arrays;
mod context;
pub mod crew;
mod grid;
mod levels;
mod pairs;
pub mod profile;
pub mod reduce;
mod wall;

pub use arrays::{material_at, Body, Counts, HistorySlots, ImageCount, Images, Load, PairFlags, PairReports, Props};
pub use grid::{detect_pairs, hash_cells, CellGrid};
pub use levels::{class_index, class_tops, detect_pairs_in, Grids, CLASS_RATIO, MAX_CLASSES};
pub use pairs::{owned_pairs, owner_capacity, remap_all, remap_history, PairList, OWNER_DOUBLINGS};
pub use context::{coeffs_of, ForceContext};
pub use wall::{mesh_contacts, wall_contact, wall_contact_records, wall_overlaps, wall_reals, walls_reals, WallState};

/// Bytes a vector holds allocated.
#[allow(clippy::ptr_arg)] // the capacity lives on the Vec, not the slice
pub fn allocated<X>(v: &Vec<X>) -> u64 {
    (v.capacity() * std::mem::size_of::<X>()) as u64
}

/// Resizes `v` to `n` default values with no growth slack (a pair array of 10^6 grains is tens
/// of megabytes).
pub fn renew<X: Clone + Default>(v: &mut Vec<X>, n: usize) {
    v.clear();
    v.shrink_to(n);
    v.reserve_exact(n);
    v.resize(n, X::default());
}
