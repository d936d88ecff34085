//! The solve's schedule: the step's grain-pair contacts in colours, no two contacts of a colour
//! sharing a grain, so that a colour's local problems are independent and solving them at once
//! on any number of threads gives the bits of solving them one after the other. The wall
//! contacts (a moving wall is one body for all its contacts) and any pair left without a colour
//! follow, solved one after the other on one thread.

use super::{Contact, Partner};
use crate::real::Real;

/// Most colours. Greedy edge colouring needs at most `2 d - 1` colours for grains of at most `d`
/// contacts; a grain of a dense bidisperse packing has about 6-20, so pairs that find no free
/// colour among these (none seen so far) go to the serial tail rather than fail.
pub const MAX_COLOURS: usize = 128;

/// The order in which a sweep solves the contacts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Schedule {
    /// Colour `k` is `contacts[starts[k]..starts[k + 1]]`; the serial tail runs from the last
    /// entry to the end.
    pub starts: Vec<usize>,
    /// Each scheduled contact's index in detection order.
    pub order: Vec<u32>,
}

impl Schedule {
    /// Colour ranges, then the tail's start.
    pub fn colours(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.starts.windows(2).map(|w| w[0]..w[1])
    }

    /// Where the serial tail starts.
    pub fn tail(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }
}

/// Sorts `contacts` (grain pairs in canonical order, then walls) into colours, greedily in that
/// order: each pair takes the lowest colour free at both its grains. Within a colour and in the
/// tail the canonical order is kept, so the schedule is a function of the contacts alone.
pub fn schedule<T: Real>(contacts: &mut Vec<Contact<T>>, grains: usize) -> Schedule {
    let mut used = vec![0u128; grains];
    let mut colour = Vec::with_capacity(contacts.len());
    let mut counts = [0usize; MAX_COLOURS + 1];
    for c in contacts.iter() {
        let k = match c.b {
            Partner::Grain(j) => {
                let (a, b) = (c.a as usize, j as usize);
                let k = (used[a] | used[b]).trailing_ones() as usize;
                if k < MAX_COLOURS {
                    used[a] |= 1 << k;
                    used[b] |= 1 << k;
                }
                k.min(MAX_COLOURS)
            }
            Partner::Wall(_) => MAX_COLOURS,
        };
        colour.push(k as u8);
        counts[k] += 1;
    }
    let colours = counts[..MAX_COLOURS].iter().rposition(|&n| n > 0).map_or(0, |k| k + 1);
    let mut starts = Vec::with_capacity(colours + 1);
    let mut at = 0;
    for &n in &counts[..colours] {
        starts.push(at);
        at += n;
    }
    starts.push(at);
    let mut next: Vec<usize> = starts.clone();
    next.push(at);
    let mut sorted = vec![None; contacts.len()];
    let mut order = vec![0u32; contacts.len()];
    for (i, (c, &k)) in contacts.iter().zip(&colour).enumerate() {
        let slot = &mut next[(k as usize).min(colours)];
        sorted[*slot] = Some(*c);
        order[*slot] = i as u32;
        *slot += 1;
    }
    *contacts = sorted.into_iter().map(|c| c.expect("every slot filled")).collect();
    Schedule { starts, order }
}
