//! Helpers shared by the integration tests.
#![allow(dead_code, reason = "each test binary uses a different subset")]

pub mod cd;

use grains::checkpoint::EngineState;
use grains::cpu::CpuEngine;
use grains::engine::{Engine, Frame, Stats};
use grains::output::RunRecorder;
use grains::protocol::{Progress, Recorder, StageResult};
use grains::real::Real;
use grains::scene::{self, Scene};
use std::path::{Path, PathBuf};

/// Path of a shipped scene.
pub fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)
}

/// Loads a shipped scene.
pub fn shipped(name: &str) -> Scene {
    scene::load(&scene_path(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// Parses scene text.
pub fn parse(text: &str) -> Scene {
    scene::parse(Path::new("test.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

/// A CPU engine for a scene.
pub fn engine<T: Real>(scene: &Scene) -> CpuEngine<T> {
    CpuEngine::new(scene).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs `f` on a pool of `threads` workers.
pub fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool").install(f)
}

/// Says on the terminal that the running test is skipped and why. The test harness captures
/// `eprintln!` of a passing test, so this writes to stderr itself: `cargo test` then shows one
/// `SKIPPED` line per test that returned early, under its name.
pub fn skipped(reason: &str) {
    use std::io::Write;
    let name = std::thread::current().name().unwrap_or("(unnamed)").to_string();
    let _ = writeln!(std::io::stderr().lock(), "test {name} ... SKIPPED: {reason}");
}

/// Opens the best GPU adapter. Without one, CI fails (it installs lavapipe) and a developer
/// machine skips the test with a visible message.
pub fn gpu() -> Option<grains::gpu::Gpu> {
    match grains::gpu::open(None) {
        Ok(g) => Some(g),
        Err(e) if std::env::var_os("CI").is_some() => panic!("CI must have a GPU adapter (lavapipe): {e}"),
        Err(e) => {
            skipped(&e.to_string());
            None
        }
    }
}

/// A GPU engine for a scene, or `None` (skipped) without an adapter.
pub fn gpu_engine(scene: &Scene) -> Option<grains::gpu::GpuEngine> {
    let gpu = gpu()?;
    Some(grains::gpu::GpuEngine::new(gpu, scene).unwrap_or_else(|e| panic!("{e}")))
}

/// Makes an engine for a scene (None: no GPU adapter).
pub type EngineMaker = Box<dyn Fn(&Scene) -> Option<Box<dyn Engine>>>;

/// The engines a resume test compares, by name: the CPU in f64 and, where an adapter opens,
/// the GPU.
pub fn resumable_engines() -> Vec<(&'static str, EngineMaker)> {
    let mut makers: Vec<(&str, EngineMaker)> = vec![("cpu f64", Box::new(|s| Some(Box::new(engine::<f64>(s)) as Box<dyn Engine>)))];
    if gpu().is_some() {
        makers.push(("gpu", Box::new(|s| gpu_engine(s).map(|g| Box::new(g) as Box<dyn Engine>))));
    }
    makers
}

/// `first` saved and restored into a fresh engine of `make`'s for `scene`, then advanced by
/// `rest` steps: the run resumed from a checkpoint taken where `first` stands.
pub fn resumed(make: &EngineMaker, scene: &Scene, first: &dyn Engine, rest: u64) -> Box<dyn Engine> {
    let saved = first.save().unwrap();
    let mut resumed = make(scene).unwrap();
    resumed.restore(&saved).unwrap();
    resumed.advance(rest).unwrap();
    resumed
}

/// `text` with each `(from, to)` replaced, failing loudly when a `from` is absent (so that a
/// change to a shipped scene cannot silently leave a test on the wrong parameters).
pub fn edit(text: &str, edits: &[(&str, &str)]) -> String {
    edits.iter().fold(text.to_string(), |t, (from, to)| {
        assert!(t.contains(from), "the scene text has no {from:?}");
        t.replace(from, to)
    })
}

/// Oquendo et al.'s elastic gas made frictional, damped and wet (w = 0.01): 120 grains whose
/// liquid bridges break and form as they collide.
pub fn wet_gas() -> Scene {
    let text = std::fs::read_to_string(scene_path("elastic_gas.toml")).unwrap();
    parse(&edit(
        &text,
        &[
            ("count = 50", "count = 120"),
            ("max = [6.0e-3, 6.0e-3, 6.0e-3] }\nrandom_speed = 0.5", "max = [8.0e-3, 8.0e-3, 8.0e-3] }\nrandom_speed = 0.3"),
            ("max = [6.0e-3, 6.0e-3, 6.0e-3]\n", "max = [8.0e-3, 8.0e-3, 8.0e-3]\n"),
            ("poisson_ratio = 0.3", "poisson_ratio = 0.3\nmu_s = 0.4\nrestitution = 0.8"),
            ("damping = \"none\"\ntangential = \"none\"", "damping = \"restitution\"\ntangential = \"mindlin\"\ncohesion = \"capillary\""),
            ("duration = 0.05", "duration = 0.05\nwater_content = 0.01"),
        ],
    ))
}

/// A dense, frictional, colliding gas of `count` grains (0.8-1.2 mm) in a box of `side` metres
/// under gravity, with Oquendo et al.'s laws (the force on the owner kept per pair) and orientations
/// tracked: many pairs, wall contacts and rebuilds.
pub fn box_gas(count: usize, side: f64) -> String {
    format!(
        concat!(r#"
seed = 11
"#, include_str!("../fixtures/sand.toml"), r#"mu_s = 0.5
mu_k = 0.4
rolling_angle = 3.0
gamma_n = 1.0e5
gamma_nt = 10.0

[[generate]]
material = "sand"
count = {count}
diameter = {{ min = 0.8e-3, max = 1.2e-3 }}
region = {{ shape = "box", min = [0.0, 0.0, 0.0], max = [{side:e}, {side:e}, {side:e}] }}
random_speed = 0.5

[[wall]]
type = "box"
material = "sand"
min = [0.0, 0.0, 0.0]
max = [{side:e}, {side:e}, {side:e}]

[model]
damping = "papers"
tangential = "oquendo"
twisting = "oquendo"

[simulation]
track_orientation = true

[[stage]]
kind = "run"
duration = 1.0e-3
"#), count = count, side = side
    )
}

/// Whether an outside program the tests read files back with runs (`program args` exits 0).
/// Without it CI fails (`.ci/run` installs it) and a developer machine skips the test with a
/// visible message naming the package.
pub fn reader(program: &str, args: &[&str], package: &str) -> bool {
    let ok = std::process::Command::new(program).args(args).output().is_ok_and(|o| o.status.success());
    if !ok {
        if std::env::var_os("CI").is_some() {
            panic!("CI must have {program} (Debian package {package}); .ci/run installs it");
        }
        skipped(&format!("{program} is not installed; install the Debian package {package}"));
    }
    ok
}

/// Keeps checkpoint number `at` (1 = the first offered) in memory, passing every one to the
/// inner recorder, and stops the run there.
pub struct StopAt {
    /// The recorder every call goes on to.
    pub inner: RunRecorder,
    at: usize,
    seen: usize,
    /// Where the run stopped and the engine's state there.
    pub saved: Option<(Progress, EngineState)>,
}

impl StopAt {
    /// Stops at checkpoint `at`.
    pub fn new(inner: RunRecorder, at: usize) -> Self {
        StopAt { inner, at, seen: 0, saved: None }
    }
}

impl Recorder for StopAt {
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
        self.inner.checkpoint(progress, engine)?;
        self.seen += 1;
        if self.seen < self.at {
            return Ok(());
        }
        self.saved = Some((progress.clone(), engine.save().unwrap()));
        anyhow::bail!("interrupted at checkpoint {} (stage {}, inside it: {})", self.seen, progress.next_stage, progress.in_stage.is_some())
    }
}

/// Two glass grains (d = 1 mm) moving at 2 m/s from x = +-2 mm onto a third at rest at the
/// origin, listed out of their order in space (ids: right, left, middle), wetted (w = 0.01) with
/// capillary cohesion, no gravity, dt = 2e-7 s, one run stage of `duration` (s): both hit the
/// middle grain in the same step, and both bridges form then from its liquid.
pub fn three_wet_grains(duration: f64) -> String {
    let grain = |x: f64, v: f64| format!("[[grain]]\nmaterial = \"glass\"\nradius = 5.0e-4\nposition = [{x:e}, 0.0, 0.0]\nvelocity = [{v:e}, 0.0, 0.0]\n");
    format!(
        r#"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e8
poisson_ratio = 0.3
restitution = 0.5
{}{}{}
[model]
damping = "restitution"
cohesion = "capillary"
[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 2.0e-7
stats_interval = 50
[[stage]]
kind = "run"
duration = {duration:e}
water_content = 0.01
"#,
        grain(2.0e-3, -2.0),
        grain(-2.0e-3, 2.0),
        grain(0.0, 0.0)
    )
}

/// The files below `dir` whose names end in `.ext`, every level down, in sorted order.
pub fn files_below(dir: &std::path::Path, ext: &str) -> Vec<std::path::PathBuf> {
    let mut out: Vec<std::path::PathBuf> = walkdir::WalkDir::new(dir)
        .into_iter()
        .map(|e| e.unwrap_or_else(|e| panic!("{}: {e}", dir.display())).into_path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == ext))
        .collect();
    out.sort();
    out
}
