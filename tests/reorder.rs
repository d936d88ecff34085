//! Renumbering the grains in cell order (`simulation.reorder_every`) changes no result, bit
//! for bit: trajectories, statistics, frames with their contacts, and a checkpoint written by a
//! renumbered run and resumed, against the same scene never renumbered. The scenes cover what
//! reads an order: wall sums feeding a servo, liquid bridges forming and breaking, the gather's
//! partner sums, periodic images, and Oquendo et al.'s law, which keeps the owner's force.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::scene::Scene;

/// The box gas of `common::box_gas` (Oquendo et al.'s laws, orientations) with about 5,000 grains,
/// so that every reduction splits into several chunks.
fn dry() -> String {
    common::box_gas(5000, 22.0e-3)
}

/// Everything a run shows, as bits: every grain's state (permanent-id order), the
/// statistics, and a frame with its contacts.
fn outputs<T: grains::real::Real>(e: &mut CpuEngine<T>) -> (Vec<u64>, String, String) {
    let mut bits = Vec::new();
    for b in e.bodies() {
        for v in [b.pos, b.vel, b.omega] {
            bits.extend([v.x.f64().to_bits(), v.y.f64().to_bits(), v.z.f64().to_bits()]);
        }
    }
    for q in e.orientations().unwrap_or_default() {
        bits.extend(q.iter().map(|x| x.f64().to_bits()));
    }
    // Debug prints every float exactly (shortest round trip), so equal text is equal bits.
    let stats = format!("{:?}", e.stats().unwrap());
    let frame = format!("{:?}", e.frame(true).unwrap());
    (bits, stats, frame)
}

/// Runs `scene` for `steps` with renumbering every `every` rebuilds (0: never); `prepare`
/// runs on the new engine first (e.g. wetting).
fn run<T: grains::real::Real>(scene: &Scene, every: u64, steps: u64, prepare: impl Fn(&mut CpuEngine<T>)) -> (Vec<u64>, String, String) {
    let mut s = scene.clone();
    s.reorder_every = every;
    let mut e: CpuEngine<T> = common::engine(&s);
    prepare(&mut e);
    e.advance(steps).unwrap();
    assert_eq!(e.renumberings() > 0, every > 0, "renumbered {} times", e.renumberings());
    outputs(&mut e)
}

/// Asserts that two runs' outputs are equal, naming the first difference.
fn same(what: &str, a: &(Vec<u64>, String, String), b: &(Vec<u64>, String, String)) {
    let first = a.0.iter().zip(&b.0).position(|(x, y)| x != y);
    assert_eq!(first, None, "{what}: grain states differ at value {first:?}");
    assert_eq!(a.0.len(), b.0.len());
    assert!(a.1 == b.1, "{what}: statistics differ:\n{}\n{}", a.1, b.1);
    assert!(a.2 == b.2, "{what}: frames differ");
}

#[test]
fn renumbering_changes_no_bit_of_a_dense_gas_in_a_box() {
    let scene = common::parse(&dry());
    let plain = run::<f64>(&scene, 0, 200, |_| {});
    let every = run::<f64>(&scene, 1, 200, |_| {});
    let stats = &plain.1;
    println!("f64, 200 steps, {} grains: {}", scene.grains.len(), &stats[..stats.len().min(400)]);
    assert!(stats.contains("wall_contacts: ") && !stats.contains("wall_contacts: 0,"), "the gas must touch its walls");
    same("f64, every rebuild", &plain, &every);
    let plain32 = run::<f32>(&scene, 0, 200, |_| {});
    let every32 = run::<f32>(&scene, 3, 200, |_| {});
    same("f32, every 3 rebuilds", &plain32, &every32);
}

#[test]
fn a_renumbered_run_resumes_from_its_checkpoint_with_the_same_bits() {
    let scene = common::parse(&dry());
    let plain = run::<f64>(&scene, 0, 200, |_| {});
    let mut s = scene.clone();
    s.reorder_every = 1;
    let mut first: CpuEngine<f64> = common::engine(&s);
    first.advance(100).unwrap();
    let saved = first.save().unwrap();
    // A fresh engine renumbers at its first build; the checkpoint brings its own numbering.
    let mut resumed: CpuEngine<f64> = common::engine(&s);
    resumed.restore(&saved).unwrap();
    resumed.advance(100).unwrap();
    same("resumed at step 100", &plain, &outputs(&mut resumed));
}

#[test]
fn renumbering_changes_no_bit_of_wet_grains_pushed_by_servo_walls() {
    let text = std::fs::read_to_string(common::scene_path("elastic_gas.toml")).unwrap();
    let scene = common::parse(&common::edit(
        &text,
        &[
            ("count = 50", "count = 300"),
            ("max = [6.0e-3, 6.0e-3, 6.0e-3] }\nrandom_speed = 0.5", "max = [8.5e-3, 8.5e-3, 8.5e-3] }\nrandom_speed = 0.5"),
            ("type = \"box\"", "type = \"servo_box\"\npressure = 20.0\nmax_speed = 0.05"),
            ("max = [6.0e-3, 6.0e-3, 6.0e-3]\n", "max = [8.5e-3, 8.5e-3, 8.5e-3]\n"),
            ("poisson_ratio = 0.3", "poisson_ratio = 0.3\nmu_s = 0.4\nrestitution = 0.8"),
            ("damping = \"none\"\ntangential = \"none\"", "damping = \"restitution\"\ntangential = \"mindlin\"\ncohesion = \"capillary\""),
            ("duration = 0.05", "duration = 0.05\nwater_content = 0.01"),
        ],
    ));
    let volume = scene.stages[0].wet_volume.unwrap();
    let wet = |e: &mut CpuEngine<f64>| e.wet(volume).unwrap();
    let plain = run::<f64>(&scene, 0, 5000, wet);
    let every = run::<f64>(&scene, 1, 5000, wet);
    let stats = &plain.1;
    println!("wet servo box, 5000 steps: {}", &stats[..stats.len().min(600)]);
    assert!(!stats.contains("bridges: 0,"), "the grains must hold bridges");
    same("wet, servo walls", &plain, &every);
}

#[test]
fn renumbering_changes_no_bit_of_a_periodic_gas() {
    let scene = common::parse(&common::edit(
        &dry(),
        &[
            ("[[wall]]\ntype = \"box\"\nmaterial = \"sand\"\nmin = [0.0, 0.0, 0.0]\nmax = [2.2e-2, 2.2e-2, 2.2e-2]\n", "[periodic]\nx = [0.0, 22.0e-3]\ny = [0.0, 22.0e-3]\nz = [0.0, 22.0e-3]\n"),
            ("[simulation]\n", "[simulation]\ngravity = [0.0, 0.0, 0.0]\n"),
        ],
    ));
    let plain = run::<f64>(&scene, 0, 300, |_| {});
    let every = run::<f64>(&scene, 1, 300, |_| {});
    same("periodic", &plain, &every);
}

/// Two grains hitting a wet third one from both sides in the same step, listed out of their
/// order in space (ids: right, left, middle), wetted while too far apart for bridges, so the
/// liquid waits on the grains: both bridges form in one step from the middle grain's liquid,
/// and the volumes depend on which forms first. Renumbering puts the left
/// grain first in memory; the bridges must still form in permanent-id order.
#[test]
fn two_bridges_formed_in_one_step_take_their_liquid_in_id_order() {
    let scene = common::parse(&common::three_wet_grains(1.0e-3));
    let volume = scene.stages[0].wet_volume.unwrap();
    let wet = |e: &mut CpuEngine<f64>| e.wet(volume).unwrap();
    let plain = run::<f64>(&scene, 0, 2700, wet);
    let every = run::<f64>(&scene, 1, 2700, wet);
    println!("three grains, 2700 steps: {}", plain.1);
    assert!(plain.1.contains("bridges: 2,"), "both bridges must have formed");
    same("three wet grains", &plain, &every);
}
