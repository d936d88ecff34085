//! Conservation laws of the contact laws: linear and angular momentum of a frictional
//! Hertz-Mindlin gas (round-off only), and the documented non-conservation of Oquendo et al.'s
//! rolling regime.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::real::Vec3;

/// Momentum drift allowed relative to the sum of |momentum| of the grains (f64 round-off).
const MOMENTUM_ROUNDOFF: f64 = 1e-12;

const FRICTIONAL_GAS: &str = concat!(r#"
seed = 3
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
restitution = 0.6

[[generate]]
material = "sand"
count = 200
diameter = { min = 0.8e-3, max = 1.2e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [8.0e-3, 8.0e-3, 8.0e-3] }
random_speed = 0.3

[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"
tangential_damping_ratio = 0.9075
rolling = "sds"
rolling_k = 50.0
rolling_gamma = 1.0e-4
rolling_mu = 0.1
twisting = "oquendo"

[simulation]
gravity = [0.0, 0.0, 0.0]

[[stage]]
kind = "run"
duration = 1.0e-3
"#);

#[test]
fn hertz_mindlin_conserves_linear_and_angular_momentum_to_round_off() {
    let mut scene = common::parse(&FRICTIONAL_GAS.replace("mu_s = 0.5", "mu_s = 0.5\ngamma_nt = 50.0"));
    scene.track_orientation = false;
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let s0 = e.stats().unwrap();
    let scale_p: f64 = e.bodies().iter().zip(&scene.grains.mass).map(|(b, m)| m * b.vel.norm()).sum();
    let scale_l: f64 = e.bodies().iter().zip(&scene.grains.mass).map(|(b, m)| m * b.vel.norm() * b.pos.norm()).sum();
    e.advance(3000).unwrap();
    let s1 = e.stats().unwrap();
    let dp: Vec3<f64> = Vec3::of(s1.momentum) - Vec3::of(s0.momentum);
    let dl: Vec3<f64> = Vec3::of(s1.angular_momentum) - Vec3::of(s0.angular_momentum);
    println!(
        "after 3000 steps: {} contacts now, |dP| / sum|p| = {:.2e}, |dL| / sum|r||p| = {:.2e}, rotational KE {:.3e} J",
        s1.contacts,
        dp.norm() / scale_p,
        dl.norm() / scale_l,
        s1.ke_rotational
    );
    assert!(s1.ke_rotational > 0.0, "friction must have spun the grains up");
    assert!(dp.norm() < MOMENTUM_ROUNDOFF * scale_p, "linear momentum drift {dp:?}");
    assert!(dl.norm() < MOMENTUM_ROUNDOFF * scale_l, "angular momentum drift {dl:?}");
}

/// Two counter-rotating equal grains of radius `r` in light contact (overlap `-gap`; no slip
/// at the contact point, like meshing gears) after one step under Oquendo et al.'s rolling
/// friction `friction`; returns the scene and the engine.
fn counter_rotating_pair(friction: &str, r: f64, gap: f64) -> (grains::scene::Scene, CpuEngine<f64>) {
    let text = format!(
        concat!(r#"
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
mu_k = 0.4
rolling_angle = 10.0

[[grain]]
material = "sand"
radius = {r}
position = [0.0, 0.0, 0.0]
angular_velocity = [0.0, 0.0, 10.0]

[[grain]]
material = "sand"
radius = {r}
position = [2.0e-3, 0.0, 0.0]
angular_velocity = [0.0, 0.0, -10.0]

[model]
tangential = "oquendo"
rolling_friction = "{friction}"

[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 1.0e-8

[[stage]]
kind = "run"
duration = 1.0e-8
"#), r = r, friction = friction
    );
    // Listed grains may not start overlapping; put the second one in light contact here.
    let mut scene = common::parse(&text);
    scene.grains.position[1][0] = 2.0 * r + gap;
    let mut e: CpuEngine<f64> = common::engine(&scene);
    e.step().unwrap();
    (scene, e)
}

/// The Hertz force of the pair at overlap `h` (N).
fn hertz(scene: &grains::scene::Scene, r: f64, h: f64) -> f64 {
    let c = scene.pair_coeffs::<f64>()[0];
    4.0 / 3.0 * c.v_eff * (r / 2.0).sqrt() * h.powf(1.5)
}

/// Oquendo et al.'s rolling friction as the paper writes it applies eqs. 8-9 to each grain with its
/// own m, I, R', along the same t for both (v_r is the same vector seen from either grain), so
/// the pair's momentum changes at `2 |F_n| tan(theta_r) / (1 + I/(m R'^2))` along `-t`.
#[test]
fn the_rolling_regime_as_written_does_not_conserve_the_pairs_linear_momentum() {
    const RATE_TOLERANCE: f64 = 1e-6;
    let (r, gap) = (5.0e-4, -1.0e-7);
    let (scene, e) = counter_rotating_pair("as_written", r, gap);
    let dt = e.dt();
    let p: Vec3<f64> = e.bodies().iter().zip(&scene.grains.mass).fold(Vec3::ZERO, |acc, (b, m)| acc + b.vel * *m);
    // Expected: both grains pushed along -t with |F_n| tan(theta_r) / (1 + I/(m R'^2)).
    let m = scene.grains.mass[0];
    let rp = r - (-gap) / 2.0;
    let inertia = 0.4 * m * r * r;
    let each = hertz(&scene, r, -gap) * 10.0f64.to_radians().tan() / (1.0 + inertia / (m * rp * rp));
    let rate = p.norm() / dt;
    println!("as written: pair momentum rate {rate:.6e} N, expected 2 x {each:.6e} N; direction {:?}", p * (1.0 / p.norm()));
    assert!((rate / (2.0 * each) - 1.0).abs() < RATE_TOLERANCE, "rate {rate:e} vs {:e}", 2.0 * each);
}

/// The default realisation puts Oquendo et al.'s rolling friction on the pair as a torque pair
/// `+-R'_eff |F_n| tan(theta_r)`: the pair's momentum stays zero and the relative spin slows
/// at the rate that torque gives.
#[test]
fn the_rolling_regime_as_a_torque_pair_conserves_momentum() {
    const RATE_TOLERANCE: f64 = 1e-6;
    let (r, gap) = (5.0e-4, -1.0e-7);
    let (scene, e) = counter_rotating_pair("torque", r, gap);
    let dt = e.dt();
    let m = scene.grains.mass[0];
    let b = e.bodies();
    let p: Vec3<f64> = b.iter().fold(Vec3::ZERO, |acc, b| acc + b.vel * m);
    let spin: f64 = b.iter().map(|b| b.omega.z).sum();
    let rp_eff = (r - (-gap) / 2.0) / 2.0;
    let inertia = 0.4 * m * r * r;
    let torque = rp_eff * hertz(&scene, r, -gap) * 10.0f64.to_radians().tan();
    let slowed = (10.0 - b[0].omega.z) * inertia / dt;
    println!("torque pair: momentum {:.3e} kg m/s, total spin {spin:.3e} rad/s, torque {slowed:.6e} N m (R'_eff F_n tan(theta_r) = {torque:.6e})", p.norm());
    assert!(p.norm() < MOMENTUM_ROUNDOFF * 2.0 * m * 1.0e-6, "momentum {p:?}");
    assert!(spin.abs() < 1e-12 * 10.0, "the torques are equal and opposite: total spin {spin:e}");
    assert!((slowed / torque - 1.0).abs() < RATE_TOLERANCE, "torque {slowed:e} vs {torque:e}");
}
