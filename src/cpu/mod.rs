//! The CPU engine: the step's kernels as Rust twins, one invocation per grain or pair, mapped
//! over threads with rayon. Generic over `f32` and `f64` (the reference).
//!
//! One step runs the operations of [`crate::schedule`]: kicks, drifts (with the walls'
//! controllers), the rebuild check (`hash_cells`, `detect_pairs`, `remap_history` when a grain
//! has moved half the skin) and the force evaluations (`update_bridges`, `pair_force`,
//! `gather`, `wall_contacts`). Results are bitwise identical for any thread count: every
//! invocation writes its own output, and reductions combine fixed chunks in order.

mod bridges;
mod built_at;
mod forces;
mod gather;
mod controllers;
mod integrate;
mod lanes;
mod pair_force;
mod play;
// What a run over several processes reads and writes of the engine (ranks/).
#[cfg(feature = "mpi")]
mod parts;
mod rebuild;
mod reorder;
mod setup;
mod snapshot;
mod split;
pub mod simd;
// One run over several processes: the engine's step with hooks between its operations.
#[cfg(feature = "mpi")]
pub mod ranks;
mod stats;
mod step;
mod traffic;
mod wall_contacts;
mod wall_springs;
mod wall_sums;
mod warm;

#[cfg(feature = "mpi")]
pub(crate) use parts::{state_of_rows, touch_of_row, touches_state, RowWidths, Rows, BRIDGE_ROW, TOUCH_ROW};
#[cfg(feature = "mpi")]
pub(crate) use wall_contacts::WallTouch as WallContact;
use crate::state::{allocated, renew, walls_reals, Body, Counts, ForceContext, HistorySlots, ImageCount, Images, Load, PairFlags, PairList, PairReports, Props, WallState};

use rebuild::kept_or_found;
use crate::engine::EngineState;
use crate::engine::{ContactRecord, Engine, Frame, Insertion, PistonStats, RegimeCounts, SimError, Stats, WallStats, RATTLER_CONTACTS};
use crate::model::{capillary_potential, share_liquid, within_rupture, CohesionLaw, ContactModel, PairCoeffs};
use crate::periodic::Periodic;
use crate::position;
use crate::real::{Real, Vec3};
use crate::schedule::{Op, Schedule, Sweep, Trace};
use crate::scene::{Scene, WallShape};
use crate::walls::{WallGeom, SERVO_RELAXATION};
use controllers::{Piston, Servo};
use crate::state::crew::{Crew, Who};
use gather::gather_block;
use crate::state::{CellGrid, Grids};
use pair_force::{owner_block, OwnerBlock, TaskScratch};
use crate::state::profile::{Phase, PhaseClock};
use reorder::Renumbering;
use rayon::prelude::*;
use std::borrow::Cow;
use crate::state::reduce::{chunked, CHUNK, PAR_MIN_ITEMS};
use wall_contacts::{wall_block, WallTouch};
use wall_springs::WallSprings;

/// The CPU engine in precision `T`.
pub struct CpuEngine<T: Real> {
    model: ContactModel<T>,
    slots: HistorySlots,
    coeffs: Vec<PairCoeffs<T>>,
    n_materials: usize,
    gravity: Vec3<T>,
    dt: T,
    /// Step suggested when the state turns non-finite (s).
    suggested_dt: f64,
    schedule: Schedule,
    /// The operations run, when tracing.
    trace: Trace,
    skin: T,
    /// Distance beyond contact that pair detection reaches: the skin plus, for capillary
    /// scenes, the rupture distance of the largest bridge (m).
    detect_reach: T,
    cutoff: T,
    /// `simulation.max_neighbours`: the pairs a grain of the smallest size may own
    /// ([`crate::state::owner_capacity`]).
    capacity: usize,
    /// The smallest grain's radius (m, f32 as the GPU holds it), for the capacities.
    r_min: f32,
    /// Largest bridge volume (m^3).
    bridge_cap: T,
    /// Liquid on each grain waiting for its next bridge (m^3); empty without cohesion.
    liquid: Vec<T>,
    periodic: Periodic<T>,
    /// Rebuilds between renumberings of the slots in cell order (0: never).
    reorder_every: u64,
    // Grains, indexed by slot (renumbered in cell order by `reorder`).
    /// The permanent id of each slot.
    id: Vec<u32>,
    /// The slot of each permanent id where a run over several processes keeps it
    /// ([`Self::keep_slots`]: they look grains up by id every step); empty otherwise, and
    /// [`Self::slots`] finds it from `id` when a pass wants it (4 bytes a grain saved).
    slot: Vec<u32>,
    body: Vec<Body<T>>,
    /// What rounding took off each `body[i].pos` ([`crate::position`]): the grain is at
    /// `pos + residual`. Empty in f64, whose positions are plain.
    residual: Vec<Vec3<T>>,
    prop: Vec<Props<T>>,
    /// Material index by slot; empty in a scene of one material (all 0).
    material: Vec<u32>,
    load: Vec<Load<T>>,
    /// Each grain's position at the last neighbour build, in f32 ([`built_at`]).
    built_at: Vec<Vec3<f32>>,
    /// Periods each grain has been wrapped by, along the wrapping axes.
    image: Images,
    orientation: Option<Vec<[T; 4]>>,
    // Walls.
    walls: Vec<WallState<T>>,
    /// The mesh walls' surfaces, by [`WallGeom::Mesh`]'s index.
    meshes: Vec<crate::mesh::MeshSurface<T>>,
    /// A grain that touched a mesh at more places than it has slots, at the last force
    /// evaluation: the run stops.
    mesh_overflow: Option<u32>,
    wall_names: Vec<String>,
    piston: Option<Piston<T>>,
    servo: Option<Servo<T>>,
    /// The grain-wall contacts' history, for the grains a wall can reach.
    wall_springs: WallSprings<T>,
    /// The grain-wall contacts of the last force evaluation, by grain id, then wall (their
    /// loads went straight into the grains' loads).
    wall_touches: Vec<WallTouch<T>>,
    wall_reaction: Vec<Vec3<T>>,
    wall_count: Vec<u64>,
    /// Wall contacts sliding and rolling at the last force evaluation.
    wall_regimes: RegimeCounts,
    /// Sum over each wall's contacts of the normal tangent stiffness (N/m) and damping
    /// coefficient (N s/m).
    wall_response: Vec<(T, T)>,
    /// Power (W) each wall's spin gives the grains at the last force evaluation.
    wall_power: Vec<T>,
    /// The walls a prescribed motion may move (`crate::scene::WallDrive`: every wall but the
    /// piston and the servo box's planes); each drift moves those that move.
    drivable: Vec<usize>,
    // Pairs.
    pairs: PairList,
    hist: Vec<T>,
    /// The partner's share of each pair's force and torque at the last evaluation (the
    /// owner's went straight into its load).
    share: Vec<Load<T>>,
    /// What the statistics and frames read of each pair's last evaluation.
    report: PairReports<T>,
    /// Each pair's force on its owner (N), for the laws whose force on the owner is not the
    /// partner's reversed ([`crate::model::ContactModel::keeps_both_forces`]); empty otherwise.
    force_i: Vec<Vec3<T>>,
    // Clocks.
    /// Largest squared displacement of a grain since the last build (m^2), as of the last drift.
    max_moved2: T,
    /// True when the current step's first sweep, a kick and a drift, already ran in the step
    /// before's gather sweep ([`Self::step_in_run`]).
    carried: bool,
    /// The largest distance between a grain's kept position at the last build and the one
    /// recorded (m; [`built_at`]), added to every displacement found since.
    built_margin: T,
    forces_valid: bool,
    step: u64,
    time: f64,
    rebuilds: u64,
    /// Renumberings that moved a grain.
    renumberings: u64,
    external_work: f64,
    /// Time per phase, when profiling.
    clock: PhaseClock<Phase>,
    /// Whether a run's steps go on the pool or on the calling thread alone ([`crate::state::crew`]).
    crew: Crew,
}

impl<T: Real> CpuEngine<T> {

    /// Renumberings so far that moved a grain.
    pub fn renumberings(&self) -> u64 {
        self.renumberings
    }

    /// The slot of each permanent id: kept ([`Self::keep_slots`]) or found from `id`.
    fn slots(&self) -> Cow<'_, [u32]> {
        kept_or_found(&self.slot, &self.id)
    }

    /// The lowest permanent id of a grain whose state is not finite.
    fn first_non_finite(&self) -> Option<u32> {
        // In slot order, which streams, not id order, which jumps about the grains.
        self.body.iter().zip(&self.id).filter(|(b, _)| !(b.pos.is_finite() && b.vel.is_finite() && b.omega.is_finite())).map(|(_, &id)| id).min()
    }

    fn non_finite_error(&self) -> SimError {
        SimError::Unstable {
            step: self.step,
            time: self.time,
            what: "non-finite position or velocity".into(),
            grain: self.first_non_finite().unwrap_or(0),
            suggested_dt: self.suggested_dt,
            also: "",
        }
    }

    /// The time step (s).
    pub fn dt(&self) -> f64 {
        self.dt.f64()
    }

    /// `v`'s items (one per slot) in permanent-id order.
    fn by_id<X: Copy>(&self, v: &[X]) -> Vec<X> {
        self.slots().iter().map(|&s| v[s as usize]).collect()
    }

    /// Grain states, in permanent-id order (positions to this precision: see [`Self::positions`]).
    pub fn bodies(&self) -> Vec<Body<T>> {
        self.by_id(&self.body)
    }

    /// Grain positions in permanent-id order (m, f64): `pos + residual` where compensated.
    pub fn positions(&self) -> Vec<glam::DVec3> {
        self.slots().iter().map(|&s| position::absolute(self.body[s as usize].pos, position::residual_at(&self.residual, s as usize))).collect()
    }

    /// The separation `r_i - r_j` of slots `i` and `j` (m, minimum image, residuals included).
    #[inline]
    fn separation(&self, i: usize, j: usize) -> Vec3<T> {
        position::separation_of(&self.periodic, |k| self.body[k].pos, &self.residual, i, j)
    }

    /// Loads from the last force evaluation, in permanent-id order.
    pub fn loads(&self) -> Vec<Load<T>> {
        self.by_id(&self.load)
    }

    /// Orientation quaternions (scalar first) in permanent-id order, when tracked.
    pub fn orientations(&self) -> Option<Vec<[T; 4]>> {
        self.orientation.as_deref().map(|q| self.by_id(q))
    }

    /// The current pair list in permanent ids: `starts[id]..starts[id + 1]` index the
    /// partners' ids of the pairs grain `id` owns.
    pub fn pair_list(&self) -> (Vec<u32>, Vec<u32>) {
        let l = &self.pairs;
        let mut starts = vec![0u32];
        let mut partners = Vec::with_capacity(l.len());
        for &s in self.slots().iter() {
            let (a, b) = (l.owner_start[s as usize] as usize, l.owner_start[s as usize + 1] as usize);
            partners.extend(l.partner[a..b].iter().map(|&j| self.id[j as usize]));
            starts.push(partners.len() as u32);
        }
        (starts, partners)
    }

    /// The force pair `k` exerted on its owner at the last evaluation (N).
    fn owner_force(&self, k: usize) -> Vec3<T> {
        if self.force_i.is_empty() {
            -self.share[k].force
        } else {
            self.force_i[k]
        }
    }

    /// Overlap (m) and smaller radius (m) of grains `i` and `j`.
    fn pair_overlap(&self, i: usize, j: usize) -> (T, T) {
        let d = self.separation(i, j).norm();
        (self.prop[i].radius + self.prop[j].radius - d, self.prop[i].radius.min(self.prop[j].radius))
    }
}

/// Grains per block of the gather's sweep: a multiple of [`split::ALIGN`], so that a block
/// starts where a run of wall-spring candidates does.
const SWEEP_BLOCK: usize = 16 * split::ALIGN;

impl<T: Real> Engine for CpuEngine<T> {
    fn backend(&self) -> &'static str {
        "cpu"
    }
    fn precision(&self) -> &'static str {
        T::NAME
    }
    fn grain_count(&self) -> usize {
        self.body.len()
    }
    fn steps(&self) -> u64 {
        self.step
    }
    fn time(&self) -> f64 {
        self.time
    }
    fn advance(&mut self, n: u64) -> Result<(), SimError> {
        let timed = rayon::current_num_threads() > 1;
        warm::with_warm_pool(|warm| {
            for k in 0..n {
                if self.crew.who() == Who::Pool {
                    warm.rearm();
                }
                if timed {
                    self.crew.step_starts();
                }
                let rebuilds = self.rebuilds;
                self.step_in_run(k + 1 < n)?;
                self.crew.step_ends(self.rebuilds != rebuilds);
            }
            Ok(())
        })
    }

    fn set_piston_pressure(&mut self, pressure: f64) {
        if let Some(p) = &mut self.piston {
            p.pressure = T::of(pressure);
        }
    }

    fn set_wall_drive(&mut self, wall: usize, drive: &crate::scene::WallDrive) {
        debug_assert!(self.drivable.contains(&wall), "wall {wall} is moved by a controller");
        let turned = self.walls[wall].turns;
        self.walls[wall].drive(Vec3::of(drive.velocity), Vec3::of(drive.angular_velocity), drive.turns);
        if self.walls[wall].turns && !turned {
            self.wall_springs.expire();
        }
    }

    fn set_wall_present(&mut self, wall: usize, present: bool) {
        self.walls[wall].present = present;
    }

    fn remove_grains(&mut self, ids: &[u32]) -> anyhow::Result<()> {
        self.take_out_of_play(ids);
        Ok(())
    }

    fn insert_grains(&mut self, grains: &[Insertion]) -> anyhow::Result<()> {
        self.put_into_play(grains);
        Ok(())
    }

    fn set_servo(&mut self, pressure: Option<f64>, axial_strain_rate: Option<f64>) {
        if let Some(s) = &mut self.servo {
            if let Some(p) = pressure {
                s.pressure = T::of(p);
            }
            s.strain_rate = axial_strain_rate.map(T::of);
        }
    }

    fn wet(&mut self, volume: f64) -> anyhow::Result<()> {
        let CohesionLaw::Capillary { theta, .. } = self.model.cohesion else {
            anyhow::bail!("the scene wets the sample but has no capillary cohesion; fix: set model.cohesion = \"capillary\"");
        };
        let order = self.pairs.in_id_order(&self.slots());
        let pairs: Vec<(f64, f64, f64)> = order
            .iter()
            .map(|&(i, k)| {
                let (i, j) = (i as usize, self.pairs.partner[k as usize] as usize);
                (self.prop[i].radius.f64(), self.prop[j].radius.f64(), self.gap(i, j).f64())
            })
            .collect();
        let (shares, rest) = share_liquid(volume, &pairs, self.bridge_cap.f64(), theta.f64());
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        for (c, v) in shares {
            self.hist[order[c].1 as usize * stride + b] += T::of(v);
        }
        // What the bridges could not hold waits on the grains.
        let rest = T::of(rest / self.liquid.len() as f64);
        for l in &mut self.liquid {
            *l += rest;
        }
        self.forces_valid = false;
        Ok(())
    }

    fn stats(&mut self) -> Result<Stats, SimError> {
        Ok(self.statistics())
    }

    fn frame(&self, contacts: bool) -> Result<Frame, SimError> {
        Ok(self.snapshot(contacts))
    }

    fn save(&self) -> Result<EngineState, SimError> {
        Ok(self.save_state())
    }

    fn restore(&mut self, s: &EngineState) -> anyhow::Result<()> {
        self.restore_state(s)
    }

    fn memory_bytes(&self) -> u64 {
        let l = &self.pairs;
        let grains = allocated(&self.liquid) + allocated(&self.id) + allocated(&self.slot) + allocated(&self.body) + allocated(&self.residual) + allocated(&self.prop) + allocated(&self.material) + allocated(&self.load) + allocated(&self.built_at) + self.image.bytes();
        let ws = &self.wall_springs;
        let walls = allocated(&ws.candidate) + allocated(&ws.run_start) + allocated(&ws.springs) + allocated(&self.wall_touches) + self.orientation.as_ref().map_or(0, allocated);
        let pairs = allocated(&self.hist) + allocated(&self.share) + allocated(&self.report.f_n) + allocated(&self.report.f_c) + allocated(&self.report.flags) + allocated(&self.force_i) + allocated(&l.owner_start) + allocated(&l.partner) + allocated(&l.rev_start) + allocated(&l.rev_pair);
        grains + walls + pairs + allocated(&self.coeffs)
    }

    fn set_profiling(&mut self, on: bool) {
        self.clock.enable(on);
    }

    fn phase_seconds(&self) -> Vec<(&'static str, f64)> {
        self.clock.totals()
    }

    fn step_traffic(&self) -> Vec<(&'static str, u64)> {
        self.traffic()
    }

    fn place_piston(&mut self, z: f64) {
        if let Some(p) = self.piston {
            self.walls[p.wall].geom = WallGeom::Piston { z: T::of(z) };
            self.walls[p.wall].velocity = Vec3::ZERO;
        }
    }
}
