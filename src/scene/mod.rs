//! Scenes: the TOML schema ([`schema`]), its validation into a [`Scene`] (whose types are in
//! [`types`]), and grain generation.

pub mod dotted;
mod error;
mod flow_specs;
mod generate;
mod model_specs;
mod periodic_specs;
mod read;
mod stage_specs;
mod wall_presence;
mod wall_specs;
mod wall_schema;
pub mod schema;
pub mod types;

pub use error::SceneError;
pub(crate) use generate::random_direction;
pub use stage_specs::pressure_label;
pub use types::*;
pub use wall_specs::{cross_section, wall_distance, wall_distance_now};
use glam::DVec3;
use model_specs::{bridge_limits, validate_method, validate_model};
use periodic_specs::{check_periodic, validate_periodic};
use stage_specs::validate_stages;
use wall_presence::wall_presence;
use wall_specs::{check_overlaps, finish_walls, servo_box, validate_walls};

use crate::model::cohesion::DEFAULT_LIQUID_DENSITY;
use crate::model::{CohesionLaw, ContactModel, DampingLaw, MaterialConstants, MixedOverride};
use crate::timestep;
use error::Complainer;
use schema::{ContactDynamicsSpec, DtSpec, ModelSpec, SceneFile, SimulationSpec, StageSpec, WallSpec};
use std::collections::HashMap;
use std::path::Path;

/// Reads and validates a scene file.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|reason| SceneError::Read { file: path.to_path_buf(), reason })?;
    parse(path, &text)
}

/// Validates scene text as if read from `path`.
pub fn parse(path: &Path, text: &str) -> Result<Scene, SceneError> {
    let file: SceneFile = toml::from_str(text).map_err(|e| SceneError::syntax(path, text, &e))?;
    validate(path, file)
}

fn positive(c: &Complainer, key: &str, v: f64, fix: &str) -> Result<f64, SceneError> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(c.invalid(key, v, "must be a positive number", fix)) }
}

fn non_negative(c: &Complainer, key: &str, v: f64, fix: &str) -> Result<f64, SceneError> {
    if v.is_finite() && v >= 0.0 { Ok(v) } else { Err(c.invalid(key, v, "must be zero or positive", fix)) }
}

fn finite3(c: &Complainer, key: &str, v: DVec3) -> Result<DVec3, SceneError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(c.invalid(key, format!("{:?}", v.to_array()), "must be three finite numbers", "give finite values in SI units"))
    }
}

fn validate(path: &Path, f: SceneFile) -> Result<Scene, SceneError> {
    let c = Complainer { file: path };
    let mut warnings = Vec::new();
    let materials = validate_materials(&c, &f)?;
    let index: HashMap<&str, u16> = materials.iter().enumerate().map(|(i, m)| (m.name.as_str(), i as u16)).collect();
    let material_of = |key: String, name: &str| -> Result<u16, SceneError> {
        index.get(name).copied().ok_or_else(|| {
            let known: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
            c.invalid(key, format!("\"{name}\""), "names no [[material]]", format!("use one of {known:?} or add a [[material]] with this name"))
        })
    };
    let grain_density = |key: String, m: u16| -> Result<f64, SceneError> {
        materials[m as usize].density.ok_or_else(|| {
            c.invalid(key, format!("\"{}\"", materials[m as usize].name), "grain material has no density", "add `density` (kg/m^3) to that [[material]]")
        })
    };

    let pairs = validate_pairs(&c, &f, &material_of)?;
    let seed = f.seed.unwrap_or(1);
    let periodic = validate_periodic(&c, &f)?;
    let mut grains = Grains::default();
    for (i, g) in f.grains.iter().enumerate() {
        let key = |k: &str| format!("grain[{i}].{k}");
        let m = material_of(key("material"), &g.material)?;
        let rho = grain_density(key("material"), m)?;
        let r = positive(&c, &key("radius"), g.radius, "give the radius in metres, e.g. 5e-4")?;
        let p = finite3(&c, &key("position"), g.position)?;
        let v = finite3(&c, &key("velocity"), g.velocity)?;
        let w = finite3(&c, &key("angular_velocity"), g.angular_velocity)?;
        grains.push(r, sphere_mass(r, rho), p, v, w, m);
    }
    let mut origins = Origins { listed: grains.len(), blocks: Vec::new() };
    for (k, spec) in f.reads.iter().enumerate() {
        let n = read::grains(&c, k, spec, &materials, &material_of, &mut grains, &mut warnings)?;
        origins.blocks.push((format!("read[{k}]"), n, true));
    }
    let walls = validate_walls(&c, &f, &material_of)?;
    for (k, spec) in f.generators.iter().enumerate() {
        let key = |s: &str| format!("generate[{k}].{s}");
        let m = material_of(key("material"), &spec.material)?;
        let rho = grain_density(key("material"), m)?;
        let before = grains.len();
        generate::place(&c, k, spec, m, rho, seed, &periodic, &mut grains)?;
        origins.blocks.push((format!("generate[{k}]"), grains.len() - before, false));
    }
    let reservoirs = flow_specs::reservoirs(&c, &f, &material_of, &grain_density, seed, &mut grains)?;
    for (k, ids) in reservoirs.iter().enumerate() {
        origins.blocks.push((format!("inlet[{k}]"), ids.len(), false));
    }
    if grains.is_empty() {
        return Err(c.invalid("grain", "[]", "the scene has no grains", "add [[grain]], [[generate]] or [[inlet]] tables"));
    }
    let servo = servo_box(&walls);
    let mut walls = finish_walls(&c, walls, &grains, &periodic)?;
    let (present, presence) = wall_presence(&c, &f.stages, &walls, servo)?;
    for (w, p) in walls.iter_mut().zip(present) {
        w.present = p;
    }
    check_overlaps(&c, &origins, &grains, &walls)?;
    check_periodic(&c, &origins, &grains, &periodic, f.simulation.skin)?;

    let model = validate_model(&c, &f.model, &materials, &pairs, &grains, &walls)?;
    let sim = &f.simulation;
    let gravity = finite3(&c, "simulation.gravity", sim.gravity)?;
    let integrator = match sim.integrator.as_deref().unwrap_or("velocity_verlet") {
        "velocity_verlet" => Integrator::VelocityVerlet,
        "optimized_verlet" => Integrator::OptimizedVerlet,
        other => {
            return Err(c.invalid("simulation.integrator", format!("\"{other}\""), "unknown integrator", "use \"velocity_verlet\" or \"optimized_verlet\""));
        }
    };
    let d_mean = 2.0 * grains.radius.iter().sum::<f64>() / grains.len() as f64;
    let skin = match sim.skin {
        Some(s) => positive(&c, "simulation.skin", s, "give the skin in metres, e.g. 0.1 x the mean diameter")?,
        None => 0.1 * d_mean,
    };
    let method = validate_method(&c, sim, f.contact_dynamics.as_ref(), d_mean)?;
    let rigid = matches!(method, Method::ContactDynamics(_));
    let time_step = choose_time_step(&c, sim, rigid, &materials, &grains, &walls, &model, gravity, &mut warnings)?;
    let (inlets, outlets) = flow_specs::inlets_and_outlets(&c, &f, reservoirs, time_step.dt, seed)?;
    let flows = !(inlets.is_empty() && outlets.is_empty());
    if rigid && flows {
        return Err(c.invalid("simulation.method", "\"contact_dynamics\"", "keeps every grain in play: it takes no [[inlet]] or [[outlet]] yet", "use method = \"dem\", or leave out the inlets and outlets"));
    }
    if flows && !matches!(model.cohesion, CohesionLaw::None) {
        return Err(c.invalid("model.cohesion", "\"capillary\"", "keeps liquid on the grains, which [[inlet]] and [[outlet]] do not carry yet", "leave out the cohesion, or the inlets and outlets"));
    }
    let stats_interval = sim.stats_interval.unwrap_or(500);
    if stats_interval == 0 {
        return Err(c.invalid("simulation.stats_interval", 0, "must be at least 1", "give a number of steps, e.g. 500"));
    }
    let max_neighbours = sim.max_neighbours.unwrap_or(32);
    if max_neighbours == 0 {
        return Err(c.invalid("simulation.max_neighbours", 0, "must be at least 1", "give a capacity, e.g. 32"));
    }
    let max_overlap = match sim.max_overlap {
        Some(v) => positive(&c, "simulation.max_overlap", v, "give a fraction of the radius, e.g. 0.2")?,
        None => 0.2,
    };
    let liquid_density = match f.model.liquid_density {
        Some(v) => positive(&c, "model.liquid_density", v, "give the liquid's density in kg/m^3, e.g. 1000")?,
        None => DEFAULT_LIQUID_DENSITY,
    };
    let stages = validate_stages(&c, &f.stages, &presence, &grains, gravity, d_mean, &walls, servo, liquid_density)?;
    let bridges = bridge_limits(&c, &model, &stages, &grains)?;
    let output = Output {
        frame_interval: non_negative(&c, "output.frame_interval", f.output.frame_interval, "give seconds, or 0 for a frame per stage")?,
        contact_forces: f.output.contact_forces,
        analysis: f.output.analysis,
        vtk: f.output.vtk,
        checkpoint_interval: non_negative(&c, "output.checkpoint_interval", f.output.checkpoint_interval.unwrap_or(DEFAULT_CHECKPOINT_INTERVAL), "give wall-clock seconds, or 0 for checkpoints at stage ends only")?,
    };
    let name = f.name.clone().unwrap_or_else(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    Ok(Scene {
        path: path.to_path_buf(),
        name,
        description: f.description.clone().unwrap_or_default(),
        materials,
        pairs,
        grains,
        walls,
        inlets,
        outlets,
        servo,
        periodic,
        gravity,
        model,
        method,
        integrator,
        time_step,
        skin,
        stats_interval,
        max_neighbours,
        reorder_every: sim.reorder_every.unwrap_or(DEFAULT_REORDER_EVERY),
        max_overlap,
        track_orientation: sim.track_orientation,
        stages,
        output,
        warnings,
        bridges,
    })
}

/// Mass (kg) of a sphere of radius `r` (m) and density `rho` (kg/m^3).
pub fn sphere_mass(r: f64, rho: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r * r * r * rho
}

fn validate_materials(c: &Complainer, f: &SceneFile) -> Result<Vec<Material>, SceneError> {
    let mut out: Vec<Material> = Vec::new();
    for (i, m) in f.materials.iter().enumerate() {
        let key = |k: &str| format!("material[{i}].{k}");
        if out.iter().any(|o| o.name == m.name) {
            return Err(c.invalid(key("name"), format!("\"{}\"", m.name), "is used by an earlier material", "give each material its own name"));
        }
        let density = match m.density {
            Some(d) => Some(positive(c, &key("density"), d, "give the density in kg/m^3, e.g. 2650")?),
            None => None,
        };
        let youngs_modulus = positive(c, &key("youngs_modulus"), m.youngs_modulus, "give Young's modulus in Pa, e.g. 7e7")?;
        if !(0.0..0.5).contains(&m.poisson_ratio) {
            return Err(c.invalid(key("poisson_ratio"), m.poisson_ratio, "must lie in [0, 0.5)", "give a Poisson ratio such as 0.3"));
        }
        let mu_s = non_negative(c, &key("mu_s"), m.mu_s, "give a friction coefficient such as 0.5")?;
        let mu_k = non_negative(c, &key("mu_k"), m.mu_k.unwrap_or(mu_s), "give a friction coefficient such as 0.4")?;
        if !(0.0..90.0).contains(&m.rolling_angle) {
            return Err(c.invalid(key("rolling_angle"), m.rolling_angle, "must lie in [0, 90) degrees", "give the rolling angle in degrees, e.g. 5"));
        }
        let gamma_n = non_negative(c, &key("gamma_n"), m.gamma_n, "give gamma_n in s^-1 m^-1/2, or 0")?;
        let gamma_nt = non_negative(c, &key("gamma_nt"), m.gamma_nt, "give gamma_nt in s^-1, or 0")?;
        if let Some(e) = m.restitution.filter(|e| !(*e > 0.0 && *e <= 1.0)) {
            let why = if e == 0.0 { "must lie in (0, 1]: no dashpot of finite strength stops an impact dead without holding the grains together" } else { "must lie in (0, 1]" };
            return Err(c.invalid(key("restitution"), e, why, "give a restitution coefficient such as 0.5"));
        }
        out.push(Material {
            name: m.name.clone(),
            density,
            restitution: m.restitution,
            constants: MaterialConstants {
                youngs_modulus,
                poisson_ratio: m.poisson_ratio,
                mu_s,
                mu_k,
                rolling_angle: m.rolling_angle.to_radians(),
                gamma_n,
                gamma_nt,
                restitution: m.restitution.unwrap_or(1.0),
            },
        });
    }
    if out.is_empty() {
        return Err(c.invalid("material", "[]", "the scene has no [[material]]", "add a [[material]] table with name, density, youngs_modulus and poisson_ratio"));
    }
    Ok(out)
}

/// The `[[pair]]` tables: known materials, each pair once, values in the ranges a material's
/// take, and at least one value given.
fn validate_pairs(c: &Complainer, f: &SceneFile, material_of: &dyn Fn(String, &str) -> Result<u16, SceneError>) -> Result<Vec<MaterialPair>, SceneError> {
    let mut out: Vec<MaterialPair> = Vec::new();
    for (k, p) in f.pairs.iter().enumerate() {
        let key = |s: &str| format!("pair[{k}].{s}");
        let materials = [material_of(key("materials"), &p.materials[0])?, material_of(key("materials"), &p.materials[1])?];
        let same = |m: &[u16; 2]| m == &materials || m == &[materials[1], materials[0]];
        if let Some(j) = out.iter().position(|o| same(&o.materials)) {
            return Err(c.invalid(key("materials"), format!("{:?}", p.materials), format!("names the same pair as pair[{j}]"), "give each pair of materials one [[pair]] table"));
        }
        let friction = |k: &str, v: Option<f64>| v.map(|v| non_negative(c, &key(k), v, "give a friction coefficient such as 0.3")).transpose();
        let rolling_angle = match p.rolling_angle {
            Some(a) if !(0.0..90.0).contains(&a) => return Err(c.invalid(key("rolling_angle"), a, "must lie in [0, 90) degrees", "give the rolling angle in degrees, e.g. 5")),
            a => a.map(f64::to_radians),
        };
        if let Some(e) = p.restitution.filter(|e| !(*e > 0.0 && *e <= 1.0)) {
            return Err(c.invalid(key("restitution"), e, "must lie in (0, 1]", "give a restitution coefficient such as 0.5"));
        }
        let given = MixedOverride {
            mu_s: friction("mu_s", p.mu_s)?,
            mu_k: friction("mu_k", p.mu_k)?,
            rolling_angle,
            gamma_n: p.gamma_n.map(|v| non_negative(c, &key("gamma_n"), v, "give gamma_n in s^-1 m^-1/2, or 0")).transpose()?,
            gamma_nt: p.gamma_nt.map(|v| non_negative(c, &key("gamma_nt"), v, "give gamma_nt in s^-1, or 0")).transpose()?,
            restitution: p.restitution,
        };
        if given == MixedOverride::default() {
            return Err(c.invalid(format!("pair[{k}]"), format!("{:?}", p.materials), "gives no coefficient", "add mu_s, mu_k, rolling_angle, gamma_n, gamma_nt or restitution, or remove the table"));
        }
        out.push(MaterialPair { materials, given });
    }
    Ok(out)
}

/// Rebuilds between renumberings of the grains in cell order when the scene does not say
/// (`simulation.reorder_every`); not tuned: the benchmarks measured it on against off only.
pub const DEFAULT_REORDER_EVERY: u64 = 10;

/// Overlap with a wall (fraction of the radius) that a grain read from a file may start with:
/// a settled packing rests on its floor with overlaps of about 1e-3 of a radius.
const READ_WALL_OVERLAP: f64 = 0.01;

#[allow(clippy::too_many_arguments, reason = "validation needs the whole scene")]
/// The scene's step: "auto" or a given one within the stability limits; for `rigid` grains
/// (contact dynamics), which have no contact time to resolve, a given one with no limit.
fn choose_time_step(
    c: &Complainer,
    sim: &SimulationSpec,
    rigid: bool,
    materials: &[Material],
    grains: &Grains,
    walls: &[Wall],
    model: &ContactModel<f64>,
    gravity: DVec3,
    warnings: &mut Vec<String>,
) -> Result<TimeStep, SceneError> {
    let expected_speed = match sim.expected_speed {
        Some(v) => positive(c, "simulation.expected_speed", v, "give a speed in m/s")?,
        None => timestep::default_expected_speed(grains, gravity),
    };
    let times = timestep::characteristic_times(materials, grains, walls, model, expected_speed);
    match sim.dt.unwrap_or(DtSpec::Auto) {
        DtSpec::Auto if rigid => Err(c.invalid("simulation.dt", "\"auto\"", "has no automatic value for rigid grains (contact dynamics)", "give the step in seconds, e.g. 1e-4")),
        DtSpec::Seconds(dt) if rigid => Ok(TimeStep::given(positive(c, "simulation.dt", dt, "give the step in seconds, e.g. 1e-4")?, times)),
        DtSpec::Auto => Ok(TimeStep::auto(times)),
        DtSpec::Seconds(dt) => {
            let dt = positive(c, "simulation.dt", dt, "give the step in seconds or \"auto\"")?;
            let ts = TimeStep::given(dt, times);
            if let Some(limit) = ts.exceeds_limit() {
                return Err(c.invalid("simulation.dt", dt, format!("is above the stability limit {limit}"), format!("use dt <= {:.3e} s or \"auto\" ({:.3e} s)", ts.safe_limit(), ts.auto_dt())));
            }
            if let Some(w) = ts.warning() {
                warnings.push(format!("{}: simulation.dt = {dt:e}: {w}", c.file.display()));
            }
            Ok(ts)
        }
    }
}

/// Where each grain of a scene came from, for messages: the `[[grain]]` tables first, then
/// blocks of `[[read]]` and `[[generate]]` grains.
struct Origins {
    /// Grains listed one by one.
    listed: usize,
    /// (table, grains, read from a file) in order.
    blocks: Vec<(String, usize, bool)>,
}

impl Origins {
    /// `grain[3].position`, `read[0] grain 41` or `generate[1] grain 7`.
    fn name(&self, i: usize) -> String {
        if i < self.listed {
            return format!("grain[{i}].position");
        }
        let mut k = i - self.listed;
        for (table, n, _) in &self.blocks {
            if k < *n {
                return format!("{table} grain {k}");
            }
            k -= n;
        }
        format!("grain {i}")
    }

    /// Whether grain `i` was read from a file (a packing that may rest on its walls).
    fn read(&self, i: usize) -> bool {
        let mut end = self.listed;
        for &(_, n, read) in &self.blocks {
            end += n;
            if i < end {
                return read && i >= self.listed;
            }
        }
        false
    }
}
