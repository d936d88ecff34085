//! Running a scene end to end with its outputs: what `grains run` and every sweep point do.

use crate::analysis::fit::{BauerFit, Estimate};
use crate::cd::ContactDynamics;
use crate::checkpoint::{CheckpointHeader, EngineState, RunIdentity};
use crate::cpu::CpuEngine;
use crate::engine::Engine;
use crate::output::{RunRecorder, Summary};
use crate::protocol::{Progress, Recorder, StageResult};
use crate::scene::{self, Method, Scene};
use anyhow::Context;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a checkpoint of this run belongs to.
pub fn identity(scene_file: &Path, engine: &dyn Engine) -> anyhow::Result<RunIdentity> {
    let text = std::fs::read(scene_file).with_context(|| format!("cannot read {}", scene_file.display()))?;
    Ok(identity_of(scene_file, &text, engine))
}

/// [`identity`] of a run whose scene file holds `text`.
pub fn identity_of(scene_file: &Path, text: &[u8], engine: &dyn Engine) -> RunIdentity {
    RunIdentity {
        scene_file: scene_file.display().to_string(),
        scene_hash: crate::checkpoint::fnv1a(text),
        backend: engine.backend().to_string(),
        precision: engine.precision().to_string(),
    }
}

/// A CPU engine of precision "f32" or "f64": under mpirun (feature `mpi`) a DEM engine over
/// every process, else [`local_cpu_engine`].
pub fn cpu_engine(scene: &Scene, precision: &str) -> anyhow::Result<Box<dyn Engine>> {
    #[cfg(feature = "mpi")]
    if processes() > 1 && !matches!(scene.method, Method::ContactDynamics(_)) {
        return Ok(match precision {
            "f32" => Box::new(crate::cpu::ranks::Distributed::<f32>::new(scene)?),
            "f64" => Box::new(crate::cpu::ranks::Distributed::<f64>::new(scene)?),
            other => anyhow::bail!("precision `{other}`: the CPU engine computes in f32 or f64; fix: give --precision f32 or f64"),
        });
    }
    Ok(local_cpu_engine(scene, precision)?)
}

/// A CPU engine of precision "f32" or "f64" on this process alone: `Send`, so that a caller
/// can step it on another thread (the Python module does, with the interpreter's lock
/// released; an engine over several processes holds MPI handles, which are not).
pub fn local_cpu_engine(scene: &Scene, precision: &str) -> anyhow::Result<Box<dyn Engine + Send>> {
    if let Method::ContactDynamics(params) = scene.method {
        return Ok(match precision {
            "f32" => Box::new(ContactDynamics::<f32>::new(scene, params)?),
            "f64" => Box::new(ContactDynamics::<f64>::new(scene, params)?),
            other => anyhow::bail!("precision `{other}`: contact dynamics computes in f32 or f64; fix: give --precision f32 or f64"),
        });
    }
    Ok(match precision {
        "f32" => Box::new(CpuEngine::<f32>::new(scene)?),
        "f64" => Box::new(CpuEngine::<f64>::new(scene)?),
        other => anyhow::bail!("precision `{other}`: the CPU engine computes in f32 or f64; fix: give --precision f32 or f64"),
    })
}

/// A GPU engine on an opened device (f32): the DEM kernels, or for a contact-dynamics scene
/// the host's contact detection with the sweeps on the device.
pub fn gpu_engine(gpu: crate::gpu::Gpu, scene: &Scene) -> anyhow::Result<Box<dyn Engine + Send>> {
    if let Method::ContactDynamics(params) = scene.method {
        let sweeps = crate::gpu::GpuSweeps::new(gpu, scene.grains.len(), scene.walls.len());
        return Ok(Box::new(ContactDynamics::<f32>::new(scene, params)?.with_sweeps(Box::new(sweeps))));
    }
    Ok(Box::new(crate::gpu::GpuEngine::new(gpu, scene)?))
}

/// The engine a checkpoint was written by: its backend ("cpu" or "gpu", on the adapter whose
/// name contains `adapter`, or the best one) and precision.
fn engine_of(scene: &Scene, id: &RunIdentity, adapter: Option<&str>) -> anyhow::Result<Box<dyn Engine>> {
    match id.backend.as_str() {
        "cpu" => cpu_engine(scene, &id.precision),
        _ => Ok(local_engine_of(scene, id, adapter)?),
    }
}

/// [`engine_of`] on this process alone (`Send`: see [`local_cpu_engine`]).
pub fn local_engine_of(scene: &Scene, id: &RunIdentity, adapter: Option<&str>) -> anyhow::Result<Box<dyn Engine + Send>> {
    match id.backend.as_str() {
        "cpu" => local_cpu_engine(scene, &id.precision),
        "gpu" => gpu_engine(crate::gpu::open(adapter)?, scene),
        other => anyhow::bail!("the checkpoint was written by a `{other}` backend, which this grains lacks; fix: resume with the grains that wrote it"),
    }
}

/// Runs the stages from `start` on, recording into `out` (with checkpoints at every stage
/// end), and writes `summary.json` last: a directory with a summary holds a finished run.
/// In a run over several processes every process runs this alike, and rank 0 alone writes.
pub fn execute(scene: &Scene, engine: &mut dyn Engine, out: Option<&Path>, start: Progress, identity: RunIdentity, resumed_from: Option<&CheckpointHeader>, progress_bar: bool) -> anyhow::Result<Summary> {
    let mut run = Run::start(scene, engine, out, start, identity, resumed_from, progress_bar)?;
    let mut stages = || -> anyhow::Result<()> {
        while run.next_stage(scene, engine)?.is_some() {}
        Ok(())
    };
    match stages() {
        Ok(()) => run.finish(scene, engine),
        Err(e) => {
            // Whatever happened, keep what was recorded.
            run.close()?;
            Err(e)
        }
    }
}

/// A run with its outputs, driven a stage at a time ([`execute`] runs every stage; the Python
/// module lets its caller step between them).
pub struct Run {
    rec: RunRecorder,
    /// The output directory, on the process that writes.
    out: Option<PathBuf>,
    progress: Progress,
    progress_bar: bool,
    /// Wall-clock seconds spent in the stages so far.
    wall_seconds: f64,
}

impl Run {
    /// Opens the outputs of a run from `start` (into `out` when given, continuing those of a
    /// run resumed from `resumed_from`), with a checkpoint into `out` at every stage end.
    pub fn start(scene: &Scene, engine: &dyn Engine, out: Option<&Path>, start: Progress, identity: RunIdentity, resumed_from: Option<&CheckpointHeader>, progress_bar: bool) -> anyhow::Result<Run> {
        let writes = is_root();
        let (out, progress_bar) = (out.filter(|_| writes), progress_bar && writes);
        let rec = match (out, resumed_from) {
            (Some(dir), Some(header)) => RunRecorder::resume(dir, header, progress_bar)?,
            _ => RunRecorder::new(out, progress_bar)?,
        };
        let rec = match out {
            Some(dir) => rec.with_checkpoints(dir, identity).with_vtk(dir, scene, resumed_from.map(|_| engine.time()))?,
            None => rec,
        };
        Ok(Run { rec, out: out.map(Path::to_path_buf), progress: start, progress_bar, wall_seconds: 0.0 })
    }

    /// Where the run stands.
    pub fn progress(&self) -> &Progress {
        &self.progress
    }

    /// Runs the next stage; its result, or `None` when every stage has run.
    pub fn next_stage(&mut self, scene: &Scene, engine: &mut dyn Engine) -> anyhow::Result<Option<&StageResult>> {
        self.next_stage_watched(scene, engine, &mut Unwatched)
    }

    /// [`Self::next_stage`], telling `watch` of each statistics read ([`Watch`]).
    pub fn next_stage_watched(&mut self, scene: &Scene, engine: &mut dyn Engine, watch: &mut dyn Watch) -> anyhow::Result<Option<&StageResult>> {
        let started = Instant::now();
        let mut rec = Watched { rec: &mut self.rec, watch };
        let result = crate::protocol::run_next_stage(scene, engine, &mut rec, &mut self.progress);
        self.wall_seconds += started.elapsed().as_secs_f64();
        result
    }

    /// Writes a checkpoint of where the run stands now (between stages or inside one, at a
    /// statistics read) into the output directory; nothing without one.
    pub fn checkpoint(&mut self, engine: &dyn Engine) -> anyhow::Result<()> {
        self.rec.checkpoint(&self.progress, engine)
    }

    /// Flushes and closes the output files, keeping what was recorded (a run stopped early).
    pub fn close(self) -> anyhow::Result<()> {
        self.rec.finish()
    }

    /// Closes the outputs and writes what a finished run leaves: `compression.csv` and its
    /// plots, the force-transmission analysis when the scene asks for it, and `summary.json`.
    pub fn finish(self, scene: &Scene, engine: &mut dyn Engine) -> anyhow::Result<Summary> {
        let Run { rec, out, progress, progress_bar, wall_seconds } = self;
        rec.finish()?;
        let threads = if engine.backend() == "cpu" { rayon::current_num_threads() } else { 1 };
        let summary = Summary::new(scene, engine, threads, wall_seconds, progress.results, &progress.flow)?;
        let Some(dir) = out.as_deref() else { return Ok(summary) };
        if !summary.compression.is_empty() {
            let path = dir.join("compression.csv");
            std::fs::write(&path, summary.compression_csv()).with_context(|| format!("cannot write {}", path.display()))?;
            let fits: Vec<(&str, &BauerFit)> = [("e0 held", summary.bauer.as_ref()), ("e0 fitted", summary.bauer_free.as_ref())].into_iter().filter_map(|(n, f)| f.map(|f| (n, f))).collect();
            if let Err(e) = crate::output::plot::compression(&dir.join("compression"), &scene.name, &summary.compression, &fits) {
                eprintln!("warning: {e:#}");
            }
            if let Some(profile) = summary.bauer_profile.as_ref().filter(|p| !p.points.is_empty()) {
                let points: Vec<_> = profile.points.iter().map(|p| (Estimate { value: p.eta, error: 0.0 }, Estimate { value: p.h_s / 1e6, error: 0.0 })).collect();
                let title = format!("{}: Bauer fit with e0 held from {:.4} to {:.4}", scene.name, profile.points[0].e0, profile.points[profile.points.len() - 1].e0);
                if let Err(e) = crate::output::plot::hardness(&dir.join("bauer_profile"), &title, &points, profile.power_law.as_ref(), true) {
                    eprintln!("warning: {e:#}");
                }
            }
        }
        if scene.output.analysis {
            // Rank 0 alone reads this last state; the statistics and frame of a run over
            // several processes are gathered at every advance, so the others need not join.
            let stats = engine.stats()?;
            let a = crate::output::network::write(scene, &engine.frame(true)?, &stats, dir)?;
            if progress_bar {
                eprint!("{}", crate::output::network::human(&a));
            }
        }
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary)?).with_context(|| format!("cannot write {}", path.display()))?;
        Ok(summary)
    }
}

/// What a caller driving a [`Run`] hears at every statistics read of a stage
/// ([`Run::next_stage_watched`]).
pub trait Watch {
    /// Whether to go on: an error ends the stage there (a user's interrupt), with what was
    /// recorded kept.
    fn go_on(&mut self) -> anyhow::Result<()>;
    /// `done` steps of stage `stage` taken, of at most `total`.
    fn progress(&mut self, stage: &str, done: u64, total: u64);
}

/// Nobody watching.
struct Unwatched;

impl Watch for Unwatched {
    fn go_on(&mut self) -> anyhow::Result<()> {
        Ok(())
    }
    fn progress(&mut self, _: &str, _: u64, _: u64) {}
}

/// A run's recorder, with a [`Watch`] told of each statistics read.
struct Watched<'a> {
    rec: &'a mut RunRecorder,
    watch: &'a mut dyn Watch,
}

impl Recorder for Watched<'_> {
    fn stats(&mut self, stage: &str, s: &crate::engine::Stats) -> anyhow::Result<()> {
        self.rec.stats(stage, s)?;
        self.watch.go_on()
    }
    fn frame(&mut self, f: &crate::engine::Frame) -> anyhow::Result<()> {
        self.rec.frame(f)
    }
    fn stage_end(&mut self, r: &StageResult) -> anyhow::Result<()> {
        self.rec.stage_end(r)
    }
    fn checkpoint(&mut self, progress: &Progress, engine: &dyn Engine) -> anyhow::Result<()> {
        self.rec.checkpoint(progress, engine)
    }
    fn progress(&mut self, stage: &str, done: u64, total: u64) {
        self.rec.progress(stage, done, total);
        self.watch.progress(stage, done, total);
    }
}

/// True on the process that writes outputs and prints: always, unless this is a run over
/// several processes (feature `mpi`), where rank 0 alone does.
pub fn is_root() -> bool {
    #[cfg(feature = "mpi")]
    return crate::cpu::ranks::is_root();
    #[cfg(not(feature = "mpi"))]
    true
}

/// Processes this run is spread over: 1, unless started by mpirun (feature `mpi`).
pub fn processes() -> usize {
    #[cfg(feature = "mpi")]
    return crate::cpu::ranks::size();
    #[cfg(not(feature = "mpi"))]
    1
}

/// A fresh run of the scene file on a CPU engine, into `out`.
pub fn run_cpu(scene_file: &Path, precision: &str, out: Option<&Path>, progress_bar: bool) -> anyhow::Result<Summary> {
    let scene = scene::load(scene_file)?;
    let mut engine = cpu_engine(&scene, precision)?;
    let start = Progress::start(&scene, engine.as_mut())?;
    let id = identity(scene_file, engine.as_ref())?;
    execute(&scene, engine.as_mut(), out, start, id, None, progress_bar)
}

/// Continues the run of `dir` from its checkpoint, into `dir`, on the backend and precision
/// that wrote it (a GPU checkpoint on the adapter `adapter` names, or the best one). The scene
/// is the one the checkpoint names unless `scene_file` is given; it must be unchanged.
pub fn resume(dir: &Path, scene_file: Option<&Path>, precision: Option<&str>, adapter: Option<&str>, progress_bar: bool) -> anyhow::Result<Summary> {
    let mut r = open_checkpoint(dir, scene_file, precision, |scene, id| engine_of(scene, id, adapter))?;
    execute(&r.scene, r.engine.as_mut(), Some(dir), r.header.progress.clone(), r.identity, Some(&r.header), progress_bar)
}

/// A run's checkpoint opened to continue it ([`open_checkpoint`]), with its engine `E`.
pub struct Resumed<E> {
    /// The scene, as the run recorded it (VTK files kept on where the run wrote them).
    pub scene: Scene,
    /// The scene's file.
    pub scene_file: PathBuf,
    /// The scene file's text.
    pub scene_text: String,
    /// The engine `make` gave, restored to the checkpoint's state.
    pub engine: E,
    /// The checkpoint's header: where the run stands and the files it continues.
    pub header: CheckpointHeader,
    /// What the continued run's checkpoints belong to.
    pub identity: RunIdentity,
}

/// Opens the checkpoint in `dir` (see [`resume`]): checks that the scene is unchanged and the
/// precision the one that wrote it, and restores the engine `make` builds for the scene and
/// the checkpoint's identity ([`engine_of`], [`local_engine_of`]).
pub fn open_checkpoint<E>(dir: &Path, scene_file: Option<&Path>, precision: Option<&str>, make: impl FnOnce(&Scene, &RunIdentity) -> anyhow::Result<E>) -> anyhow::Result<Resumed<E>>
where
    E: std::ops::DerefMut,
    E::Target: Engine,
{
    let (header, state): (CheckpointHeader, EngineState) = crate::checkpoint::read(&dir.join(crate::checkpoint::FILE))?;
    let id = &header.identity;
    let path = scene_file.map(Path::to_path_buf).unwrap_or_else(|| id.scene_file.clone().into());
    let mut scene = scene::load(&path)?;
    // A run that wrote VTK files (`grains run --vtk`) goes on writing them.
    scene.output.vtk |= dir.join(crate::output::vtk::DIR).join("grains.pvd").exists();
    let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
    if crate::checkpoint::fnv1a(text.as_bytes()) != id.scene_hash {
        anyhow::bail!("{}: the scene differs from the one the checkpoint in {} was written for; fix: restore the scene or start the run afresh", path.display(), dir.display());
    }
    if precision.is_some_and(|p| p != id.precision) {
        anyhow::bail!("the checkpoint was written in {}; fix: drop --precision or give --precision {}", id.precision, id.precision);
    }
    let mut engine = make(&scene, id)?;
    engine.restore(&state).with_context(|| format!("cannot resume from {}", dir.display()))?;
    // The engine is the identity's backend and precision; the scene file is the one read.
    let identity = RunIdentity { scene_file: path.display().to_string(), ..id.clone() };
    Ok(Resumed { scene, scene_file: path, scene_text: text, engine, header, identity })
}

/// A finished run directory's summary (`summary.json`), scene (the file the summary names) and
/// last recorded frame (`frames.mcap`).
pub fn read_finished_run(run: &Path) -> anyhow::Result<(serde_json::Value, Scene, crate::engine::Frame)> {
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(run.join("summary.json")).with_context(|| format!("{}: no summary.json; fix: give the --out directory of a finished run", run.display()))?)?;
    let scene_file = summary["file"].as_str().with_context(|| format!("{}: summary.json names no scene file", run.display()))?;
    let scene = scene::load(Path::new(scene_file))?;
    let frame = crate::output::mcap::last_frame(&run.join("frames.mcap"))?;
    Ok((summary, scene, frame))
}

/// [`read_finished_run`], whose last frame must hold the contact forces (the force-transmission
/// analysis reads them).
pub fn read_finished_run_with_contacts(run: &Path) -> anyhow::Result<(serde_json::Value, Scene, crate::engine::Frame)> {
    let (summary, scene, frame) = read_finished_run(run)?;
    if frame.contacts.is_none() {
        anyhow::bail!("{}: the frames hold no contact forces; fix: set output.contact_forces = true in the scene and run it again", run.display());
    }
    Ok((summary, scene, frame))
}

/// The statistics at the end of a finished run's last stage, from its summary.
pub fn last_stage_stats(summary: &serde_json::Value) -> anyhow::Result<crate::engine::Stats> {
    let last = summary["stages"].as_array().and_then(|s| s.last()).context("summary.json has no stages")?;
    Ok(serde_json::from_value(last["stats"].clone())?)
}
