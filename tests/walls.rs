//! Grain-wall contacts use the grain-grain laws with the wall as a partner of infinite radius
//! and mass: a Hertz bounce off a plane and off the cylinder lasts the grain-wall Hertz time;
//! a piston under a target pressure comes to rest on a column of grains with its pressure
//! carried down to the floor.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::protocol;
use grains::timestep::hertz_collision_time;

/// Contact time at t_c / 50 (see tests/hertz_collision.rs).
const HERTZ_TOLERANCE: f64 = 0.01;

const GLASS: &str = r#"
[[material]]
name = "glass"
density = 2650.0
youngs_modulus = 7.0e7
poisson_ratio = 0.3
[[material]]
name = "steel"
youngs_modulus = 2.0e11
poisson_ratio = 0.3
"#;

/// Throws a grain at a wall and measures the contact time and the rebound speed.
fn bounce(wall: &str, position: [f64; 3], velocity: [f64; 3]) -> (f64, f64, f64) {
    let text = format!(
        r#"{GLASS}
[[grain]]
material = "glass"
radius = 5.0e-4
position = {position:?}
velocity = {velocity:?}
{wall}
[simulation]
gravity = [0.0, 0.0, 0.0]
[[stage]]
kind = "run"
duration = 1.0e-3
"#
    );
    let scene = common::parse(&text);
    let (m, r) = (scene.grains.mass[0], 5.0e-4);
    let v = (velocity[0] * velocity[0] + velocity[1] * velocity[1] + velocity[2] * velocity[2]).sqrt();
    let c = scene.pair_coeffs::<f64>()[1];
    let t_c = hertz_collision_time(m, r, c.v_eff, v);
    let mut s = scene.clone();
    s.time_step.dt = t_c / 50.0;
    let mut e: CpuEngine<f64> = common::engine(&s);
    let (mut t_on, mut t_off) = (None, None);
    while t_off.is_none() && e.time() < 0.05 {
        e.step().unwrap();
        let touching = e.stats().unwrap().wall_contacts > 0;
        if touching && t_on.is_none() {
            t_on = Some(e.time());
        }
        if !touching && t_on.is_some() {
            t_off = Some(e.time());
        }
    }
    let speed = e.bodies()[0].vel.norm();
    (t_off.unwrap() - t_on.unwrap(), t_c, speed / v)
}

#[test]
fn a_bounce_off_a_plane_lasts_the_grain_wall_hertz_time() {
    let plane = "[[wall]]\ntype = \"plane\"\nmaterial = \"steel\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]";
    let (t, t_c, ratio) = bounce(plane, [0.0, 0.0, 6.0e-4], [0.0, 0.0, -0.2]);
    println!("plane: contact {t:.4e} s (theory {t_c:.4e} s), speed after/before {ratio:.6}");
    // Contact is counted at whole steps: one step of slack.
    assert!((t / t_c - 1.0).abs() < HERTZ_TOLERANCE + 1.0 / 50.0);
    assert!((ratio - 1.0).abs() < 1e-3);
}

#[test]
fn a_bounce_off_the_cylinder_lasts_the_grain_wall_hertz_time() {
    let cylinder = "[[wall]]\ntype = \"cylinder\"\nmaterial = \"steel\"\ncenter = [0.0, 0.0]\nradius = 5.0e-3";
    let (t, t_c, ratio) = bounce(cylinder, [1.5e-3, 2.0e-3, 0.0], [0.15, 0.2, 0.0]);
    println!("cylinder: contact {t:.4e} s (theory {t_c:.4e} s), speed after/before {ratio:.6}");
    assert!((t / t_c - 1.0).abs() < HERTZ_TOLERANCE + 1.0 / 50.0);
    assert!((ratio - 1.0).abs() < 1e-3);
}


/// A piston at 200 Pa on grains in a cylinder, settled: the piston reads its target, and the
/// floor carries the piston's load plus the grains' weight (no friction on the side wall).
#[test]
fn a_piston_settles_at_its_target_pressure_and_the_floor_carries_the_load() {
    const PRESSURE_TOLERANCE: f64 = 0.01;
    let text = format!(
        r#"seed = 2
{GLASS}
[[generate]]
material = "glass"
count = 60
diameter = {{ min = 0.9e-3, max = 1.1e-3 }}
region = {{ shape = "cylinder", center = [0.0, 0.0], radius = 2.5e-3, z_min = 0.0, z_max = 9.0e-3 }}
[[wall]]
type = "plane"
material = "steel"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[wall]]
type = "cylinder"
material = "steel"
center = [0.0, 0.0]
radius = 2.5e-3
[[wall]]
type = "piston"
material = "steel"
z = 9.2e-3
pressure = 200.0
mass = 1.0e-5
[model]
damping = "papers"
[simulation]
stats_interval = 200
[[stage]]
kind = "settle"
duration = 0.5
unbalanced_force = 1.0e-3
"#
    )
    .replace("poisson_ratio = 0.3\n[[material]]", "poisson_ratio = 0.3\ngamma_n = 3.0e6\n[[material]]")
    .replace("youngs_modulus = 2.0e11\npoisson_ratio = 0.3", "youngs_modulus = 2.0e11\npoisson_ratio = 0.3\ngamma_n = 3.0e6");
    let scene = common::parse(&text);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let stages = protocol::run(&scene, &mut e, &mut grains::output::RunRecorder::new(None, false).unwrap()).unwrap();
    let s = &stages[0].stats;
    let piston = s.piston.as_ref().unwrap();
    let area = std::f64::consts::PI * 2.5e-3 * 2.5e-3;
    let weight: f64 = scene.grains.mass.iter().sum::<f64>() * 9.81;
    let floor = -s.walls[0].force[2];
    println!(
        "settled: {:?}, t = {:.3e} s; piston at {:.4e} m reads {:.2} Pa (target 200); floor carries {floor:.4e} N, piston load + weight {:.4e} N",
        stages[0].settled,
        s.time,
        piston.z,
        piston.pressure,
        200.0 * area + weight
    );
    assert_eq!(stages[0].settled, Some(true));
    assert!((piston.pressure / 200.0 - 1.0).abs() < PRESSURE_TOLERANCE);
    assert!((floor / (200.0 * area + weight) - 1.0).abs() < PRESSURE_TOLERANCE);
}
