//! Throughput on the dense bed: particle-steps per second with what they were bought with
//! (contacts and pairs per grain, bytes per grain, peak memory) and where the time goes.

use super::memory;
use crate::engine::Engine;
use serde::Serialize;
use std::time::Instant;

/// Share of one phase in the timed steps.
#[derive(Clone, Debug, Serialize)]
pub struct PhaseShare {
    /// Phase name (hash, detect, remap, force, walls, gather, integrate).
    pub phase: String,
    /// Fraction of the summed phase times (-).
    pub share: f64,
    /// Nanoseconds per particle-step spent in it.
    pub ns_per_particle_step: f64,
}

/// Bytes one phase or kernel of a step moves, per grain.
#[derive(Clone, Debug, Serialize)]
pub struct PhaseBytes {
    /// Phase (CPU) or kernel (GPU).
    pub phase: String,
    /// Bytes per particle-step.
    pub bytes_per_particle_step: f64,
}

/// One throughput measurement.
#[derive(Clone, Debug, Serialize)]
pub struct Throughput {
    /// The scene's name: the bench bed's, or a bed of [`super::mixed`].
    pub scene: String,
    /// "cpu" or "gpu".
    pub backend: String,
    /// The CPU model or the GPU adapter.
    pub device: String,
    /// "f32" or "f64".
    pub precision: String,
    /// Worker threads (CPU); 1 for the GPU's host thread.
    pub threads: usize,
    /// Busy threads that competed for the cores during the run (`grains bench --busy`).
    pub busy: usize,
    /// Rebuilds between the CPU engine's renumberings of the grains in cell order (0: never;
    /// `simulation.reorder_every`); absent on the GPU, which keeps the scene's order.
    pub reorder_every: Option<u64>,
    /// Grains.
    pub grains: usize,
    /// Untimed steps before the timed ones.
    pub warmup_steps: u64,
    /// Timed steps per repeat.
    pub steps: u64,
    /// Wall seconds of the median repeat.
    pub seconds: f64,
    /// Grains x steps / seconds, median over the repeats.
    pub particle_steps_per_second: f64,
    /// Particle-steps per second of every repeat, in order (the spread is the noise).
    pub repeats: Vec<f64>,
    /// Nanoseconds per particle-step, median over the repeats.
    pub ns_per_particle_step: f64,
    /// Touching grain-grain pairs per grain, x2 (the coordination number Z).
    pub contacts_per_grain: f64,
    /// Listed neighbour pairs per grain (each pair once).
    pub pairs_per_grain: f64,
    /// Neighbour-list rebuilds during the timed steps.
    pub rebuilds: u64,
    /// Nanoseconds a rebuild's phases (hash, detect, remap) took per grain, over the timed
    /// steps (CPU; absent where the engine does not time its phases or nothing was rebuilt).
    pub rebuild_ns_per_grain: Option<f64>,
    /// Translational kinetic energy per grain at the end (J): the bed stayed static.
    pub ke_per_grain: f64,
    /// Bytes of the engine's arrays or device buffers.
    pub engine_bytes: u64,
    /// `engine_bytes` per grain.
    pub bytes_per_grain: f64,
    /// Peak resident memory of the process while building and stepping this engine (bytes);
    /// absent where the system does not report it.
    pub peak_rss_bytes: Option<u64>,
    /// Time per phase (CPU backend).
    pub phases: Vec<PhaseShare>,
    /// Bytes a step that keeps its neighbour list moves to and from memory, per grain
    /// (`Engine::step_traffic`); absent where the engine does not count them.
    pub bytes_per_particle_step: Option<f64>,
    /// Those bytes per grain by phase (CPU) or kernel (GPU).
    pub traffic: Vec<PhaseBytes>,
    /// Those bytes at the measured speed (bytes/s): what the step draws of the memory's
    /// bandwidth.
    pub traffic_bytes_per_second: Option<f64>,
    /// Kernel dispatches per timed step (GPU), the rebuild kernels' empty ones included.
    pub dispatches_per_step: Option<f64>,
    /// GPU rows: the speed this step would reach on the GPUs of [`PROJECTED_GPUS`], from its
    /// bytes and dispatches ([`projected`]).
    pub projected: Vec<Projection>,
}

/// The phases of a neighbour-list rebuild ([`crate::state::profile::PHASE_NAMES`]).
const REBUILD_PHASES: [&str; 3] = ["hash", "detect", "remap"];

/// Memory bandwidths (bytes/s) of the GPUs the GPU rows are projected to (their data sheets).
pub const PROJECTED_GPUS: [(&str, f64); 2] = [("H100 SXM, 3.35 TB/s", 3.35e12), ("H200, 4.8 TB/s", 4.8e12)];

/// Seconds a dispatch costs beyond its memory traffic in the projection: an assumption (a few
/// microseconds per dependent dispatch on current GPUs), to be replaced by a measurement on a
/// lent GPU.
pub const DISPATCH_SECONDS: f64 = 2e-6;

/// A projected speed.
#[derive(Clone, Debug, Serialize)]
pub struct Projection {
    /// The GPU.
    pub gpu: String,
    /// Its memory bandwidth (bytes/s).
    pub bandwidth: f64,
    /// Particle-steps per second: `N / (N b / bandwidth + d DISPATCH_SECONDS)` for `b` bytes
    /// per particle-step and `d` dispatches per step.
    pub particle_steps_per_second: f64,
}

/// The speed of a step of `grains` grains moving `bytes_per_particle_step` each in
/// `dispatches` dispatches, on a GPU of `bandwidth` bytes/s.
pub fn projected(grains: usize, bytes_per_particle_step: f64, dispatches: f64, bandwidth: f64) -> f64 {
    let n = grains as f64;
    n / (n * bytes_per_particle_step / bandwidth + dispatches * DISPATCH_SECONDS)
}

impl Throughput {
    /// Half the range of the repeats over their median (%): the run-to-run noise.
    pub fn spread_percent(&self) -> f64 {
        super::spread_percent(&self.repeats, self.particle_steps_per_second)
    }
}

/// Times `repeats` runs of `steps` steps of `engine`, one after the other, after `warmup`
/// untimed ones, and reports the median. `peak_reset` says whether the process's peak
/// memory was reset before the engine was built; `reorder_every` is what the engine was
/// built with.
#[allow(clippy::too_many_arguments)]
pub fn measure(engine: &mut dyn Engine, device: &str, threads: usize, reorder_every: Option<u64>, warmup: u64, steps: u64, repeats: usize, peak_reset: bool) -> anyhow::Result<Throughput> {
    engine.advance(warmup)?;
    let before = engine.stats()?;
    let dispatches_before = engine.dispatches();
    engine.set_profiling(true);
    let mut seconds_each = Vec::with_capacity(repeats);
    for _ in 0..repeats.max(1) {
        // `advance` returns when its steps are done: the GPU's ends on the rebuild check's
        // read-back. The statistics, a pass in permanent-id order that a run makes once per
        // `stats_interval`, are not timed: at 10^6 grains one took as long as five steps.
        let started = Instant::now();
        engine.advance(steps)?;
        seconds_each.push(started.elapsed().as_secs_f64());
    }
    let after = engine.stats()?;
    engine.set_profiling(false);
    let n = engine.grain_count();
    let work = (n as u64 * steps) as f64;
    let mut sorted = seconds_each.clone();
    sorted.sort_by(f64::total_cmp);
    let seconds = sorted[sorted.len() / 2];
    let work_all = work * seconds_each.len() as f64;
    let phase_total: f64 = engine.phase_seconds().iter().map(|(_, s)| s).sum();
    let phases = engine
        .phase_seconds()
        .into_iter()
        .map(|(phase, s)| PhaseShare { phase: phase.to_string(), share: if phase_total > 0.0 { s / phase_total } else { 0.0 }, ns_per_particle_step: s * 1e9 / work_all })
        .collect();
    let rebuilds = after.rebuilds - before.rebuilds;
    let rebuild_seconds: f64 = engine.phase_seconds().iter().filter(|(p, _)| REBUILD_PHASES.contains(p)).map(|(_, s)| s).sum();
    let rebuild_ns_per_grain = (rebuilds > 0 && rebuild_seconds > 0.0).then(|| rebuild_seconds * 1e9 / (rebuilds * n as u64) as f64);
    let engine_bytes = engine.memory_bytes();
    let by_phase = engine.step_traffic();
    let traffic: u64 = by_phase.iter().map(|(_, b)| b).sum();
    let bytes_per_particle_step = (traffic > 0).then(|| traffic as f64 / n as f64);
    let traffic = by_phase.into_iter().map(|(phase, b)| PhaseBytes { phase: phase.to_string(), bytes_per_particle_step: b as f64 / n as f64 }).collect();
    let timed_steps = (steps * seconds_each.len() as u64) as f64;
    let dispatches_per_step = dispatches_before.zip(engine.dispatches()).map(|(a, b)| (b - a) as f64 / timed_steps);
    let projected = match (bytes_per_particle_step, dispatches_per_step) {
        (Some(b), Some(d)) => PROJECTED_GPUS.iter().map(|&(gpu, bandwidth)| Projection { gpu: gpu.to_string(), bandwidth, particle_steps_per_second: projected(n, b, d, bandwidth) }).collect(),
        _ => Vec::new(),
    };
    Ok(Throughput {
        scene: String::new(),
        backend: engine.backend().to_string(),
        device: device.to_string(),
        precision: engine.precision().to_string(),
        threads,
        busy: 0,
        reorder_every,
        grains: n,
        warmup_steps: warmup,
        steps,
        seconds,
        particle_steps_per_second: work / seconds,
        repeats: seconds_each.iter().map(|s| work / s).collect(),
        ns_per_particle_step: seconds * 1e9 / work,
        contacts_per_grain: after.coordination,
        pairs_per_grain: after.pairs as f64 / n as f64,
        rebuilds,
        rebuild_ns_per_grain,
        ke_per_grain: after.ke_translational / n as f64,
        engine_bytes,
        bytes_per_grain: engine_bytes as f64 / n as f64,
        peak_rss_bytes: if peak_reset { memory::peak_rss() } else { None },
        phases,
        bytes_per_particle_step,
        traffic,
        traffic_bytes_per_second: bytes_per_particle_step.map(|b| b * work / seconds),
        dispatches_per_step,
        projected,
    })
}
