//! The sweeps on several threads. Every thread of the pool runs the whole solve: colour by
//! colour, each solves its share of the colour's contacts (a contiguous part, [`share`]) and
//! waits at a barrier for the others; after the last colour the first thread
//! solves the serial tail and decides whether the sweeps go on, and all wait once more. No two
//! contacts of a colour share a grain, so each contact's solve reads and writes what it would
//! one after the other, and the step gives the bits of one thread ([`super::solve::sweep`]) on
//! any thread count.
//!
//! A solve of the 8,000-grain S_1 sweeps about 20 colours of 1,000 contacts, half of them open
//! contacts that cost a comparison: tens of microseconds a colour, so a rayon loop per colour
//! (a fork and a join, several microseconds each on a virtual machine, more when a sleeping
//! worker must be woken) cost more than the second thread gave: that run took 151 s on two
//! threads against 124 s on one, and 105 s with the threads meeting here (2-core AMD EPYC,
//! quiet). The serial tail (the wall contacts) and the step's own passes over the contacts
//! (detection, laws, residuals, the warm start) stay on one thread. The barrier here spins, and
//! yields the core after [`SPINS`] turns so that a thread the kernel has parked can run.
//! std's `Barrier` parks at once (a futex wake-up per colour), and the `spin` crate's never
//! yields, which on a machine with another job running beside would spin through time slices.

use super::colour::Schedule;
use super::solve::{quadratic_norm2, solve_serial, solve_tail};
use super::{Contact, Partner, Solved, SweepSettings, WallMotion};
use crate::real::Real;
use crate::state::Body;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};

/// Spin turns at a barrier before the waiting thread yields its core at each further turn.
const SPINS: u32 = 1 << 14;

/// Fewest contacts a solve must have for the threads to share it: below, a colour holds too
/// few contacts to pay for a barrier (see [`super::solve::CpuSweeps`]).
pub const THREADS_MIN_CONTACTS: usize = 4096;

/// Where the threads of a solve meet: each colour's end, each sweep's end.
struct Barrier {
    /// Threads arrived at the current barrier.
    arrived: AtomicUsize,
    /// Barriers passed: a waiting thread leaves when it changes.
    passed: AtomicU32,
    threads: usize,
}

impl Barrier {
    fn wait(&self) {
        let passed = self.passed.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.threads {
            self.arrived.store(0, Ordering::Relaxed);
            self.passed.fetch_add(1, Ordering::Release);
            return;
        }
        let mut turns = 0u32;
        while self.passed.load(Ordering::Acquire) == passed {
            if turns < SPINS {
                std::hint::spin_loop();
                turns += 1;
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// The solve's arrays as the threads share them.
struct Shared<T> {
    contacts: *mut Contact<T>,
    body: *mut Body<T>,
    walls: *mut WallMotion<T>,
    sums: *mut (T, T),
    n_contacts: usize,
    n_body: usize,
    n_walls: usize,
}

// SAFETY: the threads write through these pointers only to the contacts of their own part of
// a colour, the two grains of each (no two contacts of a colour share a grain), and those
// contacts' sums; the serial tail is solved by one thread while the others wait at the
// barrier. The barrier's release and acquire order each colour's writes before the next
// colour's reads. The arrays outlive the solve, which borrows them mutably throughout.
#[allow(unsafe_code)]
unsafe impl<T: Send> Send for Shared<T> {}
#[allow(unsafe_code)]
unsafe impl<T: Send> Sync for Shared<T> {}

/// The `part`-th of `parts` contiguous shares of `range`. (Shares by the grains' place in the
/// packing, slabs along x so that a thread's grains stayed in its core's cache, ran slower:
/// the threads' contacts then interleaved in the arrays, and their impulses and measures
/// shared cache lines; S_1 at 8,000 grains on two threads took 119 s that way against 105 s.)
///
/// A panic on one thread (none is reachable: a colour holds grain pairs of two grains) would
/// leave the others at the barrier.
fn share(range: std::ops::Range<usize>, part: usize, parts: usize) -> std::ops::Range<usize> {
    let len = range.len();
    range.start + len * part / parts..range.start + len * (part + 1) / parts
}

/// Sweeps the contacts on the pool's threads until a sweep's quadratic norm falls to the
/// tolerance or the cap of sweeps has run (as [`super::solve::CpuSweeps`] does on one).
#[allow(unsafe_code)]
pub(super) fn solve<T: Real>(contacts: &mut [Contact<T>], schedule: &Schedule, body: &mut [Body<T>], walls: &mut [WallMotion<T>], settings: SweepSettings<T>, sums: &mut Vec<(T, T)>) -> Solved {
    let n = contacts.len();
    sums.resize(n, (T::ZERO, T::ZERO));
    let shared = Shared { contacts: contacts.as_mut_ptr(), body: body.as_mut_ptr(), walls: walls.as_mut_ptr(), sums: sums.as_mut_ptr(), n_contacts: n, n_body: body.len(), n_walls: walls.len() };
    let threads = rayon::current_num_threads();
    let barrier = Barrier { arrived: AtomicUsize::new(0), passed: AtomicU32::new(0), threads };
    let stop = AtomicBool::new(false);
    let omega = settings.relaxation;
    let tail = schedule.tail();
    // Written by the first thread only, read after the broadcast.
    let solved = std::sync::Mutex::new(Solved::default());
    rayon::broadcast(|ctx| {
        let (me, parts) = (ctx.index(), ctx.num_threads());
        let s = &shared;
        loop {
            for range in schedule.colours() {
                for k in share(range, me, parts) {
                    debug_assert!(k < s.n_contacts);
                    // SAFETY: see `Shared`: contact k is this thread's alone in this colour.
                    let (c, sum) = unsafe { (&mut *s.contacts.add(k), &mut *s.sums.add(k)) };
                    let Partner::Grain(j) = c.b else { unreachable!("colours hold grain pairs") };
                    // SAFETY: the contact's two grains are touched by no other contact of the colour.
                    let (a, b) = unsafe { two_raw(s.body, s.n_body, c.a as usize, j as usize) };
                    *sum = solve_serial(c, a, b, omega);
                }
                barrier.wait();
            }
            if me == 0 {
                // SAFETY: the other threads wait at the barrier below and touch nothing.
                let (contacts, body, walls, sums) = unsafe { (std::slice::from_raw_parts_mut(s.contacts, s.n_contacts), std::slice::from_raw_parts_mut(s.body, s.n_body), std::slice::from_raw_parts_mut(s.walls, s.n_walls), std::slice::from_raw_parts_mut(s.sums, s.n_contacts)) };
                solve_tail(&mut contacts[tail..], body, walls, &mut sums[tail..], omega);
                let norm2 = quadratic_norm2(sums);
                if solved.lock().expect("only this thread locks it").after_sweep(norm2, &settings) {
                    stop.store(true, Ordering::Release);
                }
            }
            barrier.wait();
            if stop.load(Ordering::Acquire) {
                break;
            }
        }
    });
    solved.into_inner().expect("the threads are done")
}

/// Grains `a` and `b` (different) of the `n` at `body`, mutably.
///
/// # Safety
/// `body` points to `n` grains, `a` and `b` are below `n`, and no other reference to either
/// grain lives while the two returned ones do.
#[allow(unsafe_code)]
unsafe fn two_raw<'a, T>(body: *mut Body<T>, n: usize, a: usize, b: usize) -> (&'a mut Body<T>, &'a mut Body<T>) {
    assert!(a != b && a < n && b < n, "a contact joins two grains of the system");
    // SAFETY: in bounds and distinct (checked), unaliased (the caller's promise).
    unsafe { (&mut *body.add(a), &mut *body.add(b)) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shares of a range tile it, in order, for any number of parts.
    #[test]
    fn shares_tile_the_range() {
        for parts in 1..6 {
            for len in [0, 1, 5, 1000, 1001] {
                let range = 7..7 + len;
                let tiles: Vec<usize> = (0..parts).flat_map(|p| share(range.clone(), p, parts)).collect();
                assert_eq!(tiles, range.collect::<Vec<_>>(), "{parts} parts of {len}");
            }
        }
    }
}
