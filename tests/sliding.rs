//! A sphere launched sliding along a plane (scenes/sphere_on_plane.toml) against rigid-body
//! theory: friction mu_k g decelerates it and spins it up until it rolls without slipping
//! at t* = 2 v0 / (7 mu_k g), then moves on at 5/7 v0.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;

/// Final speed and transition time within this relative error of rigid-body theory (the
/// grain is soft: the contact point sits R - h below the centre, not R).
const ROLLING_TOLERANCE: f64 = 0.01;

fn check(tangential: &str) {
    let text = std::fs::read_to_string(common::scene_path("sphere_on_plane.toml")).unwrap();
    let text = text.replace("tangential = \"oquendo\"", tangential);
    let text = if tangential.contains("mindlin") { text.replace("mu_k = 0.4", "mu_k = 0.5") } else { text };
    let scene = common::parse(&text);
    let mu_k = scene.materials[0].constants.mu_k;
    let (v0, g, r) = (0.5, 9.81, 5.0e-4);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let mut t_roll = None;
    while e.time() < 0.06 {
        e.step().unwrap();
        let b = e.bodies()[0];
        let slip = b.vel.x - b.omega.y * r;
        if t_roll.is_none() && slip.abs() < 1e-3 * v0 {
            t_roll = Some(e.time());
        }
    }
    let v = e.bodies()[0].vel.x;
    let t_star = 2.0 * v0 / (7.0 * mu_k * g);
    let t_roll = t_roll.expect("the sphere must start rolling");
    println!("{tangential}: v_final / v0 = {:.5} (theory {:.5}), rolling from {t_roll:.5e} s (theory {t_star:.5e} s)", v / v0, 5.0 / 7.0);
    assert!((v / v0 / (5.0 / 7.0) - 1.0).abs() < ROLLING_TOLERANCE);
    assert!((t_roll / t_star - 1.0).abs() < ROLLING_TOLERANCE);
}

#[test]
fn oquendo_regimes_slide_then_roll_at_five_sevenths() {
    check("tangential = \"oquendo\"");
}

#[test]
fn hertz_mindlin_slides_then_rolls_at_five_sevenths() {
    check("tangential = \"mindlin\"");
}
