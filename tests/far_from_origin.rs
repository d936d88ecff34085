//! f32 engines far from the origin: compensated positions (src/position.rs) keep contact
//! forces as close to f64's at 1 m from the origin as next to it. Plain f32 positions at 1 m
//! have a last bit of 6e-8 m, a fifth of these contacts' overlaps (2-4e-7 m).

mod common;

use grains::cpu::CpuEngine;
use grains::engine::{Engine, Frame};
use grains::real::Real;
use std::collections::HashMap;

/// Largest difference of a contact's normal force between f32 and f64, over the contacts both
/// have, as a fraction of f64's mean contact force, next to the origin and at 1 m alike.
const CONTACT_FORCE_TOLERANCE: f64 = 1e-2;

/// How much further from f64 f32 may be at 1 m than next to the origin.
const FAR_OVER_NEAR: f64 = 2.0;

/// Steps each run takes (5e-8 s each): the lattice mid-collision (contacts last about 130).
const STEPS: u64 = 60;

/// A simple cubic lattice of 6 x 6 x 6 glass grains (1 mm) closing on its centre: neighbours
/// meet at 0.02 m/s and press into each other by a few 1e-7 m (the spacing varies a little
/// per row so that no two contacts are alike), no gravity, no walls, its corner at `corner`
/// (m) along each axis.
fn glass_lattice(corner: f64) -> String {
    let mut text = String::from(
        r#"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 7.0e10
poisson_ratio = 0.25
mu_s = 0.3
mu_k = 0.3

[simulation]
gravity = [0.0, 0.0, 0.0]

[[stage]]
kind = "run"
duration = 1.0e-3
"#,
    );
    let n = 6;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                // Row r's spacing leaves gaps of 1-11 nm; each grain moves towards the
                // lattice's centre at 20 /s times its distance from it.
                let at = |q: usize, r: usize| 0.5e-3 + q as f64 * (1.0e-3 + 1.0e-9 + 2.0e-9 * r as f64);
                let (x, y, z) = (at(i, j), at(j, k), at(k, i));
                let mid = 0.5e-3 + 2.5e-3;
                let v = [-20.0 * (x - mid), -20.0 * (y - mid), -20.0 * (z - mid)];
                let (x, y, z) = (corner + x, corner + y, corner + z);
                text.push_str(&format!("[[grain]]\nmaterial = \"glass\"\nradius = 0.5e-3\nposition = [{x:e}, {y:e}, {z:e}]\nvelocity = [{:e}, {:e}, {:e}]\n", v[0], v[1], v[2]));
            }
        }
    }
    text
}

/// Normal force (N) of every touching pair, by (i, j).
fn contact_forces<T: Real>(corner: f64) -> HashMap<(u32, u32), f64>
where
    CpuEngine<T>: Engine,
{
    let scene = common::parse(&glass_lattice(corner));
    let mut e: CpuEngine<T> = common::engine(&scene);
    e.advance(STEPS).unwrap();
    let frame: Frame = e.frame(true).unwrap();
    frame.contacts.unwrap().iter().filter(|c| c.overlap > 0.0).map(|c| ((c.i, c.j), c.normal_force)).collect()
}

/// (largest difference over the shared contacts / mean f64 force, shared contacts).
fn worst_difference(a: &HashMap<(u32, u32), f64>, reference: &HashMap<(u32, u32), f64>) -> (f64, usize) {
    let mean = reference.values().sum::<f64>() / reference.len() as f64;
    let shared: Vec<f64> = reference.iter().filter_map(|(k, f)| a.get(k).map(|g| (g - f).abs())).collect();
    (shared.iter().copied().fold(0.0, f64::max) / mean, shared.len())
}

#[test]
fn f32_contact_forces_at_1_m_match_f64_as_at_the_origin() {
    let mut worst = Vec::new();
    for corner in [0.0, 1.0] {
        let f64s = contact_forces::<f64>(corner);
        let f32s = contact_forces::<f32>(corner);
        let (w, shared) = worst_difference(&f32s, &f64s);
        let mean = f64s.values().sum::<f64>() / f64s.len().max(1) as f64;
        println!("corner at {corner} m: mean force {mean:.3e} N, {} contacts in f64, {shared} shared with f32; largest difference {w:.2e} of the mean force", f64s.len());
        assert!(shared > 100 && shared * 10 >= f64s.len() * 9, "the runs share most contacts");
        assert!(w < CONTACT_FORCE_TOLERANCE, "corner at {corner} m: f32 contact forces {w:.2e} of the mean from f64's");
        worst.push(w);
    }
    assert!(worst[1] <= FAR_OVER_NEAR * worst[0], "f32 at 1 m: {:.2e} against {:.2e} next to the origin", worst[1], worst[0]);
}
