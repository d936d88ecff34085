//! The subcommands' bodies.

use crate::cli::{Backend, BenchBackend, BenchPart, Cli, Command, E0Choice, ExportFormat, FitLaw, Precision, Reorder};
use anyhow::Context;
use grains::engine::Engine;
use grains::output::Summary;
use grains::protocol::Progress;
use grains::scene::{self, Scene};
use std::io::IsTerminal;
use std::path::Path;

/// Runs one command.
pub fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run { scene, resume, backend, adapter, precision, out, json, vtk, threads, force } => {
            // Under mpirun, one run over every process (see grains::cpu::ranks); alone, one process.
            #[cfg(feature = "mpi")]
            let _mpi = grains::cpu::ranks::init();
            // The whole run happens on a worker of the pool, so that the CPU kernels' parallel
            // loops split work among workers instead of waking them from outside every time.
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build().context("cannot start the worker threads")?;
            match resume {
                Some(dir) => {
                    let precision = precision.map(|p| if p == Precision::F32 { "f32" } else { "f64" });
                    let summary = pool.install(|| grains::runner::resume(&dir, scene.as_deref(), precision, adapter.as_deref(), progress_bar(json)))?;
                    report_from_root(&summary, json)
                }
                None => {
                    let path = scene.expect("clap requires a scene without --resume");
                    let mut scene = scene::load(&path)?;
                    scene.output.vtk |= vtk;
                    if !force {
                        scene.check_practical()?;
                    }
                    if !json && grains::runner::is_root() {
                        for w in &scene.warnings {
                            eprintln!("warning: {w}");
                        }
                    }
                    let summary = pool.install(|| {
                        let mut engine = engine_for(&scene, backend, adapter.as_deref(), precision, json)?;
                        let start = Progress::start(&scene, engine.as_mut())?;
                        let identity = grains::runner::identity(&path, engine.as_ref())?;
                        grains::runner::execute(&scene, engine.as_mut(), out.as_deref(), start, identity, None, progress_bar(json))
                    })?;
                    report_from_root(&summary, json)
                }
            }
        }
        Command::Export { run, format, out } => {
            let (_, scene, frame) = grains::runner::read_finished_run(&run)?;
            let atoms = grains::output::lammps::atoms(&scene, &frame);
            let (text, default) = match format {
                ExportFormat::LammpsData => (grains::lammps::data::write(&atoms, &format!("{} at t = {:e} s", scene.name, frame.time)), "grains.data"),
                ExportFormat::LammpsDump => (grains::lammps::dump::write(&atoms), "grains.dump"),
            };
            let path = out.unwrap_or_else(|| run.join(default));
            std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
            println!("wrote {}: {} atoms of {} types at t = {:e} s (time step {})", path.display(), atoms.len(), scene.materials.len(), frame.time, atoms.timestep);
            Ok(())
        }
        Command::Check { scene } => {
            let scene = scene::load(&scene)?;
            print!("{}", grains::output::check_report(&scene));
            scene.check_practical()
        }
        Command::Fit { law: FitLaw::Bauer { file, p_column, e_column, mean_stress, trace_column, e0, profile, json } } => {
            use grains::analysis::fit::{e0_profile, fit_bauer, profile_e0s};
            // The mean-stress form takes 3p as the measured trace of the stress.
            let points = read_columns(&file, if mean_stress { &trace_column } else { &p_column }, &e_column)?;
            let held = match e0 {
                E0Choice::Free => None,
                E0Choice::Fixed(v) => Some(v),
            };
            let fit = fit_bauer(&points, held, 1.0).with_context(|| format!("{}: cannot fit Bauer's law", file.display()))?;
            let profile = profile.then(|| e0_profile(&points, &profile_e0s(&points, fit.e0.value, grains::output::PROFILE_POINTS), 1.0));
            if json {
                println!("{}", serde_json::json!({ "fit": fit, "profile": profile }));
            } else {
                let c = &fit.correlations;
                let r = |x: Option<f64>| x.map_or(String::new(), |x| format!(", ln h_s-e0 {x:.3}"));
                let form = if mean_stress { format!(", mean-stress form: 3p = {trace_column}") } else { String::new() };
                println!("{} ({} points, rms residual {:.2e}{form}; correlation ln h_s-eta {:.3}{})", fit.line(), fit.points, fit.rms, c.ln_h_s_eta, r(c.ln_h_s_e0));
                if let Some(p) = profile {
                    println!("e0 held at    h_s (MPa)     eta      rms");
                    for q in &p.points {
                        println!("{:>9.4}  {:>11.4e}  {:.4}  {:.2e}", q.e0, q.h_s / 1e6, q.eta, q.rms);
                    }
                    if let Some(l) = p.power_law {
                        println!("along the profile: {} (Oquendo et al.'s sweep: {})", l.line(), grains::analysis::oquendo::POWER_LAW.line());
                    }
                }
            }
            Ok(())
        }
        Command::Sweep { sweep, out, only, emit_slurm, gather, jobs, threads, precision, json } => {
            let sw = grains::sweep::load(&sweep)?;
            let out = out.unwrap_or_else(|| {
                let stem = sweep.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "sweep".into());
                sweep.parent().unwrap_or(Path::new(".")).join(format!("{stem}-runs"))
            });
            std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
            if emit_slurm {
                let exe = std::env::current_exe().context("cannot find the grains executable")?;
                let path = out.join("sweep.sbatch");
                std::fs::write(&path, sw.slurm_script(&out, &exe)).with_context(|| format!("cannot write {}", path.display()))?;
                println!("{} ({} tasks); submit with `sbatch {}`, then gather with `grains sweep {} --out {}`", path.display(), sw.points.len(), path.display(), sweep.display(), out.display());
                return Ok(());
            }
            let precision = if precision == Precision::F32 { "f32" } else { "f64" };
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            let points: Vec<usize> = match only {
                Some(k) if k >= sw.points.len() => anyhow::bail!("--only {k}: the sweep has points 0 to {}; fix: give one of those", sw.points.len() - 1),
                Some(k) => vec![k],
                None if gather => Vec::new(),
                None => sw.points.iter().filter(|p| !grains::sweep::done(&out, p)).map(|p| p.index).collect(),
            };
            let threads = threads.unwrap_or(if only.is_some() { cores } else { 1 });
            let jobs = jobs.unwrap_or((cores / threads).max(1)).min(points.len().max(1));
            let failures = grains::sweep::run_points(&sw, &out, &points, precision, jobs, threads);
            if only.is_none() {
                let table = grains::sweep::gather(&sw, &out)?;
                std::fs::write(out.join("sweep.csv"), table.csv())?;
                std::fs::write(out.join("sweep.json"), serde_json::to_string_pretty(&table)?)?;
                if !table.ensemble.is_empty() {
                    std::fs::write(out.join("ensemble.csv"), grains::analysis::ensemble::csv(&table.ensemble))?;
                }
                let fitted: Vec<_> = table.rows.iter().filter_map(|r| Some((r.eta?, r.h_s?))).collect();
                if !fitted.is_empty() {
                    let title = sweep.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                    if let Err(e) = grains::output::plot::hardness(&out.join("hardness"), &title, &fitted, table.power_law.as_ref(), true) {
                        eprintln!("warning: {e:#}");
                    }
                }
                if json {
                    println!("{}", serde_json::to_string(&table)?);
                } else {
                    print!("{}", table.human());
                }
            }
            if !failures.is_empty() {
                let list: Vec<String> = failures.iter().map(|(k, e)| format!("point {k}: {e}")).collect();
                anyhow::bail!("{} of {} points failed ({}); fix: see each point's error, then run the sweep again to retry them", failures.len(), points.len(), list.join("; "));
            }
            Ok(())
        }
        Command::Analyze { run, beside, json } => {
            let (summary, scene, frame) = grains::runner::read_finished_run_with_contacts(&run)?;
            let stats = grains::runner::last_stage_stats(&summary)?;
            let a = grains::output::network::write(&scene, &frame, &stats, &run)?;
            if let Some(other) = &beside {
                let (_, other_scene, other_frame) = grains::runner::read_finished_run_with_contacts(other)?;
                grains::output::network::write_beside(&scene, &a, &other_scene, &other_frame, &run)?;
            }
            if json {
                println!("{}", serde_json::to_string(&a)?);
            } else {
                print!("{}", grains::output::network::human(&a));
            }
            Ok(())
        }
        Command::Bench { sizes, backend, adapter, precision, threads, reorder, busy, work, repeats, part, compaction_grains, cache, bed, out, json } => {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            let mut threads = if threads.is_empty() { vec![1, cores] } else { threads };
            threads.dedup();
            if let Some(t) = threads.iter().find(|&&t| t == 0) {
                anyhow::bail!("--threads {t}: a run needs at least one thread; fix: give counts from 1 to {cores}");
            }
            let backends: Vec<String> = match backend {
                BenchBackend::Cpu => vec!["cpu".into()],
                BenchBackend::Gpu => vec!["gpu".into()],
                BenchBackend::All => vec!["cpu".into(), "gpu".into()],
            };
            let opts = grains::bench::BenchOptions {
                sizes,
                backends,
                precisions: precision.iter().map(|p| if *p == Precision::F32 { "f32".to_string() } else { "f64".to_string() }).collect(),
                threads,
                reorder: reorder.iter().map(|r| *r == Reorder::On).collect(),
                busy,
                work,
                repeats: repeats as usize,
                throughput: matches!(part, BenchPart::Throughput | BenchPart::All),
                ladder: matches!(part, BenchPart::Ladder | BenchPart::All),
                mixed: matches!(part, BenchPart::Mixed | BenchPart::All),
                small: part == BenchPart::Small,
                compaction: (part == BenchPart::Compaction).then_some(compaction_grains as usize),
                cache: cache.unwrap_or_else(grains::bench::bed::default_cache),
                bed,
                adapter,
                progress: !json,
            };
            let report = grains::bench::run(&opts)?;
            if let Some(dir) = &out {
                report.write(dir)?;
            }
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                print!("{}", report.human());
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
            let mut g = grains::runner::gpu_engine(gpu, &scene)?;
            let mut c32 = grains::runner::cpu_engine(&scene, "f32")?;
            let mut c64 = grains::runner::cpu_engine(&scene, "f64")?;
            let report = grains::compare::compare(&scene, &name, g.as_mut(), c32.as_mut(), c64.as_mut(), steps, checkpoints)?;
            if json {
                println!("{}", serde_json::to_string(&report)?);
            } else {
                print!("{}", report.human());
            }
            if report.passed() { Ok(()) } else { anyhow::bail!("the backends disagree beyond the named tolerances (see the table); fix: report the scene and the table as a bug") }
        }
    }
}

/// A progress bar on a terminal, not with --json.
fn progress_bar(json: bool) -> bool {
    !json && std::io::stderr().is_terminal()
}

/// The engine `--backend` and `--precision` ask for.
fn engine_for(scene: &Scene, backend: Backend, adapter: Option<&str>, precision: Option<Precision>, quiet: bool) -> anyhow::Result<Box<dyn Engine>> {
    let gpu = |gpu| -> anyhow::Result<Box<dyn Engine>> { Ok(grains::runner::gpu_engine(gpu, scene)?) };
    let cpu = |precision: Option<Precision>| grains::runner::cpu_engine(scene, if precision == Some(Precision::F32) { "f32" } else { "f64" });
    let rigid = matches!(scene.method, grains::scene::Method::ContactDynamics(_));
    if grains::runner::processes() > 1 {
        if backend == Backend::Gpu {
            anyhow::bail!("--backend gpu: a run over several processes runs on the CPU; fix: drop --backend or run on one process");
        }
        return cpu(precision);
    }
    match backend {
        Backend::Cpu => cpu(precision),
        // Contact dynamics takes the GPU only when asked: its contacts are found on the host
        // and crossed over every step, and the wall contacts are swept on one invocation.
        Backend::Auto if rigid => cpu(precision),
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

/// [`report`] on the process that prints (every process of a run over several ends with
/// the same summary).
fn report_from_root(summary: &Summary, json: bool) -> anyhow::Result<()> {
    if grains::runner::is_root() { report(summary, json) } else { Ok(()) }
}

/// Prints a finished run's summary.
fn report(summary: &Summary, json: bool) -> anyhow::Result<()> {
    if json {
        println!("{}", serde_json::to_string(summary)?);
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
