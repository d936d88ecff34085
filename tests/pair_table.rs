//! `[[pair]]` tables: a pair of materials given its own restitution and friction rebounds and
//! slides by them, on grain pairs and on walls, by DEM (CPU f64, and the GPU against its CPU
//! f32 twin) and by contact dynamics, while every other pair of materials keeps the mixing
//! rule's values to the bit.

mod common;

use grains::cd::{CdParams, ContactDynamics};
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::scene::Scene;
use glam::DVec3;

/// Radius (m) of every grain.
const R: f64 = 2.5e-3;
/// The materials' own restitution and friction, and the glass-steel pair's.
const E_MATERIALS: f64 = 0.9;
const E_PAIR: f64 = 0.4;
const MU_MATERIALS: f64 = 0.5;
const MU_PAIR: f64 = 0.2;
/// The impacts' tolerance on the rebound, relative: tests/impacts.rs' at t_c/50 (the automatic
/// step is finer).
const REBOUND_TOLERANCE: f64 = 0.01;
/// The slide's tolerance on the speed lost, relative: the speed lost is `mu / m` times the
/// normal impulse, the weight's `m g t` less the vertical momentum the grain's settling into
/// its resting overlap still holds at `t` (measured: 2e-10 of it).
const SLIDE_TOLERANCE: f64 = 1e-6;
const G: f64 = 9.81;

/// A glass and a steel material (restitution [`E_MATERIALS`], friction [`MU_MATERIALS`]), a
/// steel floor at z = 0 and `grains` (`[[grain]]` blocks), with the glass-steel `[[pair]]`
/// table when `table`; DEM with Hertz, restitution damping and Mindlin friction unless `cd`
/// gives contact dynamics' step.
fn scene(grains: &str, gravity: f64, duration: f64, table: bool, cd: Option<f64>) -> Scene {
    let pair = if table { format!("[[pair]]\nmaterials = [\"steel\", \"glass\"]\nrestitution = {E_PAIR}\nmu_s = {MU_PAIR}\n") } else { String::new() };
    let method = match cd {
        Some(dt) => format!("method = \"contact_dynamics\"\ndt = {dt:e}\n"),
        None => "dt = \"auto\"\n".to_string(),
    };
    common::parse(&format!(
        "[[material]]\nname = \"glass\"\ndensity = 2500.0\nyoungs_modulus = 6.3e10\npoisson_ratio = 0.24\nmu_s = {MU_MATERIALS}\nrestitution = {E_MATERIALS}\n\n\
         [[material]]\nname = \"steel\"\ndensity = 7800.0\nyoungs_modulus = 2.0e11\npoisson_ratio = 0.3\nmu_s = {MU_MATERIALS}\nrestitution = {E_MATERIALS}\n\n\
         {pair}\n\
         [[wall]]\ntype = \"plane\"\nmaterial = \"steel\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\n\
         {grains}\n\
         [model]\nnormal = \"hertz\"\ndamping = \"restitution\"\ntangential = \"mindlin\"\n\n\
         [simulation]\ngravity = [0.0, 0.0, {:e}]\n{method}\n\
         [[stage]]\nkind = \"run\"\nduration = {duration:e}\n",
        -gravity
    ))
}

fn grain(material: &str, x: [f64; 3], v: [f64; 3]) -> String {
    format!("[[grain]]\nmaterial = \"{material}\"\nradius = {R:e}\nposition = [{:e}, {:e}, {:e}]\nvelocity = [{:e}, {:e}, {:e}]\n", x[0], x[1], x[2], v[0], v[1], v[2])
}

/// Steps of the scene's `dt` in `t` (s).
fn steps(s: &Scene, t: f64) -> u64 {
    (t / s.time_step.dt).round() as u64
}

/// Impacts without gravity, each pair of grains 20 mm from the next and 20 mm above the floor:
/// glass-glass, glass-steel and steel-steel head on along x at 1 m/s relative speed, then a
/// glass and a steel grain onto the steel floor at 1 m/s, each `gap` (m) from contact.
fn impacts(gap: f64) -> String {
    let mut s = String::new();
    for (k, (a, b)) in [("glass", "glass"), ("glass", "steel"), ("steel", "steel")].into_iter().enumerate() {
        let y = 0.02 * k as f64;
        s += &grain(a, [-R - 0.5 * gap, y, 0.02], [0.5, 0.0, 0.0]);
        s += &grain(b, [R + 0.5 * gap, y, 0.02], [-0.5, 0.0, 0.0]);
    }
    s += &grain("glass", [0.0, 0.06, R + gap], [0.0, 0.0, -1.0]);
    s + &grain("steel", [0.0, 0.08, R + gap], [0.0, 0.0, -1.0])
}

/// The rebound of each impact of [`impacts`] (speed out over speed in) from the grains'
/// velocities after it, in its order: glass-glass, glass-steel, steel-steel, glass on steel,
/// steel on steel.
fn rebounds(v: &[DVec3]) -> [f64; 5] {
    [v[1][0] - v[0][0], v[3][0] - v[2][0], v[5][0] - v[4][0], v[6][2], v[7][2]]
}

/// What each impact should give back with the table: the pair's restitution where glass meets
/// steel, the materials' elsewhere.
const EXPECTED: [f64; 5] = [E_MATERIALS, E_PAIR, E_MATERIALS, E_PAIR, E_MATERIALS];

#[test]
fn a_pair_table_changes_that_pairs_rebound_and_no_other() {
    let run = |table: bool| {
        let s = scene(&impacts(1e-4), 0.0, 1e-3, table, None);
        let mut e: CpuEngine<f64> = common::engine(&s);
        e.advance(steps(&s, 1e-3)).unwrap();
        e.frame(false).unwrap().velocity
    };
    let (with, without) = (run(true), run(false));
    let measured = rebounds(&with);
    println!("rebounds with the table {measured:?}, without {:?}", rebounds(&without));
    for (k, (&m, &want)) in measured.iter().zip(&EXPECTED).enumerate() {
        assert!((m / want - 1.0).abs() < REBOUND_TOLERANCE, "impact {k}: rebound {m}, want {want}");
    }
    // The impacts the table does not name are the same bits without it.
    for grain in [0, 1, 4, 5, 7] {
        assert_eq!(with[grain], without[grain], "grain {grain}");
    }
    assert!(rebounds(&without).iter().all(|&m| (m / E_MATERIALS - 1.0).abs() < REBOUND_TOLERANCE));
}

/// A glass and a steel grain slide on the steel floor at 1 m/s with no spin: until they roll
/// (after `2 v / (7 mu g)`, 0.146 s at the pair's friction) each loses `mu g t` of its speed.
#[test]
fn a_pair_tables_friction_is_the_one_a_grain_slides_with() {
    let t = 0.04;
    let grains = grain("glass", [0.0, 0.0, R], [1.0, 0.0, 0.0]) + &grain("steel", [0.0, 0.02, R], [1.0, 0.0, 0.0]);
    let s = scene(&grains, G, t, true, None);
    let mut e: CpuEngine<f64> = common::engine(&s);
    let n = steps(&s, t);
    e.advance(n).unwrap();
    let v = e.frame(false).unwrap().velocity;
    let elapsed = n as f64 * s.time_step.dt;
    for (grain, mu) in [(0, MU_PAIR), (1, MU_MATERIALS)] {
        let (lost, want) = (1.0 - v[grain][0], mu * G * elapsed);
        println!("grain {grain}: lost {lost} m/s, mu g t = {want} m/s");
        assert!((lost / want - 1.0).abs() < SLIDE_TOLERANCE, "grain {grain}: lost {lost} m/s against {want}");
    }
}

/// The GPU reads the same table: the impacts and the slide on the GPU end where its CPU f32
/// twin ends (bitwise on a software adapter, within f32 round-off on hardware).
#[test]
fn pair_tables_run_on_the_gpu_as_on_the_cpu() {
    /// Relative difference allowed on a hardware GPU (its own sqrt and fused arithmetic).
    const F32_TOLERANCE: f64 = 1e-5;
    let slide = grain("glass", [0.0, 0.0, R], [1.0, 0.0, 0.0]) + &grain("steel", [0.0, 0.02, R], [1.0, 0.0, 0.0]);
    for (grains, gravity, duration) in [(impacts(1e-4), 0.0, 3e-4), (slide, G, 2e-3)] {
        let s = scene(&grains, gravity, duration, true, None);
        let Some(mut g) = common::gpu_engine(&s) else { return };
        let exact = g.adapter().device_type == wgpu::DeviceType::Cpu;
        let mut c: CpuEngine<f32> = common::engine(&s);
        let n = steps(&s, duration);
        g.advance(n).unwrap();
        c.advance(n).unwrap();
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        for (a, b) in fg.velocity.iter().zip(&fc.velocity).chain(fg.position.iter().zip(&fc.position)) {
            if exact {
                assert_eq!(a, b);
            } else {
                assert!((0..3).all(|k| (a[k] - b[k]).abs() <= F32_TOLERANCE * (1.0 + b[k].abs())), "gpu {a:?} cpu {b:?}");
            }
        }
    }
}

/// Contact dynamics takes the pair's restitution too: Newton's impact law gives back exactly
/// `e v` (frictionless here: the impacts are head on).
#[test]
fn contact_dynamics_rebounds_with_the_pairs_restitution() {
    let params = CdParams { tolerance: 1e-13, max_iterations: 10_000, ..CdParams::default() };
    let dt = 1e-5;
    // Each impact meets mid-step: 0.5e-5 m at 1 m/s relative speed.
    let mut cd = ContactDynamics::<f64>::new(&scene(&impacts(0.5e-5), 0.0, 1e-4, true, Some(dt)), params).unwrap();
    for _ in 0..10 {
        cd.step().unwrap();
    }
    let v: Vec<DVec3> = cd.bodies().iter().map(|b| DVec3::new(b.vel.x, b.vel.y, b.vel.z)).collect();
    let measured = rebounds(&v);
    println!("contact dynamics rebounds {measured:?}");
    for (k, (&m, &want)) in measured.iter().zip(&EXPECTED).enumerate() {
        assert!((m / want - 1.0).abs() < 1e-9, "impact {k}: rebound {m}, want {want}");
    }
}
