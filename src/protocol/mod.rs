//! The host loop: runs a scene's stages on an engine, reading statistics back every
//! `stats_interval` steps (never the particle arrays), deciding when a stage ends, and
//! stopping a run that goes unstable.

use crate::engine::{Engine, Frame, SimError, Stats};
use crate::scene::{Scene, Stage, StageKind};
use serde::Serialize;

/// A run whose mechanical energy (kinetic + elastic + gravitational - external work) grows
/// above its start by more than this fraction of the energy in play is unstable: with
/// dissipation it can only fall, and without it integration errors stay near 1e-3 at sane
/// steps.
pub const ENERGY_GROWTH_TOLERANCE: f64 = 0.5;

/// The step suggested after an instability: half the step, and no more than `auto` would pick.
pub fn suggested_dt(scene: &Scene) -> f64 {
    (0.5 * scene.time_step.dt).min(scene.time_step.auto_dt())
}

/// What a stage did.
#[derive(Clone, Debug, Serialize)]
pub struct StageResult {
    /// Stage name.
    pub name: String,
    /// "fill", "settle" or "run".
    pub kind: &'static str,
    /// Steps taken in the stage.
    pub steps: u64,
    /// Simulated time at the start and the end (s).
    pub time_start: f64,
    /// Simulated time at the end (s).
    pub time_end: f64,
    /// Fill/settle: whether both criteria were met before the stage's duration ran out.
    pub settled: Option<bool>,
    /// Kinetic energy per grain at the end (J).
    pub ke_per_grain: f64,
    /// Unbalanced-force ratio at the end (-).
    pub unbalanced_force: f64,
    /// Statistics at the end.
    pub stats: Stats,
}

/// Receives what the host loop produces as it goes.
pub trait Recorder {
    /// A statistics read.
    fn stats(&mut self, stage: &str, s: &Stats) -> anyhow::Result<()>;
    /// A frame (requested by the scene's frame interval or at a stage end).
    fn frame(&mut self, f: &Frame) -> anyhow::Result<()>;
    /// A stage finished.
    fn stage_end(&mut self, r: &StageResult) -> anyhow::Result<()>;
    /// Progress within a stage: steps done out of at most `total`.
    fn progress(&mut self, stage: &str, done: u64, total: u64);
}

/// Runs every stage of `scene` on `engine`.
pub fn run(scene: &Scene, engine: &mut dyn Engine, rec: &mut dyn Recorder) -> anyhow::Result<Vec<StageResult>> {
    let start = engine.stats();
    let guard = Guard::new(scene, &start);
    let mut next_frame = if scene.output.frame_interval > 0.0 { Some(engine.time()) } else { None };
    let mut results = Vec::with_capacity(scene.stages.len());
    for stage in &scene.stages {
        results.push(run_stage(scene, stage, engine, rec, &guard, &mut next_frame)?);
    }
    Ok(results)
}

fn run_stage(
    scene: &Scene,
    stage: &Stage,
    engine: &mut dyn Engine,
    rec: &mut dyn Recorder,
    guard: &Guard,
    next_frame: &mut Option<f64>,
) -> anyhow::Result<StageResult> {
    if let Some(p) = stage.piston_pressure {
        engine.set_piston_pressure(p);
    }
    let dt = scene.time_step.dt;
    let total = (stage.duration / dt).round().max(1.0) as u64;
    let k = scene.stats_interval;
    let n = engine.grain_count() as f64;
    let (step0, time0) = (engine.steps(), engine.time());
    let settles = stage.kind != StageKind::Run;
    let mut done = 0;
    let mut settled = false;
    let mut stats = engine.stats();
    while done < total {
        let chunk = k.min(total - done);
        engine.advance(chunk)?;
        done += chunk;
        stats = engine.stats();
        guard.check(&stats)?;
        rec.stats(&stage.name, &stats)?;
        rec.progress(&stage.name, done, total);
        if let Some(t) = next_frame.as_mut().filter(|t| engine.time() >= **t) {
            rec.frame(&engine.frame(scene.output.contact_forces))?;
            *t += scene.output.frame_interval;
        }
        if settles && stats.kinetic_energy() / n < stage.ke_per_grain && stats.unbalanced_force < stage.unbalanced_force {
            settled = true;
            break;
        }
    }
    if next_frame.is_none() {
        rec.frame(&engine.frame(scene.output.contact_forces))?;
    }
    let result = StageResult {
        name: stage.name.clone(),
        kind: match stage.kind {
            StageKind::Fill => "fill",
            StageKind::Settle => "settle",
            StageKind::Run => "run",
        },
        steps: engine.steps() - step0,
        time_start: time0,
        time_end: engine.time(),
        settled: settles.then_some(settled),
        ke_per_grain: stats.kinetic_energy() / n,
        unbalanced_force: stats.unbalanced_force,
        stats,
    };
    rec.stage_end(&result)?;
    Ok(result)
}

/// The stability checks made at every statistics read.
struct Guard {
    max_overlap: f64,
    suggested_dt: f64,
    energy0: f64,
    kinetic_elastic0: f64,
    gravity0: f64,
}

impl Guard {
    fn new(scene: &Scene, s: &Stats) -> Self {
        Guard { max_overlap: scene.max_overlap, suggested_dt: suggested_dt(scene), energy0: s.mechanical_energy(), kinetic_elastic0: s.kinetic_energy() + s.elastic_energy, gravity0: s.gravity_energy }
    }

    fn check(&self, s: &Stats) -> Result<(), SimError> {
        let unstable = |what: String, grain: u32| SimError::Unstable { step: s.step, time: s.time, what, grain, suggested_dt: self.suggested_dt };
        if let Some(g) = s.non_finite_grain {
            return Err(unstable("non-finite position or velocity".into(), g));
        }
        if s.max_overlap > self.max_overlap {
            return Err(unstable(
                format!("overlap {:.3} of the radius exceeds simulation.max_overlap = {}", s.max_overlap, self.max_overlap),
                s.max_overlap_grain,
            ));
        }
        let in_play = self.kinetic_elastic0 + (s.gravity_energy - self.gravity0).abs() + s.external_work.abs() + s.kinetic_energy() * 1e-6;
        let growth = s.mechanical_energy() - self.energy0;
        if growth > ENERGY_GROWTH_TOLERANCE * in_play && growth > 0.0 {
            return Err(unstable(
                format!("mechanical energy grew by {growth:.3e} J with {in_play:.3e} J in play and no input"),
                s.max_overlap_grain,
            ));
        }
        Ok(())
    }
}
