//! The host loop: runs a scene's stages on an engine, reading statistics back every
//! `stats_interval` steps (never the particle arrays), deciding when a stage ends, and
//! stopping a run that goes unstable.

use crate::analysis::{container_volume, contact_moments, macroscopic_stress, solid_volume, void_ratio, Tensor};
use crate::engine::{Engine, Frame, SimError, Stats};
use crate::flow::FlowState;
use crate::periodic::Periodic;
use crate::scene::{Scene, Stage, StageKind};
use serde::{Deserialize, Serialize};

/// A run whose mechanical energy (kinetic + elastic + gravitational - external work) grows
/// above its start by more than this fraction of the energy in play is unstable: with
/// dissipation it can only fall, and without it integration errors stay near 1e-3 at sane
/// steps.
pub const ENERGY_GROWTH_TOLERANCE: f64 = 0.5;

/// What a stage did.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageResult {
    /// Stage name.
    pub name: String,
    /// "fill", "settle" or "run".
    pub kind: String,
    /// Steps taken in the stage.
    pub steps: u64,
    /// Simulated time at the start and the end (s).
    pub time_start: f64,
    /// Simulated time at the end (s).
    pub time_end: f64,
    /// Fill/settle: whether both criteria were met before the stage's duration ran out.
    pub settled: Option<bool>,
    /// Translational kinetic energy per grain at the end (J), the settle criterion's measure.
    pub ke_per_grain: f64,
    /// Unbalanced-force ratio at the end (-; infinite, `null` in JSON, while no grain touches).
    #[serde(deserialize_with = "crate::engine::infinite_if_null")]
    pub unbalanced_force: f64,
    /// Statistics at the end.
    pub stats: Stats,
    /// The compression point of an oedometer step.
    pub compression: Option<CompressionPoint>,
    /// The void ratio of the sample when the piston was lowered onto it, up to the top of the
    /// highest grain (before any pressure acts; it counts the rough surface's hollows as
    /// voids), for the stage that lowered it.
    pub initial_void_ratio: Option<f64>,
}

/// The state of an oedometric sample at the end of a pressure step.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CompressionPoint {
    /// The piston's target pressure (Pa).
    pub target_pressure: f64,
    /// The pressure the grains exert on the piston (Pa).
    pub pressure: f64,
    /// Piston height (m).
    pub piston_z: f64,
    /// Void ratio of the sample between floor and piston.
    pub void_ratio: f64,
    /// Grain-grain contacts per grain.
    pub coordination: f64,
    /// Kinetic energy (J).
    pub kinetic_energy: f64,
    /// Volume-weighted particle stress over the sample, compression positive (Pa).
    #[serde(with = "crate::analysis::tensor_rows")]
    pub stress: Tensor,
    /// Its vertical component (Pa), to compare with the pressure.
    pub stress_zz: f64,
    /// Whether the step met its settle criteria.
    pub settled: bool,
    /// The seating load's point: its void ratio is Bauer's e0, and it is not fitted.
    #[serde(default)]
    pub seating: bool,
}

impl CompressionPoint {
    /// Trace of the macroscopic stress, `3 p_mean` (Pa, compression positive).
    pub fn stress_trace(&self) -> f64 {
        crate::analysis::trace(&self.stress)
    }
    /// Lateral over vertical stress, `(sigma_xx + sigma_yy) / (2 sigma_zz)`: K0 at rest (-).
    pub fn lateral_ratio(&self) -> f64 {
        0.5 * (self.stress.x_axis.x + self.stress.y_axis.y) / self.stress.z_axis.z
    }
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
    /// A stage boundary, or a statistics read inside a stage when a checkpoint is due: the
    /// moment to write a checkpoint of `engine` and `progress`.
    fn checkpoint(&mut self, progress: &Progress, engine: &dyn Engine) -> anyhow::Result<()>;
}

/// Where a run stands between stages: what a checkpoint stores besides the engine.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Progress {
    /// Index of the next stage to run.
    pub next_stage: usize,
    /// Results of the stages run so far.
    pub results: Vec<StageResult>,
    /// The stability guard's references.
    guard: Guard,
    /// Simulated time of the next frame, when frames are taken at an interval.
    next_frame: Option<f64>,
    /// Where stage `next_stage` stands, when the checkpoint was taken inside it.
    #[serde(default)]
    pub in_stage: Option<StageProgress>,
    /// What the inlets and outlets have done.
    #[serde(default)]
    pub flow: FlowState,
}

/// Where a stage stands at a checkpoint taken inside it (at a statistics read).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageProgress {
    /// Steps done in the stage.
    pub done: u64,
    /// The engine's step count at the stage's start.
    pub step0: u64,
    /// Simulated time at the stage's start (s).
    pub time0: f64,
    /// The void ratio when the stage lowered the piston, if it did.
    pub initial_void_ratio: Option<f64>,
}

/// When a checkpoint is due inside a stage: every `interval` seconds of wall-clock time since
/// the last one (never with an interval of 0).
struct CheckpointClock {
    interval: f64,
    last: std::time::Instant,
}

impl CheckpointClock {
    fn new(interval: f64) -> Self {
        CheckpointClock { interval, last: std::time::Instant::now() }
    }
    fn due(&self) -> bool {
        self.interval > 0.0 && self.last.elapsed().as_secs_f64() >= self.interval
    }
    fn reset(&mut self) {
        self.last = std::time::Instant::now();
    }
}

impl Progress {
    /// Checks statistics read outside the stages (a caller's own steps) as every read inside
    /// them is: an error names what went unstable and a time step to try.
    pub fn check_stable(&self, stats: &Stats) -> Result<(), SimError> {
        self.guard.check(stats)
    }

    /// The start of a run on a freshly set-up engine.
    pub fn start(scene: &Scene, engine: &mut dyn Engine) -> Result<Self, SimError> {
        let stats = engine.stats()?;
        Ok(Progress {
            next_stage: 0,
            results: Vec::new(),
            guard: Guard::new(scene, &stats),
            next_frame: (scene.output.frame_interval > 0.0).then(|| engine.time()),
            in_stage: None,
            flow: FlowState::new(scene),
        })
    }

    /// Advances `engine` by `n` steps, the inlets and outlets acting at their steps on the way.
    pub fn advance(&mut self, scene: &Scene, engine: &mut dyn Engine, mut n: u64) -> anyhow::Result<()> {
        while n > 0 {
            let to_event = self.flow.steps_to_next(scene, engine.steps()).unwrap_or(u64::MAX);
            let m = n.min(to_event);
            if scene.has_flow() {
                self.flow.grain_steps += self.flow.in_play(scene) * m;
            }
            engine.advance(m)?;
            n -= m;
            if m == to_event {
                self.flow.act(scene, engine)?;
            }
        }
        Ok(())
    }

    /// The engine's statistics with the inlets' and outlets' totals.
    pub fn stats(&self, engine: &mut dyn Engine) -> Result<Stats, SimError> {
        let mut s = engine.stats()?;
        s.flow = self.flow.counts.clone();
        Ok(s)
    }
}

/// Runs every stage of `scene` on `engine`.
pub fn run(scene: &Scene, engine: &mut dyn Engine, rec: &mut dyn Recorder) -> anyhow::Result<Vec<StageResult>> {
    let progress = Progress::start(scene, engine)?;
    run_from(scene, engine, rec, progress)
}

/// Runs the stages from `progress` on (a fresh start, or a resumed checkpoint), offering a
/// checkpoint to the recorder after each, and inside a stage every
/// `output.checkpoint_interval` seconds of wall-clock time.
pub fn run_from(scene: &Scene, engine: &mut dyn Engine, rec: &mut dyn Recorder, mut progress: Progress) -> anyhow::Result<Vec<StageResult>> {
    while run_next_stage(scene, engine, rec, &mut progress)?.is_some() {}
    Ok(progress.results)
}

/// Runs the next stage from where `progress` stands (its start, or inside it where a
/// checkpoint left it), offering a checkpoint to the recorder at its end and inside it every
/// `output.checkpoint_interval` seconds of wall-clock time; returns its result, or `None`
/// when every stage has run.
pub fn run_next_stage<'p>(scene: &Scene, engine: &mut dyn Engine, rec: &mut dyn Recorder, progress: &'p mut Progress) -> anyhow::Result<Option<&'p StageResult>> {
    let Some(stage) = scene.stages.get(progress.next_stage) else { return Ok(None) };
    let mut clock = CheckpointClock::new(scene.output.checkpoint_interval);
    let result = run_stage(scene, stage, engine, rec, progress, &mut clock)?;
    progress.results.push(result);
    progress.next_stage += 1;
    rec.checkpoint(progress, engine)?;
    Ok(progress.results.last())
}

/// Sets stage `stage` up on the engine (pressures, liquid, the walls it moves, the piston
/// lowered), returning
/// where it starts.
fn start_stage(scene: &Scene, stage: &Stage, engine: &mut dyn Engine) -> anyhow::Result<StageProgress> {
    if let Some(p) = stage.piston_pressure {
        engine.set_piston_pressure(p);
    }
    if let Some(v) = stage.wet_volume {
        engine.wet(v)?;
    }
    if scene.servo.is_some() {
        engine.set_servo(stage.servo_pressure, stage.axial_strain_rate);
    }
    for (wall, drive) in &stage.walls {
        engine.set_wall_drive(*wall, drive);
    }
    for &(wall, present) in &stage.presence {
        set_wall_present(scene, engine, wall, present, &format!("stage {}", stage.name))?;
    }
    let mut initial_void_ratio = None;
    if stage.lower_piston {
        let f = engine.frame(false)?;
        let top = (0..f.radius.len()).map(|i| f.position[i][2] + f.radius[i]).fold(f64::NEG_INFINITY, f64::max);
        engine.place_piston(top);
        initial_void_ratio = container_volume(scene, top).map(|v| void_ratio(solid_volume(&f), v));
    }
    Ok(StageProgress { done: 0, step0: engine.steps(), time0: engine.time(), initial_void_ratio })
}

/// Adds wall `wall` back (`present`) or takes it away, for `by` (`stage fill`, a Python
/// call) as [`Engine::set_wall_present`] does; refuses to add one that is away where a grain
/// overlaps it.
pub fn set_wall_present(scene: &Scene, engine: &mut dyn Engine, wall: usize, present: bool, by: &str) -> anyhow::Result<()> {
    if present {
        let f = engine.frame(false)?;
        if !f.walls_present[wall] {
            clear_of_grains(scene, wall, &f, by)?;
        }
    }
    engine.set_wall_present(wall, present);
    Ok(())
}

/// Refuses to add wall `wall` (for `by`) where a grain of `frame` overlaps it: the first step
/// would release the overlap's energy at once.
fn clear_of_grains(scene: &Scene, wall: usize, frame: &Frame, by: &str) -> anyhow::Result<()> {
    let distance = |p: glam::DVec3| crate::scene::wall_distance_now(&scene.walls[wall].shape, &frame.walls[wall], p);
    for (i, (&p, &r)) in frame.position.iter().zip(&frame.radius).enumerate() {
        let d = distance(p);
        if d < r {
            anyhow::bail!(
                "{}: {by} adds wall {}, which grain {} (radius {r:.4e} m at {:?}) overlaps by {:.4e} m; fix: add the wall where no grain is (at an earlier stage, or outside the grains and moved in with the stage's `walls`)",
                scene.path.display(),
                scene.walls[wall].name,
                frame.id[i],
                p.to_array(),
                r - d
            );
        }
    }
    Ok(())
}

/// Runs a stage from its start, or from where a checkpoint inside it left it (the engine
/// restored from that checkpoint already holds what the stage set up).
fn run_stage(scene: &Scene, stage: &Stage, engine: &mut dyn Engine, rec: &mut dyn Recorder, progress: &mut Progress, clock: &mut CheckpointClock) -> anyhow::Result<StageResult> {
    let start = match progress.in_stage.take() {
        Some(resumed) => resumed,
        None => start_stage(scene, stage, engine)?,
    };
    let StageProgress { mut done, step0, time0, initial_void_ratio } = start;
    let guard = progress.guard.clone();
    let dt = scene.time_step.dt;
    let total = stage.max_steps(dt);
    let k = scene.stats_interval;
    let settles = stage.kind != StageKind::Run;
    let mut settled = false;
    let mut stats = progress.stats(engine)?;
    while done < total {
        let chunk = k.min(total - done);
        progress.advance(scene, engine, chunk)?;
        done += chunk;
        stats = progress.stats(engine)?;
        // Per grain in play (an inlet's waiting grains are not yet in the packing).
        let n = stats.grains.max(1) as f64;
        guard.check(&stats)?;
        rec.stats(&stage.name, &stats)?;
        rec.progress(&stage.name, done, total);
        if let Some(t) = progress.next_frame.as_mut().filter(|t| engine.time() >= **t) {
            rec.frame(&engine.frame(scene.output.frames_with_contacts())?)?;
            *t += scene.output.frame_interval;
        }
        let pressure_reached = match (stage.piston_pressure, &stats.piston) {
            (Some(target), Some(p)) if target > 0.0 => ((p.pressure - target) / target).abs() < stage.pressure_tolerance,
            _ => true,
        };
        // Translational energy: a rattler spinning in its cage (nothing to brake it on a
        // frictionless wall) says nothing about whether the packing stands.
        // A loaded packing (ke_ratio) is judged on its loaded grains: a rattler bouncing in its
        // cage does not move the piston. A deposit is judged on every grain: one in flight is
        // not settled.
        let (still, unbalanced) = match stage.ke_ratio {
            Some(r) => (stats.ke_translational - stats.ke_rattlers < r * stats.elastic_energy, stats.unbalanced_force_loaded),
            None => (stats.ke_translational / n < stage.ke_per_grain, stats.unbalanced_force),
        };
        if settles && still && unbalanced < stage.unbalanced_force && pressure_reached {
            settled = true;
            break;
        }
        if done < total && clock.due() {
            progress.in_stage = Some(StageProgress { done, step0, time0, initial_void_ratio });
            rec.checkpoint(progress, engine)?;
            progress.in_stage = None;
            clock.reset();
        }
    }
    if progress.next_frame.is_none() {
        rec.frame(&engine.frame(scene.output.frames_with_contacts())?)?;
    }
    let compression = if stage.records_compression { Some(CompressionPoint { seating: stage.seating, ..compression_point(scene, engine, &stats, settled)? }) } else { None };
    let result = StageResult {
        name: stage.name.clone(),
        kind: match stage.kind {
            StageKind::Fill => "fill",
            StageKind::Settle => "settle",
            StageKind::Run => "run",
        }
        .to_string(),
        steps: engine.steps() - step0,
        time_start: time0,
        time_end: engine.time(),
        settled: settles.then_some(settled),
        ke_per_grain: stats.ke_translational / stats.grains.max(1) as f64,
        unbalanced_force: stats.unbalanced_force,
        stats,
        compression,
        initial_void_ratio,
    };
    rec.stage_end(&result)?;
    Ok(result)
}

/// Measures the sample at the end of a pressure step (`stats` read just before; `settled`
/// whether the step met its criteria): the void ratio between the floor and the piston, the
/// particle stress over that volume, the coordination.
pub fn compression_point(scene: &Scene, engine: &mut dyn Engine, stats: &Stats, settled: bool) -> Result<CompressionPoint, SimError> {
    let piston = stats.piston.clone().unwrap_or_default();
    let frame = engine.frame(true)?;
    let volume = container_volume(scene, piston.z).unwrap_or(f64::NAN);
    let moments = contact_moments(&frame, &Periodic::of(&scene.periodic));
    let stress = -macroscopic_stress(&moments, volume);
    Ok(CompressionPoint {
        target_pressure: piston.target_pressure,
        pressure: piston.pressure,
        piston_z: piston.z,
        void_ratio: void_ratio(solid_volume(&frame), volume),
        coordination: stats.coordination,
        kinetic_energy: stats.kinetic_energy(),
        stress_zz: stress.z_axis.z,
        stress,
        settled,
        seating: false,
    })
}

/// The stability checks made at every statistics read.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Guard {
    max_overlap: f64,
    suggested_dt: f64,
    energy0: f64,
    kinetic_elastic0: f64,
    gravity0: f64,
}

impl Guard {
    fn new(scene: &Scene, s: &Stats) -> Self {
        Guard { max_overlap: scene.max_overlap, suggested_dt: scene.time_step.suggested_after_instability(), energy0: s.mechanical_energy(), kinetic_elastic0: s.kinetic_energy() + s.elastic_energy, gravity0: s.gravity_energy }
    }

    fn check(&self, s: &Stats) -> Result<(), SimError> {
        let unstable = |what: String, grain: u32, also: &'static str| SimError::Unstable { step: s.step, time: s.time, what, grain, suggested_dt: self.suggested_dt, also };
        if let Some(g) = s.non_finite_grain {
            return Err(unstable("non-finite position or velocity".into(), g, ""));
        }
        if s.max_overlap > self.max_overlap {
            // A large overlap can be a load the contacts cannot carry as well as too long a step.
            return Err(unstable(
                format!("overlap {:.3} of the radius exceeds simulation.max_overlap = {}", s.max_overlap, self.max_overlap),
                s.max_overlap_grain,
                ", or, if the grains carry more load than their stiffness allows, stiffen them (youngs_modulus) or lower the pressure",
            ));
        }
        // Inlets bring energy in (counted positive), outlets take it out (counted negative).
        let (brought, moved) = s.flow.iter().fold((0.0, 0.0), |(b, m), f| (b + f.energy, m + f.energy.abs()));
        let in_play = self.kinetic_elastic0 + (s.gravity_energy - self.gravity0).abs() + s.external_work.abs() + s.kinetic_energy() * 1e-6 + moved;
        let growth = s.mechanical_energy() - self.energy0 - brought;
        if growth > ENERGY_GROWTH_TOLERANCE * in_play && growth > 0.0 {
            return Err(unstable(
                format!("mechanical energy grew by {growth:.3e} J with {in_play:.3e} J in play and no input"),
                s.max_overlap_grain,
                "",
            ));
        }
        Ok(())
    }
}
