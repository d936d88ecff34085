//! The TOML scene schema, as written by users. Every key is documented with its unit; unknown
//! keys are rejected. [`super::load`] turns a file into a validated [`super::Scene`].
//!
//! docs/scene-reference.md documents every key; tests/docs.rs checks it against this schema.

use glam::DVec3;
use serde::Deserialize;

pub use super::wall_schema::WallSpec;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name used in reports (default: the file stem).
    pub name: Option<String>,
    /// One line saying what the scene is for.
    pub description: Option<String>,
    /// Seed of every random choice of the scene (grain sizes, placement, velocities). Default 1.
    pub seed: Option<u64>,
    /// `[[material]]` tables.
    #[serde(default, rename = "material")]
    pub materials: Vec<MaterialSpec>,
    /// `[[pair]]` tables: coefficients of a pair of materials in place of the mixing rule's.
    #[serde(default, rename = "pair")]
    pub pairs: Vec<PairSpec>,
    /// `[[grain]]` tables: grains given one by one.
    #[serde(default, rename = "grain")]
    pub grains: Vec<GrainSpec>,
    /// `[[read]]` tables: grains read from a LAMMPS / LIGGGHTS file.
    #[serde(default, rename = "read")]
    pub reads: Vec<ReadSpec>,
    /// `[[generate]]` tables: grains placed at random.
    #[serde(default, rename = "generate")]
    pub generators: Vec<GeneratorSpec>,
    /// `[[wall]]` tables.
    #[serde(default, rename = "wall")]
    pub walls: Vec<WallSpec>,
    /// `[[inlet]]` tables: grains put into play at a mass rate.
    #[serde(default, rename = "inlet")]
    pub inlets: Vec<InletSpec>,
    /// `[[outlet]]` tables: regions that take the grains entering them out of play.
    #[serde(default, rename = "outlet")]
    pub outlets: Vec<OutletSpec>,
    /// `[periodic]`: axes along which the domain wraps.
    #[serde(default)]
    pub periodic: PeriodicSpec,
    /// `[model]`: the contact law per slot.
    #[serde(default)]
    pub model: ModelSpec,
    /// `[simulation]`: gravity, integrator, time step, neighbour search, safety limits.
    #[serde(default)]
    pub simulation: SimulationSpec,
    /// `[[stage]]` tables: the host loop's program, run in order.
    #[serde(default, rename = "stage")]
    pub stages: Vec<StageSpec>,
    /// `[output]`: what `--out DIR` records.
    #[serde(default)]
    pub output: OutputSpec,
    /// `[contact_dynamics]`: the solver's settings when `simulation.method` is
    /// "contact_dynamics".
    pub contact_dynamics: Option<ContactDynamicsSpec>,
}

/// `[contact_dynamics]`: Moreau-Jean settings (see `grains::cd`).
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactDynamicsSpec {
    /// Weight of the end-of-step velocity in the position update, in [0.5, 1]. Default 0.5.
    pub theta: Option<f64>,
    /// Quadratic norm of a sweep (its velocity corrections against the impulses' velocities)
    /// at which a step's solve stops. Default 1e-3.
    pub tolerance: Option<f64>,
    /// Most Gauss-Seidel sweeps per step. Default 1000.
    pub max_iterations: Option<u32>,
    /// Over-relaxation factor of the sweeps, in (0, 2). Default 1 (plain Gauss-Seidel).
    pub relaxation: Option<f64>,
    /// Surfaces closer than this (m) are contacts of a step. Default 0.1 x the mean diameter.
    pub gap_allowance: Option<f64>,
    /// Mass of each servo wall (kg). Default: the grains' total mass.
    pub wall_mass: Option<f64>,
}

/// `[[material]]`: one grain or wall material.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Name that grains and walls refer to.
    pub name: String,
    /// Density (kg/m^3). Required for grain materials; walls have infinite mass.
    pub density: Option<f64>,
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Poisson ratio nu (-), in [0, 0.5).
    pub poisson_ratio: f64,
    /// Static friction coefficient mu_s (-). Default 0. The Hertz-Mindlin law uses it as its
    /// single Coulomb coefficient.
    #[serde(default)]
    pub mu_s: f64,
    /// Kinetic (sliding) friction coefficient mu_k (-). Default: mu_s.
    pub mu_k: Option<f64>,
    /// Rolling angle theta_r (degrees) of Oquendo et al.'s rolling regime. Default 0.
    #[serde(default)]
    pub rolling_angle: f64,
    /// Normal damping gamma_n (s^-1 m^-1/2) of `damping = "papers"`. Default 0.
    #[serde(default)]
    pub gamma_n: f64,
    /// Twisting damping gamma_nt (s^-1) of `twisting = "oquendo"`. Default 0.
    #[serde(default)]
    pub gamma_nt: f64,
    /// Restitution coefficient (-), in (0, 1], of `damping = "restitution"`.
    pub restitution: Option<f64>,
}

/// `[[pair]]`: what a contact between two materials takes in place of the mixing rule
/// (LIGGGHTS' per-type-pair coefficients). A key left out comes from the rule; `mu_k` follows
/// a given `mu_s` as a material's does.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    /// The two materials' names (in either order; the same name twice for a material with
    /// itself).
    pub materials: [String; 2],
    /// Static friction coefficient mu_s (-).
    pub mu_s: Option<f64>,
    /// Kinetic friction coefficient mu_k (-).
    pub mu_k: Option<f64>,
    /// Rolling angle theta_r (degrees).
    pub rolling_angle: Option<f64>,
    /// Normal damping gamma_n (s^-1 m^-1/2) of `damping = "papers"`.
    pub gamma_n: Option<f64>,
    /// Twisting damping gamma_nt (s^-1) of `twisting = "oquendo"`.
    pub gamma_nt: Option<f64>,
    /// Restitution coefficient (-), in (0, 1], of `damping = "restitution"`.
    pub restitution: Option<f64>,
}

/// `[[grain]]`: one grain.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrainSpec {
    /// Material name.
    pub material: String,
    /// Radius (m).
    pub radius: f64,
    /// Centre position (m).
    pub position: DVec3,
    /// Velocity (m/s). Default 0.
    #[serde(default)]
    pub velocity: DVec3,
    /// Angular velocity (rad/s). Default 0.
    #[serde(default)]
    pub angular_velocity: DVec3,
}

/// `[[read]]`: grains from a LAMMPS data file (`atom_style sphere`) or a LAMMPS / LIGGGHTS
/// text dump (`dump custom`), in SI units (`units si`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReadSpec {
    /// The file, relative to the scene file's folder.
    pub file: String,
    /// "lammps-data" or "lammps-dump".
    pub format: String,
    /// Material name of each atom type, e.g. `{ 1 = "sand", 2 = "glass" }`.
    pub types: std::collections::BTreeMap<String, String>,
    /// "lammps-dump": the time step whose snapshot to read. Default: the last.
    pub step: Option<u64>,
}

/// `[[generate]]`: grains of one material placed at random without overlap in a region.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeneratorSpec {
    /// Material name.
    pub material: String,
    /// Number of grains.
    pub count: usize,
    /// Diameters, uniform in `[min, max]` (m); `min = max` for equal grains.
    pub diameter: RangeSpec,
    /// Where the centres go; each grain lies wholly inside the region.
    pub region: RegionSpec,
    /// Velocity of every grain (m/s). Default 0.
    #[serde(default)]
    pub velocity: DVec3,
    /// Speed (m/s) added in a random direction per grain (a gas). Default 0.
    #[serde(default)]
    pub random_speed: f64,
}

/// `[[inlet]]`: grains of one material put into play in a region at a mass rate, each clear
/// of the grains and walls there (`grains::flow`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InletSpec {
    /// Name: its columns in `stats.csv`.
    pub name: String,
    /// Material name.
    pub material: String,
    /// Diameters, uniform in `[min, max]` (m).
    pub diameter: RangeSpec,
    /// Where the centres go; each grain lies wholly inside the region.
    pub region: RegionSpec,
    /// Mass put into play per second (kg/s).
    pub mass_rate: f64,
    /// Mass put into play in all (kg); the inlet closes when it is in.
    pub mass: f64,
    /// Velocity of each grain put into play (m/s). Default 0.
    #[serde(default)]
    pub velocity: DVec3,
    /// When it opens (s of simulated time). Default 0.
    #[serde(default)]
    pub start: f64,
    /// Simulated time between insertions (s). Default [`DEFAULT_FLOW_INTERVAL`].
    pub interval: Option<f64>,
}

/// `[[outlet]]`: a region whose grains (their centres inside it) leave play, counted
/// (`grains::flow`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutletSpec {
    /// Name: its columns in `stats.csv`.
    pub name: String,
    /// The region.
    pub region: RegionSpec,
    /// Simulated time between removals (s). Default [`DEFAULT_FLOW_INTERVAL`].
    pub interval: Option<f64>,
}

/// Simulated time between an inlet's insertions and between an outlet's removals where the
/// scene does not say (s).
pub const DEFAULT_FLOW_INTERVAL: f64 = 0.005;

/// A closed interval.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
}

/// A region of space.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum RegionSpec {
    /// Axis-aligned box.
    Box {
        /// Lower corner (m).
        min: DVec3,
        /// Upper corner (m).
        max: DVec3,
    },
    /// Vertical cylinder (axis along z).
    Cylinder {
        /// Axis position (x, y) (m).
        center: [f64; 2],
        /// Radius (m).
        radius: f64,
        /// Bottom (m).
        z_min: f64,
        /// Top (m).
        z_max: f64,
    },
}

/// `[periodic]`: each axis given wraps over `[lo, hi)` (m); grains leaving at `hi` come back
/// at `lo`, and contacts act across the boundary (minimum image).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PeriodicSpec {
    /// `[lo, hi]` of x (m).
    pub x: Option<[f64; 2]>,
    /// `[lo, hi]` of y (m).
    pub y: Option<[f64; 2]>,
    /// `[lo, hi]` of z (m).
    pub z: Option<[f64; 2]>,
}

/// `[model]`: the contact law chosen per slot, with the parameters of the chosen laws.
/// A parameter of a law not chosen is an error.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// "hertz" (default), "linear" or "dmt" (Hertz with DMT adhesion).
    pub normal: Option<String>,
    /// "none" (default), "papers", "restitution" or "viscous".
    pub damping: Option<String>,
    /// "none" (default), "oquendo" or "mindlin".
    pub tangential: Option<String>,
    /// "none" (default) or "sds".
    pub rolling: Option<String>,
    /// "none" (default) or "oquendo".
    pub twisting: Option<String>,
    /// "none" (default) or "capillary" (Richefeu et al.'s liquid bridges; a stage must wet the
    /// sample with `water_content`).
    pub cohesion: Option<String>,
    /// Liquid surface tension gamma_s (N/m), `cohesion = "capillary"`. Default 0.0728 (water).
    pub surface_tension: Option<f64>,
    /// Contact angle theta (degrees), `cohesion = "capillary"`. Default 0 (perfectly wetting).
    pub contact_angle: Option<f64>,
    /// Liquid density (kg/m^3) turning a gravimetric water content into a volume. Default 1000.
    pub liquid_density: Option<f64>,
    /// Linear normal stiffness k_n (N/m), `normal = "linear"`.
    pub k_n: Option<f64>,
    /// Surface energy gamma (J/m^2) of DMT adhesion, `normal = "dmt"`: the pull-off force is
    /// `4 pi gamma R_eff`.
    pub surface_energy: Option<f64>,
    /// Viscous coefficient c_n (N s/m), `damping = "viscous"`.
    pub c_n: Option<f64>,
    /// The no-pull clamp (LAMMPS' `limit_damping`): true (default, docs/physics.md's ruling) holds
    /// the elastic and damping normal force at zero where the dashpot would pull; false lets it
    /// pull at the end of a contact, as LIGGGHTS, EDEM and MercuryDPM do.
    pub limit_damping: Option<bool>,
    /// No longer used (Oquendo et al.'s contacts slide on their spring's Coulomb test); read only to
    /// say so.
    pub v_slip: Option<f64>,
    /// No longer used (Oquendo et al.'s contacts roll on their rolling spring's limit); read only to
    /// say so.
    pub v_roll: Option<f64>,
    /// Damping of Oquendo et al.'s static and rolling springs as a fraction of their critical
    /// damping (-), `tangential = "oquendo"`. Default 0.3.
    pub static_damping: Option<f64>,
    /// How Oquendo et al.'s rolling friction acts, `tangential = "oquendo"`: "torque" (default, a
    /// momentum-conserving torque pair) or "as_written" (eqs. 8-9 on each grain).
    pub rolling_friction: Option<String>,
    /// Tangential spring as a ratio of the normal secant stiffness (-). Default: Mindlin
    /// `8 G_eff sqrt(R_eff h)` for Hertz, 2/7 for linear.
    pub kt_ratio: Option<f64>,
    /// Tangential damping as a fraction of the normal damping coefficient (-): the dashpot of
    /// the Hertz-Mindlin spring (LAMMPS' `x_gammat`). Default 0.
    pub tangential_damping_ratio: Option<f64>,
    /// Rolling stiffness k_r (N/m), `rolling = "sds"`.
    pub rolling_k: Option<f64>,
    /// Rolling damping gamma_r (N s/m), `rolling = "sds"`. Default 0.
    pub rolling_gamma: Option<f64>,
    /// Rolling friction coefficient mu_r (-), `rolling = "sds"`.
    pub rolling_mu: Option<f64>,
}

/// A time step: a number of seconds or "auto".
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DtSpec {
    /// Pick from the Rayleigh and Hertz times.
    Auto,
    /// This many seconds.
    Seconds(f64),
}

impl<'de> Deserialize<'de> for DtSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = DtSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a time step in seconds or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<DtSpec, E> {
                Ok(DtSpec::Seconds(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<DtSpec, E> {
                Ok(DtSpec::Seconds(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<DtSpec, E> {
                if v == "auto" { Ok(DtSpec::Auto) } else { Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)) }
            }
        }
        d.deserialize_any(V)
    }
}

/// `[simulation]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Gravity (m/s^2). Default [0, 0, -9.81].
    #[serde(default = "default_gravity")]
    pub gravity: DVec3,
    /// "velocity_verlet" (default; one force evaluation per step) or "optimized_verlet"
    /// (Oquendo et al. eqs. 11-15, two evaluations per step).
    pub integrator: Option<String>,
    /// Time step (s) or "auto" (default): the smaller of 0.1 t_R and t_c / 50.
    pub dt: Option<DtSpec>,
    /// Largest speed expected in a collision (m/s), for the Hertz time t_c. Default: the
    /// largest initial speed or the free-fall speed over the grains' height, whichever is larger.
    pub expected_speed: Option<f64>,
    /// Verlet skin (m): pairs closer than R_i + R_j + skin are listed; the list is rebuilt when
    /// a grain has moved skin/2. Default: 0.1 x the mean diameter.
    pub skin: Option<f64>,
    /// Steps between statistics reads (kinetic energy, overlaps, wall forces). Default 500.
    pub stats_interval: Option<u64>,
    /// Neighbour capacity per grain (pairs a grain owns); exceeding it is an error. Default 32.
    pub max_neighbours: Option<usize>,
    /// Rebuilds between renumberings of the grains in cell order (0: never). Default 10. The
    /// results do not depend on it, bit for bit; only the speed does.
    pub reorder_every: Option<u64>,
    /// Overlap, as a fraction of the smaller radius, at which a run is stopped as unstable.
    /// Default 0.2.
    pub max_overlap: Option<f64>,
    /// Integrate orientation quaternions (Omelyan's norm-preserving update). Default false.
    #[serde(default)]
    pub track_orientation: bool,
    /// "dem" (default: soft contacts, the `[model]` laws) or "contact_dynamics" (rigid grains,
    /// Moreau-Jean with `[contact_dynamics]`).
    pub method: Option<String>,
}

fn default_gravity() -> DVec3 {
    DVec3::new(0.0, 0.0, -9.81)
}

impl Default for SimulationSpec {
    fn default() -> Self {
        SimulationSpec {
            gravity: default_gravity(),
            integrator: None,
            dt: None,
            expected_speed: None,
            skin: None,
            stats_interval: None,
            max_neighbours: None,
            reorder_every: None,
            max_overlap: None,
            track_orientation: false,
            method: None,
        }
    }
}

/// `[[stage]]`: one step of the host loop's program.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    /// Name used in reports. Default: the kind and its position.
    pub name: Option<String>,
    /// "fill" (deposition under gravity until settled), "settle" (until settled), "run"
    /// (for a duration) or "oedometer" (the piston lowered onto the sample at p0, then the
    /// pressure multiplied by `factor` at each step up to p_max, each step settling).
    pub kind: String,
    /// "run": simulated time (s). "fill"/"settle": the most time to wait (s). "oedometer": the
    /// most time to wait at each pressure (s).
    pub duration: f64,
    /// "fill"/"settle": translational kinetic energy per grain (J) below which the sample
    /// counts as settled (rattlers spinning in their cages do not count).
    /// Default: that of a grain of mean mass moving at 1e-2 sqrt(|g| d_mean) (1 mm/s for 1 mm grains).
    pub ke_per_grain: Option<f64>,
    /// Settle criterion in place of `ke_per_grain`: translational kinetic energy over the
    /// contacts' elastic energy (-), for loaded packings whose stiff contacts keep a little
    /// vibration.
    pub ke_ratio: Option<f64>,
    /// "fill"/"settle": unbalanced-force ratio (mean net force on a grain over mean contact
    /// force) below which the sample counts as settled. Default 0.01.
    pub unbalanced_force: Option<f64>,
    /// Target pressure (Pa) of the scene's piston during this stage. Default: unchanged.
    pub piston_pressure: Option<f64>,
    /// "oedometer": first pressure (Pa).
    pub p0: Option<f64>,
    /// "oedometer": last pressure (Pa), reached or not exceeded.
    pub p_max: Option<f64>,
    /// "oedometer": pressure multiplier between steps. Default 2 (Oquendo et al.).
    pub factor: Option<f64>,
    /// "oedometer": a seating load (Pa, below p0) put on the sample before p0, as an
    /// experimenter seats the cap: its void ratio is Bauer's e0 and it is not fitted.
    /// Default: none (e0 is then the void ratio up to the top of the highest grain).
    pub seating_pressure: Option<f64>,
    /// Target pressure (Pa) of the servo walls during this stage. Default: unchanged.
    pub servo_pressure: Option<f64>,
    /// Triaxial compression: the servo box's z walls close at this strain rate (1/s) while
    /// the x and y walls hold the servo pressure. Default: none (all walls servo).
    pub axial_strain_rate: Option<f64>,
    /// Wet the sample at the start of the stage: gravimetric water content w (liquid mass over
    /// solid mass), shared among pairs closer than their rupture distance in proportion to
    /// their reduced diameter. Needs `model.cohesion = "capillary"`.
    pub water_content: Option<f64>,
    /// Settle stages with a piston pressure, and oedometer steps: the piston's measured
    /// pressure must also be within this fraction of its target. Default 0.01.
    pub pressure_tolerance: Option<f64>,
    /// Walls (planes, boxes, cylinders) this stage sets moving, by name: each one's velocity
    /// and angular velocity from the stage's start on (a key left out is zero); walls not named
    /// keep their motion.
    #[serde(default)]
    pub walls: std::collections::BTreeMap<String, WallDriveSpec>,
    /// Walls (by name; a box's name adds all its faces) that grains meet from this stage's
    /// start on: a wall that a stage adds before any removes it is not there at the start (a
    /// lid, a shutter closing an orifice). No grain may overlap it when it comes.
    #[serde(default)]
    pub add_walls: Vec<String>,
    /// Walls (by name) taken away at this stage's start (a gate lifted out): grains pass
    /// through them until a later stage adds them again. A removed wall keeps its motion.
    #[serde(default)]
    pub remove_walls: Vec<String>,
}

/// A stage's motion for one wall (`[[stage]] walls = { gate = { velocity = [...] } }`).
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallDriveSpec {
    /// Velocity (m/s). Default 0.
    pub velocity: Option<DVec3>,
    /// Angular velocity (rad/s): a plane's about the axis through its point, a cylinder's
    /// about its own axis, a mesh's about the axis through its `center`. Default 0.
    pub angular_velocity: Option<DVec3>,
}

/// `[output]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Simulated time (s) between MCAP frames; 0 (default) records one frame at each stage end.
    #[serde(default)]
    pub frame_interval: f64,
    /// Record contact forces in the MCAP frames. Default false.
    #[serde(default)]
    pub contact_forces: bool,
    /// At the end of the run, analyse the force transmission (force and pressure PDFs, bonds,
    /// particle stresses, percolation, fabric) into `analysis.json` and pictures. Default false.
    #[serde(default)]
    pub analysis: bool,
    /// Write every frame as VTK files for ParaView under `DIR/vtk` (grains, contacts and walls,
    /// with a `.pvd` collection of each). Default false; `grains run --vtk` sets it too.
    #[serde(default)]
    pub vtk: bool,
    /// Wall-clock seconds between checkpoints inside a stage (besides the one at every stage
    /// end) when the run has `--out`; 0 checkpoints at stage ends only. Default
    /// [`crate::scene::DEFAULT_CHECKPOINT_INTERVAL`].
    pub checkpoint_interval: Option<f64>,
}

impl crate::model::keys::LawKeys for ModelSpec {
    /// The laws' numeric keys by name (each slot's registry reads them through this; a test
    /// checks that every key a registry row names has its arm here).
    fn number(&self, key: &str) -> Option<f64> {
        match key {
            "k_n" => self.k_n,
            "surface_energy" => self.surface_energy,
            "c_n" => self.c_n,
            "static_damping" => self.static_damping,
            "kt_ratio" => self.kt_ratio,
            "tangential_damping_ratio" => self.tangential_damping_ratio,
            "rolling_k" => self.rolling_k,
            "rolling_gamma" => self.rolling_gamma,
            "rolling_mu" => self.rolling_mu,
            "surface_tension" => self.surface_tension,
            "contact_angle" => self.contact_angle,
            "liquid_density" => self.liquid_density,
            _ => None,
        }
    }

    /// The laws' text keys by name.
    fn text(&self, key: &str) -> Option<&str> {
        match key {
            "rolling_friction" => self.rolling_friction.as_deref(),
            _ => None,
        }
    }
}
