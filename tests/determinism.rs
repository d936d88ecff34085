//! Same inputs, same bits, on any thread count (DESIGN.md "Determinism").

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::real::Real;

/// Grains in the box gas of `common::box_gas`: enough that every kernel and reduction splits
/// into several chunks.
const GRAINS: usize = 12000;
/// The box's side (m).
const SIDE: f64 = 30.0e-3;

fn trajectory_bits<T: Real>(threads: usize, steps: u64) -> (Vec<u64>, u64) {
    let scene = common::parse(&common::box_gas(GRAINS, SIDE));
    common::with_threads(threads, || {
        let mut e: CpuEngine<T> = common::engine(&scene);
        e.advance(steps).unwrap();
        let s = e.stats().unwrap();
        let mut bits: Vec<u64> = Vec::new();
        for b in e.bodies() {
            for v in [b.pos, b.vel, b.omega] {
                bits.extend([v.x.f64().to_bits(), v.y.f64().to_bits(), v.z.f64().to_bits()]);
            }
        }
        for q in e.orientations().unwrap() {
            bits.extend(q.iter().map(|x| x.f64().to_bits()));
        }
        bits.extend([s.kinetic_energy().to_bits(), s.elastic_energy.to_bits(), s.walls[0].force[2].to_bits()]);
        (bits, s.contacts)
    })
}

fn check<T: Real>() {
    let (one, contacts) = trajectory_bits::<T>(1, 300);
    println!("{}: {} values compared after 300 steps, {contacts} contacts", T::NAME, one.len());
    assert!(contacts > 100, "the scene must be colliding");
    // Two and three threads: the slots split in two and three parts (`cpu::split`; six where
    // three threads share fewer cores), the parts' boundaries in different places.
    for threads in [2, 3] {
        let (other, _) = trajectory_bits::<T>(threads, 300);
        let first = one.iter().zip(&other).position(|(a, b)| a != b);
        assert_eq!(first, None, "1 and {threads} threads differ at value {first:?}");
    }
}

#[test]
fn one_two_and_three_threads_give_bitwise_identical_trajectories_in_f64() {
    check::<f64>();
}

#[test]
fn one_two_and_three_threads_give_bitwise_identical_trajectories_in_f32() {
    check::<f32>();
}

/// The hot loops compiled for each instruction-set level this CPU has (portable, AVX2,
/// AVX-512) give the same trajectory, bit for bit. The other tests of this file may run
/// meanwhile under the cap this one sets, which by this very claim changes nothing for them.
fn check_levels<T: Real>() {
    use grains::cpu::simd::{set_max_level, supported, Level};
    let widest = supported();
    let mut runs = Vec::new();
    for cap in [Level::Portable, Level::V3, Level::V4].into_iter().filter(|l| *l <= widest) {
        set_max_level(cap);
        runs.push((cap, trajectory_bits::<T>(1, 300).0));
    }
    set_max_level(Level::V4);
    println!("{}: levels compared: {:?} (this CPU's widest: {widest:?})", T::NAME, runs.iter().map(|r| r.0).collect::<Vec<_>>());
    for (cap, bits) in &runs[1..] {
        let first = runs[0].1.iter().zip(bits).position(|(a, b)| a != b);
        assert_eq!(first, None, "{cap:?} differs from the portable build at value {first:?}");
    }
}

#[test]
fn every_instruction_set_level_gives_bitwise_identical_trajectories() {
    // One test for both precisions, so that no two runs of this file move the cap at once.
    check_levels::<f64>();
    check_levels::<f32>();
}
