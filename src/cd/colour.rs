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
    /// The grains each colour touches, colour after colour, each colour's by grain (a grain
    /// appears once in a colour at most); colour `k` is `touch[touch_starts[k]..touch_starts[k + 1]]`.
    touch: Vec<Touch>,
    touch_starts: Vec<usize>,
}

/// A grain touched by a contact of a colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Touch {
    /// The grain's slot.
    pub grain: u32,
    /// The contact's index in the schedule's order.
    pub contact: u32,
    /// Whether the grain is the contact's second body.
    pub second: bool,
}

impl Schedule {
    /// Colour ranges, then the tail's start.
    pub fn colours(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.starts.windows(2).map(|w| w[0]..w[1])
    }

    /// The grains colour `k` touches, by grain.
    pub fn touches(&self, k: usize) -> &[Touch] {
        &self.touch[self.touch_starts[k]..self.touch_starts[k + 1]]
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
    for (c, &k) in contacts.iter().zip(&colour) {
        let slot = &mut next[(k as usize).min(colours)];
        sorted[*slot] = Some(*c);
        *slot += 1;
    }
    *contacts = sorted.into_iter().map(|c| c.expect("every slot filled")).collect();
    let (mut touch, mut touch_starts) = (Vec::with_capacity(2 * at), vec![0]);
    for w in starts.windows(2) {
        let from = touch.len();
        for (k, c) in contacts[w[0]..w[1]].iter().enumerate() {
            let Partner::Grain(j) = c.b else { unreachable!("colours hold grain pairs") };
            let contact = (w[0] + k) as u32;
            touch.push(Touch { grain: c.a, contact, second: false });
            touch.push(Touch { grain: j, contact, second: true });
        }
        touch[from..].sort_unstable();
        touch_starts.push(touch.len());
    }
    Schedule { starts, touch, touch_starts }
}
