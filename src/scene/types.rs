//! The validated scene's types, in SI units and `f64`: what the engines, the host loop and
//! the analysis read. Plain data: the checks that make them live in [`super`] (validation),
//! [`crate::timestep`] (the time step) and [`crate::walls`] (wall geometry).

use glam::DVec3;
use crate::model::{ContactModel, MaterialConstants, MixedConstants, MixedOverride, PairCoeffs};
use crate::real::Real;
use serde::Serialize;
use std::path::PathBuf;

/// A material, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name grains and walls refer to.
    pub name: String,
    /// Density (kg/m^3); `None` for wall-only materials.
    pub density: Option<f64>,
    /// Restitution coefficient as given (`constants.restitution` is 1 when not given).
    pub restitution: Option<f64>,
    /// Elastic and frictional constants.
    pub constants: MaterialConstants,
}

/// A `[[pair]]` table, validated: what contacts between two materials take in place of the
/// mixing rule.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialPair {
    /// Indices into [`Scene::materials`], as the scene names them.
    pub materials: [u16; 2],
    /// The coefficients it gives.
    pub given: MixedOverride,
}

/// The mixed constants of every pair of `materials`, row-major (`a * n + b`): the mixing rule,
/// overridden where `pairs` gives a value (for both orders of the pair).
pub fn mixed_table(materials: &[Material], pairs: &[MaterialPair]) -> Vec<MixedConstants> {
    let n = materials.len();
    let mut table: Vec<MixedConstants> = materials.iter().flat_map(|a| materials.iter().map(|b| MixedConstants::rule(&a.constants, &b.constants))).collect();
    for p in pairs {
        let [a, b] = p.materials.map(usize::from);
        table[a * n + b] = p.given.over(table[a * n + b]);
        table[b * n + a] = table[a * n + b];
    }
    table
}

/// The initial state of every grain, indexed by permanent id.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Grains {
    /// Radius (m).
    pub radius: Vec<f64>,
    /// Mass (kg).
    pub mass: Vec<f64>,
    /// Centre position (m).
    pub position: Vec<DVec3>,
    /// Velocity (m/s).
    pub velocity: Vec<DVec3>,
    /// Angular velocity (rad/s).
    pub angular_velocity: Vec<DVec3>,
    /// Index into [`Scene::materials`].
    pub material: Vec<u16>,
    /// Whether each grain starts in play; empty when all do. The grains an inlet will insert
    /// wait out of play ([`crate::flow`]).
    pub in_play: Vec<bool>,
}

impl Grains {
    /// The same grains renumbered: grain `k` of the result is grain `order[k]` of `self`.
    pub fn permuted(&self, order: &[usize]) -> Grains {
        let pick = |v: &[DVec3]| order.iter().map(|&i| v[i]).collect();
        Grains {
            radius: order.iter().map(|&i| self.radius[i]).collect(),
            mass: order.iter().map(|&i| self.mass[i]).collect(),
            position: pick(&self.position),
            velocity: pick(&self.velocity),
            angular_velocity: pick(&self.angular_velocity),
            material: order.iter().map(|&i| self.material[i]).collect(),
            in_play: if self.in_play.is_empty() { Vec::new() } else { order.iter().map(|&i| self.in_play[i]).collect() },
        }
    }

    /// Whether grain `i` starts in play.
    pub fn starts_in_play(&self, i: usize) -> bool {
        self.in_play.get(i).copied().unwrap_or(true)
    }

    /// Number of grains.
    pub fn len(&self) -> usize {
        self.radius.len()
    }
    /// True when there are no grains.
    pub fn is_empty(&self) -> bool {
        self.radius.is_empty()
    }
    /// Appends a grain waiting out of play, at rest at `position` (m).
    pub(super) fn push_waiting(&mut self, radius: f64, mass: f64, position: DVec3, material: u16) {
        let n = self.len();
        self.push(radius, mass, position, DVec3::ZERO, DVec3::ZERO, material);
        if self.in_play.is_empty() {
            self.in_play = vec![true; n + 1];
        }
        self.in_play[n] = false;
    }

    pub(super) fn push(&mut self, radius: f64, mass: f64, position: DVec3, velocity: DVec3, angular_velocity: DVec3, material: u16) {
        self.radius.push(radius);
        self.mass.push(mass);
        self.position.push(position);
        self.velocity.push(velocity);
        self.angular_velocity.push(angular_velocity);
        self.material.push(material);
        if !self.in_play.is_empty() {
            self.in_play.push(true);
        }
    }
}

/// Shape and motion of a wall.
#[derive(Clone, Debug, PartialEq)]
pub enum WallShape {
    /// Fixed plane through `point` with unit `normal` pointing into the domain.
    Plane {
        /// A point on the plane (m).
        point: DVec3,
        /// Unit normal into the domain.
        normal: DVec3,
    },
    /// Fixed vertical cylinder, grains inside.
    Cylinder {
        /// Axis (x, y) (m).
        center: [f64; 2],
        /// Radius (m).
        radius: f64,
    },
    /// Triangle mesh, grains on either side of its triangles.
    Mesh {
        /// The triangles, placed in the scene (m).
        mesh: std::sync::Arc<crate::mesh::TriMesh>,
        /// Its rank among the scene's mesh walls (the engines' mesh tables).
        index: u32,
        /// The point (m) it turns about, where the scene puts it.
        pivot: DVec3,
    },
    /// Horizontal plate facing down, driven by a target pressure.
    Piston {
        /// Initial height (m).
        z: f64,
        /// Target pressure (Pa).
        pressure: f64,
        /// Mass (kg).
        mass: f64,
        /// Area the pressure acts on (m^2).
        area: f64,
    },
}

/// The servo-controlled box of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoBox {
    /// Wall indices of the x_min, x_max, y_min, y_max, z_min, z_max planes.
    pub walls: [usize; 6],
    /// Initial target pressure (Pa).
    pub pressure: f64,
    /// Wall speed per pressure error (m/(s Pa)).
    pub gain: f64,
    /// Largest wall speed (m/s).
    pub max_speed: f64,
}

/// Default largest speed of servo walls (m/s).
pub const DEFAULT_SERVO_SPEED: f64 = 0.005;
/// Pressure (Pa) below which the default servo gain stops growing.
pub const SERVO_PRESSURE_FLOOR: f64 = 10.0;

/// A wall, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Wall {
    /// Name in reports, e.g. `wall[0]` or `wall[1].bottom`.
    pub name: String,
    /// Geometry and motion.
    pub shape: WallShape,
    /// Index into [`Scene::materials`].
    pub material: u16,
    /// Its prescribed motion (zero for a fixed wall, and for the piston's and the servo box's,
    /// which their controllers move).
    pub drive: WallDrive,
    /// Whether grains meet it from the start: false for a wall that a stage adds first
    /// ([`Stage::presence`]).
    pub present: bool,
}

/// A wall's prescribed motion: it translates at `velocity` and spins at `angular_velocity`
/// about an axis through its pivot (a plane's point, a cylinder's axis, a mesh's `center`),
/// each point of it moving at `velocity + angular_velocity x (x - pivot)`. A spin along a
/// plane's normal or a cylinder's axis leaves the surface in place; a plane's about another
/// axis, and a mesh's, turn it ([`crate::walls::turns_with`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WallDrive {
    /// Velocity (m/s).
    pub velocity: DVec3,
    /// Angular velocity (rad/s).
    pub angular_velocity: DVec3,
    /// Whether the spin turns the surface ([`crate::walls::turns_with`]).
    pub turns: bool,
}

impl WallDrive {
    /// Whether the wall moves at all.
    pub fn moves(&self) -> bool {
        *self != WallDrive::default()
    }
}

/// Time integration scheme (Oquendo et al. sec. 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Velocity Verlet: one force evaluation per step.
    VelocityVerlet,
    /// Optimised velocity Verlet (Oquendo et al. eqs. 11-15), `xi = 0.1931833275037836`, two force
    /// evaluations per step.
    OptimizedVerlet,
}

impl Integrator {
    /// Name as written in scenes.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::VelocityVerlet => "velocity_verlet",
            Integrator::OptimizedVerlet => "optimized_verlet",
        }
    }

}

/// What a stage waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageKind {
    /// Deposition under gravity until settled.
    Fill,
    /// Relaxation until settled.
    Settle,
    /// A fixed duration.
    Run,
}

/// One stage of the host loop's program.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// Name in reports.
    pub name: String,
    /// What ends the stage.
    pub kind: StageKind,
    /// Run: the duration (s); fill/settle: the longest wait (s).
    pub duration: f64,
    /// Settled when the kinetic energy per grain (J) is below this ...
    pub ke_per_grain: f64,
    /// ... or, when set, when the translational kinetic energy of the loaded grains (rattlers
    /// left out) over the elastic energy of the contacts is below this (-), in place of
    /// `ke_per_grain`; the unbalanced force is then that of the loaded grains too ...
    pub ke_ratio: Option<f64>,
    /// ... and the unbalanced-force ratio is below this (-).
    pub unbalanced_force: f64,
    /// Piston target pressure during the stage (Pa), if it changes.
    pub piston_pressure: Option<f64>,
    /// Settling also needs the piston's measured pressure within this fraction of its
    /// target (stages with a piston pressure).
    pub pressure_tolerance: f64,
    /// Move the piston down onto the sample (just above the highest grain) at the start.
    pub lower_piston: bool,
    /// Record a compression point (pressure, void ratio, macroscopic stress) at the end.
    pub records_compression: bool,
    /// The oedometer's seating load: its compression point gives Bauer's e0.
    pub seating: bool,
    /// Wet the sample at the start with this liquid volume (m^3).
    pub wet_volume: Option<f64>,
    /// Servo walls' target pressure during the stage (Pa), if it changes.
    pub servo_pressure: Option<f64>,
    /// Triaxial: strain rate (1/s) of the servo box's z walls, or `None` for all-servo.
    pub axial_strain_rate: Option<f64>,
    /// Walls (indices into [`Scene::walls`]) set moving at the start, with their motion.
    pub walls: Vec<(usize, WallDrive)>,
    /// Walls (indices into [`Scene::walls`]) added (true) or removed (false) at the start: a
    /// removed wall touches no grain and keeps its motion; an added one touches them again.
    pub presence: Vec<(usize, bool)>,
}

/// What `--out` records.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// Simulated time between MCAP frames (s); 0 for one frame per stage end.
    pub frame_interval: f64,
    /// Record contact forces in frames.
    pub contact_forces: bool,
    /// Analyse the force transmission at the end of the run.
    pub analysis: bool,
    /// Write frames as VTK files (`DIR/vtk`).
    pub vtk: bool,
    /// Wall-clock seconds between checkpoints inside a stage; 0 for stage ends only.
    pub checkpoint_interval: f64,
}

/// Wall-clock seconds between checkpoints inside a stage by default: a run killed mid-stage
/// loses at most about this much work.
pub const DEFAULT_CHECKPOINT_INTERVAL: f64 = 600.0;

/// Steps above which a run cannot finish in practice: at 10^4 steps per second (a few
/// thousand grains on a fast machine) a billion steps take 28 hours. `grains run` refuses
/// more without `--force`.
pub const PRACTICAL_STEPS: u64 = 1_000_000_000;

impl Output {
    /// Whether frames are taken with their contacts: for the MCAP recording when asked for,
    /// and always for VTK files (their contact network and per-grain forces).
    pub fn frames_with_contacts(&self) -> bool {
        self.contact_forces || self.vtk
    }
}

impl Stage {
    /// The stage's longest run in steps of `dt` (s).
    pub fn max_steps(&self, dt: f64) -> u64 {
        (self.duration / dt).round().max(1.0) as u64
    }
}

impl Scene {
    /// Whether grains enter or leave (an `[[inlet]]` or an `[[outlet]]`).
    pub fn has_flow(&self) -> bool {
        !(self.inlets.is_empty() && self.outlets.is_empty())
    }

    /// The mixed constants of materials `a` and `b` (indices into [`Self::materials`]).
    pub fn mixed(&self, a: usize, b: usize) -> MixedConstants {
        mixed_table(&self.materials, &self.pairs)[a * self.materials.len() + b]
    }

    /// Each pair of materials' contact coefficients, row-major (`a * n + b`), as the engines
    /// read them ([`crate::state::coeffs_of`]).
    pub fn pair_coeffs<T: Real>(&self) -> Vec<PairCoeffs<T>> {
        let mixed = mixed_table(&self.materials, &self.pairs);
        let n = self.materials.len();
        (0..n * n).map(|k| PairCoeffs::of(&self.materials[k / n].constants, &self.materials[k % n].constants, &mixed[k], &self.model)).collect()
    }

    /// The mesh walls' surfaces in precision `T`, by their index, binned for the largest
    /// grain's radius plus the skin (widened by a thousandth for the rounding of the positions
    /// the wall springs are chosen from).
    pub fn mesh_surfaces<T: Real>(&self) -> Vec<crate::mesh::MeshSurface<T>> {
        let reach = (self.grains.radius.iter().copied().fold(0.0, f64::max) + self.skin) * 1.001;
        self.walls
            .iter()
            .filter_map(|w| match &w.shape {
                WallShape::Mesh { mesh, .. } => Some(crate::mesh::MeshSurface::new(mesh, reach)),
                _ => None,
            })
            .collect()
    }

    /// Steps of the whole run at most (every stage to its longest).
    pub fn max_steps(&self) -> u64 {
        self.stages.iter().map(|s| s.max_steps(self.time_step.dt)).fold(0u64, u64::saturating_add)
    }

    /// Refuses a run of more than [`PRACTICAL_STEPS`] steps, naming the count and the fix.
    pub fn check_practical(&self) -> anyhow::Result<()> {
        let steps = self.max_steps();
        if steps > PRACTICAL_STEPS {
            anyhow::bail!(
                "{}: simulation.dt = {:e} s: the stages take up to {steps:.3e} steps, more than a run can finish ({PRACTICAL_STEPS:.0e} steps take about a day at 10^4 steps/s); fix: raise simulation.dt (or \"auto\"), shorten the stages, or pass --force",
                self.path.display(),
                self.time_step.dt
            );
        }
        Ok(())
    }
}

/// A validated scene, in SI units and `f64`; engines convert to their precision.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The file it came from.
    pub path: PathBuf,
    /// Name in reports.
    pub name: String,
    /// One line saying what it is for.
    pub description: String,
    /// Materials.
    pub materials: Vec<Material>,
    /// `[[pair]]` tables, in the scene's order.
    pub pairs: Vec<MaterialPair>,
    /// Initial grain state.
    pub grains: Grains,
    /// Walls.
    pub walls: Vec<Wall>,
    /// Inlets: grains put into play at a mass rate ([`crate::flow`]).
    pub inlets: Vec<Inlet>,
    /// Outlets: regions whose grains leave play ([`crate::flow`]).
    pub outlets: Vec<Outlet>,
    /// The servo-controlled box, if any (its planes are among the walls).
    pub servo: Option<ServoBox>,
    /// Wrapping interval `[lo, hi)` (m) of each periodic axis.
    pub periodic: [Option<[f64; 2]>; 3],
    /// Gravity (m/s^2).
    pub gravity: DVec3,
    /// Contact law per slot.
    pub model: ContactModel<f64>,
    /// DEM or contact dynamics.
    pub method: Method,
    /// Time integration scheme (DEM).
    pub integrator: Integrator,
    /// The time step and the times it was chosen from.
    pub time_step: TimeStep,
    /// Verlet skin (m).
    pub skin: f64,
    /// Steps between statistics reads.
    pub stats_interval: u64,
    /// Pairs a grain may own before the run stops with a capacity error.
    pub max_neighbours: usize,
    /// Rebuilds between renumberings of the grains in cell order (0: never).
    pub reorder_every: u64,
    /// Overlap / smaller radius at which a run stops as unstable.
    pub max_overlap: f64,
    /// Integrate orientation quaternions.
    pub track_orientation: bool,
    /// Host-loop program.
    pub stages: Vec<Stage>,
    /// Recording options.
    pub output: Output,
    /// Warnings found while validating (e.g. a time step above the recommended fraction).
    pub warnings: Vec<String>,
    /// Capillary scenes: the largest bridge volume (m^3) and the rupture distance it reaches
    /// (m), which the neighbour search adds to the skin; zero without cohesion.
    pub bridges: BridgeLimits,
}

/// `[[inlet]]`: its reservoir of grains waiting out of play, put into play in id order in
/// its region at its mass rate ([`crate::flow`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Inlet {
    /// Name in `stats.csv`.
    pub name: String,
    /// Where the grains' centres go, each grain wholly inside.
    pub region: super::schema::RegionSpec,
    /// Mass put into play per second (kg/s).
    pub mass_rate: f64,
    /// Velocity of the grains put into play (m/s).
    pub velocity: DVec3,
    /// The step at which it opens.
    pub start_step: u64,
    /// Steps between insertions.
    pub every: u64,
    /// The permanent ids of its reservoir, in the order they go into play.
    pub grains: std::ops::Range<u32>,
    /// The seed of its placements.
    pub seed: u64,
}

/// `[[outlet]]`: a region whose grains leave play ([`crate::flow`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Outlet {
    /// Name in `stats.csv`.
    pub name: String,
    /// The region: a grain whose centre lies inside leaves.
    pub region: super::schema::RegionSpec,
    /// Steps between removals.
    pub every: u64,
}

/// How the grains interact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Method {
    /// Soft contacts with the `[model]` laws, explicit integration.
    #[default]
    Dem,
    /// Rigid grains, Moreau-Jean time stepping with nonsmooth Gauss-Seidel (`grains::cd`).
    ContactDynamics(CdParams),
}

/// Contact-dynamics settings (`[contact_dynamics]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CdParams {
    /// Weight of the end-of-step velocity in the position update (-), in [0.5, 1].
    pub theta: f64,
    /// Quadratic norm of a sweep (`grains::cd`: its velocity corrections against the impulses'
    /// velocities) at which a step's solve stops (-).
    pub tolerance: f64,
    /// Most Gauss-Seidel sweeps per step.
    pub max_iterations: u32,
    /// Over-relaxation factor of the sweeps (-), in (0, 2); 1 is plain Gauss-Seidel.
    pub relaxation: f64,
    /// Surfaces closer than this are contacts of the step (m).
    pub gap_allowance: f64,
    /// Mass of each servo wall (kg); `None`: the grains' total mass.
    pub wall_mass: Option<f64>,
}

impl Default for CdParams {
    fn default() -> Self {
        CdParams { theta: 0.5, tolerance: 1e-3, max_iterations: 1000, relaxation: 1.0, gap_allowance: 0.0, wall_mass: None }
    }
}

/// Bounds on liquid bridges.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BridgeLimits {
    /// Largest bridge volume (m^3).
    pub volume_cap: f64,
    /// Rupture distance of the largest bridge (m).
    pub reach: f64,
}

/// Default settle criterion on the unbalanced-force ratio.
pub const DEFAULT_UNBALANCED_FORCE: f64 = 0.01;
/// Bridges per grain assumed when sizing the largest bridge: the mean bridge holds the
/// liquid over `BRIDGES_PER_GRAIN / 2` pairs per grain...
pub const BRIDGES_PER_GRAIN: f64 = 6.0;
/// ... and no bridge holds more than this many mean bridges (the excess stays on the grains),
/// which bounds the rupture distance the neighbour search must reach.
pub const BRIDGE_CAP_IN_MEANS: f64 = 8.0;

/// Default tolerance on the piston's pressure at the end of a pressure stage.
pub const DEFAULT_PRESSURE_TOLERANCE: f64 = 0.01;
/// Default pressure multiplier between oedometer steps (Oquendo et al.: doubled).
pub const DEFAULT_OEDOMETER_FACTOR: f64 = 2.0;
/// Default settle speed, as a fraction of `sqrt(|g| d_mean)`.
pub const DEFAULT_SETTLE_SPEED_FRACTION: f64 = 1e-2;

/// The times a step is chosen from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CharacteristicTimes {
    /// Rayleigh time of the smallest grain (s); infinite for the linear law.
    pub rayleigh: f64,
    /// Shortest collision time at `expected_speed` (s).
    pub collision: f64,
    /// Speed the collision time is computed for (m/s).
    pub expected_speed: f64,
}

/// The chosen step and where it came from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimeStep {
    /// Time step (s).
    pub dt: f64,
    /// True when chosen by `auto`.
    pub auto: bool,
    /// The times it was chosen from.
    pub times: CharacteristicTimes,
}

