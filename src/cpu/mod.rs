//! The CPU engine: the step's kernels as Rust twins, one invocation per grain or pair, mapped
//! over threads with rayon. Generic over `f32` and `f64` (the reference).
//!
//! One step runs the operations of [`crate::schedule`]: kicks, drifts (with the walls'
//! controllers), the rebuild check (`hash_cells`, `detect_pairs`, `remap_history` when a grain
//! has moved half the skin) and the force evaluations (`update_bridges`, `pair_force`,
//! `gather`, `wall_contacts`). Results are bitwise identical for any thread count: every
//! invocation writes its own output, and reductions combine fixed chunks in order.

mod gather;
mod built_at;
mod controllers;
mod integrate;
mod lanes;
mod pair_force;
// What a run over several processes reads and writes of the engine (ranks/).
#[cfg(feature = "mpi")]
mod parts;
mod reorder;
mod snapshot;
mod split;
pub mod simd;
// One run over several processes: the engine's step with hooks between its operations.
#[cfg(feature = "mpi")]
pub mod ranks;
mod stats;
mod traffic;
mod wall_contacts;
mod wall_springs;
mod warm;

pub use integrate::rotate;
#[cfg(feature = "mpi")]
pub(crate) use parts::{state_of_rows, touch_of_row, touches_state, RowWidths, Rows, BRIDGE_ROW, TOUCH_ROW};
#[cfg(feature = "mpi")]
pub(crate) use wall_contacts::WallTouch as WallContact;
use crate::state::{allocated, renew, Body, Counts, ForceContext, HistorySlots, ImageCount, Images, Load, PairFlags, PairList, PairReports, Props, WallState};

use crate::engine::EngineState;
use crate::engine::{ContactRecord, Engine, Frame, PistonStats, RegimeCounts, SimError, Stats, WallStats, RATTLER_CONTACTS};
use crate::model::{capillary_potential, normal_potential, share_liquid, within_rupture, CohesionLaw, ContactModel, PairCoeffs};
use crate::periodic::Periodic;
use crate::position;
use crate::real::{Real, Vec3};
use crate::schedule::{Op, Schedule, Sweep, Trace};
use crate::scene::{Scene, WallShape};
use crate::walls::{WallGeom, SERVO_RELAXATION};
use controllers::{Piston, Servo};
use gather::gather_block;
use crate::state::{hash_cells, CellGrid};
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
    capacity: usize,
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
}

impl<T: Real> CpuEngine<T> {
    /// Sets up the engine for a scene and builds the first neighbour list.
    pub fn new(scene: &Scene) -> Result<Self, SimError> {
        let n_materials = scene.materials.len();
        let mut coeffs = Vec::with_capacity(n_materials * n_materials);
        for a in &scene.materials {
            for b in &scene.materials {
                coeffs.push(PairCoeffs::mix(&a.constants, &b.constants, &scene.model));
            }
        }
        let g = &scene.grains;
        let n = g.len();
        let (positions, residual): (Vec<Vec3<T>>, Vec<Vec3<T>>) = g.position.iter().map(|&x| position::split(x)).unzip();
        let body: Vec<Body<T>> = (0..n).map(|i| Body { pos: positions[i], vel: Vec3::of(g.velocity[i]), omega: Vec3::of(g.angular_velocity[i]) }).collect();
        let residual = if T::COMPENSATED { residual } else { Vec::new() };
        let prop: Vec<Props<T>> = (0..n)
            .map(|i| Props::sphere(g.radius[i], g.mass[i]))
            .collect();
        let r_max = g.radius.iter().copied().fold(0.0, f64::max);
        let model = scene.model.cast::<T>();
        let slots = HistorySlots::new(model.history_layout());
        let mut piston = None;
        let walls: Vec<WallState<T>> = scene
            .walls
            .iter()
            .enumerate()
            .map(|(w, wall)| {
                if let WallShape::Piston { pressure, mass, area, .. } = wall.shape {
                    piston = Some(Piston { wall: w, mass: T::of(mass), area: T::of(area), pressure: T::of(pressure) });
                }
                WallState { geom: WallGeom::of(&wall.shape), velocity: Vec3::ZERO, material: wall.material as u32 }
            })
            .collect();
        let n_walls = walls.len();
        let mut engine = CpuEngine {
            model,
            slots,
            coeffs,
            n_materials,
            gravity: Vec3::of(scene.gravity),
            dt: T::of(scene.time_step.dt),
            suggested_dt: scene.time_step.suggested_after_instability(),
            schedule: Schedule::new(scene.integrator, scene.time_step.dt),
            trace: Trace::default(),
            skin: T::of(scene.skin),
            detect_reach: T::of(scene.skin + scene.bridges.reach),
            cutoff: T::of(2.0 * r_max + scene.skin + scene.bridges.reach),
            capacity: scene.max_neighbours,
            bridge_cap: T::of(scene.bridges.volume_cap),
            liquid: if slots.layout.bridge { vec![T::ZERO; n] } else { Vec::new() },
            periodic: Periodic::of(&scene.periodic),
            reorder_every: scene.reorder_every,
            id: (0..n as u32).collect(),
            slot: Vec::new(),
            built_at: body.iter().map(|b| built_at::record(b.pos)).collect(),
            image: Images::new([0, 1, 2].map(|a| scene.periodic[a].is_some()), n),
            body,
            residual,
            prop,
            material: if n_materials > 1 { g.material.iter().map(|&m| m as u32).collect() } else { Vec::new() },
            load: vec![Load::default(); n],
            orientation: scene.track_orientation.then(|| vec![[T::ONE, T::ZERO, T::ZERO, T::ZERO]; n]),
            wall_names: scene.walls.iter().map(|w| w.name.clone()).collect(),
            walls,
            piston,
            servo: scene.servo.map(|s| Servo { walls: s.walls, pressure: T::of(s.pressure), gain: T::of(s.gain), max_speed: T::of(s.max_speed), strain_rate: None }),
            wall_springs: WallSprings::default(),
            wall_touches: Vec::new(),
            wall_reaction: vec![Vec3::ZERO; n_walls],
            wall_count: vec![0; n_walls],
            wall_regimes: RegimeCounts::default(),
            wall_response: vec![(T::ZERO, T::ZERO); n_walls],
            pairs: PairList::default(),
            hist: Vec::new(),
            share: Vec::new(),
            report: PairReports::default(),
            force_i: Vec::new(),
            max_moved2: T::ZERO,
            carried: false,
            built_margin: T::ZERO,
            forces_valid: false,
            step: 0,
            time: 0.0,
            rebuilds: 0,
            renumberings: 0,
            external_work: 0.0,
            clock: PhaseClock::default(),
        };
        engine.rebuild()?;
        Ok(engine)
    }

    /// Rebuilds the neighbour list now (`hash_cells`, `detect_pairs`, `remap_history`),
    /// carrying every contact's history over, and every `reorder_every` rebuilds renumbers the
    /// slots in cell order (`reorder`).
    pub fn rebuild(&mut self) -> Result<(), SimError> {
        let t = self.clock.start();
        if self.periodic.any() {
            let (p, axes) = (self.periodic, self.image.axes().to_vec());
            let wrapped = match self.image.counts_mut() {
                Counts::Narrow(c) => wrap_grains(&p, &mut self.body, &mut self.residual, c, &axes),
                Counts::Wide(c) => wrap_grains(&p, &mut self.body, &mut self.residual, c, &axes),
            };
            match wrapped {
                Ok(largest) => self.image.widen_for(largest),
                Err(slot) => {
                    return Err(SimError::Unstable {
                        step: self.step,
                        time: self.time,
                        what: format!("a grain crossed more than {} periods between two neighbour builds", Images::WIDEN_AT),
                        grain: self.id[slot],
                        suggested_dt: self.suggested_dt,
                        also: "",
                    })
                }
            }
        }
        // The grid lives for the rebuild alone (6 bytes a grain at the bed's density).
        let mut grid = CellGrid::default();
        if !hash_cells(&self.body, self.cutoff, &self.periodic, &mut grid) {
            return Err(self.non_finite_error());
        }
        self.clock.stop(Phase::Hash, t);
        let t = self.clock.start();
        let pairs = PairList::detect(&self.body, &self.residual, &self.prop, &self.id, &grid, &self.periodic, self.detect_reach, self.capacity)
            .map_err(|(i, count)| SimError::Capacity { step: self.step, grain: self.id[i], count, capacity: self.capacity })?;
        self.clock.stop(Phase::Detect, t);
        let t = self.clock.start();
        self.hist = crate::state::remap_all(&pairs, &self.pairs, &self.hist, &self.id, self.slots.stride);
        self.pairs = pairs;
        if self.reorder_every > 0 && self.rebuilds.is_multiple_of(self.reorder_every) {
            self.reorder(&grid);
        }
        self.pairs.build_reverse(&kept_or_found(&self.slot, &self.id));
        let n_pairs = self.pairs.len();
        renew(&mut self.share, n_pairs);
        self.report.renew(n_pairs, self.slots.layout.bridge);
        renew(&mut self.force_i, if self.model.keeps_both_forces() { n_pairs } else { 0 });
        let mut margin2 = T::ZERO;
        for (b, at) in self.body.iter().zip(self.built_at.iter_mut()) {
            *at = built_at::record(b.pos);
            margin2 = margin2.max((b.pos - built_at::widen(*at)).norm2());
        }
        // One root for all (it is monotonic and correctly rounded: the same bits).
        self.built_margin = margin2.sqrt();
        self.choose_wall_springs();
        self.rebuilds += 1;
        self.max_moved2 = T::ZERO;
        self.forces_valid = false;
        self.clock.stop(Phase::Remap, t);
        Ok(())
    }

    /// `reorder`: renumbers the slots in Z order of `grid`'s cells (see [`reorder`]).
    fn reorder(&mut self, grid: &CellGrid<T>) {
        let r = Renumbering::new(reorder::z_order(grid, &self.body));
        if r.is_identity() {
            return;
        }
        r.apply(&mut self.id);
        r.apply(&mut self.body);
        r.apply(&mut self.residual);
        r.apply(&mut self.prop);
        r.apply(&mut self.material);
        r.apply(&mut self.load);
        r.apply(&mut self.built_at);
        let width = self.image.width();
        match self.image.counts_mut() {
            Counts::Narrow(c) => r.apply_blocks(c, width),
            Counts::Wide(c) => r.apply_blocks(c, width),
        }
        r.apply(&mut self.liquid);
        self.wall_springs = self.wall_springs.renumbered(&r.from, self.walls.len() * self.slots.stride);
        if let Some(q) = &mut self.orientation {
            r.apply(q);
        }
        (self.pairs, self.hist) = r.apply_pairs(&self.pairs, &self.hist, self.slots.stride);
        self.refresh_slots();
        self.renumberings += 1;
    }

    /// Chooses the grains whose wall springs are kept ([`WallSprings::choose`]), from the
    /// positions of the last rebuild and the walls now.
    fn choose_wall_springs(&mut self) {
        let per_grain = self.walls.len() * self.slots.stride;
        self.wall_springs = WallSprings::choose(&self.built_at, &self.prop, &self.walls, self.skin, per_grain, &self.wall_springs);
    }

    /// Renumberings so far that moved a grain.
    pub fn renumberings(&self) -> u64 {
        self.renumberings
    }

    /// The slot of each permanent id: kept ([`Self::keep_slots`]) or found from `id`.
    fn slots(&self) -> Cow<'_, [u32]> {
        kept_or_found(&self.slot, &self.id)
    }

    /// Brings the kept slots of the ids, if kept, up to date with `id`.
    fn refresh_slots(&mut self) {
        if !self.slot.is_empty() {
            self.slot = slots_of(&self.id);
        }
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
    pub fn positions(&self) -> Vec<[f64; 3]> {
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

    /// Gap (m) between the surfaces of grains `i` and `j` (negative when they overlap).
    fn gap(&self, i: usize, j: usize) -> T {
        self.separation(i, j).norm() - self.prop[i].radius - self.prop[j].radius
    }

    /// `update_bridges`: ruptures bridges stretched past their rupture distance, returning
    /// their liquid to the two grains in equal halves, and forms bridges at new contacts from
    /// half of each grain's liquid (capped at the largest bridge volume). Liquid is conserved
    /// to round-off.
    ///
    /// Whether a pair ruptures or may form a bridge depends on its own gap and volume alone,
    /// so a parallel pass finds those events ([`Self::bridge_events`]); the liquid then moves
    /// serially, in canonical order, so that a grain forming several bridges in one step gives
    /// its liquid out in a fixed order (the same bits as one serial walk over every pair, which
    /// cost a quarter of a wet scene's step on two threads).
    fn update_bridges(&mut self) {
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        for (k, event) in self.bridge_events() {
            let k = k as usize;
            let (i, j) = self.pairs.grains_of(k);
            let (mut l_i, mut l_j) = (self.liquid[i], self.liquid[j]);
            self.hist[k * stride + b] = move_liquid(event, self.hist[k * stride + b], self.bridge_cap, &mut l_i, &mut l_j);
            (self.liquid[i], self.liquid[j]) = (l_i, l_j);
        }
    }

    /// The pairs whose bridge ruptures or may form at this evaluation, in canonical order
    /// (owner id, then partner id: the pair order within an owner); none without cohesion.
    fn bridge_events(&self) -> Vec<(u32, BridgeEvent)> {
        let CohesionLaw::Capillary { theta, .. } = self.model.cohesion else { return Vec::new() };
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        let events: Vec<Vec<(u32, BridgeEvent)>> = chunked(self.pairs.len(), |range| {
            range
                .clone()
                .zip(self.pairs.owners_of(range))
                .filter_map(|(k, i)| {
                    let (v, gap) = (self.hist[k * stride + b], self.gap(i, self.pairs.partner[k] as usize));
                    let event = if v > T::ZERO {
                        (!within_rupture(theta, v, gap)).then_some(BridgeEvent::Rupture)
                    } else {
                        (gap < T::ZERO).then_some(BridgeEvent::Touch)
                    };
                    event.map(|e| (k as u32, e))
                })
                .collect()
        });
        // Pair order by slot follows the numbering; the liquid moves in canonical order.
        let mut events: Vec<(u32, BridgeEvent)> = events.into_iter().flatten().collect();
        events.sort_by_key(|&(k, _)| (self.id[self.pairs.owner_of(k as usize)], k));
        events
    }

    /// Runs the force passes: `pair_force`, `gather`, `wall_contacts`; the springs advance by
    /// `elapsed` (s). In capillary scenes the step's hooks update the bridges just before.
    /// With `kick` (s), the grains are then kicked in the gather's sweep, each as soon as its
    /// load is whole (the piston's kick is left to the caller); with `carry`, each is then also
    /// kicked and drifted as [`Self::drift`] would (the grains alone: see [`Self::step_in_run`]).
    /// Returns the largest squared displacement since the last build that the carried drift
    /// found (zero without one).
    fn evaluate_forces(&mut self, elapsed: T, kick: Option<T>, carry: Option<Carry<T>>) -> T {
        if self.wall_springs.stale(&self.walls, self.skin) {
            self.choose_wall_springs();
        }
        let t = self.clock.start();
        // The gather's sweep takes the residuals apart, to drift a carried step.
        let sweep_ctx = ForceContext {
            model: &self.model,
            coeffs: &self.coeffs,
            n_materials: self.n_materials,
            slots: self.slots,
            elapsed,
            window: T::of(self.schedule.window(elapsed.f64())),
            periodic: self.periodic,
            residual: &[],
            material: &self.material,
        };
        let ctx = ForceContext { residual: &self.residual, ..sweep_ctx };
        let (pairs, body, prop, gravity) = (&self.pairs, &self.body, &self.prop, self.gravity);
        let bounds = self.split();
        let mut blocks = owner_blocks(pairs, self.slots.stride, &mut self.load, &mut self.share, &mut self.report, &mut self.force_i, &mut self.hist).into_iter();
        // Each part's owner blocks (parts start at block boundaries).
        let parts: Vec<Vec<OwnerBlock<T>>> = bounds.windows(2).map(|w| blocks.by_ref().take(w[1].div_ceil(pair_force::OWNERS) - w[0].div_ceil(pair_force::OWNERS)).collect()).collect();
        let together = warm::Together::new(parts.len());
        parts.into_par_iter().for_each(|part| {
            let mut scratch = TaskScratch::default();
            for b in part {
                owner_block(b, &mut scratch, pairs, body, prop, &ctx, gravity);
            }
            together.finish();
        });
        self.clock.stop(Phase::Force, t);
        let t = self.clock.start();
        let grains = Grains { body: &mut self.body, residual: &mut self.residual, built_at: &self.built_at, prop, id: &self.id };
        let (sums, touches, moved) = complete_loads(&sweep_ctx, pairs, &self.share, grains, &bounds, &self.walls, &mut self.load, &mut self.wall_springs, kick, carry);
        self.wall_touches = touches;
        self.wall_reaction = sums.reaction;
        self.wall_count = sums.count;
        self.wall_response = sums.response;
        self.wall_regimes = sums.regimes;
        self.forces_valid = true;
        self.clock.stop(Phase::Gather, t);
        moved
    }

    /// The slots' parts, one per thread of the pool ([`split::split`], [`split::parts_for`]).
    fn split(&self) -> Vec<usize> {
        split::split(&self.pairs, self.body.len(), split::parts_for(rayon::current_num_threads()))
    }

    /// Kick of every grain and of the piston by `tau` (s).
    fn kick(&mut self, tau: T) {
        let t = self.clock.start();
        let (load, prop) = (&self.load, &self.prop);
        self.body.par_iter_mut().with_min_len(PAR_MIN_ITEMS).enumerate().for_each(|(i, b)| integrate::kick(b, &load[i], &prop[i], tau));
        self.kick_piston(tau);
        self.clock.stop(Phase::Integrate, t);
    }

    /// Kick of the piston by `tau` (s) under the grains' push and its pressure.
    fn kick_piston(&mut self, tau: T) {
        if let Some(p) = self.piston {
            let push = self.wall_reaction[p.wall].z - p.pressure * p.area;
            self.walls[p.wall].velocity.z += push * tau / p.mass;
        }
    }

    /// Drift of every grain (and orientation, piston and servo walls) by `tau` (s), after a
    /// [`Self::kick`] by `kick` (s) when given: in one sweep over the grains, each kicked and
    /// then drifted (the same operations on each grain in the same order as a kick and a
    /// drift, with one pass over the grains' arrays instead of two). Notes how far the grains
    /// have moved since the last build.
    fn drift(&mut self, kick: Option<T>, tau: T) {
        let t = self.clock.start();
        let bounds = self.split();
        let (mut body, mut residual) = (&mut self.body[..], &mut self.residual[..]);
        let parts: Vec<_> = bounds
            .windows(2)
            .map(|w| {
                let grains = w[0]..w[1];
                let r = if T::COMPENSATED { take_front(&mut residual, grains.len()) } else { &mut [] };
                (take_front(&mut body, grains.len()), r, &self.built_at[grains.clone()], &self.load[grains.clone()], &self.prop[grains])
            })
            .collect();
        let together = warm::Together::new(parts.len());
        let moved: Vec<T> = parts
            .into_par_iter()
            .map(|(b, r, at, l, p)| {
                let moved = integrate::kick_drift(b, r, at, l, p, kick, tau);
                together.finish();
                moved
            })
            .collect();
        self.drift_rest(kick, tau, moved.into_iter().fold(T::ZERO, T::max));
        self.clock.stop(Phase::Integrate, t);
    }

    /// What a drift does besides kicking and drifting the grains (which read neither the
    /// walls nor the orientations, so the order does not matter): the piston kicked by `kick`
    /// (s) when given, the orientations, the piston and the servo walls drifted by `tau` (s),
    /// and `moved`, the grains' largest squared displacement since the last build, noted.
    fn drift_rest(&mut self, kick: Option<T>, tau: T, moved: T) {
        if let Some(k) = kick {
            self.kick_piston(k);
        }
        if let Some(q) = &mut self.orientation {
            let body = &self.body;
            q.par_iter_mut().with_min_len(PAR_MIN_ITEMS).enumerate().for_each(|(i, q)| *q = integrate::rotate(*q, body[i].omega, tau));
        }
        if let Some(p) = self.piston {
            let wall = &mut self.walls[p.wall];
            let dz = wall.velocity.z * tau;
            if let WallGeom::Piston { z } = &mut wall.geom {
                *z += dz;
            }
            self.external_work -= (p.pressure * p.area * dz).f64();
        }
        self.servo_drift(tau);
        self.max_moved2 = built_at::with_margin(moved, self.built_margin);
    }

    /// Rebuilds the neighbour list when a grain has moved half the skin since the last build
    /// (a non-finite displacement rebuilds too, and the rebuild reports it).
    fn rebuild_if_needed(&mut self) -> Result<(), SimError> {
        let half = self.skin * T::of(0.5);
        if !(self.max_moved2 < half * half) {
            self.rebuild()?;
        }
        Ok(())
    }

    /// Runs one operation of the schedule, with `hooks` around it.
    fn run(&mut self, op: Op, hooks: &mut impl StepHooks<T>) -> Result<(), SimError> {
        self.trace.record(op);
        match op {
            Op::Kick { tau } => self.kick(T::of(tau)),
            Op::Drift { tau } => {
                self.drift(None, T::of(tau));
                hooks.drifted(self)?;
            }
            Op::RebuildIfNeeded => hooks.rebuild_if_needed(self)?,
            Op::Forces { elapsed } => {
                self.forces(elapsed, None, None, hooks)?;
            }
        }
        Ok(())
    }

    /// A force evaluation ([`Op::Forces`]) with `hooks` around it, and with the grains kicked by
    /// `kick` (s) in its last sweep when given (and by `carry`, see [`Self::evaluate_forces`]).
    /// Returns what the carried drift found.
    fn forces(&mut self, elapsed: f64, kick: Option<T>, carry: Option<Carry<T>>, hooks: &mut impl StepHooks<T>) -> Result<T, SimError> {
        if self.slots.layout.bridge {
            let t = self.clock.start();
            hooks.bridges(self)?;
            self.clock.stop(Phase::Force, t);
        }
        let moved = self.evaluate_forces(T::of(elapsed), kick, carry);
        hooks.forces_evaluated(self)?;
        Ok(moved)
    }

    /// Makes the loads valid by the schedule's prologue, if nothing has evaluated them yet.
    fn ensure_loads(&mut self) -> Result<(), SimError> {
        self.ensure_loads_with(&mut Alone)
    }

    /// [`Self::ensure_loads`] with `hooks` around each operation.
    fn ensure_loads_with(&mut self, hooks: &mut impl StepHooks<T>) -> Result<(), SimError> {
        if !self.forces_valid {
            for k in 0..self.schedule.prologue.len() {
                self.run(self.schedule.prologue[k], hooks)?;
            }
        }
        Ok(())
    }

    /// Starts recording the operations run (see [`Trace`]).
    pub fn trace_schedule(&mut self) {
        self.trace.start();
    }

    /// The operations run since [`Self::trace_schedule`].
    pub fn traced(&self) -> &[Op] {
        self.trace.ops()
    }

    /// One time step of the scene's integrator.
    pub fn step(&mut self) -> Result<(), SimError> {
        self.step_in_run(false)
    }

    /// One time step of a run that goes on with another (`more`) inside the same `advance`.
    /// Velocity Verlet ends a step with a force evaluation and a kick and begins the next with
    /// a kick and a drift: such a next step's kick and drift then run in this step's gather
    /// sweep, each grain kicked, kicked again and drifted while it is in cache (as the GPU's
    /// runs of steps do), and the next step skips them. Each grain sees the same operations
    /// in the same order: the same bits. At 10^6 grains the kick-and-drift pass it saves
    /// streamed 228 B per grain from memory.
    fn step_in_run(&mut self, more: bool) -> Result<(), SimError> {
        self.step_with(&mut Alone, more)
    }

    /// One time step with `hooks` around its operations (a hook may replace the engine; the
    /// step goes on with the one it leaves), carrying the next step's first sweep into this
    /// one's last where `carry` and the schedule allow ([`Self::step_in_run`]).
    pub(crate) fn step_with(&mut self, hooks: &mut impl StepHooks<T>, carry: bool) -> Result<(), SimError> {
        if self.schedule.needs_loads {
            self.ensure_loads_with(hooks)?;
        }
        let sweeps = self.schedule.sweeps(self.step).len();
        for s in std::mem::take(&mut self.carried) as usize..sweeps {
            let sweep = self.schedule.sweeps(self.step)[s];
            if !matches!(sweep, Sweep::Op(_)) {
                sweep.ops().for_each(|op| self.trace.record(op));
            }
            match sweep {
                Sweep::Op(op) => self.run(op, hooks)?,
                Sweep::ForcesKick { elapsed, tau } => {
                    let next = match self.schedule.sweeps(self.step + 1).first() {
                        Some(&next @ Sweep::KickDrift { kick, tau }) if carry && s + 1 == sweeps => Some((next, Carry { kick: T::of(kick), tau: T::of(tau) })),
                        _ => None,
                    };
                    let moved = self.forces(elapsed, Some(T::of(tau)), next.map(|n| n.1), hooks)?;
                    // The piston's kick reads the walls' sums, which the hooks complete.
                    self.kick_piston(T::of(tau));
                    if let Some((next, c)) = next {
                        next.ops().for_each(|op| self.trace.record(op));
                        self.drift_rest(Some(c.kick), c.tau, moved);
                        hooks.drifted(self)?;
                        self.carried = true;
                    }
                }
                Sweep::KickDrift { kick, tau } => {
                    self.drift(Some(T::of(kick)), T::of(tau));
                    hooks.drifted(self)?;
                }
            }
        }
        self.step += 1;
        self.time += self.dt.f64();
        Ok(())
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

/// What a driver does between the operations of a step: the distributed engine exchanges
/// the grains other processes own after each drift, decides rebuilds over every process and
/// sums the walls' loads over them after each force evaluation ([`crate::cpu::ranks`]).
pub(crate) trait StepHooks<T: Real> {
    /// After each drift.
    fn drifted(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
    /// In place of the rebuild check.
    fn rebuild_if_needed(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
    /// In place of `update_bridges`, before each force evaluation of a capillary scene.
    fn bridges(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
    /// After each force evaluation.
    fn forces_evaluated(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError>;
}

/// The hooks of an engine that holds every grain: the rebuild check alone.
struct Alone;

impl<T: Real> StepHooks<T> for Alone {
    fn drifted(&mut self, _: &mut CpuEngine<T>) -> Result<(), SimError> {
        Ok(())
    }
    fn rebuild_if_needed(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        e.rebuild_if_needed()
    }
    fn bridges(&mut self, e: &mut CpuEngine<T>) -> Result<(), SimError> {
        e.update_bridges();
        Ok(())
    }
    fn forces_evaluated(&mut self, _: &mut CpuEngine<T>) -> Result<(), SimError> {
        Ok(())
    }
}

/// What `update_bridges` does to one pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum BridgeEvent {
    /// Its bridge is stretched past its rupture distance.
    Rupture,
    /// It touches without a bridge: one forms if its grains hold liquid.
    Touch,
}

/// The bridge volume (m^3) a pair holds after `event`, from its volume before it, `bridge`, and
/// the liquid waiting on its two grains (m^3), which the event changes: a rupture returns the
/// bridge to them in halves; a touch forms a bridge from half of each one's liquid, scaled down
/// to `cap` when more.
#[inline]
pub(crate) fn move_liquid<T: Real>(event: BridgeEvent, bridge: T, cap: T, liquid_i: &mut T, liquid_j: &mut T) -> T {
    let half = T::of(0.5);
    match event {
        BridgeEvent::Rupture => {
            *liquid_i += bridge * half;
            *liquid_j += bridge * half;
            T::ZERO
        }
        BridgeEvent::Touch if *liquid_i > T::ZERO || *liquid_j > T::ZERO => {
            let (mut a, mut c) = (*liquid_i * half, *liquid_j * half);
            if a + c > cap {
                let s = cap / (a + c);
                a *= s;
                c *= s;
            }
            *liquid_i -= a;
            *liquid_j -= c;
            a + c
        }
        BridgeEvent::Touch => bridge,
    }
}

/// What the walls receive from one force pass, per wall.
struct WallSums<T> {
    /// Force the grains exert (N).
    reaction: Vec<Vec3<T>>,
    /// Touching grains.
    count: Vec<u64>,
    /// Sums of the contacts' normal tangent stiffness (N/m) and damping (N s/m).
    response: Vec<(T, T)>,
    /// Contacts sliding and rolling, over all walls.
    regimes: RegimeCounts,
}

/// One wall's share of the contacts of some grains: what `wall_contacts` and `wall_reduce`
/// add up (the WGSL rows' xyz, w and the stiffness half).
#[derive(Clone, Copy)]
struct WallRow<T> {
    /// Force the grains exert (N).
    reaction: Vec3<T>,
    /// Touching grains.
    count: u64,
    /// Summed normal tangent stiffness (N/m) and damping (N s/m).
    response: (T, T),
}

impl<T: Real> WallRow<T> {
    const ZERO: Self = WallRow { reaction: Vec3::ZERO, count: 0, response: (T::ZERO, T::ZERO) };

    fn of(t: &WallTouch<T>) -> Self {
        WallRow { reaction: -t.force, count: t.touching as u64, response: (t.stiffness, t.damping) }
    }

    fn add(self, o: Self) -> Self {
        WallRow { reaction: self.reaction + o.reaction, count: self.count + o.count, response: (self.response.0 + o.response.0, self.response.1 + o.response.1) }
    }
}

impl<T: Real> WallSums<T> {
    /// The sums of `touches` (sorted by grain id, then wall) among `n_grains` grains: in the
    /// GPU's order for its twin ([`Real::GPU_TWIN`]), in chunks of ids otherwise. Either way
    /// the same bits however the slots are numbered.
    fn of(n_walls: usize, n_grains: usize, touches: &[WallTouch<T>]) -> Self {
        let totals = if T::GPU_TWIN { WallRow::in_gpu_order(n_walls, n_grains, touches) } else { WallRow::in_chunks(n_walls, touches) };
        let mut regimes = RegimeCounts::default();
        for t in touches.iter().filter(|t| t.touching) {
            regimes.count(t.regime);
        }
        WallSums { reaction: totals.iter().map(|r| r.reaction).collect(), count: totals.iter().map(|r| r.count).collect(), response: totals.iter().map(|r| r.response).collect(), regimes }
    }
}

impl<T: Real> WallRow<T> {
    /// Each wall's row, grains by permanent id in workgroups of [`WG`](crate::workgroup::WG),
    /// each summed by its tree (`wall_contacts`), then the workgroups' rows by `wall_reduce`'s
    /// strided tree: the GPU's order, whose grains sit in id order.
    fn in_gpu_order(n_walls: usize, n_grains: usize, touches: &[WallTouch<T>]) -> Vec<Self> {
        let wg = crate::workgroup::WG as usize;
        let rows = crate::workgroup::rows(n_grains as u64) as usize;
        let mut lanes = vec![WallRow::ZERO; wg];
        (0..n_walls)
            .map(|w| {
                let mut rest = touches;
                let partials = (0..rows).map(|r| {
                    let (here, next) = rest.split_at(rest.partition_point(|t| (t.grain as usize) < (r + 1) * wg));
                    rest = next;
                    if here.is_empty() {
                        return WallRow::ZERO;
                    }
                    lanes.fill(WallRow::ZERO);
                    for t in here.iter().filter(|t| t.wall as usize == w) {
                        lanes[t.grain as usize % wg] = WallRow::of(t);
                    }
                    crate::workgroup::tree_sum(&mut lanes, WallRow::add)
                });
                crate::workgroup::strided_sum(partials, WallRow::ZERO, WallRow::add)
            })
            .collect()
    }

    /// Each wall's row as running sums over fixed chunks of [`CHUNK`] ids in id order, then
    /// over the chunks in order.
    fn in_chunks(n_walls: usize, touches: &[WallTouch<T>]) -> Vec<Self> {
        let mut total = vec![WallRow::ZERO; n_walls];
        let mut part = vec![WallRow::ZERO; n_walls];
        let mut chunk = touches.first().map_or(0, |t| t.grain as usize / CHUNK);
        for t in touches {
            if t.grain as usize / CHUNK != chunk {
                absorb(&mut total, &mut part);
                chunk = t.grain as usize / CHUNK;
            }
            let p = &mut part[t.wall as usize];
            p.reaction -= t.force;
            p.count += t.touching as u64;
            p.response = (p.response.0 + t.stiffness, p.response.1 + t.damping);
        }
        absorb(&mut total, &mut part);
        total
    }
}

/// Adds one chunk's rows to the totals and clears them.
fn absorb<T: Real>(total: &mut [WallRow<T>], part: &mut [WallRow<T>]) {
    for (t, p) in total.iter_mut().zip(part.iter_mut()) {
        *t = t.add(*p);
        *p = WallRow::ZERO;
    }
}

/// The next step's kick by `kick` (s) and drift by `tau` (s), carried into a force
/// evaluation's gather sweep ([`CpuEngine::step_in_run`]).
#[derive(Clone, Copy, Debug)]
struct Carry<T> {
    kick: T,
    tau: T,
}

/// The per-grain arrays the gather's sweep reads, and writes where it kicks and drifts.
struct Grains<'a, T> {
    body: &'a mut [Body<T>],
    /// Empty unless positions are compensated.
    residual: &'a mut [Vec3<T>],
    built_at: &'a [Vec3<f32>],
    prop: &'a [Props<T>],
    id: &'a [u32],
}

/// `gather`, then `wall_contacts`, over every grain in one sweep, one part of the slots
/// ([`split::split`]'s `bounds`) a task: each grain's load gets its partners' shares, then its
/// wall load. Returns the per-wall sums ([`WallSums::of`]) and the wall contacts, sorted by
/// grain id, then wall, and the largest squared displacement the carried drift found. With
/// `kick` (s), each grain is then kicked by its load in the same sweep (see
/// [`CpuEngine::kick`]; the piston's kick is the caller's), and with `carry` kicked and
/// drifted again ([`integrate::kick_drift`]). `ctx.residual` is not read: the residuals
/// come in `grains`.
#[allow(clippy::too_many_arguments)]
fn complete_loads<T: Real>(
    ctx: &ForceContext<T>,
    pairs: &PairList,
    share: &[Load<T>],
    grains: Grains<T>,
    bounds: &[usize],
    walls: &[WallState<T>],
    load: &mut [Load<T>],
    wall_springs: &mut WallSprings<T>,
    kick: Option<T>,
    carry: Option<Carry<T>>,
) -> (WallSums<T>, Vec<WallTouch<T>>, T) {
    let per_grain = walls.len() * ctx.slots.stride;
    // Each part's first wall-spring entry (walls keep entries even where they keep no history).
    let first_entries: Vec<u32> = bounds.iter().map(|&b| wall_springs.first_entry(b)).collect();
    let (candidate, run_start, mut springs) = (&wall_springs.candidate, &wall_springs.run_start, &mut wall_springs.springs[..]);
    let Grains { body, residual, built_at, prop, id } = grains;
    let (mut loads, mut bodies, mut residuals) = (load, body, residual);
    let compensated = !residuals.is_empty();
    let parts: Vec<_> = bounds
        .windows(2)
        .zip(first_entries.windows(2))
        .map(|(w, e)| {
            let n = w[1] - w[0];
            (w[0], take_front(&mut loads, n), take_front(&mut bodies, n), take_front(&mut residuals, if compensated { n } else { 0 }), take_front(&mut springs, (e[1] - e[0]) as usize * per_grain))
        })
        .collect();
    let together = warm::Together::new(parts.len());
    let done: Vec<(Vec<WallTouch<T>>, T)> = parts
        .into_par_iter()
        .map(|(first, mut loads, mut bodies, mut residuals, mut springs)| {
            let (mut touches, mut moved) = (Vec::new(), T::ZERO);
            // A block of grains at a time, gathered, wall-contacted, kicked and (carried)
            // kicked and drifted while its arrays are in cache (a part of 10^6 grains is half
            // a million).
            let end = first + loads.len();
            let mut at = first;
            while at < end {
                let stop = (at - at % SWEEP_BLOCK + SWEEP_BLOCK).min(end);
                let grains = at..stop;
                let (loads, bodies) = (take_front(&mut loads, grains.len()), take_front(&mut bodies, grains.len()));
                let residuals = take_front(&mut residuals, if compensated { grains.len() } else { 0 });
                gather_block(at, loads, pairs, share);
                if !walls.is_empty() {
                    let springs = take_front(&mut springs, (wall_springs::first_entry(run_start, stop) - wall_springs::first_entry(run_start, at)) as usize * per_grain);
                    wall_block(at, loads, &candidate[at / split::ALIGN..], springs, &id[grains.clone()], bodies, residuals, &prop[grains.clone()], walls, ctx, &mut touches);
                }
                if let Some(tau) = kick {
                    for ((b, l), p) in bodies.iter_mut().zip(loads.iter()).zip(&prop[grains.clone()]) {
                        integrate::kick(b, l, p, tau);
                    }
                }
                if let Some(c) = carry {
                    moved = moved.max(integrate::kick_drift(bodies, residuals, &built_at[grains.clone()], loads, &prop[grains], Some(c.kick), c.tau));
                }
                at = stop;
            }
            together.finish();
            (touches, moved)
        })
        .collect();
    let moved = done.iter().fold(T::ZERO, |m, d| m.max(d.1));
    let mut touches: Vec<WallTouch<T>> = done.into_iter().flat_map(|d| d.0).collect();
    touches.sort_unstable_by_key(|t| (t.grain, t.wall));
    (WallSums::of(walls.len(), id.len(), &touches), touches, moved)
}

/// Grains per block of the gather's sweep: a multiple of [`split::ALIGN`], so that a block
/// starts where a run of wall-spring candidates does.
const SWEEP_BLOCK: usize = 16 * split::ALIGN;

/// Splits the pair pass's outputs into the tasks of [`owner_block`]: [`pair_force::OWNERS`]
/// owner grains each, with the pairs they own.
fn owner_blocks<'a, T: Real>(
    pairs: &PairList,
    stride: usize,
    mut load: &'a mut [Load<T>],
    mut share: &'a mut [Load<T>],
    report: &'a mut PairReports<T>,
    mut force_i: &'a mut [Vec3<T>],
    mut hist: &'a mut [T],
) -> Vec<OwnerBlock<'a, T>> {
    let n = load.len();
    let keep_fi = !force_i.is_empty();
    let keep_fc = !report.f_c.is_empty();
    let (mut f_n, mut f_c, mut flags) = (&mut report.f_n[..], &mut report.f_c[..], &mut report.flags[..]);
    let mut blocks = Vec::with_capacity(n.div_ceil(pair_force::OWNERS));
    for first in (0..n).step_by(pair_force::OWNERS) {
        let end = (first + pair_force::OWNERS).min(n);
        let count = (pairs.owner_start[end] - pairs.owner_start[first]) as usize;
        blocks.push(OwnerBlock {
            first,
            load: take_front(&mut load, end - first),
            share: take_front(&mut share, count),
            f_n: take_front(&mut f_n, count),
            f_c: take_front(&mut f_c, if keep_fc { count } else { 0 }),
            flags: take_front(&mut flags, count),
            force_i: take_front(&mut force_i, if keep_fi { count } else { 0 }),
            hist: take_front(&mut hist, count * stride),
        });
    }
    blocks
}

/// Wraps every grain's position into the periods and adds the periods it crossed along
/// `axes` to its image counts (`axes.len()` per grain). Returns the largest count's magnitude,
/// or, of the grains whose count no longer fits its width, the lowest slot.
fn wrap_grains<T: Real, C: ImageCount>(p: &Periodic<T>, body: &mut [Body<T>], residual: &mut [Vec3<T>], counts: &mut [C], axes: &[usize]) -> Result<u32, usize> {
    let wrap = |(s, b, r, image): (usize, &mut Body<T>, &mut Vec3<T>, &mut [C])| {
        let moved = position::wrap(p, &mut b.pos, r);
        image.iter_mut().zip(axes).try_fold(0, |m, (c, &a)| c.add(moved[a]).map(|v| m.max(v.unsigned_abs())).ok_or(s))
    };
    // Of two results the error, and of two errors the lower slot: the same on any split.
    let first = |a: Result<u32, usize>, b: Result<u32, usize>| match (a, b) {
        (Ok(x), Ok(y)) => Ok(x.max(y)),
        (Err(x), Err(y)) => Err(x.min(y)),
        (Err(x), _) | (_, Err(x)) => Err(x),
    };
    let width = axes.len();
    if T::COMPENSATED {
        body.par_iter_mut().zip(residual.par_iter_mut()).zip(counts.par_chunks_mut(width)).with_min_len(PAR_MIN_ITEMS).enumerate().map(|(s, ((b, r), c))| wrap((s, b, r, c))).reduce(|| Ok(0), first)
    } else {
        body.par_iter_mut().zip(counts.par_chunks_mut(width)).with_min_len(PAR_MIN_ITEMS).enumerate().map(|(s, (b, c))| wrap((s, b, &mut Vec3::default(), c))).reduce(|| Ok(0), first)
    }
}

/// Splits the first `n` items off `s`, leaving it the rest.
fn take_front<'a, X>(s: &mut &'a mut [X], n: usize) -> &'a mut [X] {
    let (front, rest) = std::mem::take(s).split_at_mut(n);
    *s = rest;
    front
}

/// `slot` where it is kept (as long as `id`), else the inverse of `id`.
fn kept_or_found<'a>(slot: &'a [u32], id: &[u32]) -> Cow<'a, [u32]> {
    if slot.len() == id.len() {
        Cow::Borrowed(slot)
    } else {
        Cow::Owned(slots_of(id))
    }
}

/// The inverse of a numbering: `slot[id[s]] = s`.
fn slots_of(id: &[u32]) -> Vec<u32> {
    let mut slot = vec![0; id.len()];
    for (s, &i) in id.iter().enumerate() {
        slot[i as usize] = s as u32;
    }
    slot
}

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
        warm::with_warm_pool(|| {
            for k in 0..n {
                self.step_in_run(k + 1 < n)?;
            }
            Ok(())
        })
    }

    fn set_piston_pressure(&mut self, pressure: f64) {
        if let Some(p) = &mut self.piston {
            p.pressure = T::of(pressure);
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Two grains in a box periodic in x and y, each one period past its upper end along x
    /// (and the second also one below along y), with counts one short of the widening.
    fn crossing<C: ImageCount + From<i16>>() -> (Periodic<f64>, Vec<Body<f64>>, Vec<C>) {
        let p = Periodic::of(&[Some([0.0, 1.0]), Some([0.0, 1.0]), None]);
        let at = |x: f64, y: f64| Body { pos: Vec3::new(x, y, 0.5), ..Default::default() };
        let start = C::from(Images::WIDEN_AT as i16 - 1);
        (p, vec![at(1.25, 0.5), at(1.5, -0.5)], vec![start, C::from(0), start, start])
    }

    /// The wrap adds the periods crossed to the two-byte counts and reports the largest, which
    /// widens them; a count two bytes cannot hold names its grain and changes nothing.
    #[test]
    fn image_counts_widen_before_two_bytes_overflow() {
        let (p, mut body, mut counts) = crossing::<i16>();
        let largest = wrap_grains(&p, &mut body, &mut [], &mut counts, &[0, 1]);
        assert_eq!(largest, Ok(Images::WIDEN_AT as u32));
        assert_eq!(counts, vec![Images::WIDEN_AT as i16, 0, Images::WIDEN_AT as i16, Images::WIDEN_AT as i16 - 2]);
        assert_eq!((body[0].pos.x, body[1].pos.x, body[1].pos.y), (0.25, 0.5, 0.5));
        let mut images = Images::new([true, true, false], 2);
        for (i, c) in counts.chunks(2).enumerate() {
            images.set(i, [c[0] as i32, c[1] as i32, 0]);
        }
        assert!(matches!(images.counts_mut(), Counts::Wide(_)), "a count of WIDEN_AT widens them");
        assert_eq!(images.get(1), [Images::WIDEN_AT, Images::WIDEN_AT - 2, 0]);
        images.widen_for(0);
        assert_eq!(images.bytes(), 4 * 4, "two grains, two wrapping axes, four bytes a count");
        // One past what two bytes hold: an error naming the lowest such slot.
        let (p, mut body, _) = crossing::<i16>();
        let mut full = vec![i16::MAX, 0, i16::MAX, 0];
        assert_eq!(wrap_grains(&p, &mut body, &mut [], &mut full, &[0, 1]), Err(0));
        assert_eq!(full[0], i16::MAX);
        // Four bytes take it.
        let (p, mut body, mut wide) = crossing::<i32>();
        wide[0] = i16::MAX as i32;
        assert_eq!(wrap_grains(&p, &mut body, &mut [], &mut wide, &[0, 1]), Ok(i16::MAX as u32 + 1));
    }
}
