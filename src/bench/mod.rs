//! `grains bench`: throughput on the peers' dense bed at 10^4 to 10^6 grains on each backend
//! and precision, and speed against error on fixed scenes. Headless; `--json` prints one
//! [`BenchReport`].

pub mod bandwidth;
pub mod bed;
pub mod busy;
pub mod compaction;
pub mod ladder;
pub mod memory;
pub mod mixed;
pub mod small;
pub mod throughput;

use crate::engine::Engine;
use anyhow::Context;
use bed::BedInfo;
use ladder::Ladder;
use serde::Serialize;
use std::path::PathBuf;
use throughput::Throughput;

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Grain counts of the throughput runs (multiples of the 10^4-grain bed).
    pub sizes: Vec<usize>,
    /// Backends: "cpu", "gpu".
    pub backends: Vec<String>,
    /// CPU precisions: "f32", "f64" (the GPU computes in f32).
    pub precisions: Vec<String>,
    /// CPU thread counts.
    pub threads: Vec<usize>,
    /// CPU runs with the engine renumbering the grains in cell order (true) and without.
    pub reorder: Vec<bool>,
    /// Busy threads competing for the cores during each CPU throughput run ([`busy::Busy`]),
    /// one run per entry: `[0, 1]` measures each configuration quiet and beside one.
    pub busy: Vec<usize>,
    /// Particle-steps per timed run (the steps are this over the grain count, at least 20).
    pub work: f64,
    /// Timed runs per configuration; the median is reported.
    pub repeats: usize,
    /// Run the throughput part.
    pub throughput: bool,
    /// Run the speed-against-error part.
    pub ladder: bool,
    /// Run the mixed-sizes part ([`mixed`]).
    pub mixed: bool,
    /// Run the small-scene part (steps per second at 280, 1200 and 10^4 grains).
    pub small: bool,
    /// Run the compaction part at this many grains: Richefeu et al.'s isotropic compaction to 100 Pa
    /// by DEM and by contact dynamics.
    pub compaction: Option<usize>,
    /// Where the poured bed is cached.
    pub cache: PathBuf,
    /// A scene whose grains are the bed, in place of the pour (e.g. LAMMPS' settled bed read
    /// by `[[read]]`).
    pub bed: Option<PathBuf>,
    /// GPU adapter name (substring); the best one when absent.
    pub adapter: Option<String>,
    /// Print progress on stderr.
    pub progress: bool,
}

/// The machine the figures were measured on.
#[derive(Clone, Debug, Serialize)]
pub struct Machine {
    /// CPU model.
    pub cpu: String,
    /// Logical cores.
    pub cores: usize,
    /// Vector instruction sets the whole build may use (beyond x86-64's baseline).
    pub build_features: Vec<String>,
    /// The level the CPU engine's hot loops ran at (`Portable`, `V3` = AVX2, `V4` = AVX-512).
    pub simd_level: String,
    /// grains version.
    pub version: String,
}

/// Everything `grains bench` measured.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Where it ran.
    pub machine: Machine,
    /// The bed (poured once, cached); absent when no part ran on it.
    pub bed: Option<BedInfo>,
    /// Throughput runs.
    pub throughput: Vec<Throughput>,
    /// Throughput runs on the beds of mixed sizes ([`mixed`]).
    pub mixed: Vec<Throughput>,
    /// Speed against error.
    pub ladder: Option<Ladder>,
    /// Small scenes.
    pub small: Vec<small::SmallScene>,
    /// This machine's memory bandwidth at each CPU thread count of the throughput runs.
    pub memory_bandwidth: Vec<Bandwidth>,
    /// The same compaction by DEM and by contact dynamics.
    pub compaction: Vec<compaction::Compaction>,
}

/// The STREAM triad's bandwidth on some threads ([`bandwidth::triad`]).
#[derive(Clone, Debug, Serialize)]
pub struct Bandwidth {
    /// Worker threads.
    pub threads: usize,
    /// Bytes per second.
    pub triad_bytes_per_second: f64,
}

/// This machine.
pub fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| t.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split(':').nth(1)).map(|s| s.trim().to_string()))
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let mut build_features = Vec::new();
    for (on, name) in [(cfg!(target_feature = "sse4.2"), "sse4.2"), (cfg!(target_feature = "avx2"), "avx2"), (cfg!(target_feature = "fma"), "fma"), (cfg!(target_feature = "avx512f"), "avx512f"), (cfg!(target_feature = "neon"), "neon")] {
        if on {
            build_features.push(name.to_string());
        }
    }
    Machine { cpu, cores: std::thread::available_parallelism().map_or(1, |n| n.get()), build_features, simd_level: format!("{:?}", crate::cpu::simd::level()), version: env!("CARGO_PKG_VERSION").to_string() }
}

/// Half the range of `repeats` over their `median` (%): the run-to-run noise.
pub fn spread_percent(repeats: &[f64], median: f64) -> f64 {
    let (lo, hi) = repeats.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
    50.0 * (hi - lo) / median
}

pub(crate) fn pool(threads: usize) -> anyhow::Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start the worker threads")
}

/// One configuration of a throughput run.
pub(crate) struct Config {
    /// "cpu" or "gpu".
    pub backend: String,
    /// "f32" or "f64" (the GPU's is f32).
    pub precision: String,
    /// CPU worker threads (1 on the GPU).
    pub threads: usize,
    /// Busy threads beside a CPU run ([`busy::Busy`]).
    pub busy: usize,
}

impl Config {
    /// The GPU's one configuration.
    pub fn gpu() -> Self {
        Config { backend: "gpu".into(), precision: "f32".into(), threads: 1, busy: 0 }
    }
}

/// Throughput of `scene` in `config` ([`throughput::measure`], `warmup` + `opts.repeats` x
/// `steps` steps): on the GPU `opts.adapter` names, or on the CPU on a pool of the config's
/// threads beside its busy ones.
pub(crate) fn measure_scene(opts: &BenchOptions, cpu: &str, scene: &crate::scene::Scene, config: &Config, warmup: u64, steps: u64) -> anyhow::Result<Throughput> {
    let peak_reset = memory::reset_peak();
    if config.backend == "gpu" {
        let gpu = crate::gpu::open(opts.adapter.as_deref())?;
        let device = gpu.info.name.clone();
        let mut engine = crate::gpu::GpuEngine::new(gpu, scene)?;
        return throughput::measure(&mut engine, &device, 1, None, warmup, steps, opts.repeats, peak_reset);
    }
    let row = pool(config.threads)?.install(|| -> anyhow::Result<Throughput> {
        let mut engine = crate::runner::cpu_engine(scene, &config.precision)?;
        let _busy = busy::Busy::start(config.busy);
        throughput::measure(engine.as_mut(), cpu, config.threads, Some(scene.reorder_every), warmup, steps, opts.repeats, peak_reset)
    })?;
    Ok(Throughput { busy: config.busy, ..row })
}

/// Runs the benchmark.
pub fn run(opts: &BenchOptions) -> anyhow::Result<BenchReport> {
    let say = |s: &str| {
        if opts.progress {
            eprintln!("bench: {s}");
        }
    };
    let all = pool(0)?;
    // The bed, for the parts that run on it.
    let (base, bed) = if opts.throughput || opts.ladder || opts.small {
        let (base, info) = match &opts.bed {
            Some(path) => all.install(|| bed::given_bed(path))?,
            None => all.install(|| bed::settled_bed(&opts.cache, opts.progress))?,
        };
        (Some(base), Some(info))
    } else {
        (None, None)
    };
    let base = || base.as_ref().ok_or_else(|| anyhow::anyhow!("the bench bed was not prepared"));
    let machine = machine();
    let mut rows = Vec::new();
    let mut memory_bandwidth = Vec::new();
    if opts.throughput && opts.backends.iter().any(|b| b == "cpu") {
        for &threads in &opts.threads {
            say(&format!("memory bandwidth (STREAM triad), {threads} thread(s)"));
            memory_bandwidth.push(Bandwidth { threads, triad_bytes_per_second: pool(threads)?.install(bandwidth::triad) });
        }
    }
    if opts.throughput {
        for &n in &opts.sizes {
            for backend in &opts.backends {
                let configs: Vec<(Config, bool)> = if backend == "gpu" {
                    vec![(Config::gpu(), false)]
                } else {
                    let mut configs = Vec::new();
                    for p in &opts.precisions {
                        for &t in &opts.threads {
                            for &r in &opts.reorder {
                                configs.extend(opts.busy.iter().map(|&b| (Config { backend: "cpu".into(), precision: p.clone(), threads: t, busy: b }, r)));
                            }
                        }
                    }
                    configs
                };
                for (config, reorder) in configs {
                    let steps = ((opts.work / n as f64).round() as u64).max(20);
                    let warmup = (steps / 5).max(10);
                    let order = if backend == "gpu" { "" } else if reorder { ", renumbered in cell order" } else { ", in the pour's order" };
                    let beside = if config.busy > 0 { format!(", beside {} busy thread(s)", config.busy) } else { String::new() };
                    say(&format!("{backend} {} {} thread(s), {n} grains{order}{beside}: {warmup} + {} x {steps} steps", config.precision, config.threads, opts.repeats));
                    let mut scene = bed::bed_of(base()?, n)?;
                    if backend != "gpu" {
                        scene = bed::shuffled(&scene);
                        scene.reorder_every = match (reorder, scene.reorder_every) {
                            (false, _) => 0,
                            (true, 0) => crate::scene::DEFAULT_REORDER_EVERY,
                            (true, every) => every,
                        };
                    }
                    let row = Throughput { scene: base()?.name.clone(), ..measure_scene(opts, &machine.cpu, &scene, &config, warmup, steps)? };
                    say(&format!("  {:.3e} particle-steps/s, Z = {:.3}, {:.0} B/grain", row.particle_steps_per_second, row.contacts_per_grain, row.bytes_per_grain));
                    rows.push(row);
                }
            }
        }
    }
    let mixed = if opts.mixed { mixed::run(opts, &machine.cpu, &say)? } else { Vec::new() };
    let ladder = if opts.ladder { Some(all.install(|| ladder::ladder(base()?, &say))?) } else { None };
    let mut small_rows = Vec::new();
    if opts.small {
        let mut scenes: Vec<(String, crate::scene::Scene)> = small::oedometer_scenes()?.into_iter().map(|s| (s.path.display().to_string(), s)).collect();
        scenes.push(("bench_bed.toml".into(), base()?.clone()));
        for (name, scene) in &scenes {
            for backend in &opts.backends {
                let precisions: Vec<String> = if backend == "gpu" { vec!["f32".into()] } else { opts.precisions.clone() };
                for precision in precisions {
                    let steps = ((2e7 / scene.grains.len() as f64) as u64).clamp(200, 2000);
                    say(&format!("small scenes: {name} on {backend} {precision}, {} x {steps} steps", opts.repeats));
                    let row = if backend == "gpu" {
                        let mut engine = crate::gpu::GpuEngine::new(crate::gpu::open(opts.adapter.as_deref())?, scene)?;
                        let count = |e: &dyn Engine| e.dispatches();
                        small::measure(&mut engine, name, steps / 10, steps, opts.repeats, &count)?
                    } else {
                        all.install(|| -> anyhow::Result<small::SmallScene> {
                            let mut engine = crate::runner::cpu_engine(scene, &precision)?;
                            small::measure(engine.as_mut(), name, steps / 10, steps, opts.repeats, &|e: &dyn Engine| e.dispatches())
                        })?
                    };
                    say(&format!("  {:.0} steps/s", row.steps_per_second));
                    small_rows.push(row);
                }
            }
        }
    }
    let mut compactions = Vec::new();
    if let Some(grains) = opts.compaction {
        for scene in compaction::scenes(grains)? {
            for backend in &opts.backends {
                say(&format!("compaction: {} at {grains} grains on {backend}", scene.path.display()));
                let row = if backend == "gpu" {
                    let mut engine = crate::runner::gpu_engine(crate::gpu::open(opts.adapter.as_deref())?, &scene)?;
                    compaction::measure(&scene, engine.as_mut())?
                } else {
                    let threads = opts.threads.iter().copied().max().unwrap_or(1);
                    pool(threads)?.install(|| compaction::measure(&scene, crate::runner::cpu_engine(&scene, "f64")?.as_mut()))?
                };
                say(&format!("  {} steps in {:.1} s, Z = {:.2}", row.steps, row.seconds, row.coordination));
                compactions.push(row);
            }
        }
    }
    Ok(BenchReport { machine, bed, throughput: rows, mixed, ladder, small: small_rows, memory_bandwidth, compaction: compactions })
}

impl BenchReport {
    /// Tables for a person.
    pub fn human(&self) -> String {
        let m = &self.machine;
        let mut s = format!("machine: {} ({} cores; build features: {}; hot loops at level {})\n", m.cpu, m.cores, if m.build_features.is_empty() { "baseline".to_string() } else { m.build_features.join(", ") }, m.simd_level);
        match &self.bed {
            Some(bed) if bed.source.is_empty() => s.push_str(&format!(
                "bed: the peers' pour, {:.3} s simulated ({}), Z = {:.3} at the end, poured in {:.0} s once and cached\n",
                bed.time,
                if bed.settled { "settled" } else { "not settled" },
                bed.coordination,
                bed.wall_seconds
            )),
            Some(bed) => s.push_str(&format!("bed: the grains of {}, Z = {:.3} as read\n", bed.source, bed.coordination)),
            None => {}
        }
        if !self.throughput.is_empty() {
            s.push_str("\nthroughput (dense settled bed, Hertz-Mindlin, dt = 2e-6 s)\n");
            for b in &self.memory_bandwidth {
                s.push_str(&format!("memory bandwidth (STREAM triad), {} thread(s): {:.2} GB/s\n", b.threads, b.triad_bytes_per_second / 1e9));
            }
            s.push_str("(reorder: rebuilds between the CPU engine's renumberings in cell order; 0: the grains stay in the pour's order)\n");
            s.push_str("(busy: threads computing beside the run, competing for the cores as other programs would)\n");
            s.push_str("backend prec thr busy reorder    grains  particle-steps/s  spread  ns/p-step     Z  pairs/grain  B/grain  B/p-step  GB/s (of triad)  peak RSS MiB  time shares\n");
            for r in &self.throughput {
                let mut phases = r.phases.clone();
                phases.sort_by(|a, b| b.share.total_cmp(&a.share));
                let shares: Vec<String> = phases.iter().filter(|p| p.share >= 0.005).map(|p| format!("{} {:.0}%", p.phase, 100.0 * p.share)).collect();
                let triad = self.memory_bandwidth.iter().find(|b| b.threads == r.threads && r.backend == "cpu").map(|b| b.triad_bytes_per_second);
                let traffic = match (r.traffic_bytes_per_second, triad) {
                    (Some(t), Some(peak)) => format!("{:.2} ({:.0}%)", t / 1e9, 100.0 * t / peak),
                    (Some(t), None) => format!("{:.2}", t / 1e9),
                    _ => "-".to_string(),
                };
                s.push_str(&format!(
                    "{:<7} {:<4} {:>3} {:>4} {:>7} {:>9} {:>17.3e} {:>6.1}% {:>10.1} {:>5.2} {:>12.2} {:>8.0} {:>9} {:>16} {:>13} {}\n",
                    r.backend,
                    r.precision,
                    r.threads,
                    r.busy,
                    r.reorder_every.map_or("-".to_string(), |e| e.to_string()),
                    r.grains,
                    r.particle_steps_per_second,
                    r.spread_percent(),
                    r.ns_per_particle_step,
                    r.contacts_per_grain,
                    r.pairs_per_grain,
                    r.bytes_per_grain,
                    r.bytes_per_particle_step.map_or("-".to_string(), |b| format!("{b:.0}")),
                    traffic,
                    r.peak_rss_bytes.map_or("-".to_string(), |b| format!("{:.0}", b as f64 / (1 << 20) as f64)),
                    shares.join(", ")
                ));
            }
        }
        for r in self.throughput.iter().filter(|r| !r.projected.is_empty()) {
            let each: Vec<String> = r.projected.iter().map(|p| format!("{} {:.3e}", p.gpu, p.particle_steps_per_second)).collect();
            let kernels: Vec<String> = r.traffic.iter().map(|k| format!("{} {:.0}", k.phase, k.bytes_per_particle_step)).collect();
            s.push_str(&format!(
                "gpu {} grains: {:.0} B per particle-step ({}) and {:.1} dispatches per step; projected particle-steps/s ({:.0} us per dispatch): {}\n",
                r.grains,
                r.bytes_per_particle_step.unwrap_or(0.0),
                kernels.join(", "),
                r.dispatches_per_step.unwrap_or(0.0),
                throughput::DISPATCH_SECONDS * 1e6,
                each.join(", ")
            ));
        }
        if let Some(first) = self.mixed.first() {
            s.push_str("\nmixed sizes (beds poured by the bench bed's recipe, as poured and stirred to 1 m/s in random directions; x one size: against the bench bed in the same state on the same backend, precision and threads)\n");
            s.push_str("bed                          backend prec thr  particle-steps/s  spread  x one size     Z  rebuilds  rebuild ns/grain  x one size  pairs/grain\n");
            for r in &self.mixed {
                let reference = if r.scene.ends_with(mixed::STIRRED) { format!("{}{}", first.scene, mixed::STIRRED) } else { first.scene.clone() };
                let one = self.mixed.iter().find(|o| o.scene == reference && o.backend == r.backend && o.precision == r.precision && o.threads == r.threads);
                let ratio = |a: Option<f64>, b: Option<f64>| a.zip(b).map_or("-".to_string(), |(a, b)| format!("{:.2}", a / b));
                s.push_str(&format!(
                    "{:<28} {:<7} {:<4} {:>3} {:>17.3e} {:>6.1}% {:>11} {:>5.2} {:>9} {:>17} {:>11} {:>12.2}\n",
                    r.scene,
                    r.backend,
                    r.precision,
                    r.threads,
                    r.particle_steps_per_second,
                    r.spread_percent(),
                    ratio(Some(r.particle_steps_per_second), one.map(|o| o.particle_steps_per_second)),
                    r.contacts_per_grain,
                    r.rebuilds,
                    r.rebuild_ns_per_grain.map_or("-".to_string(), |ns| format!("{ns:.0}")),
                    ratio(r.rebuild_ns_per_grain, one.and_then(|o| o.rebuild_ns_per_grain)),
                    r.pairs_per_grain
                ));
            }
        }
        if !self.small.is_empty() {
            s.push_str("\nsmall scenes (from their initial state; the GPU's dispatches per step include the rebuild kernels, empty on steps that keep the list)\n");
            s.push_str("scene                grains backend prec  steps/s  spread  dispatches/step\n");
            for r in &self.small {
                s.push_str(&format!(
                    "{:<20} {:>6} {:<7} {:<4} {:>8.0} {:>6.1}% {:>16}\n",
                    r.scene,
                    r.grains,
                    r.backend,
                    r.precision,
                    r.steps_per_second,
                    spread_percent(&r.repeats, r.steps_per_second),
                    r.dispatches_per_step.map_or("-".to_string(), |d| format!("{d:.1}"))
                ));
            }
        }
        if !self.compaction.is_empty() {
            s.push_str("\nthe same compaction to 100 Pa by DEM and by contact dynamics (Richefeu et al.'s sample scaled to the grains, each scene's settle criteria)\n");
            s.push_str("method            omega backend prec thr grains        dt   steps   wall s  settled     Z  pressure Pa  sweeps/step  capped  residual  contact updates/s  sweep share\n");
            let opt = |x: Option<f64>, digits: usize| x.map_or("-".to_string(), |v| format!("{v:.digits$}"));
            for r in &self.compaction {
                s.push_str(&format!(
                    "{:<17} {:>5} {:<7} {:<4} {:>3} {:>6} {:>9.2e} {:>7} {:>8.1} {:>8} {:>5.2} {:>12.1} {:>12} {:>7} {:>9} {:>18} {:>12}\n",
                    r.method,
                    opt(r.relaxation, 1),
                    r.backend,
                    r.precision,
                    r.threads,
                    r.grains,
                    r.dt,
                    r.steps,
                    r.seconds,
                    r.settled,
                    r.coordination,
                    r.pressure,
                    opt(r.mean_sweeps, 1),
                    r.capped_steps.map_or("-".to_string(), |c| c.to_string()),
                    r.residual.map_or("-".to_string(), |q| format!("{q:.1e}")),
                    r.contact_updates_per_second.map_or("-".to_string(), |u| format!("{u:.3e}")),
                    r.sweep_share.map_or("-".to_string(), |f| format!("{:.0}%", 100.0 * f)),
                ));
            }
        }
        if let Some(l) = &self.ladder {
            s.push_str("\nspeed against error (errors against an f64 velocity-Verlet reference at a 4x smaller step than the smallest here)\n");
            s.push_str("scene        integrator        prec        dt   steps  force evals   wall s  energy err  position err  force err\n");
            let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2e}"));
            for r in &l.rungs {
                if let Some(why) = &r.unstable {
                    s.push_str(&format!("{:<12} {:<17} {:<4} {:>9.2e}  unstable: {why}\n", r.scene, r.integrator, r.precision, r.dt));
                    continue;
                }
                s.push_str(&format!(
                    "{:<12} {:<17} {:<4} {:>9.2e} {:>7} {:>12} {:>8.3} {:>11} {:>13} {:>10}\n",
                    r.scene,
                    r.integrator,
                    r.precision,
                    r.dt,
                    r.steps,
                    r.force_evaluations,
                    r.seconds,
                    opt(r.energy_error),
                    opt(r.position_error),
                    opt(r.force_error)
                ));
            }
            if l.ovv_vs_vv.is_empty() {
                s.push_str("optimised against plain velocity Verlet: no common energy-error range\n");
            }
            for c in &l.ovv_vs_vv {
                s.push_str(&format!(
                    "at energy error {:.2e}: optimised velocity Verlet costs {:.2}x the force evaluations and {:.2}x the wall time of velocity Verlet\n",
                    c.energy_error, c.evaluation_ratio, c.time_ratio
                ));
            }
        }
        s
    }

    /// Writes `bench.json` and the speed-against-error plots into `dir`.
    pub fn write(&self, dir: &std::path::Path) -> anyhow::Result<()> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let path = dir.join("bench.json");
        std::fs::write(&path, serde_json::to_string_pretty(self)?).with_context(|| format!("cannot write {}", path.display()))?;
        if let Some(l) = &self.ladder {
            for (scene, label, pick) in [
                ("elastic_gas", "largest relative energy drift", (|r: &ladder::Rung| r.energy_error) as fn(&ladder::Rung) -> Option<f64>),
                ("dense_bed", "RMS position error / mean diameter", |r: &ladder::Rung| r.position_error),
            ] {
                let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
                for r in l.rungs.iter().filter(|r| r.scene == scene && r.unstable.is_none()) {
                    let name = format!("{} {}", r.integrator.replace('_', " "), r.precision);
                    let point = (pick(r).unwrap_or(0.0), r.seconds);
                    match series.iter_mut().find(|(n, _)| *n == name) {
                        Some((_, pts)) => pts.push(point),
                        None => series.push((name, vec![point])),
                    }
                }
                let stem = dir.join(format!("speed_error_{scene}"));
                if let Err(e) = crate::output::plot::speed_error(&stem, &format!("{scene}: wall time against error"), label, &series) {
                    eprintln!("warning: {e:#}");
                }
            }
        }
        Ok(())
    }
}
