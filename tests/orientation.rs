//! Omelyan's norm-preserving quaternion update (Oquendo et al. eqs. 16-18).

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;

/// Largest allowed departure of |q| from 1 over 1e5 steps in f64 (issue 2).
const NORM_TOLERANCE: f64 = 1e-12;
/// Largest allowed difference from the exact discrete rotation (round-off over 1e5 steps).
const ANGLE_TOLERANCE: f64 = 1e-9;

#[test]
fn quaternion_norm_is_held_and_the_rotation_angle_is_the_cayley_angle() {
    let text = r#"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 7.0e7
poisson_ratio = 0.3
[[grain]]
material = "glass"
radius = 5.0e-4
position = [0.0, 0.0, 0.0]
angular_velocity = [30.0, -40.0, 120.0]
[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 1.0e-5
track_orientation = true
[[stage]]
kind = "run"
duration = 1.0
"#;
    let scene = common::parse(text);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let w = [30.0f64, -40.0, 120.0];
    let wn = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let dt = e.dt();
    let mut worst: f64 = 0.0;
    let steps = 100_000;
    for _ in 0..100 {
        e.advance(steps / 100).unwrap();
        let q = e.orientations().unwrap()[0];
        worst = worst.max(((q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt() - 1.0).abs());
    }
    // Each step is a Cayley rotation by exactly 4 atan(|w| dt / 4) about w.
    let angle = steps as f64 * 4.0 * (wn * dt / 4.0).atan();
    let q = e.orientations().unwrap()[0];
    let expect = [(angle / 2.0).cos(), (angle / 2.0).sin() * w[0] / wn, (angle / 2.0).sin() * w[1] / wn, (angle / 2.0).sin() * w[2] / wn];
    let err = (0..4).map(|k| (q[k] - expect[k]).abs()).fold(0.0, f64::max);
    println!("|q| - 1 at most {worst:.2e} over {steps} steps; rotation {angle:.4} rad, largest component error {err:.2e}");
    assert!(worst < NORM_TOLERANCE);
    assert!(err < ANGLE_TOLERANCE);
}
