//! Servo walls: an isotropic compaction holds its target pressure on all six walls, with the
//! volume-weighted particle stress equal to it (frictionless walls: a frictional wall's shear
//! adds to the mean stress, as the boundary identity sum x (x) f says); a triaxial stage
//! closes the z walls at its strain rate while the lateral walls keep their pressure.

mod common;

use grains::analysis::{contact_moments, macroscopic_stress};
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::output::RunRecorder;
use grains::periodic::Periodic;
use grains::protocol;

/// A settled wall's pressure against its target (the settle criterion's tolerance).
const PRESSURE_TOLERANCE: f64 = 0.01;
/// Lateral walls during a triaxial compression at 0.3/s: the servo lags the shear a little.
const LATERAL_TOLERANCE: f64 = 0.05;
/// Mean particle stress against the walls' pressure.
const STRESS_TOLERANCE: f64 = 0.03;

fn scene(stages: &str) -> grains::scene::Scene {
    common::parse(&format!(
        r#"
seed = 8
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e8
poisson_ratio = 0.3
mu_s = 0.4
restitution = 0.3
[[material]]
name = "wall"
youngs_modulus = 1.0e8
poisson_ratio = 0.3
restitution = 0.3
[[generate]]
material = "glass"
count = 300
diameter = {{ min = 0.8e-3, max = 1.2e-3 }}
region = {{ shape = "box", min = [0.0, 0.0, 0.0], max = [11.0e-3, 11.0e-3, 11.0e-3] }}
[[wall]]
type = "servo_box"
material = "wall"
min = [0.0, 0.0, 0.0]
max = [11.0e-3, 11.0e-3, 11.0e-3]
pressure = 1.0e3
max_speed = 0.05
[model]
damping = "restitution"
tangential = "mindlin"
tangential_damping_ratio = 0.9
[simulation]
gravity = [0.0, 0.0, 0.0]
stats_interval = 200
{stages}
"#
    ))
}

#[test]
fn isotropic_compaction_holds_the_target_pressure_on_every_wall() {
    let s = scene("[[stage]]\nkind = \"settle\"\nduration = 0.3\nke_per_grain = 1.0e-13\nunbalanced_force = 1.0e-3");
    let mut e: CpuEngine<f64> = common::engine(&s);
    let stages = protocol::run(&s, &mut e, &mut RunRecorder::new(None, false).unwrap()).unwrap();
    let st = &stages[0].stats;
    println!("settled {:?} at t = {:.3e} s, Z = {:.2}", stages[0].settled, st.time, st.coordination);
    assert_eq!(stages[0].settled, Some(true));
    let mut extents = [0.0; 3];
    for (k, w) in st.walls.iter().enumerate() {
        let p = w.pressure.unwrap();
        println!("{}: position {:.4e} m, pressure {p:.2} Pa", w.name, w.position.unwrap());
        assert!((p / 1.0e3 - 1.0).abs() < PRESSURE_TOLERANCE, "{}", w.name);
        extents[k / 2] += if k % 2 == 1 { w.position.unwrap() } else { -w.position.unwrap() };
    }
    let volume = extents[0] * extents[1] * extents[2];
    let stress = macroscopic_stress(&contact_moments(&e.frame(true).unwrap(), &Periodic::default()), volume);
    let mean = -grains::analysis::trace(&stress) / 3.0;
    println!("mean particle stress {mean:.2} Pa, diagonal {:.1} {:.1} {:.1} Pa", -stress.x_axis.x, -stress.y_axis.y, -stress.z_axis.z);
    assert!((mean / 1.0e3 - 1.0).abs() < STRESS_TOLERANCE);
}

#[test]
fn a_triaxial_stage_closes_z_at_its_strain_rate_and_holds_the_lateral_pressure() {
    let s = scene("[[stage]]\nkind = \"settle\"\nduration = 0.3\nke_per_grain = 1.0e-13\nunbalanced_force = 1.0e-3\n[[stage]]\nkind = \"run\"\nduration = 0.03\naxial_strain_rate = 0.3");
    let mut e: CpuEngine<f64> = common::engine(&s);
    let stages = protocol::run(&s, &mut e, &mut RunRecorder::new(None, false).unwrap()).unwrap();
    let (a, b) = (&stages[0].stats, &stages[1].stats);
    let height = |st: &grains::engine::Stats| st.walls[5].position.unwrap() - st.walls[4].position.unwrap();
    let (h0, h1) = (height(a), height(b));
    // dH/dt = -rate H: H1 = H0 exp(-rate t).
    let expect = h0 * (-0.3f64 * (b.time - a.time)).exp();
    let lateral: Vec<f64> = b.walls[..4].iter().map(|w| w.pressure.unwrap()).collect();
    let axial: Vec<f64> = b.walls[4..].iter().map(|w| w.pressure.unwrap()).collect();
    println!("height {h0:.5e} -> {h1:.5e} m (expected {expect:.5e}); lateral {lateral:.1?} Pa, axial {axial:.1?} Pa");
    assert!((h1 / expect - 1.0).abs() < 1e-6, "the z walls follow the strain rate");
    for p in &lateral {
        assert!((p / 1.0e3 - 1.0).abs() < LATERAL_TOLERANCE, "lateral walls keep their pressure while the sample is sheared");
    }
    assert!(axial.iter().all(|p| *p > 1.2e3), "the axial stress rises above the confinement");
}
