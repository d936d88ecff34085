//! The GPU engine on whatever adapter there is (lavapipe in CI): kernels against their CPU
//! twins on seeded random inputs, every shipped scene against the CPU in f32, the core physics
//! tests again, and bitwise reproducibility run to run. Without an adapter these tests skip
//! with a message, except under CI, where they fail.

mod common;

use grains::compare::largest_component_difference;
use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::schedule::{Op, Schedule};
use grains::scene::{Integrator, Scene};

/// GPU and CPU f32 loads: the largest difference over the mean contact force. Both compute in
/// f32 from the same inputs; the GPU may fuse multiply-adds, so they differ by a few ulps of
/// the largest terms.
const F32_LOAD_TOLERANCE: f64 = 1e-4;
/// GPU and CPU f32 positions after a few hundred steps, over the mean diameter.
const F32_POSITION_TOLERANCE: f64 = 1e-5;
/// Relative difference of the statistics both engines reduce (kinetic, elastic energy...).
const F32_STATS_TOLERANCE: f64 = 1e-4;
/// f32 momentum drift relative to the sum of |p| over a few thousand steps.
const F32_MOMENTUM_ROUNDOFF: f64 = 1e-5;

/// A dense, frictional, colliding gas with walls and orientation: every kernel has work.
fn gas(periodic: bool) -> Scene {
    gas_with(periodic, "mu_k = 0.4\nrolling_angle = 3.0\ngamma_n = 1.0e5\ngamma_nt = 10.0", "damping = \"papers\"\ntangential = \"oquendo\"\ntwisting = \"oquendo\"")
}

/// The gas of [`gas`] with `material` added to its sand's keys (after `mu_s = 0.5`) and `model`
/// as its `[model]` table.
fn gas_with(periodic: bool, material: &str, model: &str) -> Scene {
    let grains = "count = 1500\ndiameter = { min = 0.8e-3, max = 1.2e-3 }\n";
    gas_of(periodic, material, model, 16.0e-3, &[grains])
}

/// A gas of [`gas_with`]'s kind in a cube of `edge` (m) whose grains are one `[[generate]]`
/// block per entry of `grains` (its count and diameters; the region is the cube).
fn gas_of(periodic: bool, material: &str, model: &str, edge: f64, grains: &[&str]) -> Scene {
    let walls = if periodic {
        format!("[periodic]\nx = [0.0, {edge}]\ny = [0.0, {edge}]\n[[wall]]\ntype = \"plane\"\nmaterial = \"sand\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n")
    } else {
        format!("[[wall]]\ntype = \"box\"\nmaterial = \"sand\"\nmin = [0.0, 0.0, 0.0]\nmax = [{edge}, {edge}, {edge}]\n")
    };
    let generate: String = grains
        .iter()
        .map(|g| format!("[[generate]]\nmaterial = \"sand\"\n{g}region = {{ shape = \"box\", min = [0.0, 0.0, 0.0], max = [{edge}, {edge}, {edge}] }}\nrandom_speed = 0.5\n"))
        .collect();
    common::parse(&format!(
        concat!(r#"
seed = 4
"#, include_str!("fixtures/sand.toml"), r#"mu_s = 0.5
{material}
{generate}{walls}
[model]
{model}
[simulation]
track_orientation = true
skin = 3.0e-4
[[stage]]
kind = "run"
duration = 1.0e-3
"#), material = material, generate = generate, walls = walls, model = model
    ))
}

fn mean_contact_force(e: &mut CpuEngine<f32>) -> f64 {
    let frame = e.frame(true).unwrap();
    let c = frame.contacts.unwrap();
    c.iter().map(|r| r.normal_force).sum::<f64>() / c.len().max(1) as f64
}

/// Checks that the springs of every evaluation in `ops` advance by the drifts since the one
/// before it (or since the start), as the CPU once counted them in the engine.
fn assert_elapsed_is_the_drifted_time(ops: &[Op], what: &str) {
    let mut since = 0.0;
    for op in ops {
        match *op {
            Op::Drift { tau } => since += tau,
            Op::Forces { elapsed } => {
                assert!((elapsed - since).abs() <= 1e-12 * since.max(1e-30), "{what}: an evaluation advances the springs by {elapsed:e} s after {since:e} s of drift");
                since = 0.0;
            }
            _ => {}
        }
    }
}

/// The CPU engine runs, and the GPU engine encodes, the operations of one schedule: for each
/// integrator, with and without statistics read before the first step, both walk the
/// schedule's prologue (where loads are needed), first step and later steps, and the springs
/// advance by exactly the time drifted between evaluations.
#[test]
fn both_engines_walk_the_schedule_of_each_integrator() {
    for integrator in [Integrator::VelocityVerlet, Integrator::OptimizedVerlet] {
        for stats_first in [false, true] {
            let mut scene = gas(false);
            scene.integrator = integrator;
            let schedule = Schedule::new(integrator, scene.time_step.dt);
            let mut expected = Vec::new();
            if stats_first || schedule.needs_loads {
                expected.extend(&schedule.prologue);
            }
            expected.extend(&schedule.first);
            expected.extend(&schedule.step);
            expected.extend(&schedule.step);
            let what = format!("{integrator:?}, statistics first: {stats_first}");
            let walk = |e: &mut dyn Engine| {
                if stats_first {
                    e.stats().unwrap();
                }
                e.advance(3).unwrap();
            };
            let mut c: CpuEngine<f32> = common::engine(&scene);
            c.trace_schedule();
            walk(&mut c);
            assert_eq!(c.traced(), &expected[..], "{what}: the CPU's operations");
            assert_elapsed_is_the_drifted_time(c.traced(), &what);
            let Some(mut g) = common::gpu_engine(&scene) else { return };
            g.trace_schedule();
            walk(&mut g);
            println!("{what}: {} operations walked by both engines", g.traced().len());
            assert_eq!(g.traced(), c.traced(), "{what}: the GPU's operations");
        }
    }
}

/// The GPU's neighbour search lists the CPU's pairs, in the same order: grains of one size,
/// a few grains ten times the others' diameter among them, and diameters spread over a factor
/// of ten (a grid per size class on both backends), each with and without periodic axes.
#[test]
fn hash_cells_and_detect_pairs_list_the_cpus_pairs() {
    let balls = ["count = 6\ndiameter = { min = 8.0e-3, max = 8.0e-3 }\n", "count = 6000\ndiameter = { min = 0.8e-3, max = 0.8e-3 }\n"];
    let spread = ["count = 300\ndiameter = { min = 0.4e-3, max = 4.0e-3 }\n"];
    for periodic in [false, true] {
        let cases = [("one size", gas(periodic)), ("balls among grains", gas_of(periodic, "", "", 24.0e-3, &balls)), ("ratio-10 spread", gas_of(periodic, "", "", 24.0e-3, &spread))];
        for (name, scene) in cases {
            let Some(mut g) = common::gpu_engine(&scene) else { return };
            let mut c: CpuEngine<f32> = common::engine(&scene);
            g.stats().unwrap();
            c.stats().unwrap();
            g.advance(50).unwrap();
            c.advance(50).unwrap();
            let (starts, partners) = g.pair_list().unwrap();
            // The GPU does not renumber its grains: its slots are the permanent ids.
            let (c_starts, c_partners) = c.pair_list();
            println!("{name}, periodic {periodic}: {} pairs on the GPU, {} on the CPU", partners.len(), c_partners.len());
            assert!(c_partners.len() > scene.grains.len() / 3, "{name}: {} pairs", c_partners.len());
            assert_eq!(starts, c_starts, "{name}, periodic {periodic}: pair starts per grain");
            assert_eq!(partners, c_partners, "{name}, periodic {periodic}: partners");
        }
    }
}

#[test]
fn pair_force_wall_contacts_and_gather_match_the_cpu_twins() {
    for periodic in [false, true] {
        let scene = gas(periodic);
        let Some(mut g) = common::gpu_engine(&scene) else { return };
        let mut c: CpuEngine<f32> = common::engine(&scene);
        g.advance(100).unwrap();
        c.advance(100).unwrap();
        let scale = mean_contact_force(&mut c);
        let gl = g.loads().unwrap();
        let cl = c.loads();
        let mut worst: f64 = 0.0;
        for (a, b) in gl.iter().zip(cl) {
            for k in 0..3 {
                worst = worst.max((a.0[k] as f64 - b.force.f64()[k]).abs());
            }
        }
        println!("periodic {periodic}: largest load difference {worst:.3e} N, mean contact force {scale:.3e} N");
        assert!(scale > 0.0);
        assert!(worst < F32_LOAD_TOLERANCE * scale);
        // Oquendo et al.'s regimes, contact by contact through the sliding flag and the rolling
        // spring, counted alike.
        let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
        println!("periodic {periodic}: gpu {} sliding, {} rolling; cpu {} sliding, {} rolling", sg.sliding, sg.rolling, sc.sliding, sc.rolling);
        assert!(sc.sliding > 0 && sc.rolling > 0, "the gas slides and rolls");
        assert_eq!((sg.sliding, sg.rolling), (sc.sliding, sc.rolling), "contacts per regime");
        // What the gather leaves for the statistics beside each load (the pairs that push it,
        // its wall contacts' regimes, its wall force): the rattlers and the unbalanced force,
        // whose mean contact force counts the walls' contacts.
        println!(
            "periodic {periodic}: wall contacts gpu {} cpu {}, rattlers {} / {}, unbalanced force {:.6e} / {:.6e}, loaded grains {:.6e} / {:.6e}",
            sg.wall_contacts, sc.wall_contacts, sg.rattlers, sc.rattlers, sg.unbalanced_force, sc.unbalanced_force, sg.unbalanced_force_loaded, sc.unbalanced_force_loaded
        );
        assert!(periodic || sc.wall_contacts > 0, "the walls hold grains");
        assert_eq!((sg.wall_contacts, sg.rattlers), (sc.wall_contacts, sc.rattlers));
        for (a, b) in [(sg.unbalanced_force, sc.unbalanced_force), (sg.unbalanced_force_loaded, sc.unbalanced_force_loaded)] {
            assert!((a - b).abs() <= F32_STATS_TOLERANCE * b.abs(), "unbalanced force: gpu {a:e} cpu {b:e}");
        }
    }
}

#[test]
fn integrate_and_the_reductions_match_the_cpu_twins() {
    let scene = gas(false);
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let mut c: CpuEngine<f32> = common::engine(&scene);
    g.advance(20).unwrap();
    c.advance(20).unwrap();
    let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
    let d_mean = 1.0e-3;
    let worst = largest_component_difference(&fg.position, &fc.position);
    let worst_q = fg.orientation.as_ref().unwrap().iter().zip(fc.orientation.as_ref().unwrap()).map(|(a, b)| (*a - *b).to_array().iter().map(|d| d.abs()).fold(0.0, f64::max)).fold(0.0, f64::max);
    println!("after 20 steps: positions differ by {:.3e} of a diameter, quaternions by {worst_q:.3e}", worst / d_mean);
    assert!(worst / d_mean < F32_POSITION_TOLERANCE);
    assert!(worst_q < F32_POSITION_TOLERANCE);
    let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
    for (name, a, b) in [
        ("kinetic", sg.kinetic_energy(), sc.kinetic_energy()),
        ("elastic", sg.elastic_energy, sc.elastic_energy),
        ("gravity", sg.gravity_energy, sc.gravity_energy),
    ] {
        println!("{name}: gpu {a:.6e} cpu {b:.6e}");
        assert!((a - b).abs() <= F32_STATS_TOLERANCE * b.abs().max(1e-30), "{name}");
    }
    assert_eq!((sg.contacts, sg.wall_contacts, sg.rebuilds), (sc.contacts, sc.wall_contacts, sc.rebuilds));
    assert_eq!((sg.sliding, sg.rolling), (sc.sliding, sc.rolling), "contacts per regime");
    assert_eq!(sg.max_overlap_grain, sc.max_overlap_grain);
    for (a, b) in sg.walls.iter().zip(&sc.walls) {
        assert_eq!(a.contacts, b.contacts, "{}: contacts (u32 on the GPU)", a.name);
        for k in 0..3 {
            assert!((a.force[k] - b.force[k]).abs() <= F32_LOAD_TOLERANCE * (sc.walls.iter().map(|w| w.force[2].abs()).fold(1e-9, f64::max)), "{}", a.name);
        }
    }
}

#[test]
fn every_shipped_scene_agrees_with_the_cpu_for_300_steps() {
    for name in [
        "quickstart.toml",
        "two_spheres.toml",
        "sphere_on_plane.toml",
        "elastic_gas.toml",
        "pour.toml",
        "oedometer.toml",
        "oedometer_1200.toml",
        "oedometer_5000.toml",
        "dry_iso_100pa.toml",
        "dry_triaxial.toml",
        "wet_iso_0pa.toml",
        "wet_iso_0pa_wetted_loose.toml",
        "wet_iso_100pa.toml",
        "wet_iso_100pa_wetted_loose.toml",
    ] {
        let scene = common::shipped(name);
        let Some(mut g) = common::gpu_engine(&scene) else { return };
        let mut c: CpuEngine<f32> = common::engine(&scene);
        g.advance(300).unwrap();
        c.advance(300).unwrap();
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        let d_mean = 2.0 * scene.grains.radius.iter().sum::<f64>() / scene.grains.len() as f64;
        let worst = largest_component_difference(&fg.position, &fc.position);
        let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
        println!("{name}: positions differ by {:.2e} of a diameter; KE gpu {:.6e} cpu {:.6e}", worst / d_mean, sg.kinetic_energy(), sc.kinetic_energy());
        assert!(worst / d_mean < F32_POSITION_TOLERANCE, "{name}");
        assert!((sg.kinetic_energy() - sc.kinetic_energy()).abs() <= F32_STATS_TOLERANCE * sc.kinetic_energy(), "{name}");
    }
}

/// A dense colliding gas under the restitution dashpot with Hertz-Mindlin friction, clamped
/// and pulling (`limit_damping`), GPU against the CPU f32 twin for 300 steps: the clamp's
/// override, the friction limit's magnitude and the springs counted from the touch, contact
/// by contact (the clamped counts equal, none unclamped).
#[test]
fn the_no_pull_clamp_and_its_absence_run_on_the_gpu_as_on_the_cpu() {
    for clamp in [true, false] {
        let scene = gas_with(false, "restitution = 0.3", &format!("damping = \"restitution\"\nlimit_damping = {clamp}\ntangential = \"mindlin\"\ntangential_damping_ratio = 0.9"));
        let Some(mut g) = common::gpu_engine(&scene) else { return };
        let mut c: CpuEngine<f32> = common::engine(&scene);
        g.advance(300).unwrap();
        c.advance(300).unwrap();
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        let worst = largest_component_difference(&fg.position, &fc.position);
        let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
        println!("clamp {clamp}: positions differ by {:.2e} of a diameter; contacts {} / {}, clamped {} / {}, sliding {} / {}", worst / 1.0e-3, sg.contacts, sc.contacts, sg.clamped, sc.clamped, sg.sliding, sc.sliding);
        assert!(worst / 1.0e-3 < F32_POSITION_TOLERANCE, "clamp {clamp}");
        assert!(sc.contacts > 0 && sc.sliding > 0, "the gas collides and slides");
        assert_eq!((sg.contacts, sg.clamped, sg.sliding), (sc.contacts, sc.clamped, sc.sliding), "clamp {clamp}");
        assert_eq!(sc.clamped == 0, !clamp, "clamped contacts exist with the clamp only");
    }
}

/// The oedometer's piston under a target pressure, GPU against the CPU f32 twin: it is kicked
/// and drifted in the dispatches after the grains' (its kicks wait for the walls' sums, and a
/// run of steps carries each step's first kick and drift into the step before's), with the
/// same operations in the same order. On a software adapter its height and speed stay bitwise
/// equal; on a hardware GPU within f32 round-off.
#[test]
fn the_piston_moves_on_the_gpu_as_on_the_cpu() {
    let scene = common::shipped("oedometer.toml");
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let mut c: CpuEngine<f32> = common::engine(&scene);
    let d_mean = 2.0 * scene.grains.radius.iter().sum::<f64>() / scene.grains.len() as f64;
    let exact = g.adapter().device_type == wgpu::DeviceType::Cpu;
    g.set_piston_pressure(1.0e3);
    c.set_piston_pressure(1.0e3);
    for _ in 0..3 {
        g.advance(200).unwrap();
        c.advance(200).unwrap();
        let (pg, pc) = (g.stats().unwrap().piston.unwrap(), c.stats().unwrap().piston.unwrap());
        println!("piston z gpu {:.9e} cpu {:.9e} m, velocity gpu {:.9e} cpu {:.9e} m/s", pg.z, pc.z, pg.velocity, pc.velocity);
        assert!(pc.velocity < 0.0, "the piston falls");
        if exact {
            assert_eq!((pg.z, pg.velocity), (pc.z, pc.velocity));
        } else {
            assert!((pg.z - pc.z).abs() <= F32_POSITION_TOLERANCE * d_mean, "piston height");
            assert!((pg.velocity - pc.velocity).abs() <= F32_STATS_TOLERANCE * pc.velocity.abs(), "piston velocity");
        }
    }
}

/// Servo wall pressures, GPU against CPU f32, relative, on a hardware GPU. Both add each
/// wall's reaction and contact stiffness in the GPU's workgroup order (`grains::workgroup`),
/// but a hardware GPU fuses multiply-adds, so a pressure-controlled wall's speed differs by
/// ulps and its position by about 1e-6 of a diameter after a thousand steps; at the lightly
/// loaded start of a compaction a wall's few contacts overlap by about 1e-4 of a diameter, and
/// Hertz forces grow as h^1.5, so that moves the pressure by some 0.1-1%.
const SERVO_PRESSURE_TOLERANCE: f64 = 1e-2;

/// Servo walls on the GPU against the CPU f32 twin: 300 grains compacted by six servo planes
/// (the walls first close at full speed, then feel the grains), then a triaxial leg with the
/// z planes at a fixed strain rate. On a software adapter (lavapipe), which runs the twin's
/// arithmetic, the walls stay bitwise equal through both legs; on a hardware GPU positions
/// agree to f32 round-off of the sums they follow. The walls' work and the kinetic energy
/// agree to the statistics tolerance (the host reads them in f64 from each engine's f32).
#[test]
fn servo_walls_on_the_gpu_follow_the_cpu_twin() {
    let scene = common::parse(&common::edit(
        &std::fs::read_to_string(common::scene_path("dry_iso_100pa.toml")).unwrap(),
        // Richefeu et al.'s isotropic compaction with its density of grains, 300 of them.
        &[("count = 8000", "count = 300"), ("max = [28.0e-3, 28.0e-3, 28.0e-3]", "max = [9.4e-3, 9.4e-3, 9.4e-3]")],
    ));
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let mut c: CpuEngine<f32> = common::engine(&scene);
    let d_mean = 2.0 * scene.grains.radius.iter().sum::<f64>() / scene.grains.len() as f64;
    let wall_tolerance = if g.adapter().device_type == wgpu::DeviceType::Cpu { 0.0 } else { F32_POSITION_TOLERANCE };
    let compare = |g: &mut grains::gpu::GpuEngine, c: &mut CpuEngine<f32>, leg: &str| {
        let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
        let (mut worst, mut worst_p): (f64, f64) = (0.0, 0.0);
        for (a, b) in sg.walls.iter().zip(&sc.walls).filter(|(a, _)| a.position.is_some()) {
            worst = worst.max((a.position.unwrap() - b.position.unwrap()).abs());
            let (pa, pb) = (a.pressure.unwrap(), b.pressure.unwrap());
            worst_p = worst_p.max((pa - pb).abs() / pb.abs().max(1.0));
        }
        println!(
            "{leg}: walls differ by {:.2e} of a diameter, their pressures by {worst_p:.2e}; {} / {} contacts; work gpu {:.6e} cpu {:.6e} J; KE gpu {:.6e} cpu {:.6e}",
            worst / d_mean, sg.wall_contacts, sc.wall_contacts, sg.external_work, sc.external_work, sg.kinetic_energy(), sc.kinetic_energy()
        );
        assert!(sc.wall_contacts > 0, "{leg}: the walls reached the grains");
        assert!(worst / d_mean <= wall_tolerance, "{leg}: wall positions");
        assert!(worst_p < SERVO_PRESSURE_TOLERANCE, "{leg}: wall pressures");
        assert!((sg.external_work - sc.external_work).abs() <= F32_STATS_TOLERANCE * sc.external_work.abs(), "{leg}: the walls' work");
        assert!((sg.kinetic_energy() - sc.kinetic_energy()).abs() <= F32_STATS_TOLERANCE * sc.kinetic_energy(), "{leg}: kinetic energy");
        // The frames (what the VTK files draw) hold each servo plane where the statistics put it.
        for (e, stats) in [(&*g as &dyn Engine, &sg), (&*c, &sc)] {
            let frame = e.frame(false).unwrap();
            for (w, s) in frame.walls.iter().zip(&stats.walls) {
                let (grains::walls::WallGeom::Plane { point, normal }, Some(at)) = (w, s.position) else { continue };
                let along = point.x * normal.x.abs() + point.y * normal.y.abs() + point.z * normal.z.abs();
                assert_eq!(along, at, "{leg}: {} in the {} frame", s.name, e.backend());
            }
        }
    };
    for e in [&mut g as &mut dyn Engine, &mut c] {
        e.set_servo(Some(100.0), None);
        e.advance(3000).unwrap();
    }
    compare(&mut g, &mut c, "isotropic");
    for e in [&mut g as &mut dyn Engine, &mut c] {
        e.set_servo(None, Some(0.5));
        e.advance(1000).unwrap();
    }
    compare(&mut g, &mut c, "triaxial");
}

/// Liquid bridges on the GPU against the CPU f32 twin: the wet gas's bridges break and form
/// as its grains collide; at every statistics read both engines hold the same number of
/// bridges, and the liquid in bridges and on grains adds up to what was poured to f32
/// round-off. (The capillary law's pow and exp are the GPU's own, so the two differ by ulps:
/// positions are compared with the f32 tolerance.)
#[test]
fn liquid_bridges_on_the_gpu_form_and_break_as_on_the_cpu() {
    bridges_follow_the_cpu(&common::wet_gas());
}

/// The same with rolling springs too, so that each pair holds three history blocks (tangential
/// with the normal velocity in w, rolling, bridge) and every one of them, the bridge's last,
/// must survive the rebuilds (the replaced list's blocks sit in three different record buffers
/// meanwhile).
#[test]
fn three_history_blocks_survive_rebuilds_on_the_gpu() {
    let mut scene = common::wet_gas();
    scene.model.rolling = grains::model::RollingLaw::Sds { k_r: 50.0, gamma_r: 0.0, mu_r: 0.05 };
    assert_eq!(scene.model.history_layout(), grains::model::HistoryLayout { tangential: true, normal: true, sliding: false, rolling: true, bridge: true });
    bridges_follow_the_cpu(&scene);
}

/// Runs a wet gas on the GPU and the CPU f32 twin for 2000 steps and checks the bridges, the
/// liquid and the positions at every statistics read (see
/// `liquid_bridges_on_the_gpu_form_and_break_as_on_the_cpu`).
fn bridges_follow_the_cpu(scene: &grains::scene::Scene) {
    /// Liquid conserved in f32: a bridge's volume and a grain's halves round (6e-8) at each
    /// transfer, and transfers are few.
    const LIQUID_F32_ROUNDOFF: f64 = 1e-7;
    /// Positions after 2000 steps of a colliding gas whose capillary forces differ by ulps
    /// (each backend's own pow and exp): collisions amplify the difference.
    const CAPILLARY_POSITION_TOLERANCE: f64 = 1e-4;
    let Some(mut g) = common::gpu_engine(scene) else { return };
    let mut c: CpuEngine<f32> = common::engine(scene);
    let total = scene.stages[0].wet_volume.unwrap();
    g.wet(total).unwrap();
    c.wet(total).unwrap();
    let d_mean = 2.0 * scene.grains.radius.iter().sum::<f64>() / scene.grains.len() as f64;
    let (mut changes, mut last, mut worst_liquid, mut worst_x) = (0u64, g.stats().unwrap().bridges, 0.0f64, 0.0f64);
    for read in 0..20 {
        g.advance(100).unwrap();
        c.advance(100).unwrap();
        let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
        assert_eq!(sg.bridges, sc.bridges, "bridges at read {read}");
        changes += sg.bridges.abs_diff(last);
        last = sg.bridges;
        worst_liquid = worst_liquid.max(((sg.liquid_in_bridges + sg.liquid_on_grains) / total - 1.0).abs());
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        worst_x = worst_x.max(largest_component_difference(&fg.position, &fc.position));
    }
    println!("{last} bridges at the end, {changes} net changes seen; liquid conserved to {worst_liquid:.2e}; positions differ by {:.2e} of a diameter", worst_x / d_mean);
    assert!(changes > 5, "bridges must break and form");
    assert!(worst_liquid < LIQUID_F32_ROUNDOFF);
    assert!(worst_x / d_mean < CAPILLARY_POSITION_TOLERANCE);
}

/// Richefeu et al.'s wet protocol through the host loop on both engines, in both preparations: 300
/// grains compacted by the servo box and wetted as the walls back off, or wetted loose,
/// compacted and released; then compacted again (every stage cut to 3 ms). At each stage end the GPU holds the same bridges as the CPU f32
/// twin, the same liquid, and walls and energies within the f32 tolerances.
#[test]
fn the_wet_protocol_runs_on_the_gpu_as_on_the_cpu() {
    /// Wall positions after 3000 steps of servo control and capillary forces whose pow and exp
    /// differ by ulps between the backends, over the mean diameter. The difference grows as a
    /// packing's chaos does, fastest in the last stage of the loose preparation: from 1.8e-6 to
    /// 9.2e-5 before the damped forces were taken over their windows (whose start and end tests
    /// are switches too), from 5.8e-5 to 1.0e-4 after, on lavapipe.
    const WET_WALL_TOLERANCE: f64 = 2e-4;
    for name in ["wet_iso_100pa.toml", "wet_iso_100pa_wetted_loose.toml"] {
        let scene = common::parse(&common::edit(
            &std::fs::read_to_string(common::scene_path(name)).unwrap(),
            &[("count = 8000", "count = 300"), ("max = [28.0e-3, 28.0e-3, 28.0e-3]", "max = [9.4e-3, 9.4e-3, 9.4e-3]"), ("duration = 1.0\n", "duration = 3.0e-3\n"), ("analysis = true", "analysis = false")],
        ));
        let Some(mut g) = common::gpu_engine(&scene) else { return };
        let mut c: CpuEngine<f32> = common::engine(&scene);
        let run = |e: &mut dyn Engine| grains::protocol::run(&scene, e, &mut grains::output::RunRecorder::new(None, false).unwrap()).unwrap();
        let (rg, rc) = (run(&mut g), run(&mut c));
        let d_mean = 2.0 * scene.grains.radius.iter().sum::<f64>() / scene.grains.len() as f64;
        let wetting = scene.stages.iter().position(|s| s.wet_volume.is_some()).expect("a stage wets the sample");
        let poured = scene.stages[wetting].wet_volume.unwrap();
        for (k, (a, b)) in rg.iter().zip(&rc).enumerate() {
            let (sa, sb) = (&a.stats, &b.stats);
            let walls = sa.walls.iter().zip(&sb.walls).map(|(x, y)| (x.position.unwrap() - y.position.unwrap()).abs()).fold(0.0, f64::max);
            println!(
                "{name} {}: {} / {} steps; bridges gpu {} cpu {}; liquid gpu {:.6e} cpu {:.6e} m^3; Z gpu {:.3} cpu {:.3}; walls differ by {:.2e} d; KE gpu {:.4e} cpu {:.4e}",
                a.name, a.steps, b.steps, sa.bridges, sb.bridges, sa.liquid_in_bridges + sa.liquid_on_grains, sb.liquid_in_bridges + sb.liquid_on_grains,
                sa.coordination, sb.coordination, walls / d_mean, sa.kinetic_energy(), sb.kinetic_energy()
            );
            assert_eq!(a.steps, b.steps, "{name} {}", a.name);
            assert_eq!(sa.bridges, sb.bridges, "{name} {}: bridges", a.name);
            assert!(walls / d_mean < WET_WALL_TOLERANCE, "{name} {}: walls", a.name);
            if k >= wetting {
                assert!(sa.bridges > 0, "the sample is wet");
                assert!(((sa.liquid_in_bridges + sa.liquid_on_grains) / poured - 1.0).abs() < 1e-6, "{name} {}: liquid", a.name);
            }
        }
    }
}

/// `grains compare`'s verdicts on short horizons of the scenes Oquendo et al. and Richefeu et al. (2009) run, from
/// their initial states: the 280-grain oedometer and Richefeu et al.'s servo box with 300 grains.
#[test]
fn compare_passes_on_short_horizons_of_the_papers_scenes() {
    let servo_box = common::parse(&common::edit(
        &std::fs::read_to_string(common::scene_path("dry_iso_100pa.toml")).unwrap(),
        &[("count = 8000", "count = 300"), ("max = [28.0e-3, 28.0e-3, 28.0e-3]", "max = [9.4e-3, 9.4e-3, 9.4e-3]")],
    ));
    for (name, scene) in [("oedometer.toml", common::shipped("oedometer.toml")), ("dry_iso_100pa.toml with 300 grains", servo_box)] {
        let Some(gpu) = common::gpu() else { return };
        let adapter = gpu.info.name.clone();
        let mut g = grains::gpu::GpuEngine::new(gpu, &scene).unwrap();
        let mut c32: CpuEngine<f32> = common::engine(&scene);
        let mut c64: CpuEngine<f64> = common::engine(&scene);
        let report = grains::compare::compare(&scene, &adapter, &mut g, &mut c32, &mut c64, 1000, 5).unwrap();
        println!("{name}:\n{}", report.human());
        assert!(report.passed(), "{name}");
    }
}

/// The pair records, both ways a law keeps them: Richefeu et al.'s Mindlin law (the partner's force
/// is the owner's reversed, so the pair pass stores one force and the gather subtracts it) and
/// Oquendo et al.'s (both forces stored). On a software adapter, which runs the CPU twin's
/// arithmetic, every grain's position and velocity stays bitwise equal to the CPU f32 engine's
/// through 200 steps; on any adapter the clamped, sliding and rolling contacts (the regime and
/// the clamp share a word of the record) are counted alike, and the Mindlin gas has some
/// clamped.
#[test]
fn pair_records_give_the_cpus_bits_with_one_force_or_two() {
    // The quickstart's grains set moving, so that they collide from the first steps.
    let mindlin = common::parse(&common::edit(&std::fs::read_to_string(common::scene_path("quickstart.toml")).unwrap(), &[("region = { shape", "random_speed = 2.0\nregion = { shape")]));
    for (name, scene) in [("mindlin", mindlin), ("Oquendo et al.", gas(false))] {
        assert_eq!(scene.model.keeps_both_forces(), name == "Oquendo et al.");
        let Some(mut g) = common::gpu_engine(&scene) else { return };
        let mut c: CpuEngine<f32> = common::engine(&scene);
        g.advance(200).unwrap();
        c.advance(200).unwrap();
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        let bits = |f: &grains::engine::Frame| -> Vec<u64> { f.position.iter().chain(&f.velocity).flat_map(|v| v.to_array().map(f64::to_bits)).collect() };
        let differing = bits(&fg).iter().zip(&bits(&fc)).filter(|(a, b)| a != b).count();
        let (sg, sc) = (g.stats().unwrap(), c.stats().unwrap());
        println!("{name}: {differing} position and velocity components differ; clamped gpu {} cpu {}, sliding {} / {}, rolling {} / {}", sg.clamped, sc.clamped, sg.sliding, sc.sliding, sg.rolling, sc.rolling);
        if g.adapter().device_type == wgpu::DeviceType::Cpu {
            assert_eq!(differing, 0, "{name}: bitwise on a software adapter");
        }
        assert!(sc.clamped > 0 || name != "mindlin", "{name}: some contacts are clamped");
        assert_eq!((sg.clamped, sg.sliding, sg.rolling), (sc.clamped, sc.sliding, sc.rolling), "{name}: contacts per regime");
    }
}

#[test]
fn gpu_runs_are_bitwise_reproducible() {
    let scene = gas(true);
    let run = || -> Option<Vec<u64>> {
        let mut g = common::gpu_engine(&scene)?;
        g.advance(200).unwrap();
        let f = g.frame(true).unwrap();
        let mut bits: Vec<u64> = f.position.iter().chain(&f.velocity).chain(&f.angular_velocity).flat_map(|v| v.to_array().map(f64::to_bits)).collect();
        bits.extend(f.contacts.unwrap().iter().flat_map(|c| c.force.to_array().map(f64::to_bits)));
        Some(bits)
    };
    let Some(a) = run() else { return };
    let b = run().unwrap();
    println!("{} values compared", a.len());
    assert_eq!(a, b);
}

#[test]
fn hertz_collision_on_the_gpu_matches_theory() {
    const HERTZ_TOLERANCE: f64 = 0.01;
    let mut scene = common::shipped("two_spheres.toml");
    let t_c = 7.5939e-5; // the peers' theory value (tests/hertz_collision.rs)
    scene.time_step.dt = t_c / 50.0;
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let (mut on, mut off, mut max_h) = (None, None, 0.0f64);
    while off.is_none() && g.time() < 5e-3 {
        g.advance(1).unwrap();
        let s = g.stats().unwrap();
        let h = s.max_overlap * 5.0e-4;
        if s.contacts > 0 && on.is_none() {
            on = Some(g.time());
        }
        if s.contacts == 0 && on.is_some() {
            off = Some(g.time());
        }
        max_h = max_h.max(h);
    }
    let contact = off.unwrap() - on.unwrap();
    println!("gpu: contact {contact:.5e} s (theory {t_c:.5e}, whole steps), max overlap {max_h:.5e} m (theory 2.5803e-6)");
    assert!((contact / t_c - 1.0).abs() < HERTZ_TOLERANCE + 1.0 / 50.0);
    assert!((max_h / 2.5803e-6 - 1.0).abs() < HERTZ_TOLERANCE);
}

#[test]
fn momentum_is_conserved_on_the_gpu_to_f32_round_off() {
    let text = std::fs::read_to_string(common::scene_path("elastic_gas.toml")).unwrap().replace(
        "[[wall]]\ntype = \"box\"\nmaterial = \"glass\"\nmin = [0.0, 0.0, 0.0]\nmax = [6.0e-3, 6.0e-3, 6.0e-3]",
        "[periodic]\nx = [0.0, 6.0e-3]\ny = [0.0, 6.0e-3]\nz = [0.0, 6.0e-3]",
    );
    let text = text.replace("poisson_ratio = 0.3", "poisson_ratio = 0.3\nmu_s = 0.5\nrestitution = 0.6").replace("damping = \"none\"\ntangential = \"none\"", "damping = \"restitution\"\ntangential = \"mindlin\"");
    let scene = common::parse(&text);
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let s0 = g.stats().unwrap();
    let scale: f64 = scene.grains.velocity.iter().zip(&scene.grains.mass).map(|(v, m)| m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()).sum();
    g.advance(3000).unwrap();
    let s1 = g.stats().unwrap();
    let dp = (0..3).map(|k| (s1.momentum[k] - s0.momentum[k]).powi(2)).sum::<f64>().sqrt();
    println!("gpu, 3000 steps, {} rebuilds: KE {:.3e} -> {:.3e} J, |dP| / sum|p| = {:.2e}", s1.rebuilds, s0.kinetic_energy(), s1.kinetic_energy(), dp / scale);
    assert!(s1.kinetic_energy() < s0.kinetic_energy(), "collisions must have dissipated energy");
    assert!(dp < F32_MOMENTUM_ROUNDOFF * scale);
}

#[test]
fn history_survives_a_rebuild_on_the_gpu() {
    // tests/history.rs's glancing collision, with a rebuild forced mid-contact.
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/history.rs")).unwrap();
    let scene_text = text.split("const SCENE: &str = r#\"").nth(1).unwrap().split("\"#;").next().unwrap();
    let scene = common::parse(scene_text);
    let run = |rebuild: bool| -> Option<(Vec<glam::DVec3>, glam::DVec3, u64)> {
        let mut g = common::gpu_engine(&scene)?;
        g.advance(287).unwrap();
        if rebuild {
            g.rebuild_next_step();
        }
        g.advance(5).unwrap();
        let spring = g.frame(true).unwrap().contacts.unwrap()[0].tangential_spring;
        g.advance(300).unwrap();
        let f = g.frame(false).unwrap();
        Some((f.position.iter().chain(&f.velocity).copied().collect(), spring, g.stats().unwrap().rebuilds))
    };
    let Some((plain, spring, r0)) = run(false) else { return };
    let (rebuilt, spring_rebuilt, r1) = run(true).unwrap();
    println!("spring at mid-contact {spring:?} / {spring_rebuilt:?}; rebuilds {r0} vs {r1}");
    assert_eq!(r1, r0 + 1);
    assert!(spring[1].abs() > 1e-8);
    assert_eq!(spring, spring_rebuilt);
    assert_eq!(plain, rebuilt);
}

#[test]
fn a_dense_start_with_a_wide_skin_fits_the_gpus_pair_buffers() {
    // The gas with a skin of 1.5 mean diameters lists over ten pairs per grain: the engine
    // must size the buffers to its first list before the first step, so that no rebuild
    // stops on them.
    let scene = common::parse(&common::edit(&std::fs::read_to_string(common::scene_path("quickstart.toml")).unwrap(), &[("region = { shape", "random_speed = 2.0\nregion = { shape"), ("dt = \"auto\"", "dt = \"auto\"\nskin = 1.5e-3")]));
    let Some(mut g) = common::gpu_engine(&scene) else { return };
    let mut c: CpuEngine<f32> = common::engine(&scene);
    let n = scene.grains.len() as f64;
    let listed = c.pair_list().1.len() as f64;
    println!("{:.1} pairs per grain listed, buffers for {:.1} per grain before the first step", listed / n, g.pair_capacity() as f64 / n);
    assert!(listed > 9.0 * n, "the skin must list many pairs per grain");
    assert!(g.pair_capacity() as f64 >= listed);
    assert!(g.pair_capacity() as f64 <= grains::gpu::PAIR_HEADROOM * listed + 1.0, "the buffers hold the first list with the headroom, no more");
    g.advance(100).unwrap();
    c.advance(100).unwrap();
    assert_eq!(g.pair_stops(), 0, "sized for the first list, no rebuild stops");
    let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
    let bits = |f: &grains::engine::Frame| -> Vec<u64> { f.position.iter().chain(&f.velocity).flat_map(|v| v.to_array().map(f64::to_bits)).collect() };
    let differing = bits(&fg).iter().zip(&bits(&fc)).filter(|(a, b)| a != b).count();
    let worst = fg.position.iter().zip(&fc.position).flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs())).fold(0.0, f64::max);
    println!("after 100 steps: {differing} position and velocity components differ, largest position difference {worst:.3e} m");
    if g.adapter().device_type == wgpu::DeviceType::Cpu {
        assert_eq!(differing, 0, "bitwise on a software adapter");
    }
    assert!(worst < F32_POSITION_TOLERANCE * 1e-3, "positions within f32 round-off of a 1 mm grain");
}

#[test]
fn a_pour_that_outgrows_the_pair_buffers_stops_and_goes_on_with_the_same_bits() {
    // 600 grains falling into a box under 50 g with a skin of 0.8 diameters: the list grows
    // from about 2.3 pairs per grain to over 9 within 10,000 steps. With buffers for the
    // first list's pairs exactly, the first rebuild that lists one more stops the run (inside
    // a run of steps, each carrying the next one's kick and drift) until the host has grown
    // them; with buffers for 1,024 pairs, the prologue's rebuild stops. One advance over all
    // the steps (checked every SUBMITS_PER_CHECK submissions inside), twenty advances of 500
    // (each checked at its end) and the CPU f32 twin must give the same bits.
    let quickstart = std::fs::read_to_string(common::scene_path("quickstart.toml")).unwrap();
    let scene = common::parse(&common::edit(
        &quickstart,
        &[
            ("max = [10.0e-3, 10.0e-3, 18.0e-3]", "max = [10.0e-3, 10.0e-3, 30.0e-3]"),
            ("gravity = [0.0, 0.0, -9.81]", "gravity = [0.0, 0.0, -500.0]"),
            ("dt = \"auto\"", "dt = 1.0e-6\nskin = 0.8e-3\nmax_neighbours = 64"),
        ],
    ));
    let mut c: CpuEngine<f32> = common::engine(&scene);
    let first = c.pair_list().1.len() as u64;
    let bits = |f: &grains::engine::Frame| -> Vec<u64> { f.position.iter().chain(&f.velocity).flat_map(|v| v.to_array().map(f64::to_bits)).collect() };
    let run = |pairs: u64, advances: u64| -> Option<(Vec<u64>, u64, f64, bool)> {
        let mut g = grains::gpu::GpuEngine::with_pair_capacity(common::gpu()?, &scene, Some(pairs)).unwrap_or_else(|e| panic!("{e}"));
        for _ in 0..advances {
            g.advance(10_000 / advances).unwrap();
        }
        let f = g.frame(false).unwrap();
        Some((bits(&f), g.pair_stops(), g.stats().unwrap().time, g.adapter().device_type == wgpu::DeviceType::Cpu))
    };
    let Some((once, stops, time, software)) = run(first, 1) else { return };
    let (chunked, chunked_stops, _, _) = run(first, 20).unwrap();
    let (small, small_stops, _, _) = run(1024, 1).unwrap();
    c.advance(10_000).unwrap();
    let n = scene.grains.len() as f64;
    println!("pairs per grain: {:.2} at the start, {:.2} at the end; rebuilds stopped on full buffers: {stops} in one advance, {chunked_stops} in twenty, {small_stops} from 1,024 pairs", first as f64 / n, c.pair_list().1.len() as f64 / n);
    assert!(first as f64 > 1024.0 * 1.2, "the first list must outgrow 1,024 pairs");
    assert!(stops > 0 && chunked_stops > 0 && small_stops > 0, "rebuilds must have stopped on full buffers");
    assert_eq!(once, chunked, "one advance and twenty give the same bits");
    assert_eq!(once, small, "buffers that start smaller give the same bits");
    assert_eq!(time, (0..10_000).fold(0.0, |t, _| t + scene.time_step.dt), "the clock counts every step once, stops and all");
    let twin = bits(&c.frame(false).unwrap());
    let differing = once.iter().zip(&twin).filter(|(a, b)| a != b).count();
    println!("against the CPU f32 twin: {differing} of {} position and velocity components differ", twin.len());
    if software {
        assert_eq!(differing, 0, "bitwise on a software adapter");
    }
}

#[test]
fn rebuilds_that_stop_on_full_pair_buffers_keep_each_scenes_bits() {
    // Runs that start with buffers for 16 pairs (every rebuild that outgrows them stops the
    // run until they have grown, the prologue's first) against runs sized for the first list,
    // on the GPU alone: Oquendo et al.'s gas under optimized Verlet (two rebuild checks a step,
    // rolling springs, orientations, a floor in a periodic box), the wet gas with rolling
    // springs (three history blocks, bridges; wetted through a stopped prologue) and seed
    // 001's servo box (servo walls moved in the carried steps).
    let mut ovv = gas(true);
    ovv.integrator = Integrator::OptimizedVerlet;
    let mut wet = common::wet_gas();
    wet.model.rolling = grains::model::RollingLaw::Sds { k_r: 50.0, gamma_r: 0.0, mu_r: 0.05 };
    // 2,500 grains: more than one scan block (2,048), so that the reverse lists' scan after a
    // stop reads the block totals' slot the stop zeroed.
    let servo = common::parse(&common::edit(
        &std::fs::read_to_string(common::scene_path("dry_iso_100pa.toml")).unwrap(),
        &[("count = 8000", "count = 2500"), ("max = [28.0e-3, 28.0e-3, 28.0e-3]", "max = [19.0e-3, 19.0e-3, 19.0e-3]")],
    ));
    assert!(servo.grains.len() as u64 + 1 > grains::gpu::layout::SCAN_BLOCK);
    let wet_volume = wet.stages[0].wet_volume;
    for (name, scene, volume) in [("optimized Verlet gas", &ovv, None), ("wet gas", &wet, wet_volume), ("servo box", &servo, None)] {
        let run = |pairs: Option<u64>| -> Option<(Vec<u64>, u64, u64, u64)> {
            let mut g = grains::gpu::GpuEngine::with_pair_capacity(common::gpu()?, scene, pairs).unwrap_or_else(|e| panic!("{e}"));
            if let Some(v) = volume {
                g.wet(v).unwrap();
            }
            for _ in 0..4 {
                g.advance(150).unwrap();
            }
            let (f, s) = (g.frame(false).unwrap(), g.stats().unwrap());
            let bits = f.position.iter().chain(&f.velocity).chain(&f.angular_velocity).flat_map(|v| v.to_array().map(f64::to_bits)).collect();
            Some((bits, s.pairs, s.bridges, g.pair_stops()))
        };
        let Some((sized, pairs, bridges, sized_stops)) = run(None) else { return };
        let (tight, tight_pairs, tight_bridges, stops) = run(Some(16)).unwrap();
        println!("{name}: {pairs} pairs, {bridges} bridges; {stops} rebuilds stopped from 16 pairs, {sized_stops} sized for the first list");
        assert!(stops > 0, "{name}: rebuilds must have stopped");
        assert_eq!((tight_pairs, tight_bridges), (pairs, bridges), "{name}");
        assert_eq!(tight, sized, "{name}: the same bits, stops or none");
    }
}
