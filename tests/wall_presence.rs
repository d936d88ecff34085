//! Walls that stages take away and add (`remove_walls`, `add_walls`): a grain resting on a
//! floor that a stage removes falls free, `g t^2 / 2` in `t`, and comes to rest on a lower
//! floor that the same stage adds (absent until then: the grain would have started on it);
//! the scene refuses names it cannot act on; the GPU runs it as its CPU f32 twin does; a
//! checkpoint taken after the change resumes bitwise; a wall added onto a grain is refused.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::output::RunRecorder;
use grains::protocol;
use grains::scene::Scene;

const R: f64 = 2.5e-3;
const G: f64 = 9.81;
/// How far below the first floor the second lies (m).
const DROP: f64 = 10e-3;

/// A glass grain (soft: E = 100 MPa, for longer steps) resting on floor `upper` (z = 0) for 5 ms; then stage `swap` takes `upper`
/// away and adds `lower` (z = -DROP, or `lower_z`) and runs `fall` (s).
fn scene_text(lower_z: f64, fall: f64, swap: &str) -> String {
    format!(
        "[[material]]\nname = \"glass\"\ndensity = 2500.0\nyoungs_modulus = 1.0e8\npoisson_ratio = 0.24\nmu_s = 0.5\nrestitution = 0.5\n\n\
         [[wall]]\nname = \"upper\"\ntype = \"plane\"\nmaterial = \"glass\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\n\
         [[wall]]\nname = \"lower\"\ntype = \"plane\"\nmaterial = \"glass\"\npoint = [0.0, 0.0, {lower_z:e}]\nnormal = [0.0, 0.0, 1.0]\n\n\
         [[grain]]\nmaterial = \"glass\"\nradius = {R:e}\nposition = [0.0, 0.0, {R:e}]\n\n\
         [model]\nnormal = \"hertz\"\ndamping = \"restitution\"\ntangential = \"mindlin\"\n\n\
         [simulation]\ngravity = [0.0, 0.0, {:e}]\ndt = \"auto\"\nexpected_speed = 1.0\n\n\
         [[stage]]\nname = \"rest\"\nkind = \"run\"\nduration = 5e-3\n\n\
         [[stage]]\nname = \"swap\"\nkind = \"run\"\nduration = {fall:e}\n{swap}\n",
        -G
    )
}

fn scene(fall: f64) -> Scene {
    common::parse(&scene_text(-DROP, fall, "remove_walls = [\"upper\"]\nadd_walls = [\"lower\"]"))
}

/// Runs the stages of `s` on `e`, returning the grain's height and vertical velocity at the
/// end of each.
fn heights(s: &Scene, e: &mut dyn Engine) -> Vec<(f64, f64)> {
    let mut rec = RunRecorder::new(None, false).unwrap();
    let mut progress = protocol::Progress::start(s, e).unwrap();
    let mut out = Vec::new();
    while protocol::run_next_stage(s, e, &mut rec, &mut progress).unwrap().is_some() {
        let f = e.frame(false).unwrap();
        out.push((f.position[0].z, f.velocity[0].z));
    }
    out
}

/// The lower floor is away at the start (the grain's place would not matter: it is 10 mm
/// below); the floor taken away lets the grain fall free for 30 ms, its drop `v0 t + g t^2 /
/// 2` within `g dt t` (8e-8 m: the velocity-Verlet step that starts the fall kicks with the
/// forces of the step before, the floor's support among them, for half a step); the added
/// floor then holds it at `R` above it, less the Hertz overlap of its weight.
#[test]
fn a_floor_taken_away_drops_the_grain_onto_one_added() {
    let s = scene(0.03);
    assert_eq!(s.walls.iter().map(|w| w.present).collect::<Vec<_>>(), [true, false]);
    let mut e: CpuEngine<f64> = common::engine(&s);
    let h = heights(&s, &mut e);
    let t = s.stages[1].max_steps(s.time_step.dt) as f64 * s.time_step.dt;
    let (z0, v0) = h[0];
    let fallen = z0 - h[1].0;
    let want = -v0 * t + 0.5 * G * t * t;
    println!("rested at z = {z0:e} m (v {v0:e} m/s); fell {fallen:e} m in {t} s against {want:e}");
    assert!((z0 - R).abs() < 1e-3 * R, "the grain rests on the upper floor: z = {z0}");
    assert!((fallen - want).abs() < G * s.time_step.dt * t, "free fall: {fallen:e} against {want:e} m");

    let s = scene(0.25);
    let mut e: CpuEngine<f64> = common::engine(&s);
    let h = heights(&s, &mut e);
    let (z, v) = h[1];
    println!("on the lower floor: z = {z:e} m, v = {v:e} m/s");
    assert!((z - (-DROP + R)).abs() < 1e-3 * R && v.abs() < 1e-3, "the grain rests on the added floor: z = {z}, v = {v}");
}

/// Names that cannot be added or removed are refused in one line naming the key.
#[test]
fn impossible_changes_are_refused() {
    let cases = [
        ("remove_walls = [\"upper\"]\nadd_walls = [\"upper\"]", "stage[1].remove_walls[0]", "twice in this stage"),
        ("remove_walls = [\"side\"]", "stage[1].remove_walls[0]", "names no wall"),
        ("add_walls = [\"upper\"]\n\n[[stage]]\nkind = \"run\"\nduration = 1e-3\nadd_walls = [\"upper\"]", "stage[2].add_walls[0]", "there already (stage[1].add_walls[0])"),
    ];
    for (swap, key, what) in cases {
        let text = scene_text(-DROP, 1e-3, swap);
        let err = grains::scene::parse(std::path::Path::new("presence.toml"), &text).unwrap_err().to_string();
        println!("{err}");
        assert!(err.contains(key) && err.contains(what) && !err.contains('\n'), "{err}");
    }
}

/// A stage may not add a wall where a grain is: the lower floor raised to cut the grain.
#[test]
fn a_wall_added_onto_a_grain_is_refused() {
    let s = common::parse(&scene_text(0.5 * R, 1e-3, "add_walls = [\"lower\"]"));
    let mut e: CpuEngine<f64> = common::engine(&s);
    let err = protocol::run(&s, &mut e, &mut RunRecorder::new(None, false).unwrap()).unwrap_err().to_string();
    println!("{err}");
    assert!(err.contains("adds wall lower") && err.contains("overlaps by") && !err.contains('\n'), "{err}");
}

/// The GPU takes the floor away and adds the other as its CPU f32 twin does (bitwise on a
/// software adapter), and a checkpoint taken in the fall resumes to the uninterrupted run's
/// bits on the CPU and the GPU.
#[test]
fn the_gpu_swaps_floors_as_the_cpu_does_and_a_checkpoint_resumes_bitwise() {
    let s = scene(0.06);
    if let Some(mut g) = common::gpu_engine(&s) {
        let exact = g.adapter().device_type == wgpu::DeviceType::Cpu;
        let mut c: CpuEngine<f32> = common::engine(&s);
        let (hg, hc) = (heights(&s, &mut g), heights(&s, &mut c));
        println!("gpu {hg:?}, cpu f32 {hc:?}");
        if exact {
            assert_eq!(hg, hc);
        } else {
            assert!(hg.iter().zip(&hc).all(|(a, b)| (a.0 - b.0).abs() < 1e-6 && (a.1 - b.1).abs() < 1e-4), "gpu {hg:?} cpu {hc:?}");
        }
    }
    let makers = common::resumable_engines();
    for (name, make) in &makers {
        let mut whole = make(&s).unwrap();
        heights(&s, whole.as_mut());
        // Stopped a third of the way into the fall, after the stage swapped the floors.
        let mut first = make(&s).unwrap();
        let mut rec = RunRecorder::new(None, false).unwrap();
        let mut progress = protocol::Progress::start(&s, first.as_mut()).unwrap();
        protocol::run_next_stage(&s, first.as_mut(), &mut rec, &mut progress).unwrap();
        first.set_wall_present(0, false);
        first.set_wall_present(1, true);
        let fall = s.stages[1].max_steps(s.time_step.dt);
        first.advance(fall / 3).unwrap();
        let resumed = common::resumed(make, &s, first.as_ref(), fall - fall / 3);
        let (a, b) = (whole.frame(false).unwrap(), resumed.frame(false).unwrap());
        println!("{name}: whole z {:e}, resumed z {:e}", a.position[0].z, b.position[0].z);
        assert_eq!((&a.position, &a.velocity, &a.angular_velocity), (&b.position, &b.velocity, &b.angular_velocity), "{name}");
    }
}
