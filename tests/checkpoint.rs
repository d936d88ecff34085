//! Checkpoint and resume: a run stopped after a stage and resumed from its checkpoint ends
//! bitwise where the uninterrupted run ends (CPU backend), from the library and from the
//! command line.

mod common;

use grains::checkpoint::{CheckpointHeader, EngineState, RunIdentity};
use grains::cpu::CpuEngine;
use grains::engine::{Engine, Frame, Stats};
use grains::output::RunRecorder;
use grains::protocol::{self, Progress, Recorder, StageResult};
use std::process::Command;

/// Three stages of a frictional, twisting, spinning gas in a box with a piston: every kind of
/// history (tangential springs, wall springs, orientation, piston) crosses the boundaries.
const SCENE: &str = r#"
seed = 21
[[material]]
name = "sand"
density = 2650.0
youngs_modulus = 7.0e7
poisson_ratio = 0.3
mu_s = 0.5
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
"#;

/// Keeps the first checkpoint in memory and stops the run there.
struct StopAfterFirst {
    inner: RunRecorder,
    saved: Option<(Progress, EngineState)>,
}

impl Recorder for StopAfterFirst {
    fn stats(&mut self, stage: &str, s: &Stats) -> anyhow::Result<()> {
        self.inner.stats(stage, s)
    }
    fn frame(&mut self, f: &Frame) -> anyhow::Result<()> {
        self.inner.frame(f)
    }
    fn stage_end(&mut self, r: &StageResult) -> anyhow::Result<()> {
        self.inner.stage_end(r)
    }
    fn progress(&mut self, _: &str, _: u64, _: u64) {}
    fn checkpoint(&mut self, progress: &Progress, engine: &dyn Engine) -> anyhow::Result<()> {
        self.saved = Some((progress.clone(), engine.save().unwrap()));
        anyhow::bail!("interrupted after stage {}", progress.next_stage)
    }
}

fn bits(e: &CpuEngine<f64>) -> Vec<u64> {
    let f = e.frame(true);
    let mut v: Vec<u64> = f.position.iter().chain(&f.velocity).chain(&f.angular_velocity).flat_map(|x| x.map(f64::to_bits)).collect();
    v.extend(f.orientation.unwrap().iter().flat_map(|q| q.map(f64::to_bits)));
    v.extend(f.contacts.unwrap().iter().flat_map(|c| c.tangential_spring.map(f64::to_bits)));
    v
}

#[test]
fn a_resumed_run_ends_bitwise_where_the_uninterrupted_one_does() {
    let scene = common::parse(SCENE);
    let mut whole: CpuEngine<f64> = common::engine(&scene);
    let full = protocol::run(&scene, &mut whole, &mut RunRecorder::new(None, false).unwrap()).unwrap();

    let mut first: CpuEngine<f64> = common::engine(&scene);
    let mut stopper = StopAfterFirst { inner: RunRecorder::new(None, false).unwrap(), saved: None };
    let err = protocol::run(&scene, &mut first, &mut stopper).unwrap_err();
    assert!(err.to_string().contains("interrupted after stage 1"));
    let (progress, state) = stopper.saved.unwrap();

    // Through the file format, into an engine that never ran.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(grains::checkpoint::FILE);
    let id = RunIdentity { scene_file: "test.toml".into(), scene_hash: 0, backend: "cpu".into(), precision: "f64".into() };
    grains::checkpoint::write(&path, &CheckpointHeader { identity: id, progress }, &state).unwrap();
    let (header, state): (CheckpointHeader, EngineState) = grains::checkpoint::read(&path).unwrap();
    let mut resumed: CpuEngine<f64> = common::engine(&scene);
    resumed.restore(&state).unwrap();
    let results = protocol::run_from(&scene, &mut resumed, &mut RunRecorder::new(None, false).unwrap(), header.progress).unwrap();

    let (a, b) = (bits(&whole), bits(&resumed));
    println!("{} values compared after {} steps; {} stage results", a.len(), resumed.steps(), results.len());
    assert_eq!(results.len(), full.len());
    assert_eq!(whole.steps(), resumed.steps());
    assert_eq!(a, b);
    let (x, y) = (serde_json::to_string(&full).unwrap(), serde_json::to_string(&results).unwrap());
    let at = x.chars().zip(y.chars()).position(|(a, b)| a != b).unwrap_or(0);
    assert_eq!(x, y, "first difference at {at}: {} / {}", &x[at.saturating_sub(80)..(at + 40).min(x.len())], &y[at.saturating_sub(80)..(at + 40).min(y.len())]);
}

#[test]
fn grains_run_resume_continues_a_stopped_run_to_the_same_summary() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = dir.path().join("scene.toml");
    std::fs::write(&scene_path, SCENE).unwrap();
    let grains = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_grains")).args(args).env("RUST_BACKTRACE", "0").output().unwrap();
    let whole = dir.path().join("whole");
    let o = grains(&["run", scene_path.to_str().unwrap(), "--out", whole.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let full: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();

    // A run stopped after its first stage: the library run above, written where the command
    // line expects it.
    let cut = dir.path().join("cut");
    let scene = grains::scene::load(&scene_path).unwrap();
    let mut e: CpuEngine<f64> = CpuEngine::new(&scene).unwrap();
    let mut stopper = StopAfterFirst { inner: RunRecorder::new(Some(&cut), false).unwrap(), saved: None };
    let _ = protocol::run(&scene, &mut e, &mut stopper);
    stopper.inner.finish().unwrap();
    let (progress, state) = stopper.saved.unwrap();
    let id = RunIdentity { scene_file: scene_path.display().to_string(), scene_hash: grains::checkpoint::fnv1a(SCENE.as_bytes()), backend: "cpu".into(), precision: "f64".into() };
    grains::checkpoint::write(&cut.join(grains::checkpoint::FILE), &CheckpointHeader { identity: id, progress }, &state).unwrap();

    let o = grains(&["run", "--resume", cut.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let resumed: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    println!("final: {} / {}", full["final"], resumed["final"]);
    assert_eq!(full["final"], resumed["final"]);
    assert_eq!(full["steps"], resumed["steps"]);
    assert_eq!(full["stages"], resumed["stages"]);
    let rows = |d: &std::path::Path| std::fs::read_to_string(d.join("stats.csv")).unwrap();
    assert_eq!(rows(&whole), rows(&cut), "the resumed CSV continues the stopped one row for row");

    // A changed scene is refused.
    std::fs::write(&scene_path, SCENE.replace("seed = 21", "seed = 22")).unwrap();
    let o = grains(&["run", "--resume", cut.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(err.contains("differs from the one the checkpoint") && err.contains("fix:"), "{err}");
}
