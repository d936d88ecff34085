//! Speed against error: fixed scenes run at a ladder of time steps with each integrator and
//! precision, each error measured against an f64 velocity-Verlet reference at a much smaller
//! step, with the wall time it cost.
//!
//! * The elastic gas (`scenes/elastic_gas.toml`, frictionless and undamped): the largest
//!   relative drift of the total energy over the run.
//! * The dense bed (the throughput bed, loaded by its own weight and shaken by a random
//!   velocity per grain): the RMS position error over the mean diameter and the RMS contact
//!   force error over the RMS contact force, after a fixed time.

use glam::DVec3;
use crate::cpu::CpuEngine;
use crate::engine::{Engine, Frame, SimError};
use crate::periodic::Periodic;
use crate::real::Vec3;
use crate::scene::{self, Integrator, Scene};
use rand::{RngExt, SeedableRng};
use serde::Serialize;
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

/// The elastic gas scene, bundled.
pub const GAS_SCENE: &str = include_str!("../../scenes/elastic_gas.toml");

/// Step multipliers of the ladder, relative to the scene's own step.
pub const DT_FACTORS: [f64; 5] = [4.0, 2.0, 1.0, 0.5, 0.25];
/// The reference runs at the smallest ladder step divided by this.
pub const REFERENCE_REFINEMENT: f64 = 4.0;
/// Simulated time of the dense-bed runs (s): about 25 Hertz contact times.
pub const BED_DURATION: f64 = 1.0e-3;
/// Speed of the random shake given to every grain of the dense bed (m/s).
pub const BED_SHAKE: f64 = 0.02;
/// Energy samples per gas run.
pub const ENERGY_SAMPLES: u64 = 200;

/// One rung: a scene, integrator, precision and step, with its cost and error.
#[derive(Clone, Debug, Serialize)]
pub struct Rung {
    /// "elastic_gas" or "dense_bed".
    pub scene: String,
    /// "velocity_verlet" or "optimized_verlet".
    pub integrator: String,
    /// "f32" or "f64".
    pub precision: String,
    /// Time step (s).
    pub dt: f64,
    /// Steps taken.
    pub steps: u64,
    /// Force evaluations per grain (the machine-independent cost).
    pub force_evaluations: u64,
    /// Wall seconds.
    pub seconds: f64,
    /// Largest |E(t) - E(0)| / E(0) over the run (the gas).
    pub energy_error: Option<f64>,
    /// RMS distance to the reference's positions at the end over the mean diameter (the dense
    /// bed; a gas is chaotic, so its positions part from any reference).
    pub position_error: Option<f64>,
    /// RMS contact-force difference to the reference at the end over the reference's RMS
    /// contact force (the dense bed).
    pub force_error: Option<f64>,
    /// Why the run stopped, when it went unstable.
    pub unstable: Option<String>,
}

/// At equal energy error, how much optimised velocity Verlet costs relative to velocity
/// Verlet (f64, the gas), by force evaluations and by wall time.
#[derive(Clone, Debug, Serialize)]
pub struct IntegratorCost {
    /// The energy error compared at.
    pub energy_error: f64,
    /// OVV force evaluations / VV force evaluations at that error.
    pub evaluation_ratio: f64,
    /// OVV wall time / VV wall time at that error.
    pub time_ratio: f64,
}

/// The whole speed-against-error study.
#[derive(Clone, Debug, Serialize)]
pub struct Ladder {
    /// The rungs, by scene, integrator, precision and step.
    pub rungs: Vec<Rung>,
    /// OVV against VV at equal energy error, at each VV rung within OVV's error range.
    pub ovv_vs_vv: Vec<IntegratorCost>,
}

/// The elastic gas scene.
pub fn gas_scene() -> anyhow::Result<Scene> {
    Ok(scene::parse(Path::new("scenes/elastic_gas.toml"), GAS_SCENE)?)
}

/// The dense bed shaken: every grain gets a random velocity of [`BED_SHAKE`] (fixed seed).
pub fn shaken(bed: &Scene) -> Scene {
    let mut s = bed.clone();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2026);
    for v in &mut s.grains.velocity {
        let dir: [f64; 3] = loop {
            let d = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0f64)];
            let n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if n2 > 1e-6 && n2 <= 1.0 {
                let n = n2.sqrt();
                break [d[0] / n, d[1] / n, d[2] / n];
            }
        };
        *v = DVec3::new(v[0] + BED_SHAKE * dir[0], v[1] + BED_SHAKE * dir[1], v[2] + BED_SHAKE * dir[2]);
    }
    s.name = "dense_bed".into();
    s
}

/// What one run ended with.
struct RunEnd {
    frame: Frame,
    steps: u64,
    seconds: f64,
    energy_error: Option<f64>,
}

/// Runs `scene` for `duration` at step `dt` with `integrator` in `precision`, sampling the
/// energy when `energy` is set.
fn run(scene: &Scene, integrator: Integrator, precision: &str, dt: f64, duration: f64, energy: bool) -> Result<RunEnd, SimError> {
    let mut s = scene.clone();
    s.integrator = integrator;
    s.time_step.dt = dt;
    let steps = (duration / dt).round() as u64;
    let started = Instant::now();
    let mut engine: Box<dyn Engine> = match precision {
        "f32" => Box::new(CpuEngine::<f32>::new(&s)?),
        _ => Box::new(CpuEngine::<f64>::new(&s)?),
    };
    let mut energy_error = None;
    if energy {
        let e0 = engine.stats()?.mechanical_energy();
        let chunk = (steps / ENERGY_SAMPLES).max(1);
        let mut worst: f64 = 0.0;
        let mut done = 0;
        while done < steps {
            let k = chunk.min(steps - done);
            engine.advance(k)?;
            done += k;
            worst = worst.max((engine.stats()?.mechanical_energy() - e0).abs() / e0.abs());
        }
        energy_error = Some(worst);
    } else {
        engine.advance(steps)?;
    }
    let frame = engine.frame(!energy)?;
    Ok(RunEnd { frame, steps, seconds: started.elapsed().as_secs_f64(), energy_error })
}

/// RMS distance between two frames' positions (minimum image) over `d_mean`.
fn position_error(a: &Frame, b: &Frame, periodic: &Periodic<f64>, d_mean: f64) -> f64 {
    let sum: f64 = a.position.iter().zip(&b.position).map(|(p, q)| periodic.min_image(Vec3::new(p[0] - q[0], p[1] - q[1], p[2] - q[2])).norm2()).sum();
    (sum / a.position.len() as f64).sqrt() / d_mean
}

/// RMS over the union of both frames' contacts of the contact-force difference (a contact
/// missing in one frame counts with zero force there), over the reference's RMS force.
fn force_error(a: &Frame, reference: &Frame) -> f64 {
    let index = |f: &Frame| f.contacts.as_deref().unwrap_or(&[]).iter().map(|c| ((c.i, c.j), c.force)).collect::<HashMap<_, _>>();
    let (ia, ir) = (index(a), index(reference));
    let norm2 = |f: DVec3| f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
    let mut diff = 0.0;
    for (k, fr) in &ir {
        let fa = ia.get(k).copied().unwrap_or(DVec3::ZERO);
        diff += norm2(DVec3::new(fa[0] - fr[0], fa[1] - fr[1], fa[2] - fr[2]));
    }
    diff += ia.iter().filter(|(k, _)| !ir.contains_key(k)).map(|(_, f)| norm2(*f)).sum::<f64>();
    let scale: f64 = ir.values().map(|f| norm2(*f)).sum();
    (diff / scale.max(1e-300)).sqrt()
}

/// Runs one scene's ladder: the reference, then every integrator, precision and step.
fn scene_ladder(name: &str, scene: &Scene, duration: f64, energy: bool, progress: &dyn Fn(&str)) -> anyhow::Result<Vec<Rung>> {
    let dt0 = scene.time_step.dt;
    let dt_ref = dt0 * DT_FACTORS.iter().copied().fold(f64::INFINITY, f64::min) / REFERENCE_REFINEMENT;
    progress(&format!("{name}: f64 reference at dt = {dt_ref:.3e} s"));
    let reference = run(scene, Integrator::VelocityVerlet, "f64", dt_ref, duration, energy)?;
    let periodic = Periodic::<f64>::of(&scene.periodic);
    let g = &scene.grains;
    let d_mean = 2.0 * g.radius.iter().sum::<f64>() / g.len() as f64;
    let mut rungs = Vec::new();
    for integrator in [Integrator::VelocityVerlet, Integrator::OptimizedVerlet] {
        for precision in ["f64", "f32"] {
            for factor in DT_FACTORS {
                let dt = dt0 * factor;
                progress(&format!("{name}: {} {precision} dt = {dt:.3e} s", integrator.name()));
                let evals = if integrator == Integrator::OptimizedVerlet { 2 } else { 1 };
                let mut rung = Rung {
                    scene: name.into(),
                    integrator: integrator.name().into(),
                    precision: precision.into(),
                    dt,
                    steps: (duration / dt).round() as u64,
                    force_evaluations: 0,
                    seconds: 0.0,
                    energy_error: None,
                    position_error: None,
                    force_error: None,
                    unstable: None,
                };
                match run(scene, integrator, precision, dt, duration, energy) {
                    Ok(end) => {
                        rung.steps = end.steps;
                        rung.force_evaluations = evals * end.steps;
                        rung.seconds = end.seconds;
                        rung.energy_error = end.energy_error;
                        // A gas is chaotic: its positions part from the reference's within the run.
                        rung.position_error = (!energy).then(|| position_error(&end.frame, &reference.frame, &periodic, d_mean));
                        rung.force_error = (!energy).then(|| force_error(&end.frame, &reference.frame));
                    }
                    Err(e @ SimError::Unstable { .. }) => rung.unstable = Some(e.to_string()),
                    Err(e) => return Err(e.into()),
                }
                rungs.push(rung);
            }
        }
    }
    Ok(rungs)
}

/// OVV against VV at equal energy error (f64 gas rungs): for each VV rung whose error lies
/// within the OVV rungs' range, the OVV cost at that error by log-log interpolation.
pub fn integrator_cost(rungs: &[Rung]) -> Vec<IntegratorCost> {
    let series = |integrator: &str| -> Vec<(f64, f64, f64)> {
        let mut v: Vec<(f64, f64, f64)> = rungs
            .iter()
            .filter(|r| r.scene == "elastic_gas" && r.precision == "f64" && r.integrator == integrator)
            .filter_map(|r| Some((r.energy_error.filter(|e| *e > 0.0)?, r.force_evaluations as f64, r.seconds)))
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    let (vv, ovv) = (series("velocity_verlet"), series("optimized_verlet"));
    let interpolate = |e: f64, pick: fn(&(f64, f64, f64)) -> f64| -> Option<f64> {
        ovv.windows(2).find(|w| w[0].0 <= e && e <= w[1].0).map(|w| {
            let t = if w[1].0 > w[0].0 { (e.ln() - w[0].0.ln()) / (w[1].0.ln() - w[0].0.ln()) } else { 0.0 };
            (pick(&w[0]).ln() + t * (pick(&w[1]).ln() - pick(&w[0]).ln())).exp()
        })
    };
    vv.iter()
        .filter_map(|&(e, evals, secs)| {
            Some(IntegratorCost { energy_error: e, evaluation_ratio: interpolate(e, |p| p.1)? / evals, time_ratio: interpolate(e, |p| p.2)? / secs })
        })
        .collect()
}

/// Runs the whole study on the current thread pool.
pub fn ladder(bed: &Scene, progress: &dyn Fn(&str)) -> anyhow::Result<Ladder> {
    let gas = gas_scene()?;
    let gas_duration = gas.stages.iter().map(|s| s.duration).sum::<f64>();
    let mut rungs = scene_ladder("elastic_gas", &gas, gas_duration, true, progress)?;
    rungs.extend(scene_ladder("dense_bed", &shaken(bed), BED_DURATION, false, progress)?);
    let ovv_vs_vv = integrator_cost(&rungs);
    Ok(Ladder { rungs, ovv_vs_vv })
}
