//! Running a scene end to end with its outputs: what `grains run` and every sweep point do.

use crate::analysis::fit::{BauerFit, Estimate};
use crate::cd::ContactDynamics;
use crate::checkpoint::{CheckpointHeader, EngineState, RunIdentity};
use crate::cpu::CpuEngine;
use crate::engine::Engine;
use crate::output::{RunRecorder, Summary};
use crate::protocol::Progress;
use crate::scene::{self, Method, Scene};
use anyhow::Context;
use std::path::Path;
use std::time::Instant;

/// What a checkpoint of this run belongs to.
pub fn identity(scene_file: &Path, engine: &dyn Engine) -> anyhow::Result<RunIdentity> {
    let text = std::fs::read(scene_file).with_context(|| format!("cannot read {}", scene_file.display()))?;
    Ok(RunIdentity {
        scene_file: scene_file.display().to_string(),
        scene_hash: crate::checkpoint::fnv1a(&text),
        backend: engine.backend().to_string(),
        precision: engine.precision().to_string(),
    })
}

/// A CPU engine of precision "f32" or "f64".
pub fn cpu_engine(scene: &Scene, precision: &str) -> anyhow::Result<Box<dyn Engine>> {
    if let Method::ContactDynamics(params) = scene.method {
        return Ok(match precision {
            "f32" => Box::new(ContactDynamics::<f32>::new(scene, params)?),
            "f64" => Box::new(ContactDynamics::<f64>::new(scene, params)?),
            other => anyhow::bail!("precision `{other}`: contact dynamics computes in f32 or f64; fix: give --precision f32 or f64"),
        });
    }
    #[cfg(feature = "mpi")]
    if processes() > 1 {
        return Ok(match precision {
            "f32" => Box::new(crate::cpu::ranks::Distributed::<f32>::new(scene)?),
            "f64" => Box::new(crate::cpu::ranks::Distributed::<f64>::new(scene)?),
            other => anyhow::bail!("precision `{other}`: the CPU engine computes in f32 or f64; fix: give --precision f32 or f64"),
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
pub fn gpu_engine(gpu: crate::gpu::Gpu, scene: &Scene) -> anyhow::Result<Box<dyn Engine>> {
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
        "gpu" => gpu_engine(crate::gpu::open(adapter)?, scene),
        other => anyhow::bail!("the checkpoint was written by a `{other}` backend, which this grains lacks; fix: resume with the grains that wrote it"),
    }
}

/// Runs the stages from `start` on, recording into `out` (with checkpoints at every stage
/// end), and writes `summary.json` last: a directory with a summary holds a finished run.
/// In a run over several processes every process runs this alike, and rank 0 alone writes.
pub fn execute(scene: &Scene, engine: &mut dyn Engine, out: Option<&Path>, start: Progress, identity: RunIdentity, resumed_from: Option<&CheckpointHeader>, progress_bar: bool) -> anyhow::Result<Summary> {
    let writes = is_root();
    let (out, progress_bar) = (out.filter(|_| writes), progress_bar && writes);
    let rec = match (out, resumed_from) {
        (Some(dir), Some(header)) => RunRecorder::resume(dir, header, progress_bar)?,
        _ => RunRecorder::new(out, progress_bar)?,
    };
    let mut rec = match out {
        Some(dir) => rec.with_checkpoints(dir, identity).with_vtk(dir, scene, resumed_from.map(|_| engine.time()))?,
        None => rec,
    };
    let started = Instant::now();
    let result = crate::protocol::run_from(scene, engine, &mut rec, start);
    let wall_seconds = started.elapsed().as_secs_f64();
    // Whatever happened, keep what was recorded.
    rec.finish()?;
    let stages = result?;
    let threads = if engine.backend() == "cpu" { rayon::current_num_threads() } else { 1 };
    let summary = Summary::new(scene, engine, threads, wall_seconds, stages)?;
    if let Some(dir) = out {
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
    }
    Ok(summary)
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
    let (header, state): (CheckpointHeader, EngineState) = crate::checkpoint::read(&dir.join(crate::checkpoint::FILE))?;
    let id = &header.identity;
    let path = scene_file.map(Path::to_path_buf).unwrap_or_else(|| id.scene_file.clone().into());
    let mut scene = scene::load(&path)?;
    // A run that wrote VTK files (`grains run --vtk`) goes on writing them.
    scene.output.vtk |= dir.join(crate::output::vtk::DIR).join("grains.pvd").exists();
    let text = std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
    if crate::checkpoint::fnv1a(&text) != id.scene_hash {
        anyhow::bail!("{}: the scene differs from the one the checkpoint in {} was written for; fix: restore the scene or start the run afresh", path.display(), dir.display());
    }
    if precision.is_some_and(|p| p != id.precision) {
        anyhow::bail!("the checkpoint was written in {}; fix: drop --precision or give --precision {}", id.precision, id.precision);
    }
    let mut engine = engine_of(&scene, id, adapter)?;
    engine.restore(&state).with_context(|| format!("cannot resume from {}", dir.display()))?;
    let identity = identity(&path, engine.as_ref())?;
    execute(&scene, engine.as_mut(), Some(dir), header.progress.clone(), identity, Some(&header), progress_bar)
}
