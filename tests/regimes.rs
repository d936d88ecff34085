//! Oquendo et al.'s tangential regimes under the loads the oedometer reaches, not only at one light
//! contact: a loaded sphere must come to rest, the low-load rolling and sliding laws must keep
//! their rigid-body values, and no regime switch may create energy.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;

/// A sphere of the paper's sand (V = 18 GPa, 0.5 mm radius) launched sliding along a steel
/// plane, both with a 2 degree rolling angle, under gravity `g` (m/s^2) along -z.
fn sphere_on_steel(g: f64, v0: f64) -> String {
    format!(
        r#"
[[material]]
name = "sand"
density = 2650.0
youngs_modulus = 1.6875e10
poisson_ratio = 0.25
mu_s = 0.4
mu_k = 0.4
rolling_angle = 2.0
gamma_n = 5.0e6

[[material]]
name = "steel"
youngs_modulus = 2.0e11
poisson_ratio = 0.3
mu_s = 0.4
mu_k = 0.4
rolling_angle = 2.0
gamma_n = 5.0e6

[[grain]]
material = "sand"
radius = 5.0e-4
position = [0.0, 0.0, 5.0e-4]
velocity = [{v0}, 0.0, 0.0]

[[wall]]
type = "plane"
material = "steel"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[model]
normal = "hertz"
damping = "papers"
tangential = "oquendo"
twisting = "oquendo"

[simulation]
gravity = [0.0, 0.0, -{g}]
dt = 1.75e-7

[[stage]]
kind = "run"
duration = 1.0e-3
"#
    )
}

/// Rolling deceleration within this relative error of rigid-body theory (soft contact: the
/// lever arm is R - h, not R).
const ROLLING_TOLERANCE: f64 = 2.0e-3;

/// What a sphere did: when its speed passed 0.6 v0 and 0.2 v0 (rolling, after the slide),
/// and the largest contact-point slip and centre speed over the last tenth of the run.
struct Rolled {
    t_06: f64,
    t_02: f64,
    worst_late: f64,
    stats: grains::engine::Stats,
}

/// Runs the sphere for `duration` (s), starting at its static overlap under `g` so that it
/// does not bounce.
fn roll(g: f64, v0: f64, duration: f64) -> Rolled {
    let mut scene = common::parse(&sphere_on_steel(g, v0).replace("duration = 1.0e-3", &format!("duration = {duration:e}")));
    let (r, m) = (scene.grains.radius[0], scene.grains.mass[0]);
    let c = scene.pair_coeffs::<f64>()[1];
    let h = (m * g / (4.0 / 3.0 * r.sqrt() * c.v_eff)).powf(2.0 / 3.0);
    scene.grains.position[0][2] = r - h;
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let (mut t_06, mut t_02, mut worst_late) = (None, None, 0.0f64);
    while e.time() < duration {
        e.step().unwrap();
        let b = e.bodies()[0];
        let rp = b.pos.z; // the contact point sits R - h = z below the centre
        let slip = (b.vel.x - b.omega.y * rp).hypot(b.vel.y + b.omega.x * rp);
        let speed = b.vel.x.hypot(b.vel.y);
        if t_06.is_none() && speed < 0.6 * v0 {
            t_06 = Some(e.time());
        }
        if t_02.is_none() && speed < 0.2 * v0 {
            t_02 = Some(e.time());
        }
        if e.time() > 0.9 * duration {
            worst_late = worst_late.max(slip.max(speed));
        }
    }
    Rolled { t_06: t_06.expect("slows below 0.6 v0"), t_02: t_02.expect("slows below 0.2 v0"), worst_late, stats: e.stats().unwrap() }
}

/// Rigid-body rolling deceleration of eqs. 8-9 on a sphere, g tan(theta_r) / (1 + I/(m R^2)).
fn rolling_deceleration(g: f64) -> f64 {
    g * 2.0f64.to_radians().tan() / 1.4
}

fn check_deceleration(g: f64, r: &Rolled, v0: f64) {
    let measured = 0.4 * v0 / (r.t_02 - r.t_06);
    let theory = rolling_deceleration(g);
    println!("g = {g:e}: rolling deceleration {measured:.6e} m/s^2 (theory g tan(theta_r)/1.4 = {theory:.6e}); slip or speed over the last tenth <= {:.3e} m/s; sliding {}, rolling {}", r.worst_late, r.stats.sliding, r.stats.rolling);
    assert!((measured / theory - 1.0).abs() < ROLLING_TOLERANCE, "deceleration {measured:e}, theory {theory:e}");
}

#[test]
fn a_heavily_loaded_sphere_rolls_to_rest() {
    // 0.14 N on the contact (the issue's case): slip and speed below this within 1 ms.
    const AT_REST: f64 = 1.0e-6;
    let (g, v0) = (1.0e5, 0.5);
    let r = roll(g, v0, 1.0e-3);
    check_deceleration(g, &r, v0);
    assert!(r.worst_late < AT_REST, "still moving at {:e} m/s", r.worst_late);
    assert_eq!((r.stats.sliding, r.stats.rolling), (0, 0), "a sphere at rest sticks");
}

#[test]
fn a_lightly_loaded_sphere_rolls_at_g_tan_theta_over_1_4() {
    let (g, v0) = (9.81, 0.05);
    check_deceleration(g, &roll(g, v0, 0.12), v0);
}

/// An isolated gas of frictional grains with no dissipation but friction itself: linear
/// normal and tangential springs (constant stiffnesses, so that the springs' energy is a
/// potential), no normal damping, the static spring undamped. Contacts stick, slide and stick
/// again and roll many times. Rolling friction as the default torque pair: eqs. 8-9 as the
/// paper writes them push both grains of a pair the same way, and that force can feed a gas
/// (the second half of the test).
const FRICTIONAL_GAS: &str = r#"
seed = 11
[[material]]
name = "sand"
density = 2650.0
youngs_modulus = 1.0e8
poisson_ratio = 0.25
mu_s = 0.5
mu_k = 0.3
rolling_angle = 5.0

[[generate]]
material = "sand"
count = 300
diameter = { min = 0.85e-3, max = 1.15e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [9.0e-3, 9.0e-3, 9.0e-3] }
random_speed = 0.3

[periodic]
x = [0.0, 9.0e-3]
y = [0.0, 9.0e-3]
z = [0.0, 9.0e-3]

[model]
normal = "linear"
k_n = 2000.0
kt_ratio = 0.3
damping = "none"
tangential = "oquendo"
static_damping = 0.0

[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 2.0e-7

[[stage]]
kind = "run"
duration = 5.0e-3
"#;

/// The largest rise of kinetic + spring energy between two samples over the gas's run, as a
/// fraction of the start, and the contacts counted sliding and rolling over the samples.
fn largest_energy_rise(rolling_friction: &str) -> (f64, u64, u64) {
    const SAMPLE_STEPS: u64 = 20;
    let text = FRICTIONAL_GAS.replace("static_damping = 0.0", &format!("static_damping = 0.0\nrolling_friction = \"{rolling_friction}\""));
    let mut scene = common::parse(&text);
    // Grown 5% after placement and spun: a jostling gas.
    scene.grains.radius.iter_mut().for_each(|r| *r *= 1.05);
    for (i, w) in scene.grains.angular_velocity.iter_mut().enumerate() {
        let a = i as f64;
        *w = glam::DVec3::new(300.0 * (1.3 * a).sin(), 300.0 * (2.1 * a).cos(), 300.0 * (0.7 * a).sin());
    }
    let k_t = 0.3 * 2000.0;
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let energy = |e: &mut CpuEngine<f64>| {
        let s = e.stats().unwrap();
        // The rolling spring has the static spring's stiffness.
        let norm2 = |v: glam::DVec3| v.to_array().iter().map(|x| x * x).sum::<f64>();
        let springs: f64 = e.frame(true).unwrap().contacts.unwrap().iter().map(|c| 0.5 * k_t * (norm2(c.tangential_spring) + norm2(c.rolling_spring))).sum();
        (s.kinetic_energy() + s.elastic_energy + springs, s)
    };
    let (e0, _) = energy(&mut e);
    let (mut last, mut worst, mut sliding, mut rolling) = (e0, f64::NEG_INFINITY, 0u64, 0u64);
    while e.time() < 5.0e-3 {
        e.advance(SAMPLE_STEPS).unwrap();
        let (now, s) = energy(&mut e);
        worst = worst.max((now - last) / e0);
        last = now;
        sliding += s.sliding;
        rolling += s.rolling;
    }
    println!("frictional gas, rolling friction {rolling_friction}: energy {e0:.6e} J -> {last:.6e} J, largest rise between samples {worst:.3e} of the start; {sliding} sliding and {rolling} rolling contacts counted over the samples");
    (worst, sliding, rolling)
}

#[test]
fn regime_switches_create_no_energy_in_an_isolated_frictional_gas() {
    // Kinetic + normal + tangential spring energy may only fall (friction dissipates);
    // between two samples integration error lets it rise by this fraction of the start.
    const INTEGRATION_ERROR: f64 = 1.0e-5;
    let (worst, sliding, rolling) = largest_energy_rise("torque");
    assert!(sliding > 1000 && rolling > 1000, "the gas must slide and roll");
    assert!(worst < INTEGRATION_ERROR, "energy rose by {worst:e} of its start between samples");
    // Eqs. 8-9 as written push both grains of a rolling pair along -t: that force works on
    // the pair's common motion and feeds the gas (measured: 8.8e-5 of the start in 20 steps).
    let (worst, _, _) = largest_energy_rise("as_written");
    assert!(worst > 2.0 * INTEGRATION_ERROR, "as written, eqs. 8-9 feed the gas: rise {worst:e}");
}
