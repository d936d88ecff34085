//! Regression: a checkpoint written while no grain touched (a pour cut short by its stage's
//! duration) held the unbalanced-force ratio, infinite then, as JSON `null`, and could not be
//! read back ("invalid type: null, expected f64"), so the run could not resume.

mod common;

use grains::checkpoint::{CheckpointHeader, EngineState, RunIdentity};
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::output::RunRecorder;
use grains::protocol;

/// Two grains falling side by side, far from each other and from everything: no contact, and
/// gravity acting. Checkpoints at every statistics read; the second stage starts after a fill
/// cut short, so its checkpoint carries the fill's result too.
const SCENE: &str = concat!(r#"
"#, include_str!("fixtures/sand.toml"), r#"[[grain]]
material = "sand"
radius = 5.0e-4
position = [0.0, 0.0, 0.1]
[[grain]]
material = "sand"
radius = 5.0e-4
position = [0.01, 0.0, 0.1]
[simulation]
gravity = [0.0, 0.0, -9.81]
[[stage]]
kind = "fill"
duration = 1.0e-3
[[stage]]
kind = "run"
duration = 1.0e-3
[output]
checkpoint_interval = 1.0e-9
"#);

#[test]
fn a_checkpoint_taken_while_no_grain_touches_reads_back_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::parse(SCENE);
    let mut whole: CpuEngine<f64> = common::engine(&scene);
    let full = protocol::run(&scene, &mut whole, &mut RunRecorder::new(None, false).unwrap()).unwrap();
    assert_eq!(full[0].unbalanced_force, f64::INFINITY, "forces act and nothing touches");

    let id = RunIdentity { scene_file: "t.toml".into(), scene_hash: 0, backend: "cpu".into(), precision: "f64".into() };
    let mut e: CpuEngine<f64> = common::engine(&scene);
    let mut stopper = common::StopAt::new(RunRecorder::new(None, false).unwrap().with_checkpoints(dir.path(), id), 3);
    let err = protocol::run(&scene, &mut e, &mut stopper).unwrap_err();
    assert!(err.to_string().contains("stage 1, inside it: true"), "{err}");
    let (header, state): (CheckpointHeader, EngineState) = grains::checkpoint::read(&dir.path().join(grains::checkpoint::FILE)).expect("the checkpoint reads back");
    assert_eq!(header.progress.results[0].unbalanced_force, f64::INFINITY);
    assert_eq!(header.progress.results[0].stats.unbalanced_force, f64::INFINITY);

    let mut resumed: CpuEngine<f64> = common::engine(&scene);
    resumed.restore(&state).unwrap();
    let rest = protocol::run_from(&scene, &mut resumed, &mut RunRecorder::new(None, false).unwrap(), header.progress).unwrap();
    let bits = |e: &CpuEngine<f64>| e.frame(false).unwrap().position.iter().flat_map(|p| p.to_array().map(f64::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&whole), bits(&resumed), "the resumed run ends where the whole one did");
    assert_eq!(rest.len(), full.len());
}
