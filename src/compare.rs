//! `grains compare`: one scene on the GPU (f32), the CPU in f32 and the CPU in f64 (the
//! reference), step for step, reporting how far apart they drift.
//!
//! On a short horizon the two f32 engines run the same arithmetic and agree to a few ulps
//! (bitwise on lavapipe); over a long chaotic horizon trajectories part, and what must agree
//! is the statistics. The verdict uses [`SHORT_HORIZON_POSITION`] at the first checkpoint
//! and [`LONG_HORIZON_KINETIC`] / [`LONG_HORIZON_COORDINATION`] at the last.

use crate::engine::{ContactRecord, Engine, Frame, SimError, Stats};
use serde::Serialize;
use std::collections::HashMap;

/// At the first checkpoint, GPU and CPU f32 positions agree within this fraction of the mean
/// diameter.
pub const SHORT_HORIZON_POSITION: f64 = 1e-4;
/// At the last checkpoint, the GPU's kinetic energy is within this fraction of the f64
/// reference's (or both are below 1e-12 of the initial kinetic energy).
pub const LONG_HORIZON_KINETIC: f64 = 0.1;
/// At the last checkpoint, the coordination numbers differ by at most this.
pub const LONG_HORIZON_COORDINATION: f64 = 0.1;

/// Differences between two engines at one instant.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Difference {
    /// Largest position difference over the mean diameter.
    pub position: f64,
    /// Largest velocity difference over the largest speed of the reference.
    pub velocity: f64,
    /// Largest difference of a contact's normal force over the mean normal force of the
    /// reference (pairs touching in both).
    pub contact_force: f64,
    /// Touching pairs in one engine and not the other.
    pub contacts_unmatched: usize,
    /// Kinetic energy relative difference.
    pub kinetic_energy: f64,
    /// Coordination number difference.
    pub coordination: f64,
}

/// One checkpoint of a comparison.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Checkpoint {
    /// Steps taken.
    pub step: u64,
    /// Simulated time (s).
    pub time: f64,
    /// GPU f32 against CPU f32.
    pub gpu_vs_cpu_f32: Difference,
    /// GPU f32 against CPU f64.
    pub gpu_vs_cpu_f64: Difference,
    /// CPU f32 against CPU f64.
    pub cpu_f32_vs_f64: Difference,
}

/// A whole comparison and its verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// Scene name.
    pub scene: String,
    /// GPU adapter.
    pub adapter: String,
    /// Grains.
    pub grains: usize,
    /// Checkpoints, in order.
    pub checkpoints: Vec<Checkpoint>,
    /// Short-horizon agreement of the f32 engines.
    pub short_horizon_pass: bool,
    /// Long-horizon agreement of the statistics.
    pub long_horizon_pass: bool,
}

impl Comparison {
    /// Both verdicts.
    pub fn passed(&self) -> bool {
        self.short_horizon_pass && self.long_horizon_pass
    }

    /// A table for a person.
    pub fn human(&self) -> String {
        let mut s = format!("compare {} ({} grains) on {}: differences over mean diameter (x), largest speed (v), mean normal force (F)\n", self.scene, self.grains, self.adapter);
        s.push_str("    step |  gpu-cpu32 x      v      F      | gpu-cpu64 x      v      F      KE     dZ     | cpu32-64 x      v      F\n");
        for c in &self.checkpoints {
            let (a, b, d) = (&c.gpu_vs_cpu_f32, &c.gpu_vs_cpu_f64, &c.cpu_f32_vs_f64);
            s.push_str(&format!(
                "{:>8} | {:.1e} {:.1e} {:.1e} | {:.1e} {:.1e} {:.1e} {:.1e} {:.1e} | {:.1e} {:.1e} {:.1e}\n",
                c.step, a.position, a.velocity, a.contact_force, b.position, b.velocity, b.contact_force, b.kinetic_energy, b.coordination, d.position, d.velocity, d.contact_force
            ));
        }
        let verdict = |p: bool| if p { "pass" } else { "FAIL" };
        s.push_str(&format!(
            "short horizon (f32 engines within {SHORT_HORIZON_POSITION} of a diameter at the first checkpoint): {}\nlong horizon (kinetic energy within {LONG_HORIZON_KINETIC}, coordination within {LONG_HORIZON_COORDINATION} of f64 at the end): {}\n",
            verdict(self.short_horizon_pass),
            verdict(self.long_horizon_pass)
        ));
        s
    }
}

/// The largest difference of one component between two lists of vectors, pair by pair
/// (m for positions, m/s for velocities).
pub fn largest_component_difference(a: &[glam::DVec3], b: &[glam::DVec3]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max)).fold(0.0, f64::max)
}

fn difference(a: &Frame, b: &Frame, sa: &Stats, sb: &Stats, d_mean: f64) -> Difference {
    let v_max = b.velocity.iter().map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()).fold(0.0, f64::max).max(1e-30);
    let index = |c: &[ContactRecord]| c.iter().map(|r| ((r.i, r.j), r.normal_force)).collect::<HashMap<_, _>>();
    let (ca, cb) = (index(a.contacts.as_deref().unwrap_or(&[])), index(b.contacts.as_deref().unwrap_or(&[])));
    let f_mean = cb.values().sum::<f64>() / cb.len().max(1) as f64;
    let mut worst: f64 = 0.0;
    let mut unmatched = 0;
    for (k, fb) in &cb {
        match ca.get(k) {
            Some(fa) => worst = worst.max((fa - fb).abs()),
            None => unmatched += 1,
        }
    }
    unmatched += ca.keys().filter(|k| !cb.contains_key(k)).count();
    Difference {
        position: largest_component_difference(&a.position, &b.position) / d_mean,
        velocity: largest_component_difference(&a.velocity, &b.velocity) / v_max,
        contact_force: if f_mean > 0.0 { worst / f_mean } else { 0.0 },
        contacts_unmatched: unmatched,
        kinetic_energy: (sa.kinetic_energy() - sb.kinetic_energy()).abs() / sb.kinetic_energy().max(1e-300),
        coordination: (sa.coordination - sb.coordination).abs(),
    }
}

/// Runs the three engines `steps` steps with `checkpoints` comparisons on the way.
pub fn compare(scene: &crate::scene::Scene, adapter: &str, gpu: &mut dyn Engine, f32_: &mut dyn Engine, f64_: &mut dyn Engine, steps: u64, checkpoints: u64) -> Result<Comparison, SimError> {
    let d_mean = 2.0 * scene.grains.radius.iter().sum::<f64>() / scene.grains.len() as f64;
    let every = (steps / checkpoints.max(1)).max(1);
    let ke0 = f64_.stats()?.kinetic_energy();
    let steps = steps.max(1);
    let mut out = Vec::new();
    let mut done = 0;
    let mut last_stats = (Stats::default(), Stats::default());
    while done < steps {
        let n = every.min(steps - done);
        gpu.advance(n)?;
        f32_.advance(n)?;
        f64_.advance(n)?;
        done += n;
        let (sg, s32, s64) = (gpu.stats()?, f32_.stats()?, f64_.stats()?);
        let (fg, f32f, f64f) = (gpu.frame(true)?, f32_.frame(true)?, f64_.frame(true)?);
        out.push(Checkpoint {
            step: done,
            time: f64_.time(),
            gpu_vs_cpu_f32: difference(&fg, &f32f, &sg, &s32, d_mean),
            gpu_vs_cpu_f64: difference(&fg, &f64f, &sg, &s64, d_mean),
            cpu_f32_vs_f64: difference(&f32f, &f64f, &s32, &s64, d_mean),
        });
        last_stats = (sg, s64);
    }
    let (sg, s64) = last_stats;
    let quiet = sg.kinetic_energy() < 1e-12 * ke0 && s64.kinetic_energy() < 1e-12 * ke0;
    let last = &out[out.len() - 1].gpu_vs_cpu_f64;
    let long = (quiet || last.kinetic_energy <= LONG_HORIZON_KINETIC) && last.coordination <= LONG_HORIZON_COORDINATION;
    let short = out[0].gpu_vs_cpu_f32.position <= SHORT_HORIZON_POSITION;
    Ok(Comparison { scene: scene.name.clone(), adapter: adapter.to_string(), grains: scene.grains.len(), checkpoints: out, short_horizon_pass: short, long_horizon_pass: long })
}
