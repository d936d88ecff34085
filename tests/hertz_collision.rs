//! Head-on collision of two spheres against the Hertz formulas (docs/physics.md "Time step") and
//! the peers' published figures (shared/peers/README.md, two-sphere collision).

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::timestep::{hertz_collision_time, hertz_max_overlap};

/// Contact time and largest overlap within this relative error at dt = t_c / 50 (issue 2).
const HERTZ_TOLERANCE: f64 = 0.01;
/// The peers' theory values for the same pair (R = 0.5 mm, rho = 2650, E = 70 MPa, nu = 0.3,
/// v = 0.1 m/s): t_c = 7.5939e-5 s, delta_max = 2.5803e-6 m, to the digits they printed.
const PEER_T_C: f64 = 7.5939e-5;
const PEER_DELTA_MAX: f64 = 2.5803e-6;
const PEER_DIGITS: f64 = 1e-4;

const R: f64 = 5.0e-4;
const RHO: f64 = 2650.0;
const E: f64 = 7.0e7;
const NU: f64 = 0.3;
const V_REL: f64 = 0.1;

struct Collision {
    contact_time: f64,
    max_overlap: f64,
    restitution: f64,
}

/// Runs the shipped two-sphere scene with `dt` and a damping law, and measures the contact
/// from the overlap sampled every step (crossing times by linear interpolation, as the peers).
fn collide(dt: f64, damping: &str) -> Collision {
    let text = std::fs::read_to_string(common::scene_path("two_spheres.toml")).unwrap();
    let text = text.replace("dt = \"auto\"", &format!("dt = {dt:e}"));
    let text = if damping.starts_with("normal") { text.replace("normal = \"hertz\"\ndamping = \"none\"", damping) } else { text.replace("damping = \"none\"", damping) };
    let text = if damping.contains("papers") || damping.contains("restitution") {
        text.replace("poisson_ratio = 0.3", &format!("poisson_ratio = 0.3\n{}", damping_material(damping)))
    } else {
        text
    };
    let scene = common::parse(&text);
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let overlap = |e: &CpuEngine<f64>| {
        let b = e.bodies();
        2.0 * R - (b[0].pos - b[1].pos).norm()
    };
    let v_rel = |e: &CpuEngine<f64>| (e.bodies()[1].vel - e.bodies()[0].vel).x;
    let v_in = v_rel(&e);
    let (mut t_on, mut t_off, mut max_h) = (None, None, 0.0f64);
    let mut h_prev = overlap(&e);
    while t_off.is_none() {
        e.step().unwrap();
        let h = overlap(&e);
        let t = e.time();
        if h_prev <= 0.0 && h > 0.0 {
            t_on = Some(t - dt * h / (h - h_prev));
        }
        if t_on.is_some() && h_prev > 0.0 && h <= 0.0 {
            t_off = Some(t - dt * h / (h - h_prev));
        }
        max_h = max_h.max(h);
        h_prev = h;
        assert!(t < 0.01, "the grains never separated");
    }
    Collision { contact_time: t_off.unwrap() - t_on.unwrap(), max_overlap: max_h, restitution: -v_rel(&e) / v_in }
}

fn damping_material(damping: &str) -> String {
    // `damping` is the [model] line; the coefficient comes after a '#'.
    damping.split('#').nth(1).unwrap_or("").trim().to_string()
}

fn theory() -> (f64, f64) {
    let m = 4.0 / 3.0 * std::f64::consts::PI * R.powi(3) * RHO;
    let v_eff = E / (1.0 - NU * NU) / 2.0;
    (hertz_collision_time(m / 2.0, R / 2.0, v_eff, V_REL), hertz_max_overlap(m / 2.0, R / 2.0, v_eff, V_REL))
}

#[test]
fn theory_matches_the_peers_published_values() {
    let (t_c, d_max) = theory();
    assert!((t_c / PEER_T_C - 1.0).abs() < PEER_DIGITS, "t_c = {t_c:e}, peers {PEER_T_C:e}");
    assert!((d_max / PEER_DELTA_MAX - 1.0).abs() < PEER_DIGITS, "delta_max = {d_max:e}, peers {PEER_DELTA_MAX:e}");
}

#[test]
fn contact_time_and_max_overlap_match_hertz_at_fifty_steps_per_contact() {
    let (t_c, d_max) = theory();
    let c = collide(t_c / 50.0, "damping = \"none\"");
    let (et, eh) = (c.contact_time / t_c - 1.0, c.max_overlap / d_max - 1.0);
    println!("dt = t_c/50: contact time {:.5e} s (error {et:+.2e}), max overlap {:.5e} m (error {eh:+.2e}), e = {:.6}", c.contact_time, c.max_overlap, c.restitution);
    assert!(et.abs() < HERTZ_TOLERANCE, "contact time error {et:e}");
    assert!(eh.abs() < HERTZ_TOLERANCE, "max overlap error {eh:e}");
    assert!((c.restitution - 1.0).abs() < HERTZ_TOLERANCE, "undamped restitution {}", c.restitution);
}

#[test]
fn contact_time_error_falls_with_the_time_step() {
    let (t_c, _) = theory();
    let errors: Vec<f64> = [20.0, 50.0, 100.0].iter().map(|n| (collide(t_c / n, "damping = \"none\"").contact_time / t_c - 1.0).abs()).collect();
    println!("contact-time error at t_c/20, /50, /100: {errors:?}");
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
}

/// Restitution under the papers' damping `m_eff gamma_n sqrt(h) v_n` (Oquendo et al. eq. 1) falls as
/// gamma_n grows; undamped it is 1.
#[test]
fn restitution_falls_with_the_papers_damping_coefficient() {
    let (t_c, _) = theory();
    let gammas = [0.0, 1.0e5, 1.0e6, 3.0e6, 1.0e7];
    let mut table = Vec::new();
    for g in gammas {
        let c = if g == 0.0 {
            collide(t_c / 50.0, "damping = \"none\"")
        } else {
            collide(t_c / 50.0, &format!("damping = \"papers\" # gamma_n = {g:e}"))
        };
        table.push((g, c.restitution, c.contact_time));
    }
    println!("gamma_n (s^-1 m^-1/2) | restitution | contact time (s)");
    for (g, e, t) in &table {
        println!("{g:>10.1e} | {e:.4} | {t:.4e}");
    }
    assert!((table[0].1 - 1.0).abs() < HERTZ_TOLERANCE);
    for w in table.windows(2) {
        assert!(w[1].1 < w[0].1, "restitution must fall with gamma_n: {table:?}");
    }
    assert!(table.last().unwrap().1 < 0.9, "the largest damping should dissipate visibly: {table:?}");
}

/// The restitution law with the no-pull clamp on the shipped two-sphere pair: its dashpot is
/// sized for the clamped Hertz contact ([`grains::model::restitution`]), so e = 0.5 in gives
/// 0.5 out within the velocity-Verlet step's first-order error (the dashpot sees the velocity
/// of half a step before), which falls with dt; LIGGGHTS' closed-form ratio under the same
/// clamp gives 0.550 (`tests/impacts.rs` covers every law, clamp and e).
#[test]
fn restitution_law_gives_the_restitution_asked_for() {
    const DAMPED_TOLERANCE: f64 = 0.01;
    let (t_c, _) = theory();
    let coarse = collide(t_c / 50.0, "damping = \"restitution\" # restitution = 0.5");
    let fine = collide(t_c / 200.0, "damping = \"restitution\" # restitution = 0.5");
    println!("e = 0.5 asked: t_c/50: e = {:.5}, contact {:.5e} s; t_c/200: e = {:.5}, {:.5e} s", coarse.restitution, coarse.contact_time, fine.restitution, fine.contact_time);
    assert!((coarse.restitution / 0.5 - 1.0).abs() < DAMPED_TOLERANCE);
    assert!((fine.restitution - 0.5).abs() < (coarse.restitution - 0.5).abs(), "the error must fall with dt");
    let liggghts = grains::model::restitution::restitution_of(grains::model::restitution::Spring::Hertz, true, grains::model::restitution::oscillator_beta(0.5));
    assert!((liggghts - 0.550).abs() < 0.001, "LIGGGHTS' ratio under the clamp: {liggghts}");
}

/// The linear spring (k_n) as the alternative normal law: an undamped contact lasts half a
/// period, `pi sqrt(m_eff / k_n)`, and returns the approach speed.
#[test]
fn linear_spring_contact_lasts_half_a_period() {
    let k_n = 1000.0;
    let text = std::fs::read_to_string(common::scene_path("two_spheres.toml")).unwrap().replace("normal = \"hertz\"", &format!("normal = \"linear\"\nk_n = {k_n}"));
    let scene = common::parse(&text);
    let m_eff = scene.grains.mass[0] / 2.0;
    let expect = std::f64::consts::PI * (m_eff / k_n).sqrt();
    assert!((scene.time_step.times.collision / expect - 1.0).abs() < 1e-12, "check's collision time is the linear one");
    let c = collide(scene.time_step.dt, "normal = \"linear\"\nk_n = 1000.0\ndamping = \"none\"");
    println!("linear: contact {:.5e} s, theory {expect:.5e} s, e = {:.6}", c.contact_time, c.restitution);
    assert!((c.contact_time / expect - 1.0).abs() < HERTZ_TOLERANCE);
    assert!((c.restitution - 1.0).abs() < HERTZ_TOLERANCE);
}
