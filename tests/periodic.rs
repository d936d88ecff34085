//! Periodic boundaries: contacts act across the boundary by the minimum image, wrapping
//! loses nothing, and a periodic gas conserves momentum.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::real::Vec3;

/// Same collision, placed across the boundary or in the middle: equal to f64 round-off on
/// the coordinates (1e-3 m positions: 1e-19 m; relative to the overlap 1e-6 m: ~1e-10).
const IMAGE_TOLERANCE: f64 = 1e-9;
/// Momentum drift relative to sum |p| (see tests/conservation.rs).
const MOMENTUM_ROUNDOFF: f64 = 1e-12;

fn two_spheres(x0: f64, x1: f64) -> String {
    std::fs::read_to_string(common::scene_path("two_spheres.toml"))
        .unwrap()
        .replace("position = [-6.0e-4, 0.0, 0.0]", &format!("position = [{x0:e}, 0.0, 0.0]"))
        .replace("position = [6.0e-4, 0.0, 0.0]", &format!("position = [{x1:e}, 0.0, 0.0]"))
        .replace("[model]", "[periodic]\nx = [0.0, 1.0e-2]\n\n[model]")
}

/// Runs the collision and returns the relative velocity after it and the overlap history.
fn collide(text: &str) -> (f64, Vec<f64>) {
    let scene = common::parse(text);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let mut overlaps = Vec::new();
    for _ in 0..1500 {
        e.step().unwrap();
        overlaps.push(e.stats().unwrap().max_overlap);
    }
    let b = e.bodies();
    (b[1].vel.x - b[0].vel.x, overlaps)
}

#[test]
fn a_collision_across_the_boundary_equals_the_same_collision_inside() {
    // Inside: centres at 4.4 and 5.6 mm. Across: at 0.6 and 9.4 mm, 1.2 mm apart through x = 0.
    let (v_in, h_in) = collide(&two_spheres(4.4e-3, 5.6e-3));
    let (v_across, h_across) = collide(&two_spheres(9.4e-3, 0.6e-3));
    let peak = h_in.iter().copied().fold(0.0, f64::max);
    let worst = h_in.iter().zip(&h_across).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    println!("peak overlap / R {peak:.4e}; largest difference {worst:.2e}; v_rel after {v_in:.9} vs {v_across:.9}");
    assert!(peak > 1e-3, "the grains must collide");
    assert!(worst < IMAGE_TOLERANCE * peak);
    // Both ways grain 1 ends moving away from grain 0 at the same speed.
    assert!((v_in - v_across).abs() < IMAGE_TOLERANCE);
}

#[test]
fn a_fully_periodic_frictional_gas_conserves_momentum_and_stays_in_the_cell() {
    let text = concat!(r#"
seed = 5
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
restitution = 0.7
[[generate]]
material = "sand"
count = 200
diameter = { min = 0.8e-3, max = 1.2e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [8.0e-3, 8.0e-3, 8.0e-3] }
random_speed = 0.5
[periodic]
x = [0.0, 8.0e-3]
y = [0.0, 8.0e-3]
z = [0.0, 8.0e-3]
[model]
damping = "restitution"
tangential = "mindlin"
[simulation]
gravity = [0.0, 0.0, 0.0]
[[stage]]
kind = "run"
duration = 1.0e-3
"#);
    let scene = common::parse(text);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let s0 = e.stats().unwrap();
    let scale: f64 = e.bodies().iter().zip(&scene.grains.mass).map(|(b, m)| m * b.vel.norm()).sum();
    e.advance(4000).unwrap();
    let s1 = e.stats().unwrap();
    let dp: Vec3<f64> = Vec3::of(s1.momentum) - Vec3::of(s0.momentum);
    println!("{} rebuilds, {} contacts, KE {:.3e} -> {:.3e} J, |dP| / sum|p| = {:.2e}", s1.rebuilds, s1.contacts, s0.kinetic_energy(), s1.kinetic_energy(), dp.norm() / scale);
    assert!(s1.kinetic_energy() < 0.9 * s0.kinetic_energy(), "inelastic collisions must have happened");
    assert!(dp.norm() < MOMENTUM_ROUNDOFF * scale);
    e.rebuild().unwrap();
    for b in e.bodies() {
        for x in [b.pos.x, b.pos.y, b.pos.z] {
            assert!((0.0..8.0e-3).contains(&x), "wrapped into the cell: {x}");
        }
    }
}

#[test]
fn a_period_too_short_for_the_contacts_is_refused() {
    let text = two_spheres(4.4e-3, 5.6e-3).replace("x = [0.0, 1.0e-2]", "x = [0.0, 2.0e-3]").replace("position = [4.4e-3", "position = [0.4e-3").replace("position = [5.6e-3", "position = [1.6e-3");
    let err = grains::scene::parse(std::path::Path::new("short.toml"), &text).expect_err("too short").to_string();
    println!("{err}");
    assert!(err.contains("periodic.x") && err.contains("fix:"));
}
