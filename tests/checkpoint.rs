//! Checkpoint and resume: a run stopped after a stage and resumed from its checkpoint ends
//! bitwise where the uninterrupted run ends, on the CPU and the GPU, from the library and from
//! the command line.

mod common;

use grains::checkpoint::{CheckpointHeader, EngineState, RunIdentity};
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::output::RunRecorder;
use grains::protocol;
use std::process::Command;

/// Three stages of a frictional, twisting, spinning gas in a box with a piston: every kind of
/// history (tangential springs, wall springs, orientation, piston) crosses the boundaries.
const SCENE: &str = concat!(r#"
seed = 21
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
restitution = 0.6
[[generate]]
material = "sand"
count = 400
diameter = { min = 0.8e-3, max = 1.2e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [10.0e-3, 10.0e-3, 10.0e-3] }
random_speed = 0.3
[[wall]]
type = "box"
material = "sand"
min = [0.0, 0.0, 0.0]
max = [10.0e-3, 10.0e-3, 20.0e-3]
open_top = true
[[wall]]
type = "piston"
material = "sand"
z = 12.0e-3
pressure = 50.0
[model]
damping = "restitution"
tangential = "mindlin"
tangential_damping_ratio = 0.9
rolling = "sds"
rolling_k = 50.0
rolling_mu = 0.1
[simulation]
track_orientation = true
stats_interval = 100
[[stage]]
kind = "run"
duration = 2.0e-3
[[stage]]
kind = "run"
duration = 2.0e-3
piston_pressure = 200.0
[[stage]]
kind = "run"
duration = 2.0e-3
"#);

/// SCENE with a checkpoint at every statistics read inside a stage.
fn checkpointing_within_stages() -> String {
    format!("{SCENE}[output]\ncheckpoint_interval = 1.0e-9\n")
}

fn bits(e: &dyn Engine) -> Vec<u64> {
    let f = e.frame(true).unwrap();
    let mut v: Vec<u64> = f.position.iter().chain(&f.velocity).chain(&f.angular_velocity).flat_map(|x| x.to_array().map(f64::to_bits)).collect();
    v.extend(f.orientation.unwrap().iter().flat_map(|q| q.to_array().map(f64::to_bits)));
    v.extend(f.contacts.unwrap().iter().flat_map(|c| c.tangential_spring.to_array().map(f64::to_bits)));
    v
}

/// Runs `text` whole on one engine, and stopped at checkpoint `at` on another whose checkpoint
/// goes through the file format into a third that never ran; the third must end bitwise where
/// the first did, with the same stage results. Returns whether the stop was inside a stage.
fn resume_ends_bitwise(text: &str, at: usize, make: &dyn Fn(&grains::scene::Scene) -> Box<dyn Engine>) -> bool {
    let scene = common::parse(text);
    let mut whole = make(&scene);
    let full = protocol::run(&scene, whole.as_mut(), &mut RunRecorder::new(None, false).unwrap()).unwrap();

    let mut first = make(&scene);
    let mut stopper = common::StopAt::new(RunRecorder::new(None, false).unwrap(), at);
    let err = protocol::run(&scene, first.as_mut(), &mut stopper).unwrap_err();
    assert!(err.to_string().contains(&format!("interrupted at checkpoint {at}")), "{err}");
    let (progress, state) = stopper.saved.unwrap();
    let inside = progress.in_stage.is_some();

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(grains::checkpoint::FILE);
    let id = RunIdentity { scene_file: "test.toml".into(), scene_hash: 0, backend: whole.backend().into(), precision: whole.precision().into() };
    grains::checkpoint::write(&path, &CheckpointHeader { identity: id, progress, files: Vec::new() }, &state).unwrap();
    let (header, state): (CheckpointHeader, EngineState) = grains::checkpoint::read(&path).unwrap();
    let mut resumed = make(&scene);
    resumed.restore(&state).unwrap();
    let results = protocol::run_from(&scene, resumed.as_mut(), &mut RunRecorder::new(None, false).unwrap(), header.progress).unwrap();

    let (a, b) = (bits(whole.as_ref()), bits(resumed.as_ref()));
    println!("{}, stopped at checkpoint {at} (inside a stage: {inside}): {} values compared after {} steps; {} stage results", whole.backend(), a.len(), resumed.steps(), results.len());
    assert_eq!(results.len(), full.len());
    assert_eq!(whole.steps(), resumed.steps());
    assert_eq!(a, b);
    let (x, y) = (serde_json::to_string(&full).unwrap(), serde_json::to_string(&results).unwrap());
    let d = x.chars().zip(y.chars()).position(|(a, b)| a != b).unwrap_or(0);
    assert_eq!(x, y, "first difference at {d}: {} / {}", &x[d.saturating_sub(80)..(d + 40).min(x.len())], &y[d.saturating_sub(80)..(d + 40).min(y.len())]);
    inside
}

#[test]
fn a_resumed_run_ends_bitwise_where_the_uninterrupted_one_does() {
    let cpu = |scene: &grains::scene::Scene| -> Box<dyn Engine> { Box::new(common::engine::<f64>(scene)) };
    assert!(!resume_ends_bitwise(SCENE, 1, &cpu), "the first checkpoint is the first stage's end");
    assert!(resume_ends_bitwise(&checkpointing_within_stages(), 5, &cpu), "checkpoint 5 is inside a stage");
}

#[test]
fn a_resumed_gpu_run_ends_bitwise_where_the_uninterrupted_one_does() {
    if common::gpu().is_none() {
        return;
    }
    let gpu = |scene: &grains::scene::Scene| -> Box<dyn Engine> { Box::new(common::gpu_engine(scene).expect("the adapter opened above")) };
    assert!(!resume_ends_bitwise(SCENE, 1, &gpu));
    assert!(resume_ends_bitwise(&checkpointing_within_stages(), 5, &gpu));
}

/// A run stopped inside a stage, with a statistics row written after its checkpoint (as a run
/// killed between two checkpoints leaves), resumed from the command line: the same summary as
/// the uninterrupted run, the same `stats.csv` row for row, and (frames at an interval, with
/// `--vtk`) the same VTK collection, whose last frame is the same bytes.
#[test]
fn grains_run_resume_continues_a_stopped_run_to_the_same_summary() {
    let text = format!("{}frame_interval = 2.5e-4\n", checkpointing_within_stages());
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("scene.toml");
    std::fs::write(&scene_path, &text).unwrap();
    let grains = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_grains")).args(args).env("RUST_BACKTRACE", "0").output().unwrap();
    let whole = dir.path().join("whole");
    let o = grains(&["run", scene_path.to_str().unwrap(), "--out", whole.to_str().unwrap(), "--json", "--vtk"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let full: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();

    // The library run, recording where the command line expects it, stopped at a checkpoint
    // inside the second stage.
    let cut = dir.path().join("cut");
    let mut scene = grains::scene::load(&scene_path).unwrap();
    scene.output.vtk = true;
    let mut e: CpuEngine<f64> = CpuEngine::new(&scene).unwrap();
    let id = RunIdentity { scene_file: scene_path.display().to_string(), scene_hash: grains::checkpoint::fnv1a(text.as_bytes()), backend: "cpu".into(), precision: "f64".into() };
    let mut stopper = common::StopAt::new(RunRecorder::new(Some(&cut), false).unwrap().with_checkpoints(&cut, id).with_vtk(&cut, &scene, None).unwrap(), 28);
    let err = protocol::run(&scene, &mut e, &mut stopper).unwrap_err();
    assert!(err.to_string().contains("stage 1, inside it: true"), "{err}");
    stopper.inner.finish().unwrap();
    let mut csv = std::fs::OpenOptions::new().append(true).open(cut.join("stats.csv")).unwrap();
    std::io::Write::write_all(&mut csv, b"a row written after the checkpoint\n").unwrap();

    let o = grains(&["run", "--resume", cut.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    println!("final: {} / {}", full["final"], resumed["final"]);
    assert_eq!(full["final"], resumed["final"]);
    assert_eq!(full["steps"], resumed["steps"]);
    assert_eq!(full["stages"], resumed["stages"]);
    let rows = |d: &std::path::Path| std::fs::read_to_string(d.join("stats.csv")).unwrap();
    assert_eq!(rows(&whole), rows(&cut), "the resumed CSV continues the stopped one row for row");
    assert!(cut.join(format!("frames-from-stage1-step{}.mcap", e.steps())).exists(), "frames after the resume go to their own file");
    let collection = |d: &std::path::Path| {
        let text = std::fs::read_to_string(d.join("vtk/grains.pvd")).unwrap();
        let entries: Vec<(String, String)> = text
            .lines()
            .filter_map(|l| Some((l.split("timestep=\"").nth(1)?.split('"').next()?.to_string(), l.split("file=\"").nth(1)?.split('"').next()?.to_string())))
            .collect();
        entries
    };
    let (a, b) = (collection(&whole), collection(&cut));
    assert!(a.len() >= 20, "{} frames", a.len());
    let times = |c: &[(String, String)]| c.iter().map(|e| e.0.clone()).collect::<Vec<_>>();
    assert_eq!(times(&a), times(&b), "the resumed collection lists the uninterrupted run's frame times");
    let last = |d: &std::path::Path, c: &[(String, String)]| std::fs::read(d.join("vtk").join(&c.last().unwrap().1)).unwrap();
    assert!(last(&whole, &a) == last(&cut, &b), "the last frame's grain file is the same bytes");

    // A changed scene is refused.
    std::fs::write(&scene_path, text.replace("seed = 21", "seed = 22")).unwrap();
    let o = grains(&["run", "--resume", cut.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(err.contains("differs from the one the checkpoint") && err.contains("fix:"), "{err}");
}
