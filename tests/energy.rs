//! Oquendo et al.'s integrator study (its Figure 2): the elastic gas of 50 frictionless, undamped
//! Hertz grains conserves its mechanical energy; the fluctuation `<dE^2>^(1/2)` measures the
//! integrator's error and must shrink as dt falls, and the optimised velocity Verlet must
//! beat velocity Verlet at the same dt.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::scene::{Integrator, Scene};

/// Simulated time over which the fluctuation is measured (s): about 20 collisions per grain.
const HORIZON: f64 = 0.02;
/// Energy samples per run.
const SAMPLES: usize = 400;
/// Velocity Verlet is second order; the observed order must be at least this.
const MIN_ORDER: f64 = 1.5;

/// Relative fluctuation `std(E) / mean(E)` of the total energy over the horizon.
fn fluctuation(scene: &Scene, integrator: Integrator, dt: f64) -> f64 {
    let mut s = scene.clone();
    s.integrator = integrator;
    s.time_step.dt = dt;
    let mut e: CpuEngine<f64> = common::engine(&s);
    let steps = (HORIZON / dt).round() as u64;
    let every = (steps / SAMPLES as u64).max(1);
    let mut energies = Vec::new();
    let mut done = 0;
    while done < steps {
        e.advance(every).unwrap();
        done += every;
        energies.push(e.stats().unwrap().mechanical_energy());
    }
    let n = energies.len() as f64;
    let mean = energies.iter().sum::<f64>() / n;
    let var = energies.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    var.sqrt() / mean
}

#[test]
fn energy_fluctuation_shrinks_with_dt_and_the_optimised_scheme_beats_velocity_verlet() {
    let scene = common::shipped("elastic_gas.toml");
    let t_c = scene.time_step.times.collision;
    let divisors = [10.0, 20.0, 40.0, 80.0];
    let mut vv = Vec::new();
    let mut ovv = Vec::new();
    println!("dt (s)      | t_c/dt | VV std(E)/E | OVV std(E)/E");
    for n in divisors {
        let dt = t_c / n;
        vv.push(fluctuation(&scene, Integrator::VelocityVerlet, dt));
        ovv.push(fluctuation(&scene, Integrator::OptimizedVerlet, dt));
        println!("{dt:.4e} | {n:>6} | {:.4e}  | {:.4e}", vv.last().unwrap(), ovv.last().unwrap());
    }
    let order = |f: &[f64]| (f[0] / f[f.len() - 1]).ln() / (divisors[divisors.len() - 1] / divisors[0]).ln();
    let (p_vv, p_ovv) = (order(&vv), order(&ovv));
    println!("observed order: velocity Verlet {p_vv:.2}, optimised velocity Verlet {p_ovv:.2}");
    for f in [&vv, &ovv] {
        for w in f.windows(2) {
            assert!(w[1] < w[0], "the fluctuation must shrink as dt falls: {f:?}");
        }
    }
    assert!(p_vv >= MIN_ORDER, "velocity Verlet order {p_vv}");
    assert!(p_ovv >= MIN_ORDER, "optimised velocity Verlet order {p_ovv}");
    for (a, b) in vv.iter().zip(&ovv) {
        assert!(b < a, "the optimised scheme must beat velocity Verlet at equal dt: {vv:?} vs {ovv:?}");
    }
}
