//! The run summary (`--json`, `summary.json`) and the `check` report.

use crate::analysis::fit::{e0_profile, fit_bauer, profile_e0s, BauerFit, E0Profile};
use crate::analysis::packing_fraction;
use crate::engine::Engine;
use crate::model::{CohesionLaw, TangentialLaw};
use crate::protocol::{CompressionPoint, StageResult};
use crate::real::Vec3;
use crate::scene::{Scene, WallShape};
use crate::walls::WallGeom;
use serde::Serialize;
use std::fmt::Write;

/// End-of-run figures.
#[derive(Clone, Debug, Serialize)]
pub struct FinalState {
    /// Kinetic energy, translational + rotational (J).
    pub kinetic_energy: f64,
    /// Solid fraction of the bed (see [`packing_fraction`]); null without a container.
    pub packing_fraction: Option<f64>,
    /// Grain-grain contacts per grain.
    pub coordination_number: f64,
}

/// What `grains run --json` prints and `--out` writes as `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Scene file.
    pub file: String,
    /// "cpu".
    pub backend: &'static str,
    /// "f32" or "f64".
    pub precision: &'static str,
    /// Worker threads.
    pub threads: usize,
    /// Grain count.
    pub grains: usize,
    /// Steps taken.
    pub steps: u64,
    /// Time step (s).
    pub dt: f64,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// Wall-clock time of the stages (s).
    pub wall_seconds: f64,
    /// Grains x steps / wall seconds; where grains enter and leave, the steps each grain ran
    /// in play ([`crate::flow::FlowState::grain_steps`]).
    pub particle_steps_per_second: f64,
    /// Per-stage results.
    pub stages: Vec<StageResult>,
    /// End state.
    #[serde(rename = "final")]
    pub final_state: FinalState,
    /// Oedometer points, one per pressure step.
    pub compression: Vec<CompressionPoint>,
    /// Bauer's law fitted to the compression points (at least 4, the seating load's left
    /// out) with e0 held at the measured one (`e0_seat`, else `e0_top`), if it could be.
    pub bauer: Option<BauerFit>,
    /// Why Bauer's law could not be fitted, when there were points to fit.
    pub bauer_error: Option<String>,
    /// Bauer's law with e0 fitted too.
    pub bauer_free: Option<BauerFit>,
    /// The void ratio under the seating load, when the oedometer has one.
    pub e0_seat: Option<f64>,
    /// The void ratio up to the top of the highest grain when the piston was lowered.
    pub e0_top: Option<f64>,
    /// Bauer's law with e0 held at a range of values (see [`e0_profile`]).
    pub bauer_profile: Option<E0Profile>,
    /// Validation warnings.
    pub warnings: Vec<String>,
}

impl Summary {
    /// Summarises a finished run.
    pub fn new(scene: &Scene, engine: &dyn Engine, threads: usize, wall_seconds: f64, stages: Vec<StageResult>, flow: &crate::flow::FlowState) -> Result<Self, crate::engine::SimError> {
        let last = stages.last().map(|s| &s.stats);
        let frame = engine.frame(false)?;
        let piston_z = last.and_then(|s| s.piston.as_ref().map(|p| p.z));
        let compression: Vec<CompressionPoint> = stages.iter().filter_map(|s| s.compression.clone()).collect();
        // Bauer's e0: the void ratio under the seating load when there is one, else with the
        // piston at the top of the highest grain.
        let seat = compression.iter().find(|c| c.seating).map(|c| c.void_ratio);
        let e0_top = stages.iter().find_map(|s| s.initial_void_ratio);
        let e0 = seat.or(e0_top);
        let fitted: Vec<CompressionPoint> = compression.iter().filter(|c| !c.seating).cloned().collect();
        let bauer = fit_compression(&fitted, e0);
        let data = compression_data(&fitted);
        let enough = fitted.len() >= MIN_BAUER_POINTS;
        let bauer_free = if enough { fit_bauer(&data, None, 1.0).ok() } else { None };
        let reach = e0_top.into_iter().chain(e0).chain(bauer_free.map(|b| b.e0.value)).fold(0.0, f64::max);
        let bauer_profile = enough.then(|| e0_profile(&data, &profile_e0s(&data, reach, PROFILE_POINTS), 1.0));
        Ok(Summary {
            scene: scene.name.clone(),
            file: scene.path.display().to_string(),
            backend: engine.backend(),
            precision: engine.precision(),
            threads,
            grains: engine.grain_count(),
            steps: engine.steps(),
            dt: scene.time_step.dt,
            simulated_time: engine.time(),
            wall_seconds,
            particle_steps_per_second: if scene.has_flow() { flow.grain_steps as f64 } else { engine.grain_count() as f64 * engine.steps() as f64 } / wall_seconds.max(1e-9),
            final_state: FinalState {
                kinetic_energy: last.map_or(0.0, |s| s.kinetic_energy()),
                packing_fraction: packing_fraction(scene, &frame, piston_z),
                coordination_number: last.map_or(0.0, |s| s.coordination),
            },
            compression: compression.clone(),
            bauer: bauer.as_ref().ok().and_then(|b| *b),
            bauer_error: bauer.err(),
            bauer_free,
            e0_seat: seat,
            e0_top,
            bauer_profile,
            stages,
            warnings: scene.warnings.clone(),
        })
    }

    /// The compression points as CSV (the input of `grains fit bauer`).
    pub fn compression_csv(&self) -> String {
        let mut s = String::from("target_pressure_Pa,pressure_Pa,piston_z_m,void_ratio,stress_zz_Pa,stress_trace_Pa,lateral_ratio,coordination,kinetic_energy_J,settled\n");
        for c in &self.compression {
            s.push_str(&format!(
                "{:e},{:e},{:e},{},{:e},{:e},{},{},{:e},{}\n",
                c.target_pressure,
                c.pressure,
                c.piston_z,
                c.void_ratio,
                c.stress_zz,
                c.stress_trace(),
                c.lateral_ratio(),
                c.coordination,
                c.kinetic_energy,
                c.settled
            ));
        }
        s
    }

    /// A few lines for a person.
    pub fn human(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{}: {} grains, {} steps of {:.3e} s ({:.4e} s simulated) on {} {} x{} in {:.2} s ({:.3e} particle-steps/s)",
            self.scene, self.grains, self.steps, self.dt, self.simulated_time, self.backend, self.precision, self.threads, self.wall_seconds, self.particle_steps_per_second);
        for st in &self.stages {
            let settled = match st.settled {
                Some(true) => " settled",
                Some(false) => " NOT settled (duration ran out)",
                None => "",
            };
            let _ = writeln!(s, "  stage {:<12} {:>6} {:>9} steps  t = {:.4e} s  KE/grain = {:.3e} J  unbalanced = {:.3e}  Z = {:.3}  sliding = {:.1}%  max overlap = {:.3e}{settled}",
                st.name, st.kind, st.steps, st.time_end, st.ke_per_grain, st.unbalanced_force, st.stats.coordination, 100.0 * st.stats.sliding_fraction(), st.stats.max_overlap);
        }
        // Contact dynamics says how many steps its solver left at the iteration cap.
        if let Some(c) = self.stages.last().and_then(|st| st.stats.solver) {
            if c.unconverged_total > 0 {
                let _ = writeln!(s, "  contact dynamics: {} of {} steps stopped at contact_dynamics.max_iterations before the tolerance (stats.csv: cd_unconverged_steps)", c.unconverged_total, c.steps_total);
            }
            let q = &c.residuals;
            let _ = writeln!(s, "  contact dynamics' residuals over the last statistics interval (largest): normal {:.2e} m/s, tangential {:.2e} m/s, quadratic norm {:.2e}, maximum norm {:.2e}", q.normal, q.tangential, q.quadratic, q.maximum);
        }
        if !self.compression.is_empty() {
            let _ = writeln!(s, "  oedometer: p (kPa), e, sigma_zz from particle stresses (kPa), K0 = lateral / vertical stress, Z");
            for c in &self.compression {
                let _ = writeln!(s, "    {:>9.2} {:.4} {:>9.2} {:.3} {:.3}{}", c.pressure / 1e3, c.void_ratio, c.stress_zz / 1e3, c.lateral_ratio(), c.coordination, if c.settled { "" } else { "  (not settled)" });
            }
        }
        match (&self.bauer, &self.bauer_error) {
            (Some(b), _) => {
                let top = self.e0_top.map_or(String::new(), |e| format!(" (the piston on the highest grain: e = {e:.4})"));
                let held = if self.e0_seat.is_some() { "e0 under the seating load" } else { "e0 with the piston on the highest grain" };
                let _ = writeln!(s, "  Bauer's law, {held}{top}: {}", b.line());
            }
            (None, Some(e)) => {
                let _ = writeln!(s, "  Bauer's law: not fitted: {e}");
            }
            _ => {}
        }
        if let Some(b) = &self.bauer_free {
            let c = &b.correlations;
            let r = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.3}"));
            let _ = writeln!(s, "  Bauer's law, e0 fitted: {}; correlations ln h_s-eta {:.3}, ln h_s-e0 {}, eta-e0 {}", b.line(), c.ln_h_s_eta, r(c.ln_h_s_e0), r(c.eta_e0));
        }
        if let Some((p, a, b)) = self.bauer_profile.as_ref().and_then(|p| Some((p, p.points.first()?, p.points.last()?))) {
            let law = p.power_law.map_or(String::new(), |l| format!("; along it {} (Oquendo et al.'s sweep: {})", l.line(), crate::analysis::oquendo::POWER_LAW.line()));
            let _ = writeln!(s, "  e0 profile: e0 {:.4} -> {:.4} moves h_s {:.3e} -> {:.3e} MPa and eta {:.3} -> {:.3}{law}", a.e0, b.e0, a.h_s / 1e6, b.h_s / 1e6, a.eta, b.eta);
        }
        let pf = self.final_state.packing_fraction.map_or("n/a".to_string(), |p| format!("{p:.4}"));
        let _ = writeln!(s, "  final: KE = {:.4e} J, packing fraction = {pf}, coordination = {:.3}", self.final_state.kinetic_energy, self.final_state.coordination_number);
        s
    }
}

/// Points below which no Bauer fit is tried.
pub const MIN_BAUER_POINTS: usize = 4;

/// Fits in the e0 profile of a run.
pub const PROFILE_POINTS: usize = 16;

/// The (pressure, void ratio) points Bauer's law is fitted to.
fn compression_data(points: &[CompressionPoint]) -> Vec<(f64, f64)> {
    points.iter().map(|c| (c.pressure, c.void_ratio)).collect()
}

/// Bauer's law through the measured pressures and void ratios, with e0 the void ratio
/// measured before loading (as the experiment measures it) when known, else fitted:
/// `Ok(None)` with too few points to try.
fn fit_compression(points: &[CompressionPoint], e0: Option<f64>) -> Result<Option<BauerFit>, String> {
    if points.len() < MIN_BAUER_POINTS {
        return Ok(None);
    }
    fit_bauer(&compression_data(points), e0, 1.0).map(Some).map_err(|e| e.to_string())
}

/// Pairs per grain assumed by the memory estimate: on the safe side of a dense packing with a
/// 10% skin (the peers' bed lists 3.74 at 4.65 contacts per grain).
pub const ESTIMATE_PAIRS_PER_GRAIN: f64 = 6.0;

/// Bytes the CPU engine holds for `scene` in reals of `real` bytes (4: f32, whose positions
/// carry a residual; 8: f64) with `pairs_per_grain` listed pairs per grain: the arrays
/// `CpuEngine::memory_bytes` counts, but the cell starts and the wall contacts of a step (a
/// few bytes a grain).
pub(crate) fn engine_bytes(scene: &Scene, real: usize, pairs_per_grain: f64) -> f64 {
    let model = scene.model.cast::<f64>();
    let stride = model.history_layout().reals();
    let capillary = matches!(model.cohesion, CohesionLaw::Capillary { .. });
    let owner_force = matches!(model.tangential, TangentialLaw::Oquendo(_));
    let some = |yes: bool, bytes: usize| if yes { bytes } else { 0 };
    // Reals: body 9, properties 3, load 6, the position's residual 3 (f32), the orientation
    // 4, the liquid 1. The position at the last build, 3 f32. Then the id, the pair and
    // reverse list starts (u32 each; the slot of each id is found when wanted, kept only by
    // the processes of a run over MPI), the material index where there are several, the
    // periodic image counts (one per wrapping axis, two bytes each until one reaches 2^14),
    // the wall springs' candidate bit and run start where there are walls
    // (`cpu::wall_springs`). The cell list lives for a rebuild alone.
    let walls = !scene.walls.is_empty();
    let per_grain = ((18 + some(real == 4, 3) + some(scene.track_orientation, 4) + some(capillary, 1)) * real + 3 * 4 + 3 * 4 + some(scene.materials.len() > 1, 4) + 2 * scene.periodic.iter().filter(|p| p.is_some()).count()) as f64 + if walls { (1.0 + 4.0) / 64.0 } else { 0.0 };
    // The partner and the reverse index (u32), the history, the partner's share 6 and the
    // normal force 1 reals, the capillary force, the owner's force (Oquendo et al.'s law), the flags.
    let per_pair = 8 + (stride + 7 + some(capillary, 1) + some(owner_force, 3)) * real + 1;
    // One history block per wall (a mesh's slots) for each grain a wall can reach
    // (`cpu::wall_springs`), as placed.
    let per_candidate: usize = scene.walls.iter().map(|w| if matches!(w.shape, WallShape::Mesh { .. }) { crate::mesh::slots::mesh_reals(stride) } else { stride }).sum();
    let wall_springs = wall_candidates(scene) * per_candidate * real;
    scene.grains.len() as f64 * (per_grain + pairs_per_grain * per_pair as f64) + wall_springs as f64
}

/// The grains nearer than their radius plus the skin to a wall, as placed: those whose wall
/// springs the CPU engine keeps.
fn wall_candidates(scene: &Scene) -> usize {
    let walls: Vec<WallGeom<f64>> = scene.walls.iter().map(|w| WallGeom::of(&w.shape)).collect();
    let meshes = scene.mesh_surfaces::<f64>();
    let g = &scene.grains;
    g.position.iter().zip(&g.radius).filter(|&(x, &r)| WallGeom::any_within(&walls, &meshes, Vec3::of(*x), r + scene.skin)).count()
}

/// The `grains check` report.
pub fn check_report(scene: &Scene) -> String {
    let g = &scene.grains;
    let mut s = String::new();
    let stat = |v: &[f64]| {
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (min, v.iter().sum::<f64>() / v.len() as f64, max)
    };
    let (rmin, rmean, rmax) = stat(&g.radius);
    let (mmin, mmean, mmax) = stat(&g.mass);
    let ts = &scene.time_step;
    let _ = writeln!(s, "scene: {} ({})", scene.name, scene.path.display());
    if !scene.description.is_empty() {
        let _ = writeln!(s, "  {}", scene.description);
    }
    let waiting: usize = scene.inlets.iter().map(|i| i.grains.len()).sum();
    let _ = writeln!(s, "grains: {}{}", g.len(), if waiting > 0 { format!(" ({waiting} of them waiting at inlets)") } else { String::new() });
    for (i, m) in scene.materials.iter().enumerate() {
        let count = g.material.iter().filter(|&&x| x as usize == i).count();
        let _ = writeln!(s, "  material {:<10} {count} grains, E = {:e} Pa, nu = {}, mu_s = {}, mu_k = {}", m.name, m.constants.youngs_modulus, m.constants.poisson_ratio, m.constants.mu_s, m.constants.mu_k);
    }
    let _ = writeln!(s, "radius (m): min {rmin:.4e}, mean {rmean:.4e}, max {rmax:.4e}");
    let _ = writeln!(s, "mass (kg): min {mmin:.4e}, mean {mmean:.4e}, max {mmax:.4e}, total {:.4e}", g.mass.iter().sum::<f64>());
    for w in &scene.walls {
        match &w.shape {
            WallShape::Mesh { mesh, .. } => {
                let (lo, hi) = mesh.bounds();
                let _ = writeln!(s, "wall {}: mesh {} ({} triangles, {} corners, from {:?} to {:?} m)", w.name, mesh.file.display(), mesh.triangles.len(), mesh.vertices.len(), lo.to_array(), hi.to_array());
            }
            shape => {
                let _ = writeln!(s, "wall {}: {shape:?}", w.name);
            }
        }
    }
    for i in &scene.inlets {
        let mass: f64 = i.grains.clone().map(|k| g.mass[k as usize]).sum();
        let every = i.every as f64 * ts.dt;
        let _ = writeln!(s, "inlet {}: {} grains ({mass:.4e} kg) at {:e} kg/s into {:?} every {every:.4e} s from {:.4e} s", i.name, i.grains.len(), i.mass_rate, i.region, i.start_step as f64 * ts.dt);
    }
    for o in &scene.outlets {
        let _ = writeln!(s, "outlet {}: takes the grains in {:?} every {:.4e} s", o.name, o.region, o.every as f64 * ts.dt);
    }
    match scene.method {
        crate::scene::Method::Dem => {
            let _ = writeln!(s, "model: {}", scene.model.describe());
            if matches!(scene.model.damping, crate::model::DampingLaw::Restitution) {
                // The pairs of materials that meet: a grain's with a grain's or a wall's.
                let of_grains = |m: usize| g.material.iter().any(|&x| x as usize == m);
                let of_walls = |m: usize| scene.walls.iter().any(|w| w.material as usize == m);
                let coeffs = scene.pair_coeffs::<f64>();
                let n = scene.materials.len();
                for (i, a) in scene.materials.iter().enumerate().filter(|(i, _)| of_grains(*i)) {
                    for (j, b) in scene.materials.iter().enumerate().filter(|(j, _)| (*j >= i && of_grains(*j)) || (of_walls(*j) && !of_grains(*j))) {
                        let beta = coeffs[i * n + j].beta;
                        let e = scene.mixed(i, j).restitution;
                        let _ = writeln!(s, "  restitution {} on {}: e = {e}, dashpot ratio beta = {beta:.4} (sized for this normal law and clamp)", a.name, b.name);
                    }
                }
            }
            let _ = writeln!(s, "integrator: {}", scene.integrator.name());
        }
        crate::scene::Method::ContactDynamics(p) => {
            let _ = writeln!(
                s,
                "method: contact dynamics (rigid grains, Moreau-Jean, nonsmooth Gauss-Seidel): theta = {}, tolerance = {:e}, at most {} sweeps per step, gap allowance {:.4e} m; friction mu_s and restitution of the materials",
                p.theta, p.tolerance, p.max_iterations, p.gap_allowance
            );
        }
    }
    if matches!(scene.method, crate::scene::Method::ContactDynamics(_)) {
        // Rigid grains have no contact time and no neighbour list to keep.
        let _ = writeln!(s, "dt = {:.4e} s (given; rigid grains: no contact time bounds it), stats every {} steps", ts.dt, scene.stats_interval);
    } else {
        let _ = writeln!(s, "Rayleigh time t_R = {:.4e} s", ts.times.rayleigh);
        let _ = writeln!(s, "Hertz time t_c = {:.4e} s at {:.3e} m/s", ts.times.collision, ts.times.expected_speed);
        let _ = writeln!(s, "dt = {:.4e} s ({}; {:.3} t_R, t_c/{:.1})", ts.dt, if ts.auto { "auto" } else { "given" }, ts.dt / ts.times.rayleigh, ts.times.collision / ts.dt);
        let _ = writeln!(s, "skin = {:.4e} m, stats every {} steps, neighbour capacity {}", scene.skin, scene.stats_interval, scene.max_neighbours);
    }
    for st in &scene.stages {
        let changes: String = st.presence.iter().map(|&(w, present)| format!(", {} {}", if present { "adds" } else { "removes" }, scene.walls[w].name)).collect();
        let _ = writeln!(s, "stage {}: {:?} for at most {:e} s ({} steps){changes}", st.name, st.kind, st.duration, st.max_steps(ts.dt));
    }
    let mib = |b: f64| b / (1024.0 * 1024.0);
    let _ = writeln!(s, "memory estimate (cpu, {ESTIMATE_PAIRS_PER_GRAIN} pairs/grain): {:.1} MiB in f64, {:.1} MiB in f32", mib(engine_bytes(scene, 8, ESTIMATE_PAIRS_PER_GRAIN)), mib(engine_bytes(scene, 4, ESTIMATE_PAIRS_PER_GRAIN)));
    for w in &scene.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::CpuEngine;
    use crate::real::Real;

    /// The estimate within this of the bytes the engine holds (what it leaves out: the step's
    /// wall contacts, a few bytes of several hundred a grain).
    const ESTIMATE_TOLERANCE: f64 = 0.02;

    /// `grains check`'s memory estimate, given the pairs per grain the engine listed, against
    /// the bytes the engine holds, in f64 and f32, for the peers' bed (periodic, a floor, one
    /// material) and a wet box (six servo walls, two materials, bridges).
    #[test]
    fn the_memory_estimate_follows_the_engine() {
        fn check<T: Real>(name: &str, real: usize) {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name);
            let mut scene = crate::scene::load(&path).unwrap();
            // Grown 10% where they were placed: a dense gas, pairs listed near packing's count.
            scene.grains.radius.iter_mut().for_each(|r| *r *= 1.1);
            let mut e = CpuEngine::<T>::new(&scene).unwrap();
            e.advance(1).unwrap();
            let pairs = e.stats().unwrap().pairs as f64 / scene.grains.len() as f64;
            let (held, estimate) = (e.memory_bytes() as f64, engine_bytes(&scene, real, pairs));
            println!("{name} {}: {pairs:.2} pairs/grain, {:.0} B/grain held, {:.0} estimated", T::NAME, held / scene.grains.len() as f64, estimate / scene.grains.len() as f64);
            assert!((estimate / held - 1.0).abs() < ESTIMATE_TOLERANCE, "{name} {}: estimate {estimate} B against {held} B held", T::NAME);
        }
        for name in ["bench_bed.toml", "wet_iso_100pa.toml"] {
            check::<f64>(name, 8);
            check::<f32>(name, 4);
        }
    }
}
