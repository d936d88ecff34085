//! Inlets and outlets: grains put into play and taken out of it between steps (LIGGGHTS'
//! `fix insert/rate/region` and `fix remove`; DEM-Engine's added and disabled clumps).
//!
//! An inlet's grains are drawn when the scene loads (its reservoir, [`crate::scene::Inlet`])
//! and wait out of play in every engine from the start: engines keep a fixed set of slots and
//! ids, and a grain's id is never used again. Every `every` steps from its opening, an inlet
//! puts into play the next grains of its reservoir while the mass in play stays within its
//! rate times the time it has been open: the inserted mass trails `rate x time` by less than
//! one grain. Each goes at a random place in the region (a stream seeded by the scene's seed,
//! the inlet and the step) clear of the grains and the walls there; a grain that finds no room
//! in [`ATTEMPTS`] tries waits for the next insertion, and those after it with it. Every
//! `every` steps, an outlet takes out of play the grains whose centres lie in its region and
//! counts them once. Events happen at fixed steps (multiples of `every`), whatever the host
//! loop's chunks: a run resumed from a checkpoint meets the same ones.

use crate::engine::{Engine, FlowCount, Frame, Insertion};
use crate::scene::{wall_distance_now, Inlet, Scene};
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Random places an inlet tries for a grain before it waits for the next insertion.
pub const ATTEMPTS: usize = 200;

/// What the inlets and outlets have done: what a checkpoint keeps of them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FlowState {
    /// Per inlet, then per outlet: grains and mass put into play or taken out.
    pub counts: Vec<FlowCount>,
    /// The last step whose events have run.
    pub through_step: u64,
    /// Grains in play times the steps they ran, summed (a flow scene's particle-steps: an
    /// inlet's grains count from their insertion, an outlet's until their removal).
    #[serde(default)]
    pub grain_steps: u64,
}

impl FlowState {
    /// Nothing in or out yet.
    pub fn new(scene: &Scene) -> Self {
        let names = scene.inlets.iter().map(|i| &i.name).chain(scene.outlets.iter().map(|o| &o.name));
        FlowState { counts: names.map(|n| FlowCount { name: n.clone(), ..Default::default() }).collect(), through_step: 0, grain_steps: 0 }
    }

    /// Grains in play now: those in play from the start, plus the inlets', less the outlets'.
    pub fn in_play(&self, scene: &Scene) -> u64 {
        let start = (0..scene.grains.len()).filter(|&i| scene.grains.starts_in_play(i)).count() as u64;
        let (inlets, outlets) = self.counts.split_at(scene.inlets.len());
        start + inlets.iter().map(|c| c.grains).sum::<u64>() - outlets.iter().map(|c| c.grains).sum::<u64>()
    }

    /// Steps from `step` to the next step after it at which an inlet or outlet acts, if any.
    pub fn steps_to_next(&self, scene: &Scene, step: u64) -> Option<u64> {
        let inlets = scene.inlets.iter().enumerate().filter(|(k, inlet)| self.counts[*k].grains < inlet.grains.len() as u64).map(|(_, i)| next_multiple(step.max(i.start_step), i.every, step));
        let outlets = scene.outlets.iter().map(|o| next_multiple(step, o.every, step));
        inlets.chain(outlets).min().map(|s| s - step)
    }

    /// Runs the inlets and outlets due at the engine's step (once: a resumed run does not run
    /// them again): outlets first, then inlets.
    pub fn act(&mut self, scene: &Scene, engine: &mut dyn Engine) -> anyhow::Result<()> {
        let step = engine.steps();
        if step <= self.through_step {
            return Ok(());
        }
        self.through_step = step;
        let due = |every: u64| step.is_multiple_of(every);
        if !scene.outlets.iter().any(|o| due(o.every)) && !scene.inlets.iter().any(|i| step >= i.start_step && due(i.every)) {
            return Ok(());
        }
        let mut frame = engine.frame(false)?;
        for (k, outlet) in scene.outlets.iter().enumerate().filter(|(_, o)| due(o.every)) {
            let gone: Vec<usize> = (0..frame.id.len()).filter(|&g| outlet.region.contains(frame.position[g])).collect();
            if gone.is_empty() {
                continue;
            }
            let count = &mut self.counts[scene.inlets.len() + k];
            for &g in &gone {
                let (m, r) = (scene.grains.mass[frame.id[g] as usize], frame.radius[g]);
                count.grains += 1;
                count.mass += m;
                count.energy -= energy(scene, m, frame.position[g], frame.velocity[g]) + 0.2 * m * r * r * frame.angular_velocity[g].length_squared();
            }
            let gone: Vec<u32> = gone.into_iter().map(|g| frame.id[g]).collect();
            engine.remove_grains(&gone)?;
            let gone: std::collections::HashSet<u32> = gone.into_iter().collect();
            let ids = frame.id.clone();
            frame.retain_grains(|g| !gone.contains(&ids[g]));
        }
        for (k, inlet) in scene.inlets.iter().enumerate().filter(|(_, i)| step >= i.start_step && due(i.every)) {
            let open = (step - inlet.start_step) as f64 * scene.time_step.dt;
            let placed = insert(scene, inlet, &mut self.counts[k], open, &frame, step);
            if placed.is_empty() {
                continue;
            }
            engine.insert_grains(&placed)?;
            // The next inlet places its grains clear of these too.
            for p in &placed {
                frame.id.push(p.id);
                frame.position.push(p.position);
                frame.radius.push(scene.grains.radius[p.id as usize]);
                frame.velocity.push(p.velocity);
                frame.angular_velocity.push(DVec3::ZERO);
            }
        }
        Ok(())
    }
}

/// The first multiple of `every` above `step`, at or after `from`.
fn next_multiple(from: u64, every: u64, step: u64) -> u64 {
    let at = from.max(step + 1);
    at.div_ceil(every) * every
}

/// Inlet `inlet`'s grains due after it has been open `open` seconds (those that keep the mass
/// put into play within `mass_rate x open`), placed clear of `frame`'s grains and walls and of
/// each other; `count` takes them in.
fn insert(scene: &Scene, inlet: &Inlet, count: &mut FlowCount, open: f64, frame: &Frame, step: u64) -> Vec<Insertion> {
    let g = &scene.grains;
    let target = inlet.mass_rate * open;
    let mut rng = ChaCha8Rng::seed_from_u64(inlet.seed ^ step.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    // The grains that may touch one placed in the region: near its box.
    let reach = 2.0 * inlet.grains.clone().map(|i| g.radius[i as usize]).fold(0.0, f64::max);
    let [lo, hi] = inlet.region.bounds();
    let near = |p: DVec3, r: f64| (0..3).all(|a| p[a] >= lo[a] - r - reach && p[a] <= hi[a] + r + reach);
    let mut others: Vec<(DVec3, f64)> = frame.position.iter().zip(&frame.radius).filter(|(p, r)| near(**p, **r)).map(|(&p, &r)| (p, r)).collect();
    let mut placed = Vec::new();
    for id in inlet.grains.start + count.grains as u32..inlet.grains.end {
        let (r, m) = (g.radius[id as usize], g.mass[id as usize]);
        if count.mass + m > target {
            break;
        }
        let spot = (0..ATTEMPTS).find_map(|_| {
            let p = DVec3::from(inlet.region.sample(r, &mut rng).ok()?);
            let clear = others.iter().all(|&(q, rq)| p.distance_squared(q) >= (r + rq) * (r + rq)) && clear_of_walls(scene, frame, p, r);
            clear.then_some(p)
        });
        let Some(p) = spot else { break };
        others.push((p, r));
        placed.push(Insertion { id, position: p, velocity: inlet.velocity });
        count.grains += 1;
        count.mass += m;
        count.energy += energy(scene, m, p, inlet.velocity);
    }
    placed
}

/// A grain's kinetic energy of translation and gravitational energy (J) with mass `m` (kg) at
/// `x` (m) moving at `v` (m/s), as the statistics count them.
fn energy(scene: &Scene, m: f64, x: DVec3, v: DVec3) -> f64 {
    0.5 * m * v.length_squared() - m * scene.gravity.dot(x)
}

/// Whether a grain of radius `r` (m) at `p` touches no wall that is there in `frame`.
fn clear_of_walls(scene: &Scene, frame: &Frame, p: DVec3, r: f64) -> bool {
    scene.walls.iter().zip(&frame.walls).zip(&frame.walls_present).filter(|(_, present)| **present).all(|((wall, geom), _)| wall_distance_now(&wall.shape, geom, p) >= r)
}
