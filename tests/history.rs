//! Per-contact history survives a neighbour-list rebuild: the spring of a sticking contact is
//! carried to the rebuilt list by matching the partner's permanent id.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;

/// A glancing collision: 0.1 m/s head-on with 0.02 m/s sideways, Hertz-Mindlin with mu = 0.5,
/// so that the contact sticks (|k_t xi| < mu F_n) while its spring builds up.
const SCENE: &str = r#"
[[material]]
name = "glass"
density = 2650.0
youngs_modulus = 7.0e7
poisson_ratio = 0.3
mu_s = 0.5

[[grain]]
material = "glass"
radius = 5.0e-4
position = [-5.2e-4, 0.0, 0.0]
velocity = [0.05, 0.01, 0.0]

[[grain]]
material = "glass"
radius = 5.0e-4
position = [5.2e-4, 0.0, 0.0]
velocity = [-0.05, -0.01, 0.0]

[model]
tangential = "mindlin"

[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 1.5e-6

[[stage]]
kind = "run"
duration = 1.0e-3
"#;

/// Steps until mid-contact: the 40 um gap closes at 0.1 m/s in 267 steps, and the contact
/// lasts about 50.
const MID_CONTACT: u64 = 292;
/// The forced rebuild, well inside the contact.
const REBUILD_AT: u64 = MID_CONTACT - 5;

type Record = grains::engine::ContactRecord;

/// Runs the collision, optionally forcing a rebuild; returns the trajectory, the contact
/// just before the rebuild step and at mid-contact, and the rebuild count.
fn run(rebuild: bool) -> (Vec<glam::DVec3>, Record, Record, u64) {
    let scene = common::parse(SCENE);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let (mut before, mut mid) = (None, None);
    for step in 0..2 * MID_CONTACT {
        if step == REBUILD_AT {
            before = e.frame(true).unwrap().contacts.unwrap().first().copied();
            if rebuild {
                e.rebuild().unwrap();
            }
        }
        e.step().unwrap();
        if step == MID_CONTACT {
            mid = e.frame(true).unwrap().contacts.unwrap().first().copied();
        }
    }
    let rebuilds = e.stats().unwrap().rebuilds;
    let state = e.bodies().iter().flat_map(|b| [b.pos.f64(), b.vel.f64(), b.omega.f64()]).collect();
    (state, before.expect("in contact at the rebuild"), mid.expect("in contact at mid-contact"), rebuilds)
}

#[test]
fn a_sticking_contact_keeps_its_spring_through_a_rebuild() {
    let (plain, before, at_mid, plain_rebuilds) = run(false);
    let (rebuilt, _, at_mid_rebuilt, rebuilt_rebuilds) = run(true);
    let f_t = (before.force[1].powi(2) + before.force[2].powi(2)).sqrt();
    println!(
        "at the rebuild: overlap {:.3e} m, normal force {:.3e} N, tangential force {f_t:.3e} N (mu F_n = {:.3e} N), spring {:.3e} m; rebuilds {plain_rebuilds} vs {rebuilt_rebuilds}",
        before.overlap,
        before.normal_force,
        0.5 * before.normal_force,
        before.tangential_spring[1]
    );
    assert!(rebuilt_rebuilds == plain_rebuilds + 1, "the forced rebuild must happen");
    assert!(f_t > 0.1 * 0.5 * before.normal_force, "the spring must carry a real load");
    assert!(f_t < 0.5 * before.normal_force, "the contact must be sticking");
    assert_eq!(at_mid, at_mid_rebuilt, "the contact after a rebuild must be the same contact");
    assert_eq!(plain, rebuilt, "a rebuild must not change the trajectory");
}
