//! The subcommands' bodies.

use crate::cli::{Backend, Cli, Command, FitLaw, Precision};
use anyhow::Context;
use grains::checkpoint::{CheckpointHeader, EngineState, RunIdentity};
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::gpu::GpuEngine;
use grains::output::{RunRecorder, Summary};
use grains::protocol::Progress;
use grains::scene::{self, Scene};
use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

/// Runs one command.
pub fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run { scene, resume, backend, adapter, precision, out, json, threads } => {
            // The whole run happens on a worker of the pool, so that the CPU kernels' parallel
            // loops split work among workers instead of waking them from outside every time.
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build().context("cannot start the worker threads")?;
            match resume {
                Some(dir) => pool.install(|| resume_run(&dir, scene.as_deref(), precision, json)),
                None => {
                    let path = scene.expect("clap requires a scene without --resume");
                    let scene = scene::load(&path)?;
                    if !json {
                        for w in &scene.warnings {
                            eprintln!("warning: {w}");
                        }
                    }
                    pool.install(|| {
                        let mut engine = engine_for(&scene, backend, adapter.as_deref(), precision, json)?;
                        let progress = grains::protocol::Progress::start(&scene, engine.as_mut());
                        let identity = identity(&path, engine.as_ref())?;
                        run(&scene, engine.as_mut(), out.as_deref(), json, progress, identity, false)
                    })
                }
            }
        }
        Command::Check { scene } => {
            let scene = scene::load(&scene)?;
            print!("{}", grains::output::check_report(&scene));
            Ok(())
        }
        Command::Fit { law: FitLaw::Bauer { file, p_column, e_column, mean_stress, e0, json } } => {
            let points = read_columns(&file, &p_column, &e_column)?;
            let fit = grains::analysis::fit::fit_bauer(&points, e0, if mean_stress { 3.0 } else { 1.0 }).with_context(|| format!("{}: cannot fit Bauer's law", file.display()))?;
            if json {
                println!("{}", serde_json::to_string(&fit)?);
            } else {
                println!("{} ({} points, rms residual {:.2e}{})", fit.line(), fit.points, fit.rms, if mean_stress { ", mean-stress form 3p/h_s" } else { "" });
            }
            Ok(())
        }
        Command::Devices => {
            let list = grains::gpu::describe_all();
            if list.is_empty() {
                return Err(grains::gpu::GpuError::NoAdapter.into());
            }
            for line in list {
                println!("{line}");
            }
            Ok(())
        }
        Command::Compare { scene, steps, checkpoints, adapter, json } => {
            let scene = scene::load(&scene)?;
            let gpu = grains::gpu::open(adapter.as_deref())?;
            let name = gpu.info.name.clone();
            let mut g = GpuEngine::new(gpu, &scene)?;
            let mut c32 = CpuEngine::<f32>::new(&scene)?;
            let mut c64 = CpuEngine::<f64>::new(&scene)?;
            let report = grains::compare::compare(&scene, &name, &mut g, &mut c32, &mut c64, steps, checkpoints)?;
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                print!("{}", report.human());
            }
            if report.passed() { Ok(()) } else { anyhow::bail!("the backends disagree beyond the named tolerances (see the table); fix: report the scene and the table as a bug") }
        }
    }
}

/// The engine `--backend` and `--precision` ask for.
fn engine_for(scene: &Scene, backend: Backend, adapter: Option<&str>, precision: Option<Precision>, quiet: bool) -> anyhow::Result<Box<dyn Engine>> {
    let gpu = |gpu| -> anyhow::Result<Box<dyn Engine>> { Ok(Box::new(GpuEngine::new(gpu, scene)?)) };
    let cpu = |precision: Option<Precision>| -> anyhow::Result<Box<dyn Engine>> {
        Ok(match precision.unwrap_or(Precision::F64) {
            Precision::F32 => Box::new(CpuEngine::<f32>::new(scene)?),
            Precision::F64 => Box::new(CpuEngine::<f64>::new(scene)?),
        })
    };
    match backend {
        Backend::Cpu => cpu(precision),
        Backend::Gpu => {
            if precision == Some(Precision::F64) {
                anyhow::bail!("--precision f64: the GPU backend computes in f32; fix: drop --precision or use --backend cpu");
            }
            gpu(grains::gpu::open(adapter)?)
        }
        Backend::Auto => {
            if precision == Some(Precision::F64) {
                return cpu(precision);
            }
            match grains::gpu::open(adapter) {
                Ok(g) => gpu(g),
                Err(e) => {
                    if !quiet {
                        eprintln!("notice: {e}; running on the CPU");
                    }
                    cpu(precision)
                }
            }
        }
    }
}

/// What a checkpoint of this run belongs to.
fn identity(scene_file: &Path, engine: &dyn Engine) -> anyhow::Result<RunIdentity> {
    let text = std::fs::read(scene_file).with_context(|| format!("cannot read {}", scene_file.display()))?;
    Ok(RunIdentity {
        scene_file: scene_file.display().to_string(),
        scene_hash: grains::checkpoint::fnv1a(&text),
        backend: engine.backend().to_string(),
        precision: engine.precision().to_string(),
    })
}

/// `grains run --resume DIR`: the run of DIR's checkpoint, continued into DIR.
fn resume_run(dir: &Path, scene_file: Option<&Path>, precision: Option<Precision>, json: bool) -> anyhow::Result<()> {
    let (header, state): (CheckpointHeader, EngineState) = grains::checkpoint::read(&dir.join(grains::checkpoint::FILE))?;
    let id = &header.identity;
    let path = scene_file.map(Path::to_path_buf).unwrap_or_else(|| id.scene_file.clone().into());
    let scene = scene::load(&path)?;
    let text = std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
    if grains::checkpoint::fnv1a(&text) != id.scene_hash {
        anyhow::bail!("{}: the scene differs from the one the checkpoint in {} was written for; fix: restore the scene or start the run afresh", path.display(), dir.display());
    }
    let wanted = match id.precision.as_str() {
        "f32" => Precision::F32,
        _ => Precision::F64,
    };
    if precision.is_some_and(|p| p != wanted) {
        anyhow::bail!("the checkpoint was written in {}; fix: drop --precision or give --precision {}", id.precision, id.precision);
    }
    let mut engine = engine_for(&scene, Backend::Cpu, None, Some(wanted), json)?;
    engine.restore(&state).with_context(|| format!("cannot resume from {}", dir.display()))?;
    let identity = identity(&path, engine.as_ref())?;
    run(&scene, engine.as_mut(), Some(dir), json, header.progress, identity, true)
}

fn run(scene: &Scene, engine: &mut dyn Engine, out: Option<&Path>, json: bool, start: Progress, identity: RunIdentity, resumed: bool) -> anyhow::Result<()> {
    let progress = !json && std::io::stderr().is_terminal();
    let rec = match (out, resumed) {
        (Some(dir), true) => RunRecorder::resume(dir, start.next_stage, progress)?,
        _ => RunRecorder::new(out, progress)?,
    };
    let mut rec = match out {
        Some(dir) => rec.with_checkpoints(dir, identity),
        None => rec,
    };
    let started = Instant::now();
    let result = grains::protocol::run_from(scene, engine, &mut rec, start);
    let wall_seconds = started.elapsed().as_secs_f64();
    // Whatever happened, keep what was recorded.
    rec.finish()?;
    let stages = result?;
    let threads = if engine.backend() == "cpu" { rayon::current_num_threads() } else { 1 };
    let summary = Summary::new(scene, engine, threads, wall_seconds, stages);
    if let Some(dir) = out {
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary)?).with_context(|| format!("cannot write {}", path.display()))?;
        if !summary.compression.is_empty() {
            let path = dir.join("compression.csv");
            std::fs::write(&path, summary.compression_csv()).with_context(|| format!("cannot write {}", path.display()))?;
            if let Err(e) = grains::output::plot::compression(&dir.join("compression"), &scene.name, &summary.compression, summary.bauer.as_ref()) {
                eprintln!("warning: {e:#}");
            }
        }
    }
    if json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        print!("{}", summary.human());
    }
    Ok(())
}

/// Two numeric columns of a CSV file with a header, by name.
fn read_columns(file: &Path, x: &str, y: &str) -> anyhow::Result<Vec<(f64, f64)>> {
    let text = std::fs::read_to_string(file).with_context(|| format!("cannot read {}", file.display()))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().with_context(|| format!("{}: empty file; fix: give a CSV with a header line", file.display()))?.split(',').map(str::trim).collect();
    let col = |name: &str| {
        header.iter().position(|h| *h == name).with_context(|| format!("{}: no column `{name}` (columns: {}); fix: name it with --p-column / --e-column", file.display(), header.join(", ")))
    };
    let (xi, yi) = (col(x)?, col(y)?);
    lines
        .enumerate()
        .map(|(k, line)| {
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            let get = |i: usize| -> anyhow::Result<f64> {
                cells.get(i).and_then(|c| c.parse().ok()).with_context(|| format!("{} line {}: `{}` is not a number; fix: correct the value", file.display(), k + 2, cells.get(i).unwrap_or(&"")))
            };
            Ok((get(xi)?, get(yi)?))
        })
        .collect()
}
