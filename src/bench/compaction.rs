//! Contact dynamics against DEM on the same packing: Richefeu et al.'s isotropic compaction
//! (`dry_iso_100pa.toml` and `cd_iso_100pa.toml`, the same grains, friction, servo box and
//! pressure), shrunk to a given grain count, run by each method (contact dynamics by each of
//! the compared solvers, [`RELAXATIONS`]) to its scene's settle criteria on each backend; the
//! wall time of each, and contact dynamics' sweeps: how many a step took, how many steps
//! stopped at the cap, the residual left, and contact updates (one contact's local problem
//! solved once) per second of sweeping.

use crate::engine::{Engine, Frame, Stats};
use crate::protocol::{Progress, Recorder, StageResult};
use crate::scene::Scene;
use serde::Serialize;
use std::time::Instant;

/// The MD sample's scene, and the same sample by contact dynamics.
const DEM_SCENE: (&str, &str) = ("dry_iso_100pa.toml", include_str!("../../scenes/dry_iso_100pa.toml"));
const CD_SCENE: (&str, &str) = ("cd_iso_100pa.toml", include_str!("../../scenes/cd_iso_100pa.toml"));
/// The contact-dynamics solvers compared: over-relaxation factors of the Gauss-Seidel sweeps
/// (1: plain), each at the scene's tolerance and cap.
pub const RELAXATIONS: [f64; 2] = [1.0, 1.5];
/// Grains and box side (m) of `dry_iso_100pa.toml`, the packing both scenes are scaled from.
const SAMPLE_GRAINS: f64 = 8000.0;
const SAMPLE_SIDE: f64 = 28.0e-3;

/// One compaction to the settle criteria.
#[derive(Clone, Debug, Serialize)]
pub struct Compaction {
    /// "dem" or "contact_dynamics".
    pub method: String,
    /// Contact dynamics: the sweeps' over-relaxation factor (1: plain Gauss-Seidel).
    pub relaxation: Option<f64>,
    /// The scene it was scaled from.
    pub scene: String,
    /// "cpu" or "gpu".
    pub backend: String,
    /// "f32" or "f64".
    pub precision: String,
    /// Worker threads (CPU); 1 for the GPU's host thread.
    pub threads: usize,
    /// Grains.
    pub grains: usize,
    /// Time step (s).
    pub dt: f64,
    /// Steps to the end of the stage.
    pub steps: u64,
    /// Wall seconds of the whole compaction.
    pub seconds: f64,
    /// Whether the settle criteria were met within the stage's duration.
    pub settled: bool,
    /// Coordination number at the end.
    pub coordination: f64,
    /// Mean pressure on the six walls at the end (Pa).
    pub pressure: f64,
    /// Contact dynamics: mean sweeps per step.
    pub mean_sweeps: Option<f64>,
    /// Contact dynamics: steps that stopped at `max_iterations`.
    pub capped_steps: Option<u64>,
    /// Contact dynamics: contact updates per second of sweeping.
    pub contact_updates_per_second: Option<f64>,
    /// Contact dynamics: the sweeps' share of the wall time.
    pub sweep_share: Option<f64>,
    /// Contact dynamics: the quadratic norm of the residuals over the last statistics
    /// interval (the largest a step ended with; `grains::cd`'s residual).
    pub residual: Option<f64>,
}

/// Sums what the statistics reads say of the solver.
#[derive(Default)]
struct Tally {
    steps: u64,
    sweeps: f64,
    capped: u64,
    contact_updates: u64,
    residual: f64,
    last: Option<StageResult>,
}

impl Recorder for Tally {
    fn stats(&mut self, _stage: &str, s: &Stats) -> anyhow::Result<()> {
        if let Some(c) = &s.solver {
            self.steps += c.steps;
            self.sweeps += c.mean_iterations * c.steps as f64;
            self.capped += c.unconverged_steps;
            self.contact_updates += c.contact_updates;
            self.residual = c.residuals.quadratic;
        }
        Ok(())
    }
    fn frame(&mut self, _f: &Frame) -> anyhow::Result<()> {
        Ok(())
    }
    fn stage_end(&mut self, r: &StageResult) -> anyhow::Result<()> {
        self.last = Some(r.clone());
        Ok(())
    }
    fn progress(&mut self, _stage: &str, _done: u64, _total: u64) {}
    fn checkpoint(&mut self, _progress: &Progress, _engine: &dyn Engine) -> anyhow::Result<()> {
        Ok(())
    }
}

/// The scene `(name, text)` with `grains` grains in a box holding them at the sample's
/// density (side scaled by the cube root of the count), with no outputs.
pub fn scaled((name, text): (&str, &str), grains: usize) -> anyhow::Result<Scene> {
    let mut doc: toml::Table = toml::from_str(text)?;
    let side = SAMPLE_SIDE * (grains as f64 / SAMPLE_GRAINS).cbrt();
    let corner = toml::Value::Array(vec![toml::Value::Float(side); 3]);
    for (key, value) in [("generate.0.count", toml::Value::Integer(grains as i64)), ("generate.0.region.max", corner.clone()), ("wall.0.max", corner)] {
        crate::scene::dotted::set(&mut doc, key, value).map_err(|e| anyhow::anyhow!("{name}: {key}: {e}"))?;
    }
    doc.remove("output");
    let mut scene = crate::scene::parse(std::path::Path::new(name), &toml::to_string(&doc)?)?;
    scene.output.checkpoint_interval = 0.0;
    Ok(scene)
}

/// Both scenes at `grains` grains: DEM, then contact dynamics with each of [`RELAXATIONS`].
pub fn scenes(grains: usize) -> anyhow::Result<Vec<Scene>> {
    let mut scenes = vec![scaled(DEM_SCENE, grains)?];
    for omega in RELAXATIONS {
        let mut cd = scaled(CD_SCENE, grains)?;
        if let crate::scene::Method::ContactDynamics(params) = &mut cd.method {
            params.relaxation = omega;
        }
        scenes.push(cd);
    }
    Ok(scenes)
}

/// Compacts `scene` on `engine` to its settle criteria (the scene's stages) and times it.
pub fn measure(scene: &Scene, engine: &mut dyn Engine) -> anyhow::Result<Compaction> {
    let relaxation = match scene.method {
        crate::scene::Method::ContactDynamics(p) => Some(p.relaxation),
        crate::scene::Method::Dem => None,
    };
    let rigid = relaxation.is_some();
    engine.set_profiling(true);
    let mut tally = Tally::default();
    let started = Instant::now();
    crate::protocol::run(scene, engine, &mut tally)?;
    let seconds = started.elapsed().as_secs_f64();
    let last = tally.last.ok_or_else(|| anyhow::anyhow!("{}: no stage ran", scene.path.display()))?;
    let sweep_seconds = engine.phase_seconds().iter().find(|(phase, _)| *phase == "sweeps").map(|p| p.1);
    let pressures: Vec<f64> = last.stats.walls.iter().filter_map(|w| w.pressure).collect();
    Ok(Compaction {
        method: if rigid { "contact_dynamics" } else { "dem" }.to_string(),
        relaxation,
        scene: scene.path.display().to_string(),
        backend: engine.backend().to_string(),
        precision: engine.precision().to_string(),
        threads: if engine.backend() == "gpu" { 1 } else { rayon::current_num_threads() },
        grains: engine.grain_count(),
        dt: scene.time_step.dt,
        steps: engine.steps(),
        seconds,
        settled: last.settled.unwrap_or(false),
        coordination: last.stats.coordination,
        pressure: pressures.iter().sum::<f64>() / pressures.len().max(1) as f64,
        mean_sweeps: rigid.then(|| tally.sweeps / tally.steps.max(1) as f64),
        capped_steps: rigid.then_some(tally.capped),
        contact_updates_per_second: sweep_seconds.filter(|&s| s > 0.0).map(|s| tally.contact_updates as f64 / s),
        sweep_share: sweep_seconds.map(|s| s / seconds),
        residual: rigid.then_some(tally.residual),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_methods_compact_the_same_grains_in_the_same_box_to_the_same_pressure() {
        let [dem, cd, relaxed] = <[Scene; 3]>::try_from(scenes(1000).unwrap()).unwrap();
        assert!(matches!(cd.method, crate::scene::Method::ContactDynamics(p) if p.relaxation == 1.0) && matches!(dem.method, crate::scene::Method::Dem));
        assert!(matches!(relaxed.method, crate::scene::Method::ContactDynamics(p) if p.relaxation == RELAXATIONS[1]));
        assert_eq!(dem.grains.len(), 1000);
        assert_eq!((&dem.grains.position, &dem.grains.radius, &dem.grains.mass), (&cd.grains.position, &cd.grains.radius, &cd.grains.mass));
        let side = SAMPLE_SIDE * (1000.0 / SAMPLE_GRAINS).cbrt();
        let box_of = |s: &Scene| s.walls.iter().map(|w| format!("{:?}", w.shape)).collect::<Vec<_>>();
        assert_eq!(box_of(&dem), box_of(&cd));
        assert!(box_of(&dem).iter().any(|w| w.contains(&format!("{side:?}"))), "the box is scaled to {side} m: {:?}", box_of(&dem));
        let (a, b) = (dem.servo.unwrap(), cd.servo.unwrap());
        assert_eq!((a.pressure, a.max_speed), (b.pressure, b.max_speed));
    }
}
