//! The CPU engine: the step's kernels as Rust twins, one invocation per grain or pair, mapped
//! over threads with rayon. Generic over `f32` and `f64` (the reference).
//!
//! One step: `[kick] drift -> (rebuild: hash_cells, detect_pairs, remap_history) ->
//! pair_force -> wall_contacts -> gather -> kick`, repeated per force evaluation of the
//! integrator. Results are bitwise identical for any thread count: every invocation writes
//! its own output, and reductions combine fixed chunks in order.

mod gather;
mod grid;
mod integrate;
mod lanes;
mod pair_force;
mod pairs;
mod profile;
mod reduce;
pub mod simd;
mod state;
mod wall_contacts;

pub use integrate::rotate;
pub use pairs::PairList;
pub use pair_force::ForceContext;
pub use profile::PHASE_NAMES;
pub use state::{Body, HistorySlots, Load, Props};
pub use wall_contacts::{wall_contact_records, WallState};

use crate::checkpoint::EngineState;
use crate::engine::{ContactRecord, Engine, Frame, PistonStats, RegimeCounts, SimError, Stats, WallStats, RATTLER_CONTACTS};
use crate::model::{normal_potential, rupture_distance, share_liquid, CohesionLaw, ContactForce, ContactModel, PairCoeffs, Regime};
use crate::periodic::Periodic;
use crate::real::{Real, Vec3};
use crate::schedule::{Op, Schedule, Trace};
use crate::scene::{Scene, WallShape};
use crate::walls::WallGeom;
use gather::gather_block;
use grid::{hash_cells, CellGrid};
use pair_force::pair_block;
use profile::{Phase, PhaseClock};
use rayon::prelude::*;
use reduce::{chunked, CHUNK, PAR_MIN_CHUNKS, PAR_MIN_ITEMS, PAR_MIN_PAIRS};
use wall_contacts::wall_block;

/// Fraction of the largest stable servo gain used where a wall's contacts are stiff.
pub const SERVO_RELAXATION: f64 = 0.5;

/// The piston's dynamic state.
#[derive(Clone, Copy, Debug)]
struct Piston<T> {
    /// Index into the walls.
    wall: usize,
    mass: T,
    area: T,
    /// Target pressure (Pa).
    pressure: T,
}

/// The servo box's control state.
#[derive(Clone, Copy, Debug)]
struct Servo<T> {
    /// Wall indices: x_min, x_max, y_min, y_max, z_min, z_max.
    walls: [usize; 6],
    /// Target pressure (Pa).
    pressure: T,
    /// Wall speed per pressure error (m/(s Pa)).
    gain: T,
    /// Largest wall speed (m/s).
    max_speed: T,
    /// Strain rate of the z walls (1/s), when they are strain-controlled.
    strain_rate: Option<T>,
}

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
    // Grains, indexed by slot; `id` is the permanent id (equal to the slot: grains are not
    // reordered yet, so history lookups by slot stay valid across rebuilds).
    id: Vec<u32>,
    body: Vec<Body<T>>,
    prop: Vec<Props<T>>,
    load: Vec<Load<T>>,
    built_at: Vec<Vec3<T>>,
    /// Periods each grain has been wrapped by (empty without periodic axes).
    image: Vec<[i32; 3]>,
    orientation: Option<Vec<[T; 4]>>,
    // Walls.
    walls: Vec<WallState<T>>,
    wall_names: Vec<String>,
    piston: Option<Piston<T>>,
    servo: Option<Servo<T>>,
    wall_hist: Vec<T>,
    wall_load: Vec<Load<T>>,
    wall_reaction: Vec<Vec3<T>>,
    wall_count: Vec<u64>,
    /// Wall contacts sliding and rolling at the last force evaluation.
    wall_regimes: RegimeCounts,
    /// Sum over each wall's contacts of the normal tangent stiffness (N/m) and damping
    /// coefficient (N s/m).
    wall_response: Vec<(T, T)>,
    // Pairs.
    grid: CellGrid<T>,
    pairs: PairList,
    hist: Vec<T>,
    out: Vec<ContactForce<T>>,
    // Clocks.
    /// Largest squared displacement of a grain since the last build (m^2), as of the last drift.
    max_moved2: T,
    forces_valid: bool,
    step: u64,
    time: f64,
    rebuilds: u64,
    external_work: f64,
    /// Time per phase, when profiling.
    clock: PhaseClock,
}

impl<T: Real> CpuEngine<T> {
    /// Sets up the engine for a scene and builds the first neighbour list.
    pub fn new(scene: &Scene) -> Result<Self, SimError> {
        let n_materials = scene.materials.len();
        let mut coeffs = Vec::with_capacity(n_materials * n_materials);
        for a in &scene.materials {
            for b in &scene.materials {
                coeffs.push(PairCoeffs::mix(&a.constants, &b.constants));
            }
        }
        let g = &scene.grains;
        let n = g.len();
        let body: Vec<Body<T>> =
            (0..n).map(|i| Body { pos: Vec3::of(g.position[i]), vel: Vec3::of(g.velocity[i]), omega: Vec3::of(g.angular_velocity[i]) }).collect();
        let prop: Vec<Props<T>> = (0..n)
            .map(|i| Props {
                radius: T::of(g.radius[i]),
                mass: T::of(g.mass[i]),
                inertia: T::of(0.4 * g.mass[i] * g.radius[i] * g.radius[i]),
                material: g.material[i] as u32,
            })
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
            suggested_dt: crate::protocol::suggested_dt(scene),
            schedule: Schedule::new(scene.integrator, scene.time_step.dt),
            trace: Trace::default(),
            skin: T::of(scene.skin),
            detect_reach: T::of(scene.skin + scene.bridges.reach),
            cutoff: T::of(2.0 * r_max + scene.skin + scene.bridges.reach),
            capacity: scene.max_neighbours,
            bridge_cap: T::of(scene.bridges.volume_cap),
            liquid: if slots.layout.bridge { vec![T::ZERO; n] } else { Vec::new() },
            periodic: Periodic::of(&scene.periodic),
            id: (0..n as u32).collect(),
            built_at: body.iter().map(|b| b.pos).collect(),
            image: if scene.periodic.iter().any(Option::is_some) { vec![[0; 3]; n] } else { Vec::new() },
            body,
            prop,
            load: vec![Load::default(); n],
            orientation: scene.track_orientation.then(|| vec![[T::ONE, T::ZERO, T::ZERO, T::ZERO]; n]),
            wall_names: scene.walls.iter().map(|w| w.name.clone()).collect(),
            walls,
            piston,
            servo: scene.servo.map(|s| Servo { walls: s.walls, pressure: T::of(s.pressure), gain: T::of(s.gain), max_speed: T::of(s.max_speed), strain_rate: None }),
            wall_hist: vec![T::ZERO; n * n_walls * slots.stride],
            wall_load: vec![Load::default(); n],
            wall_reaction: vec![Vec3::ZERO; n_walls],
            wall_count: vec![0; n_walls],
            wall_regimes: RegimeCounts::default(),
            wall_response: vec![(T::ZERO, T::ZERO); n_walls],
            grid: CellGrid::default(),
            pairs: PairList::default(),
            hist: Vec::new(),
            out: Vec::new(),
            max_moved2: T::ZERO,
            forces_valid: false,
            step: 0,
            time: 0.0,
            rebuilds: 0,
            external_work: 0.0,
            clock: PhaseClock::default(),
        };
        engine.rebuild()?;
        Ok(engine)
    }

    /// Rebuilds the neighbour list now (`hash_cells`, `detect_pairs`, `remap_history`),
    /// carrying every contact's history over.
    pub fn rebuild(&mut self) -> Result<(), SimError> {
        let t = self.clock.start();
        if self.periodic.any() {
            let p = self.periodic;
            self.body.par_iter_mut().zip(self.image.par_iter_mut()).with_min_len(PAR_MIN_ITEMS).for_each(|(b, image)| {
                let (pos, moved) = p.wrap(b.pos);
                b.pos = pos;
                for a in 0..3 {
                    image[a] += moved[a];
                }
            });
        }
        if !hash_cells(&self.body, self.cutoff, &self.periodic, &mut self.grid) {
            return Err(self.non_finite_error());
        }
        self.clock.stop(Phase::Hash, t);
        let t = self.clock.start();
        let pairs = PairList::detect(&self.body, &self.prop, &self.id, &self.grid, &self.periodic, self.detect_reach, self.capacity)
            .map_err(|(i, count)| SimError::Capacity { step: self.step, grain: self.id[i], count, capacity: self.capacity })?;
        self.clock.stop(Phase::Detect, t);
        let t = self.clock.start();
        self.hist = pairs::remap_all(&pairs, &self.pairs, &self.hist, &self.id, self.slots.stride);
        self.pairs = pairs;
        self.out.clear();
        self.out.reserve_exact(self.pairs.len());
        self.out.resize(self.pairs.len(), ContactForce::default());
        for (b, at) in self.body.iter().zip(self.built_at.iter_mut()) {
            *at = b.pos;
        }
        self.rebuilds += 1;
        self.max_moved2 = T::ZERO;
        self.forces_valid = false;
        self.clock.stop(Phase::Remap, t);
        Ok(())
    }

    fn non_finite_error(&self) -> SimError {
        let grain = self.body.iter().position(|b| !(b.pos.is_finite() && b.vel.is_finite() && b.omega.is_finite())).unwrap_or(0);
        SimError::Unstable {
            step: self.step,
            time: self.time,
            what: "non-finite position or velocity".into(),
            grain: self.id[grain],
            suggested_dt: self.suggested_dt,
            also: "",
        }
    }

    /// The time step (s).
    pub fn dt(&self) -> f64 {
        self.dt.f64()
    }

    /// Grain states, by slot.
    pub fn bodies(&self) -> &[Body<T>] {
        &self.body
    }

    /// Loads from the last force evaluation, by slot.
    pub fn loads(&self) -> &[Load<T>] {
        &self.load
    }

    /// Orientation quaternions (scalar first), when tracked.
    pub fn orientations(&self) -> Option<&[[T; 4]]> {
        self.orientation.as_deref()
    }

    /// The current pair list.
    pub fn pair_list(&self) -> &PairList {
        &self.pairs
    }

    /// Gap (m) between the surfaces of pair `k`'s grains (negative when they overlap).
    fn gap(&self, k: usize) -> T {
        let (i, j) = (self.pairs.owner[k] as usize, self.pairs.partner[k] as usize);
        self.periodic.min_image(self.body[i].pos - self.body[j].pos).norm() - self.prop[i].radius - self.prop[j].radius
    }

    /// `update_bridges`: ruptures bridges stretched past their rupture distance, returning
    /// their liquid to the two grains in equal halves, and forms bridges at new contacts from
    /// half of each grain's liquid (capped at the largest bridge volume). Serial, in pair
    /// order, so that a grain forming several bridges in one step gives its liquid out in a
    /// fixed order; liquid is conserved to round-off.
    fn update_bridges(&mut self) {
        let CohesionLaw::Capillary { theta, .. } = self.model.cohesion else { return };
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        let half = T::of(0.5);
        for k in 0..self.pairs.len() {
            let gap = self.gap(k);
            let (i, j) = (self.pairs.owner[k] as usize, self.pairs.partner[k] as usize);
            let v = self.hist[k * stride + b];
            if v > T::ZERO {
                if gap > rupture_distance(theta, v) {
                    self.liquid[i] += v * half;
                    self.liquid[j] += v * half;
                    self.hist[k * stride + b] = T::ZERO;
                }
            } else if gap < T::ZERO && (self.liquid[i] > T::ZERO || self.liquid[j] > T::ZERO) {
                let (mut a, mut c) = (self.liquid[i] * half, self.liquid[j] * half);
                if a + c > self.bridge_cap {
                    let s = self.bridge_cap / (a + c);
                    a *= s;
                    c *= s;
                }
                self.liquid[i] -= a;
                self.liquid[j] -= c;
                self.hist[k * stride + b] = a + c;
            }
        }
    }

    /// Runs the force passes: `update_bridges` (capillary scenes), `pair_force`,
    /// `wall_contacts`, `gather`; the springs advance by `elapsed` (s).
    fn evaluate_forces(&mut self, elapsed: T) {
        let t = self.clock.start();
        if self.slots.layout.bridge {
            self.update_bridges();
        }
        let ctx = ForceContext {
            model: &self.model,
            coeffs: &self.coeffs,
            n_materials: self.n_materials,
            slots: self.slots,
            elapsed,
            periodic: self.periodic,
        };
        let (pairs, body, prop) = (&self.pairs, &self.body, &self.prop);
        let stride = self.slots.stride;
        let min_blocks = PAR_MIN_PAIRS / pair_force::BLOCK;
        if stride == 0 {
            self.out.par_chunks_mut(pair_force::BLOCK).with_min_len(min_blocks).enumerate().for_each(|(b, o)| pair_block(b * pair_force::BLOCK, o, &mut [], pairs, body, prop, &ctx));
        } else {
            self.out
                .par_chunks_mut(pair_force::BLOCK)
                .zip(self.hist.par_chunks_mut(pair_force::BLOCK * stride))
                .with_min_len(min_blocks)
                .enumerate()
                .for_each(|(b, (o, h))| pair_block(b * pair_force::BLOCK, o, h, pairs, body, prop, &ctx));
        }
        self.clock.stop(Phase::Force, t);
        let t = self.clock.start();
        if !self.walls.is_empty() {
            let sums = wall_pass(&ctx, body, prop, &self.walls, &mut self.wall_load, &mut self.wall_hist);
            self.wall_reaction = sums.reaction;
            self.wall_count = sums.count;
            self.wall_response = sums.response;
            self.wall_regimes = sums.regimes;
        }
        self.clock.stop(Phase::Walls, t);
        let t = self.clock.start();
        let (out, wall_load, gravity) = (&self.out, &self.wall_load, self.gravity);
        self.load.par_chunks_mut(CHUNK).with_min_len(PAR_MIN_CHUNKS).enumerate().for_each(|(c, l)| gather_block(c * CHUNK, l, pairs, out, wall_load, prop, gravity));
        self.forces_valid = true;
        self.clock.stop(Phase::Gather, t);
    }

    /// Kick of every grain and of the piston by `tau` (s).
    fn kick(&mut self, tau: T) {
        let t = self.clock.start();
        let (load, prop) = (&self.load, &self.prop);
        self.body.par_iter_mut().with_min_len(PAR_MIN_ITEMS).enumerate().for_each(|(i, b)| integrate::kick(b, &load[i], &prop[i], tau));
        if let Some(p) = self.piston {
            let push = self.wall_reaction[p.wall].z - p.pressure * p.area;
            self.walls[p.wall].velocity.z += push * tau / p.mass;
        }
        self.clock.stop(Phase::Integrate, t);
    }

    /// Drift of every grain (and orientation, piston and servo walls) by `tau` (s); notes
    /// how far the grains have moved since the last build.
    fn drift(&mut self, tau: T) {
        let t = self.clock.start();
        let moved: Vec<T> = self
            .body
            .par_chunks_mut(CHUNK)
            .zip(self.built_at.par_chunks(CHUNK))
            .with_min_len(PAR_MIN_CHUNKS)
            .map(|(bodies, at)| bodies.iter_mut().zip(at).map(|(b, at)| integrate::drift(b, *at, tau)).fold(T::ZERO, T::max))
            .collect();
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
        self.max_moved2 = moved.into_iter().fold(T::ZERO, T::max);
        self.clock.stop(Phase::Integrate, t);
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

    /// Runs one operation of the schedule.
    fn run(&mut self, op: Op) -> Result<(), SimError> {
        self.trace.record(op);
        match op {
            Op::Kick { tau } => self.kick(T::of(tau)),
            Op::Drift { tau } => self.drift(T::of(tau)),
            Op::RebuildIfNeeded => self.rebuild_if_needed()?,
            Op::Forces { elapsed } => self.evaluate_forces(T::of(elapsed)),
        }
        Ok(())
    }

    /// Makes the loads valid by the schedule's prologue, if nothing has evaluated them yet.
    fn ensure_loads(&mut self) -> Result<(), SimError> {
        if !self.forces_valid {
            for k in 0..self.schedule.prologue.len() {
                self.run(self.schedule.prologue[k])?;
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

    /// Plane point and unit normal of wall `w` (a plane).
    fn plane(&self, w: usize) -> (Vec3<T>, Vec3<T>) {
        match self.walls[w].geom {
            WallGeom::Plane { point, normal } => (point, normal),
            _ => unreachable!("servo walls are planes"),
        }
    }

    /// Extent of the servo box along each axis (m).
    fn servo_extents(&self, s: &Servo<T>) -> [T; 3] {
        let coord = |k: usize, a: usize| {
            let p = self.plane(s.walls[k]).0;
            [p.x, p.y, p.z][a]
        };
        [0, 1, 2].map(|a| coord(2 * a + 1, a) - coord(2 * a, a))
    }

    /// The pressure (Pa) the grains exert on servo wall `k` (0..6) of the box.
    fn servo_pressure(&self, s: &Servo<T>, k: usize) -> T {
        let e = self.servo_extents(s);
        let a = k / 2;
        let area = e[(a + 1) % 3] * e[(a + 2) % 3];
        let (_, normal) = self.plane(s.walls[k]);
        -self.wall_reaction[s.walls[k]].dot(normal) / area
    }

    /// Moves the servo walls by `tau` (s): each plane along its normal at
    /// `gain x (target - measured pressure)`, capped at the largest speed; in triaxial mode the
    /// z planes close at the strain rate instead. Books their work on the grains.
    ///
    /// The gain is lowered where the wall's contacts respond strongly: a wall moving at `v` for
    /// `tau` changes the pressure it reads by `(k tau + c) v / A` (`k` the summed contact
    /// stiffness, `c` the summed damping coefficients: a moving wall feels its own dashpots),
    /// so a gain above `A / (k tau + c)` overshoots every step and the wall rattles; the servo
    /// keeps to [`SERVO_RELAXATION`] of that, as YADE's and Thornton's servos do for stiffness.
    fn servo_drift(&mut self, tau: T) {
        let Some(s) = self.servo else { return };
        let extents = self.servo_extents(&s);
        for k in 0..6 {
            let w = s.walls[k];
            let (point, normal) = self.plane(w);
            let a = k / 2;
            let area = extents[(a + 1) % 3] * extents[(a + 2) % 3];
            let (k_wall, c_wall) = self.wall_response[w];
            let response = k_wall * tau + c_wall;
            let gain = if response > T::ZERO { s.gain.min(T::of(SERVO_RELAXATION) * area / response) } else { s.gain };
            let speed = match s.strain_rate {
                Some(rate) if k >= 4 => rate * extents[2] * T::of(0.5),
                _ => (gain * (s.pressure - self.servo_pressure(&s, k))).max(-s.max_speed).min(s.max_speed),
            };
            let velocity = normal * speed;
            self.walls[w].geom = WallGeom::Plane { point: point + velocity * tau, normal };
            self.walls[w].velocity = velocity;
            self.external_work -= (self.wall_reaction[w].dot(velocity) * tau).f64();
        }
    }

    /// One time step of the scene's integrator.
    pub fn step(&mut self) -> Result<(), SimError> {
        if self.schedule.needs_loads {
            self.ensure_loads()?;
        }
        let ops = self.schedule.ops(self.step).len();
        for k in 0..ops {
            self.run(self.schedule.ops(self.step)[k])?;
        }
        self.step += 1;
        self.time += self.dt.f64();
        Ok(())
    }

    /// Overlap (m) and smaller radius (m) of pair `k`.
    fn pair_overlap(&self, k: usize) -> (T, T) {
        let (i, j) = (self.pairs.owner[k] as usize, self.pairs.partner[k] as usize);
        let d = self.periodic.min_image(self.body[i].pos - self.body[j].pos).norm();
        (self.prop[i].radius + self.prop[j].radius - d, self.prop[i].radius.min(self.prop[j].radius))
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

impl<T: Real> WallSums<T> {
    fn new(n: usize) -> Self {
        WallSums { reaction: vec![Vec3::ZERO; n], count: vec![0; n], response: vec![(T::ZERO, T::ZERO); n], regimes: RegimeCounts::default() }
    }
}

/// `wall_contacts` over every grain; returns the per-wall sums (per fixed chunk, then over
/// chunks in order).
fn wall_pass<T: Real>(
    ctx: &ForceContext<T>,
    body: &[Body<T>],
    prop: &[Props<T>],
    walls: &[WallState<T>],
    wall_load: &mut [Load<T>],
    wall_hist: &mut [T],
) -> WallSums<T> {
    let n_walls = walls.len();
    let per_grain = n_walls * ctx.slots.stride;
    let run = |c: usize, loads: &mut [Load<T>], hist: &mut [T]| {
        let mut sums = WallSums::new(n_walls);
        wall_block(c * CHUNK, loads, hist, body, prop, walls, ctx, &mut sums.reaction, &mut sums.count, &mut sums.response, &mut sums.regimes);
        sums
    };
    let parts: Vec<WallSums<T>> = if per_grain == 0 {
        wall_load.par_chunks_mut(CHUNK).with_min_len(PAR_MIN_CHUNKS).enumerate().map(|(c, loads)| run(c, loads, &mut [])).collect()
    } else {
        wall_load.par_chunks_mut(CHUNK).zip(wall_hist.par_chunks_mut(CHUNK * per_grain)).with_min_len(PAR_MIN_CHUNKS).enumerate().map(|(c, (loads, hist))| run(c, loads, hist)).collect()
    };
    let mut total = WallSums::new(n_walls);
    for p in parts {
        for w in 0..n_walls {
            total.reaction[w] += p.reaction[w];
            total.count[w] += p.count[w];
            total.response[w].0 += p.response[w].0;
            total.response[w].1 += p.response[w].1;
        }
        total.regimes.add(p.regimes);
    }
    total
}

/// Per-chunk partial sums of the statistics over grains.
#[derive(Clone, Copy, Default)]
struct GrainSums {
    ke_t: f64,
    ke_r: f64,
    pe_g: f64,
    momentum: [f64; 3],
    angular: [f64; 3],
    net_force: f64,
    net_force_loaded: f64,
    rattlers: u64,
    ke_rattlers: f64,
    wall_force: f64,
    wall_contacts: u64,
    wall_elastic: f64,
    max_wall_overlap: (f64, u32),
}

/// Per-chunk partial sums of the statistics over pairs.
#[derive(Clone, Copy, Default)]
struct PairSums {
    contacts: u64,
    clamped: u64,
    regimes: RegimeCounts,
    elastic: f64,
    force: f64,
    max_overlap: (f64, u32),
}

/// Bytes a vector holds allocated.
#[allow(clippy::ptr_arg)] // the capacity lives on the Vec, not the slice
fn allocated<X>(v: &Vec<X>) -> u64 {
    (v.capacity() * std::mem::size_of::<X>()) as u64
}

fn max_by_first(a: (f64, u32), b: (f64, u32)) -> (f64, u32) {
    if b.0 > a.0 { b } else { a }
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
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }

    fn stats(&mut self) -> Stats {
        // A rebuild that fails here (a non-finite grain) leaves the loads as they were: the
        // statistics name the grain and the next step returns the error.
        self.ensure_loads().ok();
        let g = self.gravity;
        let grain_sums = chunked(self.body.len(), |r| {
            let mut s = GrainSums::default();
            for i in r {
                let (b, p, l) = (&self.body[i], &self.prop[i], &self.load[i]);
                let m = p.mass.f64();
                let v = b.vel.f64();
                let pos = if self.image.is_empty() { b.pos } else { self.periodic.unwrap(b.pos, self.image[i]) };
                let x = pos.f64();
                s.ke_t += 0.5 * m * b.vel.norm2().f64();
                s.ke_r += 0.5 * p.inertia.f64() * b.omega.norm2().f64();
                s.pe_g -= m * g.dot(pos).f64();
                let w = b.omega.f64();
                let ii = p.inertia.f64();
                let mv = [m * v[0], m * v[1], m * v[2]];
                for (p, q) in s.momentum.iter_mut().zip(mv) {
                    *p += q;
                }
                s.angular[0] += x[1] * mv[2] - x[2] * mv[1] + ii * w[0];
                s.angular[1] += x[2] * mv[0] - x[0] * mv[2] + ii * w[1];
                s.angular[2] += x[0] * mv[1] - x[1] * mv[0] + ii * w[2];
                let pushes = |k: u32| (self.out[k as usize].f_n > T::ZERO) as u64;
                let pl = &self.pairs;
                let mut contacts: u64 = (pl.owner_start[i]..pl.owner_start[i + 1]).map(pushes).sum::<u64>() + pl.rev_pair[pl.rev_start[i] as usize..pl.rev_start[i + 1] as usize].iter().map(|&k| pushes(k)).sum::<u64>();
                for wall in &self.walls {
                    let (_, dist) = wall.geom.frame(b.pos);
                    let h = p.radius - dist;
                    if h > T::ZERO {
                        contacts += 1;
                        let c = &self.coeffs[wall.material as usize * self.n_materials + p.material as usize];
                        s.wall_contacts += 1;
                        s.wall_elastic += normal_potential(&self.model.normal, c, p.radius, h).f64();
                        s.max_wall_overlap = max_by_first(s.max_wall_overlap, ((h / p.radius).f64(), self.id[i]));
                    }
                }
                s.wall_force += self.wall_load[i].force.norm().f64();
                let net = l.force.norm().f64();
                s.net_force += net;
                if contacts < RATTLER_CONTACTS {
                    s.rattlers += 1;
                    s.ke_rattlers += 0.5 * m * b.vel.norm2().f64();
                } else {
                    s.net_force_loaded += net;
                }
            }
            s
        });
        let pair_sums = chunked(self.pairs.len(), |r| {
            let mut s = PairSums::default();
            for k in r {
                let (h, r_min) = self.pair_overlap(k);
                if h <= T::ZERO {
                    continue;
                }
                let (i, j) = (self.pairs.owner[k] as usize, self.pairs.partner[k] as usize);
                let (pi, pj) = (&self.prop[i], &self.prop[j]);
                let c = &self.coeffs[pi.material as usize * self.n_materials + pj.material as usize];
                let r_eff = pi.radius * pj.radius / (pi.radius + pj.radius);
                s.contacts += 1;
                s.clamped += self.out[k].clamped as u64;
                s.regimes.count(self.out[k].regime);
                s.elastic += normal_potential(&self.model.normal, c, r_eff, h).f64();
                s.force += 2.0 * self.out[k].f_i.norm().f64();
                s.max_overlap = max_by_first(s.max_overlap, ((h / r_min).f64(), self.id[i]));
            }
            s
        });
        let mut gs = GrainSums::default();
        for s in grain_sums {
            gs.ke_t += s.ke_t;
            gs.ke_r += s.ke_r;
            gs.pe_g += s.pe_g;
            for a in 0..3 {
                gs.momentum[a] += s.momentum[a];
                gs.angular[a] += s.angular[a];
            }
            gs.net_force += s.net_force;
            gs.net_force_loaded += s.net_force_loaded;
            gs.rattlers += s.rattlers;
            gs.ke_rattlers += s.ke_rattlers;
            gs.wall_force += s.wall_force;
            gs.wall_contacts += s.wall_contacts;
            gs.wall_elastic += s.wall_elastic;
            gs.max_wall_overlap = max_by_first(gs.max_wall_overlap, s.max_wall_overlap);
        }
        let mut ps = PairSums::default();
        for s in pair_sums {
            ps.contacts += s.contacts;
            ps.clamped += s.clamped;
            ps.regimes.add(s.regimes);
            ps.elastic += s.elastic;
            ps.force += s.force;
            ps.max_overlap = max_by_first(ps.max_overlap, s.max_overlap);
        }
        let n = self.body.len() as f64;
        // Each touching pair counts once per grain; each wall contact once.
        let contact_ends = 2 * ps.contacts + gs.wall_contacts;
        let unbalanced_force = crate::engine::unbalanced(gs.net_force, n, ps.force + gs.wall_force, contact_ends);
        let unbalanced_force_loaded = crate::engine::unbalanced(gs.net_force_loaded, n - gs.rattlers as f64, ps.force + gs.wall_force, contact_ends);
        let (max_overlap, max_overlap_grain) = max_by_first(ps.max_overlap, gs.max_wall_overlap);
        let walls = (0..self.walls.len())
            .map(|w| {
                let servo = self.servo.and_then(|s| s.walls.iter().position(|&x| x == w).map(|k| (s, k)));
                WallStats {
                    name: self.wall_names[w].clone(),
                    force: self.wall_reaction[w].f64(),
                    contacts: self.wall_count[w],
                    position: servo.map(|(_, k)| {
                        let p = self.plane(w).0;
                        [p.x, p.y, p.z][k / 2].f64()
                    }),
                    pressure: servo.map(|(s, k)| self.servo_pressure(&s, k).f64()),
                }
            })
            .collect();
        let piston = self.piston.map(|p| {
            let wall = &self.walls[p.wall];
            let z = match wall.geom {
                WallGeom::Piston { z } => z.f64(),
                _ => unreachable!("the piston's wall is a piston"),
            };
            PistonStats {
                z,
                velocity: wall.velocity.z.f64(),
                target_pressure: p.pressure.f64(),
                pressure: self.wall_reaction[p.wall].z.f64() / p.area.f64(),
            }
        });
        let piston_ke = self.piston.map_or(0.0, |p| 0.5 * p.mass.f64() * self.walls[p.wall].velocity.z.f64().powi(2));
        let (bridges, liquid_in_bridges) = if self.slots.layout.bridge {
            let (stride, b) = (self.slots.stride, self.slots.bridge);
            chunked(self.pairs.len(), |r| r.map(|k| self.hist[k * stride + b].f64()).filter(|v| *v > 0.0).fold((0u64, 0.0), |(n, s), v| (n + 1, s + v)))
                .into_iter()
                .fold((0, 0.0), |(n, s), (m, t)| (n + m, s + t))
        } else {
            (0, 0.0)
        };
        let liquid_on_grains: f64 = chunked(self.liquid.len(), |r| self.liquid[r].iter().map(|x| x.f64()).sum::<f64>()).into_iter().sum();
        Stats {
            step: self.step,
            time: self.time,
            ke_translational: gs.ke_t,
            ke_rotational: gs.ke_r,
            elastic_energy: ps.elastic + gs.wall_elastic,
            gravity_energy: gs.pe_g,
            piston_ke,
            external_work: self.external_work,
            momentum: gs.momentum,
            angular_momentum: gs.angular,
            pairs: self.pairs.len() as u64,
            contacts: ps.contacts,
            wall_contacts: gs.wall_contacts,
            clamped: ps.clamped,
            sliding: ps.regimes.sliding + self.wall_regimes.sliding,
            rolling: ps.regimes.rolling + self.wall_regimes.rolling,
            coordination: 2.0 * ps.contacts as f64 / n,
            max_overlap,
            max_overlap_grain,
            unbalanced_force,
            unbalanced_force_loaded,
            rattlers: gs.rattlers,
            ke_rattlers: gs.ke_rattlers,
            non_finite_grain: self.body.iter().position(|b| !(b.pos.is_finite() && b.vel.is_finite() && b.omega.is_finite())).map(|i| self.id[i]),
            rebuilds: self.rebuilds,
            bridges,
            liquid_in_bridges,
            liquid_on_grains,
            walls,
            piston,
        }
    }

    fn frame(&self, contacts: bool) -> Frame {
        Frame {
            time: self.time,
            id: self.id.clone(),
            position: self.body.iter().map(|b| b.pos.f64()).collect(),
            radius: self.prop.iter().map(|p| p.radius.f64()).collect(),
            velocity: self.body.iter().map(|b| b.vel.f64()).collect(),
            angular_velocity: self.body.iter().map(|b| b.omega.f64()).collect(),
            orientation: self.orientation.as_ref().map(|q| q.iter().map(|q| [q[0].f64(), q[1].f64(), q[2].f64(), q[3].f64()]).collect()),
            contacts: contacts.then(|| {
                (0..self.pairs.len())
                    .filter_map(|k| {
                        let (h, _) = self.pair_overlap(k);
                        (h > T::ZERO || self.out[k].f_c != T::ZERO).then(|| {
                            let springs = self.slots.load(&self.hist[k * self.slots.stride..]);
                            ContactRecord {
                                i: self.id[self.pairs.owner[k] as usize],
                                j: self.id[self.pairs.partner[k] as usize],
                                overlap: h.f64(),
                                normal_force: (self.out[k].f_n + self.out[k].f_c).f64(),
                                force: self.out[k].f_i.f64(),
                                force_j: self.out[k].f_j.f64(),
                                tangential_spring: springs.tangential.f64(),
                                rolling_spring: springs.rolling.f64(),
                            }
                        })
                    })
                    .collect()
            }),
            wall_contacts: contacts.then(|| {
                let ctx = ForceContext { model: &self.model, coeffs: &self.coeffs, n_materials: self.n_materials, slots: self.slots, elapsed: T::ZERO, periodic: self.periodic };
                wall_contact_records(&self.body, &self.prop, &self.id, &self.walls, &ctx, &self.wall_hist)
            }),
        }
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
        let d: Vec<f64> = (0..self.pairs.len())
            .map(|k| {
                let (i, j) = (self.pairs.owner[k] as usize, self.pairs.partner[k] as usize);
                let (ri, rj) = (self.prop[i].radius.f64(), self.prop[j].radius.f64());
                2.0 * ri * rj / (ri + rj)
            })
            .collect();
        let gaps: Vec<f64> = (0..self.pairs.len()).map(|k| self.gap(k).f64()).collect();
        let (shares, rest) = share_liquid(volume, &d, &gaps, self.bridge_cap.f64(), theta.f64());
        let (stride, b) = (self.slots.stride, self.slots.bridge);
        for (k, v) in shares {
            self.hist[k * stride + b] += T::of(v);
        }
        // What the bridges could not hold waits on the grains.
        let rest = T::of(rest / self.liquid.len() as f64);
        for l in &mut self.liquid {
            *l += rest;
        }
        self.forces_valid = false;
        Ok(())
    }

    fn memory_bytes(&self) -> u64 {
        let l = &self.pairs;
        let grains = allocated(&self.liquid) + allocated(&self.id) + allocated(&self.body) + allocated(&self.prop) + allocated(&self.load) + allocated(&self.built_at) + allocated(&self.image);
        let walls = allocated(&self.wall_hist) + allocated(&self.wall_load) + self.orientation.as_ref().map_or(0, allocated);
        let pairs = allocated(&self.hist) + allocated(&self.out) + allocated(&l.owner_start) + allocated(&l.owner) + allocated(&l.partner) + allocated(&l.rev_start) + allocated(&l.rev_pair);
        grains + walls + pairs + allocated(&self.grid.cell_start) + allocated(&self.grid.cell_grains) + allocated(&self.coeffs)
    }

    fn set_profiling(&mut self, on: bool) {
        self.clock.enable(on);
    }

    fn phase_seconds(&self) -> Vec<(&'static str, f64)> {
        self.clock.totals()
    }

    fn save(&self) -> Option<EngineState> {
        let mut s = EngineState::default();
        let v3 = |v: &Vec3<T>| [v.x.f64(), v.y.f64(), v.z.f64()];
        s.put_reals("body", self.body.iter().flat_map(|b| [v3(&b.pos), v3(&b.vel), v3(&b.omega)].concat()));
        s.put_reals("load", self.load.iter().flat_map(|l| [v3(&l.force), v3(&l.torque)].concat()));
        s.put_reals("wall_load", self.wall_load.iter().flat_map(|l| [v3(&l.force), v3(&l.torque)].concat()));
        s.put_reals("built_at", self.built_at.iter().flat_map(v3));
        s.put_ints("image", self.image.iter().flat_map(|i| i.map(|x| x as i64 as u64)));
        if let Some(q) = &self.orientation {
            s.put_reals("orientation", q.iter().flat_map(|q| q.map(T::f64)));
        }
        s.put_reals("wall_hist", self.wall_hist.iter().map(|x| x.f64()));
        s.put_reals("wall_reaction", self.wall_reaction.iter().flat_map(v3));
        s.put_ints("wall_count", self.wall_count.iter().copied());
        let piston = self.piston.map_or(Vec::new(), |p| {
            let z = match self.walls[p.wall].geom {
                WallGeom::Piston { z } => z.f64(),
                _ => unreachable!("the piston's wall is a piston"),
            };
            vec![z, self.walls[p.wall].velocity.z.f64(), p.pressure.f64()]
        });
        s.put_reals("piston", piston);
        let servo = self.servo.map_or(Vec::new(), |sv| {
            let mut v: Vec<f64> = sv.walls.iter().flat_map(|&w| [v3(&self.plane(w).0), v3(&self.walls[w].velocity)].concat()).collect();
            v.extend([sv.pressure.f64(), sv.strain_rate.map_or(f64::NAN, |r| r.f64())]);
            v
        });
        s.put_reals("servo", servo);
        let l = &self.pairs;
        for (name, v) in [("owner_start", &l.owner_start), ("owner", &l.owner), ("partner", &l.partner), ("rev_start", &l.rev_start), ("rev_pair", &l.rev_pair)] {
            s.put_ints(name, v.iter().map(|&x| x as u64));
        }
        s.put_reals("hist", self.hist.iter().map(|x| x.f64()));
        s.put_reals("liquid", self.liquid.iter().map(|x| x.f64()));
        s.put_reals(
            "out",
            self.out.iter().flat_map(|o| {
                let mut r = [v3(&o.f_i), v3(&o.f_j), v3(&o.t_i), v3(&o.t_j), [o.f_n.f64(), if o.clamped { 1.0 } else { 0.0 }, o.f_c.f64()]].concat();
                r.push(o.regime as u8 as f64);
                r
            }),
        );
        s.put_reals("clock", [self.max_moved2.f64(), self.time, self.external_work]);
        s.put_ints("counters", [self.step, self.rebuilds, self.forces_valid as u64]);
        Some(s)
    }

    fn restore(&mut self, s: &EngineState) -> anyhow::Result<()> {
        let n = self.body.len();
        let v3 = |a: &[f64]| Vec3::new(T::of(a[0]), T::of(a[1]), T::of(a[2]));
        for (b, c) in self.body.iter_mut().zip(s.reals("body", 9 * n)?.chunks_exact(9)) {
            *b = Body { pos: v3(&c[0..3]), vel: v3(&c[3..6]), omega: v3(&c[6..9]) };
        }
        for (l, c) in self.load.iter_mut().zip(s.reals("load", 6 * n)?.chunks_exact(6)) {
            *l = Load { force: v3(&c[0..3]), torque: v3(&c[3..6]) };
        }
        for (l, c) in self.wall_load.iter_mut().zip(s.reals("wall_load", 6 * n)?.chunks_exact(6)) {
            *l = Load { force: v3(&c[0..3]), torque: v3(&c[3..6]) };
        }
        for (b, c) in self.built_at.iter_mut().zip(s.reals("built_at", 3 * n)?.chunks_exact(3)) {
            *b = v3(c);
        }
        let images = s.ints("image", Some(3 * self.image.len()))?;
        for (i, c) in self.image.iter_mut().zip(images.chunks_exact(3)) {
            *i = [c[0] as i64 as i32, c[1] as i64 as i32, c[2] as i64 as i32];
        }
        if let Some(q) = &mut self.orientation {
            for (q, c) in q.iter_mut().zip(s.reals("orientation", 4 * n)?.chunks_exact(4)) {
                *q = [T::of(c[0]), T::of(c[1]), T::of(c[2]), T::of(c[3])];
            }
        }
        self.wall_hist = s.reals("wall_hist", self.wall_hist.len())?.iter().map(|&x| T::of(x)).collect();
        self.wall_reaction = s.reals("wall_reaction", 3 * self.walls.len())?.chunks_exact(3).map(v3).collect();
        self.wall_count = s.ints("wall_count", Some(self.walls.len()))?.to_vec();
        if let Some(p) = &mut self.piston {
            let v = s.reals("piston", 3)?;
            self.walls[p.wall].geom = WallGeom::Piston { z: T::of(v[0]) };
            self.walls[p.wall].velocity.z = T::of(v[1]);
            p.pressure = T::of(v[2]);
        }
        if let Some(mut sv) = self.servo {
            let v = s.reals("servo", 6 * 6 + 2)?;
            for (k, &w) in sv.walls.iter().enumerate() {
                let (_, normal) = self.plane(w);
                self.walls[w].geom = WallGeom::Plane { point: v3(&v[6 * k..6 * k + 3]), normal };
                self.walls[w].velocity = v3(&v[6 * k + 3..6 * k + 6]);
            }
            sv.pressure = T::of(v[36]);
            sv.strain_rate = (!v[37].is_nan()).then(|| T::of(v[37]));
            self.servo = Some(sv);
        }
        let u32s = |name: &str, len: Option<usize>| -> anyhow::Result<Vec<u32>> { Ok(s.ints(name, len)?.iter().map(|&x| x as u32).collect()) };
        let owner = u32s("owner", None)?;
        let n_pairs = owner.len();
        self.pairs = PairList {
            owner_start: u32s("owner_start", Some(n + 1))?,
            owner,
            partner: u32s("partner", Some(n_pairs))?,
            rev_start: u32s("rev_start", Some(n + 1))?,
            rev_pair: u32s("rev_pair", Some(n_pairs))?,
        };
        self.hist = s.reals("hist", n_pairs * self.slots.stride)?.iter().map(|&x| T::of(x)).collect();
        self.liquid = s.reals("liquid", self.liquid.len())?.iter().map(|&x| T::of(x)).collect();
        self.out = s
            .reals("out", 16 * n_pairs)?
            .chunks_exact(16)
            .map(|c| ContactForce { f_i: v3(&c[0..3]), f_j: v3(&c[3..6]), t_i: v3(&c[6..9]), t_j: v3(&c[9..12]), f_n: T::of(c[12]), clamped: c[13] != 0.0, f_c: T::of(c[14]), regime: Regime::from_code(c[15] as u8) })
            .collect();
        let clock = s.reals("clock", 3)?;
        (self.max_moved2, self.time, self.external_work) = (T::of(clock[0]), clock[1], clock[2]);
        let counters = s.ints("counters", Some(3))?;
        (self.step, self.rebuilds, self.forces_valid) = (counters[0], counters[1], counters[2] != 0);
        Ok(())
    }

    fn place_piston(&mut self, z: f64) {
        if let Some(p) = self.piston {
            self.walls[p.wall].geom = WallGeom::Piston { z: T::of(z) };
            self.walls[p.wall].velocity = Vec3::ZERO;
        }
    }
}
