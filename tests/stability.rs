//! Hard cases: a run that goes unstable stops with an error naming the step, the grain and a
//! smaller dt; a neighbour-capacity overflow is an error naming the grain, never a dropped
//! contact.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::SimError;
use grains::protocol;

/// The elastic gas at 1.5 collision times per step (the scene check refuses this; the engine
/// is driven directly to show what the run-time guard does): grains tunnel deep into each
/// other and the energy explodes.
#[test]
fn a_run_at_a_far_too_large_step_stops_with_step_grain_and_a_smaller_dt() {
    let mut scene = common::shipped("elastic_gas.toml");
    let dt = 1.5 * scene.time_step.times.collision;
    scene.time_step.dt = dt;
    scene.stats_interval = 5;
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let err = protocol::run(&scene, &mut e, &mut grains::output::RunRecorder::new(None, false).unwrap()).expect_err("must stop");
    let msg = err.to_string();
    println!("{msg}");
    let sim = err.downcast_ref::<SimError>().expect("a simulation error");
    match sim {
        SimError::Unstable { step, suggested_dt, .. } => {
            assert!(*step > 0);
            assert!(*suggested_dt <= scene.time_step.auto_dt(), "suggests a step that works");
        }
        other => panic!("expected an instability, got {other}"),
    }
    assert!(msg.contains("grain") && msg.contains("lower simulation.dt"), "{msg}");
}

#[test]
fn the_stable_step_runs_through() {
    let scene = common::shipped("elastic_gas.toml");
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let stages = protocol::run(&scene, &mut e, &mut grains::output::RunRecorder::new(None, false).unwrap()).expect("stable at the auto step");
    let s = &stages[0].stats;
    assert!(s.max_overlap < scene.max_overlap && s.non_finite_grain.is_none());
}

#[test]
fn a_neighbour_capacity_overflow_is_an_error_naming_the_grain() {
    let text = std::fs::read_to_string(common::scene_path("elastic_gas.toml")).unwrap().replace("count = 50", "count = 90");
    let mut dense = common::parse(&text);
    dense.max_neighbours = 2;
    dense.skin = 1.0e-3;
    let err = match CpuEngine::<f64>::new(&dense) {
        Err(e) => e,
        Ok(_) => panic!("2 neighbours with a 1 mm skin cannot hold"),
    };
    let msg = err.to_string();
    println!("{msg}");
    assert!(matches!(err, SimError::Capacity { capacity: 2, count, .. } if count > 2), "{msg}");
    assert!(msg.contains("simulation.max_neighbours"), "{msg}");
}
