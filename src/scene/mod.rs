//! Scenes: the TOML schema ([`schema`]), its validation into a [`Scene`] (whose types are in
//! [`types`]), and grain generation.

mod error;
mod generate;
mod read;
pub mod schema;
pub mod types;

pub use error::SceneError;
pub use types::*;

use crate::model::restitution::MIN_RESTITUTION;
use crate::model::{
    CohesionLaw, ContactModel, DampingLaw, MaterialConstants, NormalLaw, OquendoLaw, RollingFriction, RollingLaw, TangentialLaw,
    TangentialStiffness, TwistingLaw,
};
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

fn finite3(c: &Complainer, key: &str, v: [f64; 3]) -> Result<[f64; 3], SceneError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(c.invalid(key, format!("{v:?}"), "must be three finite numbers", "give finite values in SI units"))
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
    if grains.is_empty() {
        return Err(c.invalid("grain", "[]", "the scene has no grains", "add [[grain]] or [[generate]] tables"));
    }
    let servo = servo_box(&walls);
    let walls = finish_walls(&c, walls, &grains, &periodic)?;
    check_overlaps(&c, &origins, &grains, &walls)?;
    check_periodic(&c, &origins, &grains, &periodic, f.simulation.skin)?;

    let model = validate_model(&c, &f.model, &materials, &grains, &walls)?;
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
    let stages = validate_stages(&c, &f.stages, &grains, gravity, d_mean, &walls, servo.is_some(), liquid_density)?;
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
        grains,
        walls,
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

/// Sizes the largest bridge from the most liquid a stage adds: the mean bridge holds the
/// liquid over `BRIDGES_PER_GRAIN / 2` pairs per grain, and no bridge more than
/// `BRIDGE_CAP_IN_MEANS` of them.
fn bridge_limits(c: &Complainer, model: &ContactModel<f64>, stages: &[Stage], grains: &Grains) -> Result<BridgeLimits, SceneError> {
    let wettest = stages.iter().filter_map(|s| s.wet_volume).fold(0.0, f64::max);
    match model.cohesion {
        CohesionLaw::None => {
            if wettest > 0.0 {
                return Err(c.invalid("stage.water_content", "(set)", "wets the sample, but the model has no cohesion", "set model.cohesion = \"capillary\" or remove water_content"));
            }
            Ok(BridgeLimits::default())
        }
        CohesionLaw::Capillary { theta, .. } => {
            if wettest == 0.0 {
                return Err(c.invalid("model.cohesion", "\"capillary\"", "no stage wets the sample", "give a stage `water_content`, e.g. 0.007"));
            }
            let mean = wettest / (0.5 * BRIDGES_PER_GRAIN * grains.len() as f64);
            let volume_cap = BRIDGE_CAP_IN_MEANS * mean;
            Ok(BridgeLimits { volume_cap, reach: crate::model::rupture_distance(theta, volume_cap) })
        }
    }
}

/// `10kPa`, `1.28MPa`: a pressure for stage names.
pub fn pressure_label(p: f64) -> String {
    if p >= 1e6 {
        format!("{}MPa", (p / 1e6 * 1000.0).round() / 1000.0)
    } else if p >= 1e3 {
        format!("{}kPa", (p / 1e3 * 1000.0).round() / 1000.0)
    } else {
        format!("{}Pa", (p * 1000.0).round() / 1000.0)
    }
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

/// Walls before the piston's defaults are known.
struct PendingWall {
    wall: Wall,
    piston_mass: Option<f64>,
    piston_area: Option<f64>,
    /// The servo box this plane belongs to: (pressure, gain, max speed).
    servo: Option<(f64, f64, f64)>,
}

fn validate_walls(
    c: &Complainer,
    f: &SceneFile,
    material_of: &dyn Fn(String, &str) -> Result<u16, SceneError>,
) -> Result<Vec<PendingWall>, SceneError> {
    let mut out = Vec::new();
    let plain = |name: String, shape: WallShape, material: u16| PendingWall { wall: Wall { name, shape, material }, piston_mass: None, piston_area: None, servo: None };
    for (i, w) in f.walls.iter().enumerate() {
        let key = |k: &str| format!("wall[{i}].{k}");
        match w {
            WallSpec::Plane { material, point, normal } => {
                let m = material_of(key("material"), material)?;
                let point = finite3(c, &key("point"), *point)?;
                let normal = finite3(c, &key("normal"), *normal)?;
                let len = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
                if len == 0.0 {
                    return Err(c.invalid(key("normal"), format!("{normal:?}"), "is the zero vector", "give the direction into the domain, e.g. [0, 0, 1]"));
                }
                let normal = [normal[0] / len, normal[1] / len, normal[2] / len];
                out.push(plain(format!("wall[{i}]"), WallShape::Plane { point, normal }, m));
            }
            WallSpec::Box { material, min, max, open_top } => {
                let m = material_of(key("material"), material)?;
                let (lo, hi) = (finite3(c, &key("min"), *min)?, finite3(c, &key("max"), *max)?);
                if (0..3).any(|k| hi[k] <= lo[k]) {
                    return Err(c.invalid(key("max"), format!("{hi:?}"), format!("must exceed min {lo:?} on every axis"), "give the upper corner above the lower one"));
                }
                let faces: [(&str, [f64; 3], [f64; 3]); 6] = [
                    ("bottom", lo, [0.0, 0.0, 1.0]),
                    ("top", hi, [0.0, 0.0, -1.0]),
                    ("x_min", lo, [1.0, 0.0, 0.0]),
                    ("x_max", hi, [-1.0, 0.0, 0.0]),
                    ("y_min", lo, [0.0, 1.0, 0.0]),
                    ("y_max", hi, [0.0, -1.0, 0.0]),
                ];
                for (face, point, normal) in faces {
                    if *open_top && face == "top" {
                        continue;
                    }
                    out.push(plain(format!("wall[{i}].{face}"), WallShape::Plane { point, normal }, m));
                }
            }
            WallSpec::ServoBox { material, min, max, pressure, gain, max_speed } => {
                let m = material_of(key("material"), material)?;
                let (lo, hi) = (finite3(c, &key("min"), *min)?, finite3(c, &key("max"), *max)?);
                if (0..3).any(|k| hi[k] <= lo[k]) {
                    return Err(c.invalid(key("max"), format!("{hi:?}"), format!("must exceed min {lo:?} on every axis"), "give the upper corner above the lower one"));
                }
                if out.iter().any(|p: &PendingWall| p.servo.is_some()) {
                    return Err(c.invalid(key("type"), "\"servo_box\"", "a scene has at most one servo box", "remove the extra one"));
                }
                let pressure = non_negative(c, &key("pressure"), *pressure, "give the target pressure in Pa")?;
                let max_speed = positive(c, &key("max_speed"), max_speed.unwrap_or(DEFAULT_SERVO_SPEED), "give the largest wall speed in m/s")?;
                let gain = positive(c, &key("gain"), gain.unwrap_or(max_speed / pressure.max(SERVO_PRESSURE_FLOOR)), "give the wall speed per pressure error in m/(s Pa)")?;
                let faces: [(&str, [f64; 3], [f64; 3]); 6] = [
                    ("x_min", lo, [1.0, 0.0, 0.0]),
                    ("x_max", hi, [-1.0, 0.0, 0.0]),
                    ("y_min", lo, [0.0, 1.0, 0.0]),
                    ("y_max", hi, [0.0, -1.0, 0.0]),
                    ("z_min", lo, [0.0, 0.0, 1.0]),
                    ("z_max", hi, [0.0, 0.0, -1.0]),
                ];
                for (face, point, normal) in faces {
                    let mut w = plain(format!("wall[{i}].{face}"), WallShape::Plane { point, normal }, m);
                    w.servo = Some((pressure, gain, max_speed));
                    out.push(w);
                }
            }
            WallSpec::Cylinder { material, center, radius } => {
                let m = material_of(key("material"), material)?;
                let radius = positive(c, &key("radius"), *radius, "give the radius in metres")?;
                out.push(plain(format!("wall[{i}]"), WallShape::Cylinder { center: *center, radius }, m));
            }
            WallSpec::Piston { material, z, pressure, mass, area } => {
                let m = material_of(key("material"), material)?;
                if !z.is_finite() {
                    return Err(c.invalid(key("z"), z, "must be finite", "give the initial height in metres"));
                }
                let pressure = non_negative(c, &key("pressure"), *pressure, "give the pressure in Pa")?;
                let piston_mass = mass.map(|v| positive(c, &key("mass"), v, "give the mass in kg or leave it out")).transpose()?;
                let piston_area = area.map(|v| positive(c, &key("area"), v, "give the area in m^2 or leave it out")).transpose()?;
                if out.iter().any(|p: &PendingWall| matches!(p.wall.shape, WallShape::Piston { .. })) {
                    return Err(c.invalid(key("type"), "\"piston\"", "a scene has at most one piston", "remove the extra piston"));
                }
                out.push(PendingWall {
                    wall: Wall { name: format!("wall[{i}]"), shape: WallShape::Piston { z: *z, pressure, mass: 0.0, area: 0.0 }, material: m },
                    piston_mass,
                    piston_area,
                    servo: None,
                });
            }
        }
    }
    Ok(out)
}

/// Fills in the piston's default mass (total grain mass) and area (cross-section of the
/// cylinder, or of a box's side walls).
/// The servo box among the walls, if any.
fn servo_box(pending: &[PendingWall]) -> Option<ServoBox> {
    let first = pending.iter().position(|p| p.servo.is_some())?;
    let (pressure, gain, max_speed) = pending[first].servo?;
    Some(ServoBox { walls: [0, 1, 2, 3, 4, 5].map(|k| first + k), pressure, gain, max_speed })
}

fn finish_walls(c: &Complainer, pending: Vec<PendingWall>, grains: &Grains, periodic: &[Option<[f64; 2]>; 3]) -> Result<Vec<Wall>, SceneError> {
    let section = cross_section(pending.iter().map(|p| &p.wall.shape), periodic);
    let total_mass: f64 = grains.mass.iter().sum();
    let mut out = Vec::with_capacity(pending.len());
    for p in pending {
        let mut wall = p.wall;
        if let WallShape::Piston { mass, area, .. } = &mut wall.shape {
            *mass = p.piston_mass.unwrap_or(total_mass);
            *area = match p.piston_area.or(section) {
                Some(a) => a,
                None => {
                    return Err(c.invalid(format!("{}.area", wall.name), "(none)", "the piston's area cannot be inferred without a cylinder or box wall", "give `area` in m^2"));
                }
            };
        }
        out.push(wall);
    }
    Ok(out)
}

/// Horizontal cross-section (m^2) of a container: a cylinder wall's, or that of the side
/// planes of a box or the periods of the x and y axes; `None` when nothing bounds one.
pub fn cross_section<'a>(shapes: impl Iterator<Item = &'a WallShape> + Clone, periodic: &[Option<[f64; 2]>; 3]) -> Option<f64> {
    let cylinder = shapes.clone().find_map(|s| match *s {
        WallShape::Cylinder { radius, .. } => Some(std::f64::consts::PI * radius * radius),
        _ => None,
    });
    cylinder.or_else(|| {
        let side = |n: [f64; 3]| {
            shapes.clone().find_map(|s| match *s {
                WallShape::Plane { point, normal } if normal == n => Some(point),
                _ => None,
            })
        };
        let span = |a: usize, n: [f64; 3]| match periodic[a] {
            Some([lo, hi]) => Some(hi - lo),
            None => {
                let mut m = n;
                m[a] = -n[a];
                Some(side(m)?[a] - side(n)?[a])
            }
        };
        Some(span(0, [1.0, 0.0, 0.0])? * span(1, [0.0, 1.0, 0.0])?)
    })
}

/// Signed distance (m) from a point to a wall's surface at its initial position, positive on
/// the grains' side.
pub fn wall_distance(shape: &WallShape, p: [f64; 3]) -> f64 {
    crate::walls::WallGeom::<f64>::of(shape).frame(crate::real::Vec3::of(p), crate::real::Vec3::ZERO).1
}

fn validate_periodic(c: &Complainer, f: &SceneFile) -> Result<[Option<[f64; 2]>; 3], SceneError> {
    let p = &f.periodic;
    let mut out = [None; 3];
    for (a, (name, v)) in [("x", p.x), ("y", p.y), ("z", p.z)].into_iter().enumerate() {
        if let Some([lo, hi]) = v {
            if !(lo.is_finite() && hi.is_finite() && hi > lo) {
                return Err(c.invalid(format!("periodic.{name}"), format!("[{lo}, {hi}]"), "must be [lo, hi] with hi > lo", "give the wrapping interval in metres"));
            }
            out[a] = Some([lo, hi]);
        }
    }
    Ok(out)
}

/// A periodic axis must hold its grains and be long enough that a pair within reach has one
/// image only: period > 2 (2 R_max + skin).
fn check_periodic(c: &Complainer, origins: &Origins, grains: &Grains, periodic: &[Option<[f64; 2]>; 3], skin: Option<f64>) -> Result<(), SceneError> {
    let r_max = grains.radius.iter().copied().fold(0.0, f64::max);
    let d_mean = 2.0 * grains.radius.iter().sum::<f64>() / grains.len() as f64;
    let reach = 2.0 * r_max + skin.unwrap_or(0.1 * d_mean);
    for (a, name) in ["x", "y", "z"].into_iter().enumerate() {
        let Some([lo, hi]) = periodic[a] else { continue };
        if hi - lo <= 2.0 * reach {
            return Err(c.invalid(format!("periodic.{name}"), format!("[{lo}, {hi}]"), format!("a period of {:.4e} m is too short for contacts of reach {reach:.4e} m", hi - lo), format!("make the period longer than {:.4e} m", 2.0 * reach)));
        }
        if let Some(i) = (0..grains.len()).find(|&i| !(grains.position[i][a] >= lo && grains.position[i][a] < hi)) {
            return Err(c.invalid(origins.name(i), format!("{:?}", grains.position[i]), format!("lies outside periodic.{name} = [{lo}, {hi})"), "place grains inside the periodic interval"));
        }
    }
    Ok(())
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

/// Rebuilds between renumberings of the grains in cell order when the scene does not say
/// (`simulation.reorder_every`); not tuned: the benchmarks measured it on against off only.
pub const DEFAULT_REORDER_EVERY: u64 = 10;

/// Overlap with a wall (fraction of the radius) that a grain read from a file may start with:
/// a settled packing rests on its floor with overlaps of about 1e-3 of a radius.
const READ_WALL_OVERLAP: f64 = 0.01;

/// Grains may not start overlapping a wall (grains read from a file: by more than
/// [`READ_WALL_OVERLAP`]) or (listed grains) each other: the first step would release the
/// stored energy at once.
fn check_overlaps(c: &Complainer, origins: &Origins, grains: &Grains, walls: &[Wall]) -> Result<(), SceneError> {
    let listed = origins.listed;
    let origin = |i: usize| origins.name(i);
    for i in 0..grains.len() {
        for w in walls {
            let d = wall_distance(&w.shape, grains.position[i]);
            let allowed = if origins.read(i) { READ_WALL_OVERLAP * grains.radius[i] } else { 0.0 };
            if d < grains.radius[i] - allowed {
                return Err(c.invalid(
                    origin(i),
                    format!("{:?}", grains.position[i]),
                    format!("the grain (radius {:.4e} m) overlaps {} by {:.4e} m", grains.radius[i], w.name, grains.radius[i] - d),
                    "move the grain or its generator's region inside the walls",
                ));
            }
        }
    }
    for i in 0..listed {
        for j in 0..i {
            let d2: f64 = (0..3).map(|k| (grains.position[i][k] - grains.position[j][k]).powi(2)).sum();
            if d2.sqrt() < grains.radius[i] + grains.radius[j] {
                return Err(c.invalid(origin(i), format!("{:?}", grains.position[i]), format!("overlaps grain[{j}]"), "place listed grains apart"));
            }
        }
    }
    Ok(())
}

fn validate_model(c: &Complainer, m: &ModelSpec, materials: &[Material], grains: &Grains, walls: &[Wall]) -> Result<ContactModel<f64>, SceneError> {
    let law = |v: &Option<String>, default: &str| v.clone().unwrap_or_else(|| default.to_string());
    let unused = |key: &str, set: bool, law: &str| -> Result<(), SceneError> {
        if set {
            Err(c.invalid(format!("model.{key}"), "(set)", format!("is not used by the chosen laws ({law})"), format!("remove `{key}` or choose the law that uses it")))
        } else {
            Ok(())
        }
    };
    let need = |key: &str, v: Option<f64>, why: &str| -> Result<f64, SceneError> {
        match v {
            Some(x) => positive(c, &format!("model.{key}"), x, why),
            None => Err(c.invalid(format!("model.{key}"), "(missing)", "is required by the chosen law", why.to_string())),
        }
    };
    let normal_name = law(&m.normal, "hertz");
    let normal = match normal_name.as_str() {
        "hertz" => {
            unused("k_n", m.k_n.is_some(), "normal = \"hertz\"")?;
            NormalLaw::Hertz
        }
        "linear" => NormalLaw::Linear { k_n: need("k_n", m.k_n, "give the linear stiffness k_n in N/m")? },
        other => return Err(c.invalid("model.normal", format!("\"{other}\""), "unknown normal law", "use \"hertz\" or \"linear\"")),
    };
    let damping_name = law(&m.damping, "none");
    let damping = match damping_name.as_str() {
        "none" => DampingLaw::None,
        "papers" => DampingLaw::Papers,
        "restitution" => {
            // Every material in contact needs its restitution coefficient.
            let used: Vec<u16> = grains.material.iter().copied().chain(walls.iter().map(|w| w.material)).collect();
            if let Some((i, _)) = materials.iter().enumerate().find(|(i, mat)| used.contains(&(*i as u16)) && mat.restitution.is_none()) {
                return Err(c.invalid(format!("material[{i}].restitution"), "(missing)", "damping = \"restitution\" needs it", "add `restitution` in (0, 1] to the material"));
            }
            // Every material, used or not: the dashpot is sized for each pair of them.
            if let Some((i, e)) = materials.iter().enumerate().find_map(|(i, mat)| mat.restitution.filter(|&e| e < MIN_RESTITUTION).map(|e| (i, e))) {
                return Err(c.invalid(
                    format!("material[{i}].restitution"),
                    e,
                    format!("is below {MIN_RESTITUTION}, where the dashpot would set the contact's time scale and the time step, picked from the elastic contact time, would not resolve it"),
                    format!("give a restitution of at least {MIN_RESTITUTION}"),
                ));
            }
            DampingLaw::Restitution
        }
        "viscous" => DampingLaw::Viscous { c_n: need("c_n", m.c_n, "give the dashpot coefficient c_n in N s/m")? },
        other => return Err(c.invalid("model.damping", format!("\"{other}\""), "unknown damping law", "use \"none\", \"papers\", \"restitution\" or \"viscous\"")),
    };
    if !matches!(damping, DampingLaw::Viscous { .. }) {
        unused("c_n", m.c_n.is_some(), &format!("damping = \"{damping_name}\""))?;
    }
    if matches!(damping, DampingLaw::None) {
        unused("limit_damping", m.limit_damping.is_some(), "damping = \"none\" (an elastic force never pulls)")?;
    }
    if matches!(damping, DampingLaw::Papers) && materials.iter().all(|x| x.constants.gamma_n == 0.0) {
        return Err(c.invalid("model.damping", "\"papers\"", "no material sets gamma_n, so it would not damp", "set `gamma_n` (s^-1 m^-1/2) in the [[material]] tables or use damping = \"none\""));
    }
    let stiffness = |kt: Option<f64>| -> Result<TangentialStiffness<f64>, SceneError> {
        match (kt, normal) {
            (Some(r), _) => Ok(TangentialStiffness::RatioToNormal(positive(c, "model.kt_ratio", r, "give a ratio such as 2/7")?)),
            (None, NormalLaw::Hertz) => Ok(TangentialStiffness::Mindlin),
            (None, NormalLaw::Linear { .. }) => Ok(TangentialStiffness::RatioToNormal(DEFAULT_LINEAR_KT_RATIO)),
        }
    };
    for (key, v, why) in [
        ("v_slip", m.v_slip, "Oquendo et al.'s contacts slide when their static spring fails its Coulomb test (mu_s), not above a speed"),
        ("v_roll", m.v_roll, "Oquendo et al.'s contacts roll when their rolling spring reaches the rolling friction, not above a speed"),
    ] {
        if let Some(v) = v {
            return Err(c.invalid(format!("model.{key}"), v, format!("is no longer used: {why}"), format!("remove `{key}` (docs/physics.md, \"Oquendo et al.'s contact law\")")));
        }
    }
    let tangential_name = law(&m.tangential, "none");
    let tangential = match tangential_name.as_str() {
        "none" => {
            for (k, set) in [("static_damping", m.static_damping.is_some()), ("rolling_friction", m.rolling_friction.is_some()), ("kt_ratio", m.kt_ratio.is_some()), ("tangential_damping_ratio", m.tangential_damping_ratio.is_some())] {
                unused(k, set, "tangential = \"none\"")?;
            }
            TangentialLaw::None
        }
        "oquendo" => {
            unused("tangential_damping_ratio", m.tangential_damping_ratio.is_some(), "tangential = \"oquendo\" (its static spring is damped by static_damping)")?;
            TangentialLaw::Oquendo(OquendoLaw {
                static_damping: non_negative(c, "model.static_damping", m.static_damping.unwrap_or(DEFAULT_STATIC_DAMPING), "give a fraction of critical damping such as 0.3")?,
                stiffness: stiffness(m.kt_ratio)?,
                rolling_friction: match m.rolling_friction.as_deref().unwrap_or("torque") {
                    "torque" => RollingFriction::Torque,
                    "as_written" => RollingFriction::AsWritten,
                    other => return Err(c.invalid("model.rolling_friction", format!("\"{other}\""), "unknown rolling friction", "use \"torque\" (momentum-conserving) or \"as_written\" (eqs. 8-9 on each grain)")),
                },
            })
        }
        "mindlin" => {
            unused("static_damping", m.static_damping.is_some(), "tangential = \"mindlin\"")?;
            unused("rolling_friction", m.rolling_friction.is_some(), "tangential = \"mindlin\"")?;
            for (i, mat) in materials.iter().enumerate() {
                if mat.constants.mu_k != mat.constants.mu_s {
                    return Err(c.invalid(format!("material[{i}].mu_k"), mat.constants.mu_k, "the Hertz-Mindlin law has one friction coefficient (mu_s)", "remove mu_k or set it equal to mu_s"));
                }
            }
            TangentialLaw::Mindlin {
                damping_ratio: non_negative(c, "model.tangential_damping_ratio", m.tangential_damping_ratio.unwrap_or(0.0), "give a fraction such as 0.9075")?,
                stiffness: stiffness(m.kt_ratio)?,
            }
        }
        other => return Err(c.invalid("model.tangential", format!("\"{other}\""), "unknown tangential law", "use \"none\", \"oquendo\" or \"mindlin\"")),
    };
    let rolling_name = law(&m.rolling, "none");
    let rolling = match rolling_name.as_str() {
        "none" => {
            for (k, set) in [("rolling_k", m.rolling_k.is_some()), ("rolling_gamma", m.rolling_gamma.is_some()), ("rolling_mu", m.rolling_mu.is_some())] {
                unused(k, set, "rolling = \"none\"")?;
            }
            RollingLaw::None
        }
        "sds" => RollingLaw::Sds {
            k_r: need("rolling_k", m.rolling_k, "give the rolling stiffness in N/m")?,
            gamma_r: non_negative(c, "model.rolling_gamma", m.rolling_gamma.unwrap_or(0.0), "give the rolling damping in N s/m")?,
            mu_r: need("rolling_mu", m.rolling_mu, "give the rolling friction coefficient, e.g. 0.05")?,
        },
        other => return Err(c.invalid("model.rolling", format!("\"{other}\""), "unknown rolling law", "use \"none\" or \"sds\"")),
    };
    let twisting_name = law(&m.twisting, "none");
    let twisting = match twisting_name.as_str() {
        "none" => TwistingLaw::None,
        "oquendo" => TwistingLaw::Oquendo,
        other => return Err(c.invalid("model.twisting", format!("\"{other}\""), "unknown twisting law", "use \"none\" or \"oquendo\"")),
    };
    let cohesion_name = law(&m.cohesion, "none");
    let cohesion = match cohesion_name.as_str() {
        "none" => {
            for (k, set) in [("surface_tension", m.surface_tension.is_some()), ("contact_angle", m.contact_angle.is_some()), ("liquid_density", m.liquid_density.is_some())] {
                unused(k, set, "cohesion = \"none\"")?;
            }
            CohesionLaw::None
        }
        "capillary" => {
            let gamma_s = positive(c, "model.surface_tension", m.surface_tension.unwrap_or(DEFAULT_SURFACE_TENSION), "give the surface tension in N/m, e.g. 0.0728 for water")?;
            let theta = m.contact_angle.unwrap_or(0.0);
            if !(0.0..90.0).contains(&theta) {
                return Err(c.invalid("model.contact_angle", theta, "must lie in [0, 90) degrees for an attractive bridge", "give the contact angle in degrees, e.g. 0"));
            }
            let theta = theta.to_radians();
            CohesionLaw::Capillary { kappa: 2.0 * std::f64::consts::PI * gamma_s * theta.cos(), theta, c: CAPILLARY_C }
        }
        other => return Err(c.invalid("model.cohesion", format!("\"{other}\""), "unknown cohesion law", "use \"none\" or \"capillary\"")),
    };
    Ok(ContactModel { normal, damping, tangential, rolling, twisting, cohesion, limit_damping: m.limit_damping.unwrap_or(true) })
}

/// `simulation.method` and, for contact dynamics, its `[contact_dynamics]` settings.
fn validate_method(c: &Complainer, sim: &SimulationSpec, spec: Option<&ContactDynamicsSpec>, d_mean: f64) -> Result<Method, SceneError> {
    match sim.method.as_deref().unwrap_or("dem") {
        "dem" => {
            if spec.is_some() {
                return Err(c.invalid("contact_dynamics", "(set)", "is read only by contact dynamics", "set simulation.method = \"contact_dynamics\" or remove [contact_dynamics]"));
            }
            Ok(Method::Dem)
        }
        "contact_dynamics" => {
            let given = spec.copied().unwrap_or_default();
            let theta = given.theta.unwrap_or(CdParams::default().theta);
            if !(0.5..=1.0).contains(&theta) {
                return Err(c.invalid("contact_dynamics.theta", theta, "must lie in [0.5, 1]", "use 0.5 (the midpoint rule) to 1 (implicit Euler)"));
            }
            let tolerance = given.tolerance.unwrap_or(CdParams::default().tolerance);
            if !(tolerance > 0.0 && tolerance < 1.0) {
                return Err(c.invalid("contact_dynamics.tolerance", tolerance, "must lie in (0, 1)", "give a relative change such as 1e-6"));
            }
            let max_iterations = given.max_iterations.unwrap_or(CdParams::default().max_iterations);
            if max_iterations == 0 {
                return Err(c.invalid("contact_dynamics.max_iterations", 0, "must be at least 1", "give a number of sweeps, e.g. 1000"));
            }
            let gap_allowance = match given.gap_allowance {
                Some(v) => non_negative(c, "contact_dynamics.gap_allowance", v, "give a length in metres, e.g. 0.1 x the mean diameter")?,
                None => 0.1 * d_mean,
            };
            let wall_mass = given.wall_mass.map(|m| positive(c, "contact_dynamics.wall_mass", m, "give a mass in kg, or leave it out for the grains' total mass")).transpose()?;
            Ok(Method::ContactDynamics(CdParams { theta, tolerance, max_iterations, gap_allowance, wall_mass }))
        }
        other => Err(c.invalid("simulation.method", format!("\"{other}\""), "unknown method", "use \"dem\" or \"contact_dynamics\"")),
    }
}

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
    gravity: [f64; 3],
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

fn validate_stages(
    c: &Complainer,
    specs: &[StageSpec],
    grains: &Grains,
    gravity: [f64; 3],
    d_mean: f64,
    walls: &[Wall],
    has_servo: bool,
    liquid_density: f64,
) -> Result<Vec<Stage>, SceneError> {
    let g = (gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]).sqrt();
    let m_mean = grains.mass.iter().sum::<f64>() / grains.len() as f64;
    let has_piston = walls.iter().any(|w| matches!(w.shape, WallShape::Piston { .. }));
    let mut out = Vec::new();
    for (i, s) in specs.iter().enumerate() {
        let key = |k: &str| format!("stage[{i}].{k}");
        let oedometer = s.kind == "oedometer";
        let kind = match s.kind.as_str() {
            "fill" => StageKind::Fill,
            "settle" | "oedometer" => StageKind::Settle,
            "run" => StageKind::Run,
            other => return Err(c.invalid(key("kind"), format!("\"{other}\""), "unknown stage kind", "use \"fill\", \"settle\", \"run\" or \"oedometer\"")),
        };
        let duration = positive(c, &key("duration"), s.duration, "give the (longest) stage time in seconds")?;
        if kind == StageKind::Fill && g == 0.0 {
            return Err(c.invalid(key("kind"), "\"fill\"", "deposition needs gravity", "set simulation.gravity or use kind = \"settle\""));
        }
        if kind == StageKind::Run {
            for (k, set) in [("ke_per_grain", s.ke_per_grain.is_some()), ("ke_ratio", s.ke_ratio.is_some()), ("unbalanced_force", s.unbalanced_force.is_some()), ("pressure_tolerance", s.pressure_tolerance.is_some())] {
                if set {
                    return Err(c.invalid(key(k), "(set)", "is a settle criterion; a \"run\" stage ends after its duration", format!("remove `{k}` or use kind = \"settle\"")));
                }
            }
        }
        if !oedometer {
            for (k, set) in [("p0", s.p0.is_some()), ("p_max", s.p_max.is_some()), ("factor", s.factor.is_some()), ("seating_pressure", s.seating_pressure.is_some())] {
                if set {
                    return Err(c.invalid(key(k), "(set)", "belongs to kind = \"oedometer\"", format!("remove `{k}` or use kind = \"oedometer\"")));
                }
            }
        }
        if s.ke_per_grain.is_some() && s.ke_ratio.is_some() {
            return Err(c.invalid(key("ke_ratio"), "(set)", "replaces ke_per_grain, which is set too", "keep one of `ke_per_grain` (J per grain) and `ke_ratio` (kinetic over elastic energy)"));
        }
        let ke_ratio = s.ke_ratio.map(|r| positive(c, &key("ke_ratio"), r, "give a ratio such as 1e-4")).transpose()?;
        let ke_per_grain = match s.ke_per_grain {
            Some(v) => positive(c, &key("ke_per_grain"), v, "give an energy in J")?,
            None if kind == StageKind::Run || ke_ratio.is_some() => 0.0,
            None if g > 0.0 => {
                let v = DEFAULT_SETTLE_SPEED_FRACTION * (g * d_mean).sqrt();
                0.5 * m_mean * v * v
            }
            None => return Err(c.invalid(key("ke_per_grain"), "(missing)", "has no default without gravity", "give the settled kinetic energy per grain in J")),
        };
        let unbalanced_force = match s.unbalanced_force {
            Some(v) => positive(c, &key("unbalanced_force"), v, "give a ratio such as 0.01")?,
            None => DEFAULT_UNBALANCED_FORCE,
        };
        let pressure_tolerance = positive(c, &key("pressure_tolerance"), s.pressure_tolerance.unwrap_or(DEFAULT_PRESSURE_TOLERANCE), "give a fraction such as 0.01")?;
        if (s.piston_pressure.is_some() || oedometer) && !has_piston {
            let k = if oedometer { "kind" } else { "piston_pressure" };
            return Err(c.invalid(key(k), "(set)", "the scene has no piston", "add a [[wall]] with type = \"piston\""));
        }
        let base = Stage {
            name: s.name.clone().unwrap_or_else(|| format!("{}{}", s.kind, i)),
            kind,
            duration,
            ke_per_grain,
            ke_ratio,
            unbalanced_force,
            piston_pressure: s.piston_pressure.map(|p| non_negative(c, &key("piston_pressure"), p, "give the pressure in Pa")).transpose()?,
            pressure_tolerance,
            lower_piston: false,
            records_compression: false,
            seating: false,
            servo_pressure: match s.servo_pressure {
                Some(_) if !has_servo => return Err(c.invalid(key("servo_pressure"), "(set)", "the scene has no servo box", "add a [[wall]] with type = \"servo_box\" or remove the key")),
                Some(p) => Some(non_negative(c, &key("servo_pressure"), p, "give the pressure in Pa")?),
                None => None,
            },
            axial_strain_rate: match s.axial_strain_rate {
                Some(_) if !has_servo => return Err(c.invalid(key("axial_strain_rate"), "(set)", "the scene has no servo box", "add a [[wall]] with type = \"servo_box\" or remove the key")),
                Some(r) if !r.is_finite() => return Err(c.invalid(key("axial_strain_rate"), r, "must be finite", "give a strain rate in 1/s, positive to compress")),
                other => other,
            },
            wet_volume: match s.water_content {
                Some(w) => Some(positive(c, &key("water_content"), w, "give the gravimetric water content, e.g. 0.007")? * grains.mass.iter().sum::<f64>() / liquid_density),
                None => None,
            },
        };
        if !oedometer {
            out.push(base);
            continue;
        }
        if s.piston_pressure.is_some() {
            return Err(c.invalid(key("piston_pressure"), "(set)", "an oedometer sets the pressure itself from p0 to p_max", "remove `piston_pressure`"));
        }
        let need = |k: &str, v: Option<f64>| match v {
            Some(x) => positive(c, &key(k), x, "give a pressure in Pa"),
            None => Err(c.invalid(key(k), "(missing)", "is required by kind = \"oedometer\"", "give a pressure in Pa, e.g. p0 = 1e4 and p_max = 1.28e6")),
        };
        let (p0, p_max) = (need("p0", s.p0)?, need("p_max", s.p_max)?);
        if p_max < p0 {
            return Err(c.invalid(key("p_max"), p_max, format!("is below p0 = {p0}"), "give p_max >= p0"));
        }
        let factor = s.factor.unwrap_or(DEFAULT_OEDOMETER_FACTOR);
        if !(factor > 1.0 && factor.is_finite()) {
            return Err(c.invalid(key("factor"), factor, "must exceed 1", "give a multiplier such as 2"));
        }
        let mut first = true;
        if let Some(seat) = s.seating_pressure {
            let seat = positive(c, &key("seating_pressure"), seat, "give a small pressure in Pa, below p0")?;
            if seat >= p0 {
                return Err(c.invalid(key("seating_pressure"), seat, format!("is not below p0 = {p0}"), "give a seating load below the first pressure, e.g. p0 / 10"));
            }
            out.push(Stage {
                name: format!("{}@seat {}", base.name, pressure_label(seat)),
                piston_pressure: Some(seat),
                lower_piston: true,
                records_compression: true,
                seating: true,
                ..base.clone()
            });
            first = false;
        }
        let mut p = p0;
        while p <= p_max * (1.0 + 1e-12) {
            out.push(Stage {
                name: format!("{}@{}", base.name, pressure_label(p)),
                piston_pressure: Some(p),
                lower_piston: first,
                records_compression: true,
                wet_volume: if first { base.wet_volume } else { None },
                ..base.clone()
            });
            first = false;
            p *= factor;
        }
    }
    if out.is_empty() {
        return Err(c.invalid("stage", "[]", "the scene has no [[stage]]", "add e.g. [[stage]] kind = \"run\" duration = 1e-3"));
    }
    Ok(out)
}
