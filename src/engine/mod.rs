//! What the host loop needs from a backend: advance, read a few statistics, take a frame.

use anyhow::{bail, Context};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

mod frame;
pub use frame::{scalar_first, ContactRecord, Frame, WallContactRecord};

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A grain owns more pairs than its size allows ([`crate::state::owner_capacity`]).
    #[error(
        "neighbour capacity exceeded at step {step}: grain {grain} has {count} neighbour pairs, above what simulation.max_neighbours = {capacity} allows a grain of its size (that many for the smallest grains, 4x for each doubling of the grain's radius plus the smallest one's); fix: raise simulation.max_neighbours (or lower simulation.skin)"
    )]
    Capacity {
        /// Step at which the list was built.
        step: u64,
        /// Permanent id of the grain.
        grain: u32,
        /// Pairs it owns.
        count: usize,
        /// `simulation.max_neighbours`.
        capacity: usize,
    },
    /// The GPU's neighbour list outgrew what one storage binding of the device holds.
    #[error(
        "the GPU's neighbour list grew to {pairs} pairs by step {step}, above the {capacity} one storage binding of this device holds; fix: lower simulation.skin, run fewer grains, or run with --backend cpu"
    )]
    PairBuffers {
        /// Step at which it was seen.
        step: u64,
        /// Pairs the list needed.
        pairs: u64,
        /// Pairs the buffers held.
        capacity: u64,
    },
    /// The GPU had not the memory to grow its pair buffers.
    #[error("the GPU ran out of memory at step {step} growing its pair buffers to {pairs} pairs ({mib:.0} MiB): {reason}; fix: run fewer grains on this device, lower simulation.skin, or run with --backend cpu")]
    DeviceMemory {
        /// Step at which it was seen.
        step: u64,
        /// Pairs the buffers were to hold.
        pairs: u64,
        /// The new pair buffers' size (MiB).
        mib: f64,
        /// The driver's reason.
        reason: String,
    },
    /// The GPU failed to answer a readback (device lost, mapping refused).
    #[error("the GPU failed while reading back {what}: {reason}; fix: check the GPU driver (a device lost after a long dispatch is often the driver's watchdog) or run with --backend cpu")]
    Device {
        /// What was being read.
        what: String,
        /// The driver's reason.
        reason: String,
    },
    /// The state became non-finite, overlaps ran away, or energy grew with no input.
    #[error("unstable at step {step} (t = {time:.6e} s): {what} (grain {grain}); fix: lower simulation.dt to {suggested_dt:.3e} s or less{also}")]
    Unstable {
        /// Step at which it was seen.
        step: u64,
        /// Simulated time (s).
        time: f64,
        /// What was seen.
        what: String,
        /// Permanent id of the grain concerned.
        grain: u32,
        /// A step that should be stable (s).
        suggested_dt: f64,
        /// A second fix, when the step may not be the cause ("" otherwise), starting with ", ".
        also: &'static str,
    },
    /// A grain touched a mesh wall at more places than a grain keeps ([`crate::mesh`]).
    #[error("step {step}: grain {grain} touches mesh wall {wall} at more than {max} places, or more than {raw} of its triangles lie within the grain; fix: use a mesh whose triangles are at least as large as the grains and without pits narrower than a grain")]
    MeshContacts {
        /// Step at which it was seen.
        step: u64,
        /// Permanent id of the grain.
        grain: u32,
        /// The wall's name.
        wall: String,
        /// Distinct contacts a grain keeps with one mesh.
        max: usize,
        /// Triangles within a grain a mesh may have.
        raw: usize,
    },
    /// The processes of a run over MPI disagree on the state or its messages: a bug of grains,
    /// not of the scene or its step.
    #[error("processes disagree at step {step}: {what}; fix: report this as a bug, with the scene and the process count (the run on one process does not meet it)")]
    Internal {
        /// Step at which it was seen.
        step: u64,
        /// What was seen, naming the process.
        what: String,
    },
}

/// Force on one wall and, for the piston, its state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WallStats {
    /// Wall name.
    pub name: String,
    /// Total force the grains exert on the wall (N).
    pub force: [f64; 3],
    /// Grains touching it.
    pub contacts: u64,
    /// Servo walls: the plane's coordinate along its axis (m).
    pub position: Option<f64>,
    /// Servo walls: the pressure the grains exert on it (Pa).
    pub pressure: Option<f64>,
}

/// The piston's state.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PistonStats {
    /// Height (m).
    pub z: f64,
    /// Vertical velocity (m/s).
    pub velocity: f64,
    /// Target pressure (Pa).
    pub target_pressure: f64,
    /// Pressure the grains exert on it: upward grain force / area (Pa).
    pub pressure: f64,
}

/// Statistics read back every `stats_interval` steps.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Steps taken since the start.
    pub step: u64,
    /// Simulated time (s).
    pub time: f64,
    /// Translational kinetic energy (J).
    pub ke_translational: f64,
    /// Rotational kinetic energy (J).
    pub ke_rotational: f64,
    /// Elastic energy in the normal springs of touching pairs and wall contacts (J).
    pub elastic_energy: f64,
    /// Potential energy of the liquid bridges (J, negative: they pull; 0 without liquid).
    #[serde(default)]
    pub capillary_energy: f64,
    /// Gravitational potential energy `-sum m g.r` (J).
    pub gravity_energy: f64,
    /// Kinetic energy of the piston (J).
    pub piston_ke: f64,
    /// Work done on the system by the piston's target pressure since the start (J).
    pub external_work: f64,
    /// Total linear momentum of the grains (kg m/s).
    pub momentum: [f64; 3],
    /// Total angular momentum of the grains about the origin (kg m^2/s).
    pub angular_momentum: [f64; 3],
    /// Grain-grain pairs in the neighbour list (touching or within the skin); 0 when read
    /// from a checkpoint written before grains counted them.
    #[serde(default)]
    pub pairs: u64,
    /// Grain-grain pairs touching.
    pub contacts: u64,
    /// Grain-wall contacts.
    pub wall_contacts: u64,
    /// Touching pairs whose damping the no-pull clamp cut off at the last force evaluation.
    pub clamped: u64,
    /// Contacts (grain-grain and grain-wall) on their Coulomb limit at the last force
    /// evaluation; 0 in checkpoints written before grains counted them.
    #[serde(default)]
    pub sliding: u64,
    /// Contacts in Oquendo et al.'s rolling regime at full rolling friction at the last force
    /// evaluation (the rest of the touching contacts stick).
    #[serde(default)]
    pub rolling: u64,
    /// Mean grain-grain contacts per grain, `2 contacts / N`.
    pub coordination: f64,
    /// Largest overlap over the smaller radius of the pair (-).
    pub max_overlap: f64,
    /// Grain with the largest overlap.
    pub max_overlap_grain: u32,
    /// Mean |net force| on a grain over mean |contact force| (-); 0 when nothing acts,
    /// infinite when forces act and no grain touches (JSON writes it `null`).
    #[serde(deserialize_with = "infinite_if_null")]
    pub unbalanced_force: f64,
    /// The same over the loaded grains only (rattlers left out).
    #[serde(default, deserialize_with = "infinite_if_null")]
    pub unbalanced_force_loaded: f64,
    /// Rattlers: grains with fewer than [`RATTLER_CONTACTS`] contacts (pushing grain-grain
    /// contacts and touching walls); 0 in checkpoints from before they were counted.
    #[serde(default)]
    pub rattlers: u64,
    /// Translational kinetic energy of the rattlers (J).
    #[serde(default)]
    pub ke_rattlers: f64,
    /// First grain whose position or velocity is not finite.
    pub non_finite_grain: Option<u32>,
    /// Neighbour-list rebuilds since the start.
    pub rebuilds: u64,
    /// Liquid bridges (capillary scenes).
    pub bridges: u64,
    /// Liquid held in bridges (m^3).
    pub liquid_in_bridges: f64,
    /// Liquid held on grains, waiting for their next bridges (m^3).
    pub liquid_on_grains: f64,
    /// Per-wall forces.
    pub walls: Vec<WallStats>,
    /// The piston, if any.
    pub piston: Option<PistonStats>,
    /// Contact dynamics: what its solver did since the last read (absent for DEM).
    #[serde(default)]
    pub solver: Option<SolverStats>,
    /// Grains in play: all but those an inlet has yet to put into play and those an outlet
    /// took out ([`crate::flow`]); 0 in checkpoints written before grains counted them.
    #[serde(default)]
    pub grains: u64,
    /// The inlets' and outlets' running totals, in the scene's order (inlets first), where the
    /// scene has any: the host loop fills them in.
    #[serde(default)]
    pub flow: Vec<FlowCount>,
}

/// What an inlet has put into play, or an outlet taken out of it, since the start.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FlowCount {
    /// The inlet's or outlet's name.
    pub name: String,
    /// Grains.
    pub grains: u64,
    /// Their mass (kg).
    pub mass: f64,
    /// The mechanical energy they brought into play (J; negative for what an outlet took out):
    /// kinetic and gravitational (`-m g.x`), as each went in or out.
    #[serde(default)]
    pub energy: f64,
}

/// What contact dynamics' solver did over the steps since the last statistics read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolverStats {
    /// Steps solved.
    pub steps: u64,
    /// Steps whose solve hit `contact_dynamics.max_iterations` before the tolerance.
    pub unconverged_steps: u64,
    /// Most Gauss-Seidel sweeps a step took.
    pub max_iterations: u32,
    /// Mean sweeps per step.
    pub mean_iterations: f64,
    /// Largest quadratic norm of the last sweep a step's solve ended with (-; the stopping
    /// test's measure, `grains::cd`).
    pub sweep_norm: f64,
    /// The last step's force balance (see `grains::cd::SolveReport::unbalanced`).
    pub unbalanced: f64,
    /// Steps solved since the run started.
    #[serde(default)]
    pub steps_total: u64,
    /// Of those, the steps whose solve hit the cap.
    #[serde(default)]
    pub unconverged_total: u64,
    /// Contact updates (each step's contacts times its sweeps) summed over the steps since the
    /// last read: the solver's work.
    #[serde(default)]
    pub contact_updates: u64,
    /// The largest residuals a step's solve ended with since the last read.
    #[serde(default)]
    pub residuals: Residuals,
}

/// How far a contact-dynamics step's impulses are from the contact laws (`grains::cd`'s
/// residual module): each contact's correction its local problem would still make, in velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Residuals {
    /// Largest normal residual: interpenetration (or pull) speed left at a contact (m/s).
    pub normal: f64,
    /// Largest tangential residual: slip speed left against Coulomb's law (m/s).
    pub tangential: f64,
    /// Quadratic norm (-).
    pub quadratic: f64,
    /// Maximum norm (-).
    pub maximum: f64,
}

impl Residuals {
    /// The larger of each residual of `self` and `other`.
    pub fn max(self, other: Residuals) -> Residuals {
        Residuals { normal: self.normal.max(other.normal), tangential: self.tangential.max(other.tangential), quadratic: self.quadratic.max(other.quadratic), maximum: self.maximum.max(other.maximum) }
    }
}


/// Grains with fewer contacts than this are rattlers: they carry no load, and a rattler
/// bouncing in its cage says nothing about whether the packing stands (shared with WGSL
/// `RATTLER_CONTACTS`).
pub const RATTLER_CONTACTS: u64 = 2;

/// The unbalanced-force ratio: mean |net force| over `grains` (the summed `net` N) against the
/// mean |contact force| (`contact_force` N summed over `contact_ends`, each contact counted
/// once per grain it touches); 0 when nothing acts, infinite when forces act without contacts.
pub fn unbalanced(net: f64, grains: f64, contact_force: f64, contact_ends: u64) -> f64 {
    if contact_ends == 0 || grains <= 0.0 {
        if net > 0.0 { f64::INFINITY } else { 0.0 }
    } else {
        (net / grains) / (contact_force / contact_ends as f64)
    }
}

/// A ratio JSON holds as `null` where it was infinite ([`unbalanced`] with forces and no
/// contact), read back as infinite: a checkpoint written while grains fly resumes.
pub fn infinite_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
}

/// The coordination number `2 contacts / grains` (-); 0 without grains (all of them waiting
/// at an inlet, or gone through an outlet).
pub fn coordination(contacts: u64, grains: f64) -> f64 {
    if grains > 0.0 { 2.0 * contacts as f64 / grains } else { 0.0 }
}

/// Contacts counted per tangential regime.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegimeCounts {
    /// On the Coulomb limit.
    pub sliding: u64,
    /// At full rolling friction.
    pub rolling: u64,
}

impl RegimeCounts {
    /// Counts one contact.
    #[inline(always)]
    pub fn count(&mut self, r: crate::model::Regime) {
        self.sliding += (r == crate::model::Regime::Sliding) as u64;
        self.rolling += (r == crate::model::Regime::Rolling) as u64;
    }
    /// Adds another count.
    pub fn add(&mut self, o: RegimeCounts) {
        self.sliding += o.sliding;
        self.rolling += o.rolling;
    }
}

impl Stats {
    /// Touching contacts, grain-grain and grain-wall.
    pub fn all_contacts(&self) -> u64 {
        self.contacts + self.wall_contacts
    }
    /// Fraction of the touching contacts on their Coulomb limit (-); 0 without contacts.
    pub fn sliding_fraction(&self) -> f64 {
        if self.all_contacts() == 0 { 0.0 } else { self.sliding as f64 / self.all_contacts() as f64 }
    }

    /// Kinetic energy, translational and rotational (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.ke_translational + self.ke_rotational
    }
    /// Kinetic + elastic + capillary + gravitational + piston kinetic energy minus the external
    /// work (J): constant without dissipation, never growing with it (a bridge that forms
    /// lowers it).
    pub fn mechanical_energy(&self) -> f64 {
        self.kinetic_energy() + self.elastic_energy + self.capillary_energy + self.gravity_energy + self.piston_ke - self.external_work
    }
}

/// An engine's state as named arrays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EngineState {
    /// Real arrays (f64; f32 engines widen exactly).
    pub reals: BTreeMap<String, Vec<f64>>,
    /// Integer arrays (u64; signed values stored as their two's-complement bits).
    pub ints: BTreeMap<String, Vec<u64>>,
}

impl EngineState {
    /// Stores a real array.
    pub fn put_reals(&mut self, name: &str, v: impl IntoIterator<Item = f64>) {
        self.reals.insert(name.to_string(), v.into_iter().collect());
    }
    /// Stores an integer array.
    pub fn put_ints(&mut self, name: &str, v: impl IntoIterator<Item = u64>) {
        self.ints.insert(name.to_string(), v.into_iter().collect());
    }
    /// A real array of `len` values.
    pub fn reals(&self, name: &str, len: usize) -> anyhow::Result<&[f64]> {
        let v = self.reals.get(name).with_context(|| missing(name))?;
        if v.len() != len {
            bail!("the checkpoint's `{name}` holds {} values, this scene needs {len}", v.len());
        }
        Ok(v)
    }
    /// An integer array of `len` values (any length when `len` is `None`).
    pub fn ints(&self, name: &str, len: Option<usize>) -> anyhow::Result<&[u64]> {
        let v = self.ints.get(name).with_context(|| missing(name))?;
        if let Some(len) = len.filter(|&l| l != v.len()) {
            bail!("the checkpoint's `{name}` holds {} values, this scene needs {len}", v.len());
        }
        Ok(v)
    }
}

/// The error for an array a checkpoint lacks: it was written by another version.
fn missing(name: &str) -> String {
    format!("the checkpoint has no `{name}`: another version of grains wrote it; fix: run the scene again from its start with this version")
}

/// A grain an inlet puts into play ([`Engine::insert_grains`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Insertion {
    /// Its permanent id: a grain waiting out of play.
    pub id: u32,
    /// Where its centre goes (m).
    pub position: DVec3,
    /// Its velocity (m/s).
    pub velocity: DVec3,
}

/// Where an engine records a grain taken into or out of play as kept at the last neighbour
/// build (m, each axis): far from any grain, so that the next rebuild check finds it moved
/// and rebuilds (its square, 3e36 m^2, is still finite in f32).
pub const FAR_BUILT_AT: f32 = 1.0e18;

/// A backend the host loop can drive.
pub trait Engine {
    /// "cpu" or "gpu".
    fn backend(&self) -> &'static str;
    /// "f32" or "f64".
    fn precision(&self) -> &'static str;
    /// Number of grains the engine holds, in play or not ([`Stats::grains`] counts those in
    /// play).
    fn grain_count(&self) -> usize;
    /// Steps taken so far.
    fn steps(&self) -> u64;
    /// Simulated time (s).
    fn time(&self) -> f64;
    /// Advances `n` steps.
    fn advance(&mut self, n: u64) -> Result<(), SimError>;
    /// Reads the statistics back.
    fn stats(&mut self) -> Result<Stats, SimError>;
    /// Copies the grain state out.
    fn frame(&self, contacts: bool) -> Result<Frame, SimError>;
    /// Sets the piston's target pressure (Pa); no effect without a piston.
    fn set_piston_pressure(&mut self, pressure: f64);
    /// The engine's whole state for a checkpoint.
    fn save(&self) -> Result<EngineState, SimError>;
    /// Restores a state `save` returned, for the same scene, backend and precision.
    fn restore(&mut self, state: &EngineState) -> anyhow::Result<()>;
    /// Sets the servo walls' target pressure (Pa, when given) and switches the z walls to a
    /// fixed strain rate (1/s, positive closing) or back to pressure control (`None`).
    fn set_servo(&mut self, pressure: Option<f64>, axial_strain_rate: Option<f64>);
    /// Sets wall `wall` (an index into the scene's walls: a plane or a cylinder, not the piston
    /// or a servo plane) moving as `drive` says from now on.
    fn set_wall_drive(&mut self, wall: usize, drive: &crate::scene::WallDrive);
    /// Adds wall `wall` (index into the scene's walls) back among those grains meet
    /// (`present`), or takes it away: it then touches no grain, its contacts' history is
    /// forgotten, and it keeps its motion.
    fn set_wall_present(&mut self, wall: usize, present: bool);
    /// Takes the grains of permanent ids `ids` out of play (an outlet removed them): each keeps
    /// its slot and its id, and from the next step is in no pair, touches no wall, feels no
    /// gravity, stops, and leaves the frames and the statistics. The next step rebuilds the
    /// neighbour list. Ids out of play already, or of no grain, are ignored. An error where
    /// the engine cannot (contact dynamics).
    fn remove_grains(&mut self, ids: &[u32]) -> anyhow::Result<()>;
    /// Puts grains waiting out of play into play (an inlet inserted them) where each
    /// [`Insertion`] says, spinning not, with their weight as their load; the next step
    /// rebuilds the neighbour list. The caller places them clear of the grains and walls. An
    /// error where the engine cannot (contact dynamics).
    fn insert_grains(&mut self, grains: &[Insertion]) -> anyhow::Result<()>;
    /// Wets the sample with `volume` (m^3) of liquid: shared among the pairs closer than their
    /// rupture distance in proportion to their reduced diameter (Richefeu et al. (2009), docs/physics.md).
    fn wet(&mut self, volume: f64) -> anyhow::Result<()>;
    /// Moves the piston to height `z` (m) and stops it; no effect without a piston. The host
    /// places it where it touches nothing yet, so the last forces stay valid.
    fn place_piston(&mut self, z: f64);
    /// Bytes of the arrays and buffers the engine holds now (allocated, not just used).
    fn memory_bytes(&self) -> u64;
    /// Starts or stops timing each phase of the step; a no-op where the backend cannot.
    fn set_profiling(&mut self, _on: bool) {}
    /// Kernel dispatches recorded since the engine was made, where the backend records them
    /// (the GPU); `None` otherwise.
    fn dispatches(&self) -> Option<u64> {
        None
    }
    /// Bytes each phase of a step that keeps its neighbour list moves to and from memory,
    /// counted from the arrays it reads and writes (empty where the engine does not count).
    fn step_traffic(&self) -> Vec<(&'static str, u64)> {
        Vec::new()
    }
    /// Seconds spent in each phase while profiling, by phase name; empty where the backend
    /// does not time its phases.
    fn phase_seconds(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::Stats;

    /// Checkpoints written before `Stats::pairs` existed still resume.
    #[test]
    fn statistics_without_the_pair_count_still_read() {
        let mut json: serde_json::Value = serde_json::to_value(Stats { contacts: 7, ..Default::default() }).unwrap();
        json.as_object_mut().unwrap().remove("pairs");
        let s: Stats = serde_json::from_value(json).expect("an older header reads");
        assert_eq!((s.contacts, s.pairs), (7, 0));
    }
}
