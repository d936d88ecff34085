//! Contact dynamics (Moreau-Jean) for rigid frictional spheres and the scene's walls, beside
//! the DEM engine: the method of Richefeu et al.'s samples S1 and S2.
//!
//! One step of length `h`:
//! 1. Contacts: every grain pair whose surfaces are within the gap allowance of each other
//!    (the DEM engine's cell hash and pair detection, canonical order: owner id, then partner
//!    id) and every grain within the allowance of a wall, after the pairs. Each contact has a
//!    unit normal `n` from its first body `a` (the owner grain) to its second `b` (the partner
//!    grain, or the wall), its gap `g` (m, negative when overlapping) and its relative velocity
//!    at the contact point `u = v_b + w_b x (-R_b n) - v_a - w_a x (R_a n)` (m/s).
//! 2. Free velocities `v_free = v + h g_vec` (gravity, the only external force), angular ones
//!    unchanged.
//! 3. Impulses `r` (N s, on `b`; `-r` on `a`) by nonsmooth Gauss-Seidel: contact after contact
//!    in the fixed order, the local problem solved exactly and the velocities updated at once.
//!    The local Delassus operator of two spheres is diagonal in the contact frame,
//!    `W = w_n n n^T + w_t (1 - n n^T)` with `w_n = 1/m_a + 1/m_b` and
//!    `w_t = w_n + R_a^2/I_a + R_b^2/I_b` (1/kg; a wall has infinite mass), so that
//!    * normal (Signorini with Newton's impact law): `u_n^+ >= u_min`, `r_n >= 0`,
//!      complementary: `r_n = max(0, (u_min - u'_n) / w_n)`, with `u'` the contact's velocity
//!      without its own impulse. A contact predicted to be closed within the step (`g + h
//!      u_n^theta <= 0` on the free velocities) takes Newton's impact law, `u_min = -e u_n^-`;
//!      one predicted open only must not close by the step's end, `g + h u_n^theta >= 0`,
//!      `u_min = -(g / h + (1 - theta) u_n^-) / theta` (so that a contact in touch whose
//!      neighbours are yet to push it still carries its load);
//!    * tangential (Coulomb with `mu`): the sticking impulse `-u'_t / w_t` when it lies in the
//!      cone `|r_t| <= mu r_n`, else `-mu r_n u'_t / |u'_t|` (sliding against `u'_t`).
//!
//!    A contact without impulse whose normal velocity (`u'_n = (v_b - v_a) . n`; spin moves
//!    no contact point along `n`) is already at least `u_min` stays open, and its solve is that
//!    one comparison (`solve::stays_open`): about half the contacts within the gap allowance
//!    of a dense packing.
//!
//!    The sweep repeats until its quadratic norm, LMGC90's for nonsmooth Gauss-Seidel,
//!    `sqrt(sum |W dr|^2 / sum |W r|^2)` (the velocity corrections `W dr` the sweep's local
//!    solves made, that is how far each contact was from its laws, against the velocities
//!    `W r` the impulses give; `W` the local Delassus diagonal), falls to the tolerance or
//!    the iteration cap is reached; the statistics say which, and the step's residuals
//!    (`residual`) say how far the final impulses are from the laws.
//!    Impulses start from the previous step's (warm start), carried per contact by (grain
//!    id, partner id or wall) like the DEM engine's history.
//! 4. Positions by the theta-method: `x += h (theta v^+ + (1 - theta) v^-)`, the servo box's
//!    walls' too (`servo`: they are bodies pushed by the target pressure).
//!
//! The sweep solves the grain pairs colour by colour (`colour`: no two contacts of a colour
//! share a grain), each colour's contacts shared by the engine's threads (`parallel`, when
//! the run's crew finds that faster than one thread: `crate::state::crew`), then the wall
//! contacts one after the other; the schedule depends on the contacts alone, so a step gives
//! the same bits on any thread count.

use crate::state::crew::{Crew, Who};
use crate::state::profile::{PhaseClock, Phases};
use crate::state::{Body, Props};
use crate::engine::SimError;
use crate::periodic::Periodic;
use crate::position;
use crate::real::{Real, Vec3};
pub use crate::scene::CdParams;
use crate::scene::{Scene, WallShape};
use crate::walls::WallGeom;

mod colour;
mod engine;
mod near;
mod parallel;
mod residual;
mod servo;
mod solve;
mod warm;

pub use colour::{Schedule, MAX_COLOURS};
pub use crate::engine::Residuals;
pub use parallel::THREADS_MIN_CONTACTS;
pub use solve::{CpuSweeps, MEASURE_BLOCK};

/// The second body of a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Partner {
    /// A grain, by slot.
    Grain(u32),
    /// A wall, by index.
    Wall(u32),
}

/// One contact of a step.
#[derive(Clone, Copy, Debug)]
pub struct Contact<T> {
    /// The first body: a grain slot.
    pub a: u32,
    /// The second body.
    pub b: Partner,
    /// Unit normal from `a` to `b`.
    pub n: Vec3<T>,
    /// Gap between the surfaces at the start of the step (m; negative: overlapping).
    pub gap: T,
    /// Friction coefficient (-).
    pub mu: T,
    /// Normal restitution coefficient (-).
    pub e: T,
    /// Radius of `a` (m).
    pub radius_a: T,
    /// Radius of `b` (m; 0 for a wall).
    pub radius_b: T,
    /// `1/m_a` (1/kg).
    pub inv_mass_a: T,
    /// `1/I_a` (1/(kg m^2)).
    pub inv_inertia_a: T,
    /// `1/m_b` (1/kg): a wall's along its normal, 0 for a wall that does not yield.
    pub inv_mass_b: T,
    /// `1/I_b` (1/(kg m^2); 0 for a wall).
    pub inv_inertia_b: T,
    /// Normal Delassus diagonal `w_n` (1/kg).
    pub w_n: T,
    /// Tangential Delassus diagonal `w_t` (1/kg).
    pub w_t: T,
    /// `1 / w_n` (kg).
    pub inv_w_n: T,
    /// `1 / w_t` (kg).
    pub inv_w_t: T,
    /// Least normal relative velocity at the step's end, `u_min` (m/s).
    pub u_min: T,
    /// Impulse on `b` (N s; `-r` on `a`), world frame.
    pub r: Vec3<T>,
}

/// The skin of the pairs the contacts are drawn from ([`near`]), in gap allowances: the pairs
/// are searched again once a grain has moved half of it.
const NEAR_SKIN: f64 = 1.0;

/// A wall's motion: walls translate along their normal only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallMotion<T> {
    /// Velocity (m/s).
    pub vel: Vec3<T>,
    /// `1/M` (1/kg): 0 for a wall that moves as prescribed (or not at all).
    pub inv_mass: T,
}

/// What the last step's solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Gauss-Seidel sweeps run.
    pub iterations: u32,
    /// Whether the sweeps' quadratic norm fell to the tolerance within the cap.
    pub converged: bool,
    /// Quadratic norm of the last sweep (-).
    pub sweep_norm: f64,
    /// Contacts in the system.
    pub contacts: usize,
    /// Contacts carrying a normal impulse.
    pub loaded: usize,
    /// Colours of the grain pairs (each solved at once over the threads).
    pub colours: usize,
    /// Contacts of the largest colour.
    pub largest_colour: usize,
    /// Contacts solved one after the other: the wall contacts and any uncoloured pair.
    pub serial: usize,
    /// Force balance: the mean over grains of the net impulse that the contacts and gravity
    /// leave on a grain, `|m (v^+ - v^-)|`, over the mean normal impulse of the loaded
    /// contacts (-; 0 when every grain is in equilibrium).
    pub unbalanced: f64,
    /// How far the impulses are from the contact laws at the step's end.
    pub residuals: Residuals,
}

/// What the sweeps of one step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Solved {
    /// Sweeps run.
    pub iterations: u32,
    /// Whether the sweeps' quadratic norm fell to the tolerance within the cap.
    pub converged: bool,
    /// Quadratic norm of the last sweep (-).
    pub sweep_norm: f64,
}

/// What a step's sweeps aim at and may spend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepSettings<T> {
    /// Quadratic norm of a sweep at which the sweeps stop (-).
    pub tolerance: T,
    /// Most sweeps.
    pub max_iterations: u32,
    /// Over-relaxation factor `omega` (-; 1: plain Gauss-Seidel): each local solution `r*` is
    /// taken as `r + omega (r* - r)`, put back in the cone (`solve::relax`).
    pub relaxation: T,
    /// Whether the CPU's pool may share the sweeps (its crew's choice, [`crate::state::crew`];
    /// the same bits either way); the GPU ignores it.
    pub shared: bool,
}

/// Where a step's Gauss-Seidel sweeps run: on the CPU's threads ([`CpuSweeps`]) or on a GPU
/// (`crate::gpu::GpuSweeps`). Both sweep the contacts in the schedule's order (colour by
/// colour, then the serial tail) and sum the convergence measure as
/// [`MEASURE_BLOCK`] says, so they give the same bits where the device neither fuses nor
/// reorders f32 operations.
pub trait Sweeps<T: Real>: Send {
    /// "cpu" or "gpu".
    fn backend(&self) -> &'static str;
    /// Sweeps the contacts, whose impulses (the warm start) the bodies' velocities already
    /// hold, until a sweep's quadratic norm falls to the settings' tolerance or their cap of
    /// sweeps has run; leaves the impulses in `contacts` and the velocities in `body` and
    /// `walls`.
    fn solve(&mut self, contacts: &mut [Contact<T>], schedule: &Schedule, body: &mut [Body<T>], walls: &mut [WallMotion<T>], settings: SweepSettings<T>) -> Result<Solved, SimError>;
}

/// A contact-dynamics system: rigid spheres, static walls, the step's contacts.
pub struct ContactDynamics<T: Real> {
    params: CdParams,
    h: T,
    gravity: Vec3<T>,
    id: Vec<u32>,
    body: Vec<Body<T>>,
    /// Compensated positions' residuals ([`crate::position`]; empty in f64).
    residual: Vec<Vec3<T>>,
    prop: Vec<Props<T>>,
    /// Material index of each grain.
    material: Vec<u32>,
    walls: Vec<(WallGeom<T>, u32)>,
    wall_motion: Vec<WallMotion<T>>,
    servo: Option<servo::ServoWalls<T>>,
    /// Work of the moving walls on the grains since the start (J).
    external_work: f64,
    /// `(mu, e)` per pair of materials, row-major.
    coeffs: Vec<(T, T)>,
    n_materials: usize,
    r_max: T,
    contacts: Vec<Contact<T>>,
    schedule: Schedule,
    /// The pairs the contacts are drawn from.
    near: near::Near<T>,
    sweeps: Box<dyn Sweeps<T>>,
    /// Last step's impulses by (grain id, partner grain id or wall), for the warm start.
    warm: warm::WarmStart<T>,
    report: SolveReport,
    /// The solver's record since the last statistics read.
    since_read: crate::engine::SolverStats,
    steps: u64,
    wall_names: Vec<String>,
    /// Time per phase of the step, when profiling.
    clock: PhaseClock<CdPhase>,
    /// Whether the steps' sweeps go on the pool or on the calling thread alone.
    crew: Crew,
}

/// The phases of a contact-dynamics step, for `grains bench`.
#[derive(Clone, Copy, Debug)]
pub enum CdPhase {
    /// The servo's preparation, contact detection, colouring, the warm start and the laws.
    Detect,
    /// The Gauss-Seidel sweeps.
    Sweeps,
    /// Force balance, the warm start's record, positions and the walls' motion.
    Integrate,
}

impl Phases for CdPhase {
    const NAMES: &'static [&'static str] = &["detect", "sweeps", "integrate"];
    fn index(self) -> usize {
        self as usize
    }
}

/// Why a scene cannot run by contact dynamics.
#[derive(Debug, thiserror::Error)]
pub enum CdError {
    /// A feature the solver does not model.
    #[error("{path}: {what} is not modelled by contact dynamics; fix: {fix}")]
    Unsupported {
        /// The scene file.
        path: String,
        /// What the scene asks for.
        what: &'static str,
        /// What to do instead.
        fix: &'static str,
    },
}

impl<T: Real> ContactDynamics<T> {
    /// The system of a scene's grains and walls at step `h` = the scene's time step.
    pub fn new(scene: &Scene, params: CdParams) -> Result<Self, CdError> {
        let path = scene.path.display().to_string();
        let unsupported = |what, fix| Err(CdError::Unsupported { path: path.clone(), what, fix });
        if scene.periodic.iter().any(Option::is_some) {
            return unsupported("a periodic boundary", "bound the grains with walls");
        }
        if scene.walls.iter().any(|w| matches!(w.shape, WallShape::Piston { .. })) {
            return unsupported("a piston", "use static walls or a servo box");
        }
        if scene.walls.iter().any(|w| matches!(w.shape, WallShape::Mesh { .. })) {
            return unsupported("a mesh wall", "use the DEM method (simulation.method = \"dem\")");
        }
        if scene.walls.iter().any(|w| w.drive.moves()) || scene.stages.iter().any(|s| !s.walls.is_empty()) {
            return unsupported("a wall with a prescribed velocity or spin", "use the DEM method (simulation.method = \"dem\")");
        }
        if scene.stages.iter().any(|s| !s.presence.is_empty()) {
            return unsupported("a stage that adds or removes a wall", "use the DEM method (simulation.method = \"dem\")");
        }
        if !matches!(scene.model.cohesion, crate::model::CohesionLaw::None) {
            return unsupported("capillary cohesion", "drop [model] cohesion");
        }
        if crate::model::NormalSetup::adhesive(&scene.model.normal) {
            return unsupported("an adhesive normal law (DMT)", "use normal = \"hertz\" or the DEM method");
        }
        let n_materials = scene.materials.len();
        // Friction and restitution of each pair of materials: the mixing rule's, or the pair
        // table's.
        let coeffs = crate::scene::mixed_table(&scene.materials, &scene.pairs).iter().map(|m| (T::of(m.mu_s), T::of(m.restitution))).collect();
        let g = &scene.grains;
        let n = g.len();
        let (pos, residual): (Vec<Vec3<T>>, Vec<Vec3<T>>) = g.position.iter().map(|&x| position::split(x)).unzip();
        let body = (0..n).map(|i| Body { pos: pos[i], vel: Vec3::of(g.velocity[i]), omega: Vec3::of(g.angular_velocity[i]) }).collect();
        let prop = (0..n)
            .map(|i| Props::sphere(g.radius[i], g.mass[i]))
            .collect();
        let servo = scene.servo.as_ref().map(|b| servo::ServoWalls {
            walls: b.walls,
            pressure: T::of(b.pressure),
            max_speed: T::of(b.max_speed),
            mass: T::of(params.wall_mass.unwrap_or_else(|| g.mass.iter().sum())),
            strain_rate: None,
        });
        Ok(ContactDynamics {
            params,
            h: T::of(scene.time_step.dt),
            gravity: Vec3::of(scene.gravity),
            id: (0..n as u32).collect(),
            body,
            residual: if T::COMPENSATED { residual } else { Vec::new() },
            prop,
            material: g.material.iter().map(|&m| m as u32).collect(),
            walls: scene.walls.iter().map(|w| (WallGeom::of(&w.shape), w.material as u32)).collect(),
            wall_motion: vec![WallMotion::default(); scene.walls.len()],
            servo,
            external_work: 0.0,
            coeffs,
            n_materials,
            r_max: T::of(g.radius.iter().copied().fold(0.0, f64::max)),
            contacts: Vec::new(),
            schedule: Schedule::default(),
            near: near::Near::default(),
            sweeps: Box::new(CpuSweeps::default()),
            warm: Default::default(),
            report: SolveReport::default(),
            since_read: Default::default(),
            steps: 0,
            wall_names: scene.walls.iter().map(|w| w.name.clone()).collect(),
            clock: PhaseClock::default(),
            crew: Crew::default(),
        })
    }

    /// The same system with its sweeps run by `sweeps` (a GPU's, say).
    pub fn with_sweeps(self, sweeps: Box<dyn Sweeps<T>>) -> Self {
        ContactDynamics { sweeps, ..self }
    }

    /// The grains' states, by id (slots are ids here).
    pub fn bodies(&self) -> &[Body<T>] {
        &self.body
    }

    /// The contacts of the last step with their impulses, in solve order.
    pub fn contacts(&self) -> &[Contact<T>] {
        &self.contacts
    }

    /// What the last step's solve did.
    pub fn report(&self) -> SolveReport {
        self.report
    }

    /// Grain `i`'s position (m, f64, residual included).
    pub fn position(&self, i: usize) -> glam::DVec3 {
        position::absolute(self.body[i].pos, position::residual_at(&self.residual, i))
    }

    /// `(mu, e)` of materials `a` and `b`.
    fn pair(&self, a: u32, b: u32) -> (T, T) {
        self.coeffs[a as usize * self.n_materials + b as usize]
    }

    /// The contact's second body as the solve sees it: a grain, or a wall's motion.
    fn body_b(&self, c: &Contact<T>) -> Body<T> {
        solve::second_body(c, &self.body, &self.wall_motion)
    }

    /// Normal relative velocity of each contact (m/s).
    fn normal_velocities(&self) -> Vec<T> {
        self.contacts.iter().map(|c| solve::relative_velocity(c, &self.body[c.a as usize], &self.body_b(c)).dot(c.n)).collect()
    }

    /// Step 1: the contacts within the gap allowance, pairs in canonical order, then walls,
    /// scheduled into colours; their impulses from the warm start.
    fn detect(&mut self) {
        let allowance = T::of(self.params.gap_allowance);
        let periodic = Periodic::<T>::of(&[None, None, None]);
        let mut near = std::mem::take(&mut self.near);
        let pairs = near.update(&self.body, &self.residual, &self.prop, &self.id, self.r_max, allowance, allowance * T::of(NEAR_SKIN));
        let mut contacts = Vec::with_capacity(pairs.len() + self.walls.len());
        for (a, &b) in pairs.owners_of(0..pairs.len()).zip(&pairs.partner) {
            let b = b as usize;
            let d = position::separation_of(&periodic, |s| self.body[s].pos, &self.residual, b, a);
            let (pa, pb) = (&self.prop[a], &self.prop[b]);
            // The cell search's test (`state::grid`), on the separation's mirror image, whose
            // squared length has the same bits.
            let reach = pa.radius + pb.radius + allowance;
            if !(d.norm2() < reach * reach) {
                continue;
            }
            let dist = d.norm();
            let (inv_mass_b, inv_inertia_b) = (T::ONE / pb.mass, T::ONE / pb.inertia);
            contacts.push(self.contact(a, Partner::Grain(b as u32), d * (T::ONE / dist), dist - pa.radius - pb.radius, self.material[b], (pb.radius, inv_mass_b, inv_inertia_b)));
        }
        self.near = near;
        for i in 0..self.body.len() {
            for (w, (geom, material)) in self.walls.iter().enumerate() {
                let (normal, dist) = geom.frame(self.body[i].pos, position::residual_at(&self.residual, i));
                let gap = dist - self.prop[i].radius;
                if gap < allowance {
                    contacts.push(self.contact(i, Partner::Wall(w as u32), -normal, gap, *material, (T::ZERO, self.wall_motion[w].inv_mass, T::ZERO)));
                }
            }
        }
        self.warm.start(&mut contacts, &self.id);
        self.schedule = colour::schedule(&mut contacts, self.body.len());
        self.contacts = contacts;
    }

    /// A contact of grain `a` with `b` (of `material`; `(radius, 1/m, 1/I)`) along the unit
    /// normal `n` at `gap`, with its Delassus diagonals.
    fn contact(&self, a: usize, b: Partner, n: Vec3<T>, gap: T, material: u32, (radius_b, inv_mass_b, inv_inertia_b): (T, T, T)) -> Contact<T> {
        let pa = &self.prop[a];
        let (mu, e) = self.pair(self.material[a], material);
        let (inv_mass_a, inv_inertia_a) = (T::ONE / pa.mass, T::ONE / pa.inertia);
        let w_n = inv_mass_a + inv_mass_b;
        // A wall turns no more than it slides: only its normal motion yields.
        let w_t = inv_mass_a + pa.radius * pa.radius * inv_inertia_a + if matches!(b, Partner::Grain(_)) { inv_mass_b + radius_b * radius_b * inv_inertia_b } else { T::ZERO };
        Contact { a: a as u32, b, n, gap, mu, e, radius_a: pa.radius, radius_b, inv_mass_a, inv_inertia_a, inv_mass_b, inv_inertia_b, w_n, w_t, inv_w_n: T::ONE / w_n, inv_w_t: T::ONE / w_t, u_min: T::ZERO, r: Vec3::ZERO }
    }

    /// Each contact's least normal velocity at the step's end, from its normal velocity before
    /// (`u_minus`) and after the free motion: a contact predicted closed within the step takes
    /// Newton's impact law; one predicted open must not close by the step's end.
    fn set_laws(&mut self, u_minus: &[T]) {
        let (h, theta) = (self.h, T::of(self.params.theta));
        let u_free = self.normal_velocities();
        for ((c, &u), free) in self.contacts.iter_mut().zip(u_minus).zip(u_free) {
            let closing = c.gap + h * (theta * free + (T::ONE - theta) * u) <= T::ZERO;
            c.u_min = if closing { -c.e * u } else { -(c.gap / h + (T::ONE - theta) * u) / theta };
        }
    }

    /// Advances one step (see the module's text); fails only when a GPU running the sweeps
    /// does.
    pub fn step(&mut self) -> Result<(), SimError> {
        let started = self.clock.start();
        self.servo_prepare();
        self.detect();
        let h = self.h;
        let theta = T::of(self.params.theta);
        let u_minus = self.normal_velocities();
        let before: Vec<Body<T>> = self.body.clone();
        let walls_before = self.wall_motion.clone();
        for b in &mut self.body {
            b.vel += self.gravity * h;
        }
        self.servo_kick();
        self.set_laws(&u_minus);
        let mut contacts = std::mem::take(&mut self.contacts);
        for c in &contacts {
            let mut b = self.body_b(c);
            solve::apply_a(c, &mut self.body[c.a as usize], c.r);
            solve::apply_b(c, &mut b, c.r);
            match c.b {
                Partner::Grain(j) => self.body[j as usize] = b,
                Partner::Wall(w) => self.wall_motion[w as usize].vel = b.vel,
            }
        }
        self.clock.stop(CdPhase::Detect, started);
        let started = self.clock.start();
        let mut report = SolveReport { contacts: contacts.len(), colours: self.schedule.starts.len().saturating_sub(1), largest_colour: self.schedule.colours().map(|r| r.len()).max().unwrap_or(0), serial: contacts.len() - self.schedule.tail(), ..Default::default() };
        let settings = SweepSettings { tolerance: T::of(self.params.tolerance), max_iterations: self.params.max_iterations, relaxation: T::of(self.params.relaxation), shared: self.crew.who() == Who::Pool };
        // The crew times the sweeps alone, per contact sweep: the rest of the step runs on one
        // thread either way.
        let timed = rayon::current_num_threads() > 1;
        if timed {
            self.crew.step_starts();
        }
        let solved = self.sweeps.solve(&mut contacts, &self.schedule, &mut self.body, &mut self.wall_motion, settings)?;
        if timed {
            self.crew.step_ends_with(Some(contacts.len() as f64 * solved.iterations as f64));
        }
        (report.iterations, report.converged, report.sweep_norm) = (solved.iterations, solved.converged, solved.sweep_norm);
        self.clock.stop(CdPhase::Sweeps, started);
        let started = self.clock.start();
        report.residuals = residual::residuals(&contacts, &self.body, &self.wall_motion);
        // Force balance of the grains, and the warm start of the next step.
        let loaded: Vec<T> = contacts.iter().map(|c| c.r.dot(c.n)).filter(|&r_n| r_n > T::ZERO).collect();
        report.loaded = loaded.len();
        let mean_r = loaded.iter().map(|r| r.f64()).sum::<f64>() / loaded.len().max(1) as f64;
        let net: f64 = self.body.iter().zip(&before).zip(&self.prop).map(|((b, b0), p)| ((b.vel - b0.vel) * p.mass).norm().f64()).sum();
        report.unbalanced = if mean_r > 0.0 { net / self.body.len() as f64 / mean_r } else { 0.0 };
        self.warm = warm::WarmStart::record(&contacts, &self.schedule.order, &self.id);
        self.contacts = contacts;
        self.report = report;
        let r = &mut self.since_read;
        r.mean_iterations = (r.mean_iterations * r.steps as f64 + report.iterations as f64) / (r.steps + 1) as f64;
        r.steps += 1;
        r.unconverged_steps += u64::from(!report.converged);
        r.steps_total += 1;
        r.unconverged_total += u64::from(!report.converged);
        r.max_iterations = r.max_iterations.max(report.iterations);
        r.contact_updates += report.contacts as u64 * u64::from(report.iterations);
        r.sweep_norm = r.sweep_norm.max(report.sweep_norm);
        r.unbalanced = report.unbalanced;
        r.residuals = r.residuals.max(report.residuals);
        // Positions by the theta-method.
        for (i, b0) in before.iter().enumerate() {
            let b = &mut self.body[i];
            let dx = (b.vel * theta + b0.vel * (T::ONE - theta)) * h;
            let mut r = position::residual_at(&self.residual, i);
            position::advance(&mut b.pos, &mut r, dx);
            if T::COMPENSATED {
                self.residual[i] = r;
            }
        }
        self.servo_move(&walls_before);
        self.steps += 1;
        self.clock.stop(CdPhase::Integrate, started);
        Ok(())
    }
}
