//! Walls with a prescribed motion (`velocity`, `angular_velocity` on `[[wall]]`, or set by a
//! stage's `walls`): a grain dropped at rest on a conveyor leaves it rolling at 2/7 of the
//! belt's speed, the belt having done `(2/7) m v^2` of work, and comes to rest when a later
//! stage stops the belt; a plane driven along its normal into a grain at rest throws it at
//! `(1 + e) v`; a grain pressed against a spinning drum slides at first at `mu g` along the
//! drum's surface velocity, the drum's spin doing `mu m g (omega R) t` of work. The GPU runs
//! them as its CPU f32 twin does, and a checkpoint taken while a wall moves resumes bitwise.

mod common;

use grains::cpu::CpuEngine;
use grains::engine::Engine;
use grains::output::RunRecorder;
use grains::protocol;
use grains::scene::Scene;

const R: f64 = 2.5e-3;
const RHO: f64 = 2500.0;
const MU: f64 = 0.5;
const G: f64 = 9.81;

fn mass() -> f64 {
    RHO * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3)
}

/// One glass grain at `x` (m) beside `wall` (a `[[wall]]` table's keys), gravity `gravity`
/// (m/s^2), restitution `e`, Hertz-Mindlin friction [`MU`], one stage of `duration` (s).
fn scene(wall: &str, x: [f64; 3], gravity: [f64; 3], e: f64, duration: f64) -> Scene {
    common::parse(&scene_text(wall, x, gravity, e, &format!("[[stage]]\nkind = \"run\"\nduration = {duration:e}\n")))
}

/// [`scene`]'s text with `stages` (`[[stage]]` tables).
fn scene_text(wall: &str, x: [f64; 3], gravity: [f64; 3], e: f64, stages: &str) -> String {
    format!(
        "[[material]]\nname = \"glass\"\ndensity = {RHO}\nyoungs_modulus = 6.3e10\npoisson_ratio = 0.24\nmu_s = {MU}\nrestitution = {e}\n\n\
         [[wall]]\nmaterial = \"glass\"\n{wall}\n\n\
         [[grain]]\nmaterial = \"glass\"\nradius = {R:e}\nposition = [{:e}, {:e}, {:e}]\n\n\
         [model]\nnormal = \"hertz\"\ndamping = \"restitution\"\ntangential = \"mindlin\"\n\n\
         [simulation]\ngravity = [{:e}, {:e}, {:e}]\ndt = \"auto\"\nexpected_speed = 1.0\n\n{stages}",
        x[0], x[1], x[2], gravity[0], gravity[1], gravity[2]
    )
}

/// The belt: a floor moving along x at [`BELT`] m/s.
const BELT: f64 = 0.5;
fn conveyor(duration: f64) -> Scene {
    scene(&format!("type = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nvelocity = [{BELT}, 0.0, 0.0]"), [0.0, 0.0, R], [0.0, 0.0, -G], 0.5, duration)
}

/// The piston-like plane: a floor rising at [`PUSH`] m/s into a grain at rest 0.1 mm above it.
const PUSH: f64 = 0.2;
const PUSH_E: f64 = 0.5;
fn pushed(duration: f64) -> Scene {
    scene(&format!("type = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nvelocity = [0.0, 0.0, {PUSH}]"), [0.0, 0.0, R + 1e-4], [0.0; 3], PUSH_E, duration)
}

/// The drum: a vertical cylinder of radius [`DRUM`] m spinning at [`OMEGA`] rad/s about z,
/// gravity along +x pressing the grain onto it at x = DRUM - R.
const DRUM: f64 = 0.05;
const OMEGA: f64 = 10.0;
fn drum(duration: f64) -> Scene {
    scene(&format!("type = \"cylinder\"\ncenter = [0.0, 0.0]\nradius = {DRUM}\nangular_velocity = [0.0, 0.0, {OMEGA}]"), [DRUM - R, 0.0, 0.0], [G, 0.0, 0.0], 0.5, duration)
}

fn steps(s: &Scene, t: f64) -> u64 {
    (t / s.time_step.dt).round() as u64
}

/// A grain dropped at rest on a belt slides until it rolls: its angular momentum about the
/// contact, zero in the belt's frame, leaves it rolling at `v (1 - 5/7)` = 2/7 of the belt's
/// speed, after `2 v / (7 mu g)` = 0.029 s; the belt's friction impulse `m 2/7 v` at the belt's
/// speed is the work it did.
#[test]
fn a_grain_on_a_conveyor_leaves_rolling_at_two_sevenths_of_its_speed() {
    let t = 0.06;
    let s = conveyor(t);
    let mut e: CpuEngine<f64> = common::engine(&s);
    e.advance(steps(&s, t)).unwrap();
    let (f, st) = (e.frame(false).unwrap(), e.stats().unwrap());
    let (v, w) = (f.velocity[0], f.angular_velocity[0]);
    let work = st.external_work;
    println!("grain v = {v:?} m/s, omega = {w:?} rad/s; belt work {work:e} J against {:e}", 2.0 / 7.0 * mass() * BELT * BELT);
    assert!((v.x / (2.0 / 7.0 * BELT) - 1.0).abs() < 1e-3, "v_x = {}", v.x);
    // Rolling on the belt: the grain's contact point (at -R z) moves with it, v_x - omega_y R = v.
    assert!(((v.x - w.y * R) / BELT - 1.0).abs() < 1e-3, "rolls: v_x - omega_y R = {} against {BELT}", v.x - w.y * R);
    assert!((work / (2.0 / 7.0 * mass() * BELT * BELT) - 1.0).abs() < 1e-2, "work {work:e}");
}

/// A plane driven along its normal at `v` into a grain at rest: in the plane's frame an impact
/// at `v` rebounding at `e v`, so the grain leaves at `(1 + e) v`; the plane has moved `v t`.
#[test]
fn a_driven_plane_throws_a_grain_at_one_plus_e_times_its_speed() {
    let t = 5e-3;
    let s = pushed(t);
    let mut e: CpuEngine<f64> = common::engine(&s);
    e.advance(steps(&s, t)).unwrap();
    let f = e.frame(false).unwrap();
    let v = f.velocity[0].z;
    println!("grain leaves at {v} m/s against {}", (1.0 + PUSH_E) * PUSH);
    assert!((v / ((1.0 + PUSH_E) * PUSH) - 1.0).abs() < 1e-2, "{v}");
    let grains::walls::WallGeom::Plane { point, .. } = f.walls[0] else { panic!("{:?}", f.walls[0]) };
    let moved = steps(&s, t) as f64 * s.time_step.dt * PUSH;
    assert!((point.z - moved).abs() < 1e-12, "the plane stands at {} against {moved}", point.z);
}

/// Pressed onto a spinning drum, a grain at rest slips at first: friction `mu m g` along the
/// surface velocity `omega x (R x)` = `omega R y`, so it gains `mu g t` along y (the normal force
/// gains the centripetal `m v^2 / r`, 0.5% of the weight by the end), and the spin does
/// `mu m g (omega R) t` of work on it.
#[test]
fn a_grain_on_a_spinning_drum_is_dragged_along_the_drums_surface() {
    let t = 0.01;
    let s = drum(t);
    let mut e: CpuEngine<f64> = common::engine(&s);
    e.advance(steps(&s, t)).unwrap();
    let (f, st) = (e.frame(false).unwrap(), e.stats().unwrap());
    let elapsed = steps(&s, t) as f64 * s.time_step.dt;
    let (v, want) = (f.velocity[0], MU * G * elapsed);
    let work = MU * mass() * G * OMEGA * DRUM * elapsed;
    println!("grain v = {v:?} m/s against v_y = {want}; spin work {:e} J against {work:e}", st.external_work);
    assert!((v.y / want - 1.0).abs() < 1e-2 && v.x.abs() < 1e-2 * want, "{v:?}");
    assert!((st.external_work / work - 1.0).abs() < 1e-2, "{}", st.external_work);
}

/// A belt that stages start and stop: still for 5 ms while the grain settles, at [`BELT`] for
/// `moving` (s), then still again for `stopped` (s).
fn staged_belt(moving: f64, stopped: f64) -> Scene {
    let wall = "name = \"belt\"\ntype = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]";
    let mut stages = format!("[[stage]]\nkind = \"run\"\nduration = 5e-3\n\n[[stage]]\nkind = \"run\"\nduration = {moving:e}\nwalls = {{ belt = {{ velocity = [{BELT}, 0.0, 0.0] }} }}\n");
    if stopped > 0.0 {
        stages += &format!("\n[[stage]]\nkind = \"run\"\nduration = {stopped:e}\nwalls = {{ belt = {{}} }}\n");
    }
    common::parse(&scene_text(wall, [0.0, 0.0, R], [0.0, 0.0, -G], 0.5, &stages))
}

/// Stages start and stop the belt: the grain leaves rolling at 2/7 of its speed, and when the
/// belt stops, its angular momentum about the contact, `I omega + m R v` = 0 at that moment,
/// brings it to rest; the belt moved only while its stage ran.
#[test]
fn stages_start_and_stop_a_belt() {
    for (stopped, want) in [(0.0, 2.0 / 7.0 * BELT), (0.06, 0.0)] {
        let s = staged_belt(0.06, stopped);
        let mut e: CpuEngine<f64> = common::engine(&s);
        protocol::run(&s, &mut e, &mut RunRecorder::new(None, false).unwrap()).unwrap();
        let f = e.frame(false).unwrap();
        let grains::walls::WallGeom::Plane { point, .. } = f.walls[0] else { panic!("{:?}", f.walls[0]) };
        let moved = s.stages[1].max_steps(s.time_step.dt) as f64 * s.time_step.dt * BELT;
        println!("after {} stages: grain v = {:?} m/s, omega = {:?} rad/s; the belt moved {} m against {moved}", s.stages.len(), f.velocity[0], f.angular_velocity[0], point.x);
        assert!((f.velocity[0].x - want).abs() < 1e-3 * BELT, "v_x = {} against {want}", f.velocity[0].x);
        assert!((point.x - moved).abs() < 1e-12, "the belt stands at {}", point.x);
    }
}

/// The GPU moves the walls and reads their surface velocities as its CPU f32 twin does
/// (bitwise on a software adapter), and books the same work.
#[test]
fn driven_walls_run_on_the_gpu_as_on_the_cpu() {
    const F32_TOLERANCE: f64 = 1e-5;
    for (name, s) in [("conveyor", conveyor(2e-3)), ("pushed", pushed(1e-3)), ("drum", drum(2e-3)), ("staged belt", staged_belt(1e-3, 1e-3))] {
        let Some(mut g) = common::gpu_engine(&s) else { return };
        let exact = g.adapter().device_type == wgpu::DeviceType::Cpu;
        let mut c: CpuEngine<f32> = common::engine(&s);
        protocol::run(&s, &mut g, &mut RunRecorder::new(None, false).unwrap()).unwrap();
        protocol::run(&s, &mut c, &mut RunRecorder::new(None, false).unwrap()).unwrap();
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        let (wg, wc) = (g.stats().unwrap().external_work, c.stats().unwrap().external_work);
        println!("{name}: gpu v {:?}, cpu v {:?}; work {wg:e} / {wc:e} J; walls {:?} / {:?}", fg.velocity[0], fc.velocity[0], fg.walls[0], fc.walls[0]);
        assert!((wg - wc).abs() <= 1e-3 * wc.abs().max(1e-12), "{name}: work");
        let vectors = |f: &grains::engine::Frame| [f.position[0], f.velocity[0], f.angular_velocity[0]];
        for (a, b) in vectors(&fg).iter().zip(vectors(&fc)) {
            if exact {
                assert_eq!(*a, b, "{name}");
            } else {
                assert!((0..3).all(|k| (a[k] - b[k]).abs() <= F32_TOLERANCE * (1.0 + b[k].abs())), "{name}: gpu {a:?} cpu {b:?}");
            }
        }
        if exact {
            assert_eq!(fg.walls, fc.walls, "{name}");
        }
    }
}

/// A checkpoint taken while the belt and the pushing plane move resumes to the uninterrupted
/// run's bits: the walls where they were, the work booked, on the CPU and the GPU; and the
/// motion a stage set (here set as a stage would) comes back with it.
#[test]
fn a_run_with_driven_walls_resumes_bitwise() {
    let makers = common::resumable_engines();
    let spinning = grains::scene::WallDrive { velocity: glam::DVec3::ZERO, angular_velocity: glam::DVec3::new(0.0, 0.0, OMEGA), turns: false };
    for (s, set) in [(conveyor(2e-3), None), (pushed(1e-3), None), (drum(2e-3), Some(spinning))] {
        for (name, make) in &makers {
            let n = steps(&s, s.stages[0].duration);
            let mut whole = make(&s).unwrap();
            let mut first = make(&s).unwrap();
            if let Some(d) = &set {
                // The drum spun twice as fast by a "stage".
                let faster = grains::scene::WallDrive { angular_velocity: 2.0 * d.angular_velocity, ..*d };
                whole.set_wall_drive(0, &faster);
                first.set_wall_drive(0, &faster);
            }
            whole.advance(n).unwrap();
            first.advance(n / 3).unwrap();
            let mut resumed = common::resumed(make, &s, first.as_ref(), n - n / 3);
            let (a, b) = (whole.frame(false).unwrap(), resumed.frame(false).unwrap());
            assert_eq!((&a.position, &a.velocity, &a.angular_velocity, &a.walls), (&b.position, &b.velocity, &b.angular_velocity, &b.walls), "{name}");
            assert_eq!(whole.stats().unwrap().external_work, resumed.stats().unwrap().external_work, "{name}");
        }
    }
}
