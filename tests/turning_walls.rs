//! Walls that turn (`angular_velocity` off a plane's normal, or on a mesh, about its
//! `center`): a plane swung about a hinge turns by the angle its spin gives and, sweeping onto
//! a grain at rest that was no candidate for its contacts, throws it along its normal at
//! `(1 + e)` times its surface's speed at the contact, as a flat mesh swung so does; a grain
//! pressed onto a faceted mesh drum turning about its axis is dragged along as on a spinning
//! cylinder; a plane a stage starts turning swings onto the grain as one turning from the
//! start does; the GPU runs them as its CPU f32 twin does; a checkpoint resumes bitwise.

mod common;

use glam::DVec3;
use grains::cpu::CpuEngine;
use grains::engine::{Engine, Frame};
use grains::mesh::read::write_ascii_stl;
use grains::real::Vec3;
use grains::scene::Scene;
use grains::walls::WallGeom;
use std::path::Path;

const R: f64 = 2.5e-3;
const RHO: f64 = 2500.0;
const MU: f64 = 0.5;
const G: f64 = 9.81;
const E: f64 = 0.5;

/// A scene in `dir` with one glass grain at rest at `x`, beside `wall` (a `[[wall]]` table's
/// keys), gravity `gravity`, one stage of `duration` (s).
fn scene(dir: &Path, wall: &str, x: DVec3, gravity: DVec3, duration: f64) -> Scene {
    scene_staged(dir, wall, x, gravity, &format!("[[stage]]\nkind = \"run\"\nduration = {duration:e}\n"))
}

/// [`scene`] with `stages` (`[[stage]]` tables).
fn scene_staged(dir: &Path, wall: &str, x: DVec3, gravity: DVec3, stages: &str) -> Scene {
    let text = format!(
        "[[material]]\nname = \"glass\"\ndensity = {RHO}\nyoungs_modulus = 6.3e10\npoisson_ratio = 0.24\nmu_s = {MU}\nrestitution = {E}\n\n\
         [[wall]]\nmaterial = \"glass\"\n{wall}\n\n\
         [[grain]]\nmaterial = \"glass\"\nradius = {R:e}\nposition = [{:e}, {:e}, {:e}]\n\n\
         [model]\nnormal = \"hertz\"\ndamping = \"restitution\"\ntangential = \"mindlin\"\n\n\
         [simulation]\ngravity = [{:e}, {:e}, {:e}]\ndt = \"auto\"\nexpected_speed = 1.0\n\n{stages}",
        x.x, x.y, x.z, gravity.x, gravity.y, gravity.z
    );
    grains::scene::parse(&dir.join("scene.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

/// `triangles` written as the STL file `name` in `dir`, and the `[[wall]]` keys that read it.
fn mesh_wall(dir: &Path, name: &str, triangles: &[[DVec3; 3]], extra: &str) -> String {
    write_ascii_stl(&dir.join(name), name, triangles).unwrap();
    format!("type = \"mesh\"\nfile = \"{name}\"\n{extra}")
}

/// The flipper's spin (rad/s) about the y axis through the origin, lifting the side x > 0.
const FLIP: f64 = 10.0;
/// Where the grain waits: 20 mm from the hinge, 2 mm above the flipper (more than the skin,
/// 0.5 mm, so that no contact of the wall's is kept for it when the run starts).
const GRAIN_X: f64 = 0.02;
const GAP: f64 = 2e-3;
/// The comparisons' flipper, quicker to the grain: 40 rad/s, the grain 0.6 mm above it.
const QUICK_FLIP: f64 = 40.0;
const QUICK_GAP: f64 = 6e-4;

/// The flipper as a plane z = 0 turning at `omega` (rad/s) about the y axis through the origin.
fn flipper_plane(omega: f64) -> String {
    format!("type = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\nangular_velocity = [0.0, {:e}, 0.0]", -omega)
}

/// The flipper as a flat mesh over x in [-10, 40] mm, y in [-20, 20] mm, in 5 x 4 squares of
/// two triangles, turning at `omega` (rad/s) about the same axis.
fn flipper_mesh(dir: &Path, omega: f64) -> String {
    let (nx, ny) = (5, 4);
    let p = |i: usize, j: usize| DVec3::new(-0.01 + 0.05 * i as f64 / nx as f64, -0.02 + 0.04 * j as f64 / ny as f64, 0.0);
    let tris: Vec<[DVec3; 3]> = (0..nx).flat_map(|i| (0..ny).flat_map(move |j| [[p(i, j), p(i + 1, j), p(i + 1, j + 1)], [p(i, j), p(i + 1, j + 1), p(i, j + 1)]])).collect();
    mesh_wall(dir, "flipper.stl", &tris, &format!("angular_velocity = [0.0, {:e}, 0.0]\ncenter = [0.0, 0.0, 0.0]", -omega))
}

/// The grain at rest `gap` (m) above the flipper `wall`, no gravity.
fn flipper(dir: &Path, wall: &str, gap: f64, duration: f64) -> Scene {
    scene(dir, wall, DVec3::new(GRAIN_X, 0.0, R + gap), DVec3::ZERO, duration)
}

/// The flipper's normal turned by `theta` (rad) from +z about -y.
fn flipper_normal(theta: f64) -> DVec3 {
    DVec3::new(-theta.sin(), 0.0, theta.cos())
}

/// The angle (rad) a wall spinning at `omega` turns in `n` steps of `dt`: each step turns by
/// Omelyan's `4 atan(omega dt / 4)`.
fn turned_by(omega: f64, n: u64, dt: f64) -> f64 {
    n as f64 * 4.0 * (omega * dt / 4.0).atan()
}

fn steps(s: &Scene) -> u64 {
    (s.stages[0].duration / s.time_step.dt).round() as u64
}

/// The angle (rad) at which the flipper, turning from flat, meets a grain at rest `gap` (m)
/// above it: its distance to the grain's centre `c` falls to R; and the velocity (m/s) it
/// throws the grain at when it turns at `omega` (rad/s): `(1 + e) omega s` along its normal
/// then, `s` the contact's distance from the hinge.
fn flipper_throw(gap: f64, omega: f64) -> (f64, DVec3) {
    let c = DVec3::new(GRAIN_X, 0.0, R + gap);
    let (mut lo, mut hi) = (0.0, 0.5);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if c.dot(flipper_normal(mid)) > R { lo = mid } else { hi = mid }
    }
    let s_contact = (c.length_squared() - R * R).sqrt();
    (lo, flipper_normal(lo) * ((1.0 + E) * omega * s_contact))
}

/// A plane swung about a hinge at 10 rad/s reaches a grain at rest 2 mm above it and 20 mm
/// out after 0.1 rad, and throws it along its normal at that moment at `(1 + e) omega s`, `s`
/// the contact's distance from the hinge: an impact at its surface's speed there (it turns by
/// 2e-4 rad while the contact lasts). The plane has turned by the angle its spin gives (to
/// round-off); a flat mesh swung about the same axis throws the grain the same way (to the
/// bits its rotation's rounding leaves), its corners where the rotation takes them.
#[test]
fn a_turning_plane_flips_a_grain_at_one_plus_e_times_its_surface_speed() {
    let dir = tempfile::tempdir().unwrap();
    let t = 0.013;
    let (hit, want) = flipper_throw(GAP, FLIP);
    let run = |wall: &str| {
        let s = flipper(dir.path(), wall, GAP, t);
        let mut e: CpuEngine<f64> = common::engine(&s);
        e.advance(steps(&s)).unwrap();
        (e.frame(false).unwrap(), turned_by(FLIP, steps(&s), s.time_step.dt))
    };
    let (plane, theta) = run(&flipper_plane(FLIP));
    let v = plane.velocity[0];
    println!("hit after {hit:.5} rad: thrown at {v:?} m/s against {want:?}");
    assert!((v - want).length() < 1e-2 * want.length(), "{v:?} against {want:?}");
    let WallGeom::Plane { point, normal } = plane.walls[0] else { panic!("{:?}", plane.walls[0]) };
    println!("the plane turned to {normal:?} against {:?} ({theta} rad)", flipper_normal(theta));
    assert!((normal.f64() - flipper_normal(theta)).length() < 1e-12 && point.f64() == DVec3::ZERO, "{normal:?}");
    let (mesh, _) = run(&flipper_mesh(dir.path(), FLIP));
    println!("the mesh threw it at {:?} m/s", mesh.velocity[0]);
    assert!((mesh.velocity[0] - v).length() < 1e-9, "the mesh must throw the grain as the plane does");
    let WallGeom::Mesh { pose, .. } = mesh.walls[0] else { panic!("{:?}", mesh.walls[0]) };
    // The corner (40, 20, 0) mm, turned by theta about -y.
    let corner = pose.world_point(Vec3::new(0.04, 0.02, 0.0)).f64();
    let want_corner = DVec3::new(0.04 * theta.cos(), 0.02, 0.04 * theta.sin());
    assert!((corner - want_corner).length() < 1e-14, "{corner:?} against {want_corner:?}");
}

/// The drum: a vertical cylinder of radius [`DRUM`] m as [`FACETS`] facets whose middles
/// touch the circle, turning at [`OMEGA`] rad/s about its axis (z through the origin), gravity
/// along +x pressing the grain onto a facet's middle at x = DRUM - R.
const DRUM: f64 = 0.05;
const FACETS: usize = 96;
const OMEGA: f64 = 1.0;

fn faceted_drum(dir: &Path) -> String {
    let n = FACETS;
    let out = DRUM / (std::f64::consts::PI / n as f64).cos();
    // Corners at half a facet's angle either side of +x, so that a facet's middle faces +x.
    let corner = |k: usize, z: f64| {
        let phi = 2.0 * std::f64::consts::PI * (k as f64 - 0.5) / n as f64;
        DVec3::new(out * phi.cos(), out * phi.sin(), z)
    };
    let tris: Vec<[DVec3; 3]> = (0..n).flat_map(|k| [[corner(k, -0.01), corner(k + 1, -0.01), corner(k + 1, 0.01)], [corner(k, -0.01), corner(k + 1, 0.01), corner(k, 0.01)]]).collect();
    mesh_wall(dir, "drum.stl", &tris, &format!("angular_velocity = [0.0, 0.0, {OMEGA:e}]\ncenter = [0.0, 0.0, 0.0]"))
}

/// Pressed onto a mesh drum turning about its axis, a grain at rest slips along the drum's
/// surface velocity `omega R` as on the spinning cylinder of `driven_walls`: friction `mu m g`
/// gives it `mu g t` along y while the contact point's speed, `7/2 mu g t`, stays below the
/// surface's (2 ms of the 2.9 ms of slip); the spin does `mu m g (omega R) t` of work. The
/// facet under the grain turns by 2 mrad (a quarter of its half-width): the grain rides
/// `DRUM psi^2 / 2` outward, 0.5% of gravity's push.
#[test]
fn a_grain_on_a_turning_mesh_drum_is_dragged_as_on_a_spinning_cylinder() {
    let dir = tempfile::tempdir().unwrap();
    let t = 2e-3;
    let s = scene(dir.path(), &faceted_drum(dir.path()), DVec3::new(DRUM - R, 0.0, 0.0), DVec3::new(G, 0.0, 0.0), t);
    let mut e: CpuEngine<f64> = common::engine(&s);
    e.advance(steps(&s)).unwrap();
    let (f, st) = (e.frame(false).unwrap(), e.stats().unwrap());
    let elapsed = steps(&s) as f64 * s.time_step.dt;
    let (v, want) = (f.velocity[0], MU * G * elapsed);
    let mass = RHO * 4.0 / 3.0 * std::f64::consts::PI * R.powi(3);
    let work = MU * mass * G * OMEGA * DRUM * elapsed;
    println!("grain v = {v:?} m/s against v_y = {want}; spin work {:e} J against {work:e}", st.external_work);
    assert!((v.y / want - 1.0).abs() < 2e-2 && v.x.abs() < 2e-2 * want, "{v:?}");
    assert!((st.external_work / work - 1.0).abs() < 2e-2, "{}", st.external_work);
}

/// The scenes of the comparisons: the quick flipper as a plane and as a mesh (its sweep onto
/// the grain, after 0.75 ms, included), and the mesh drum.
fn turning_scenes(dir: &Path) -> Vec<(&'static str, Scene)> {
    vec![
        ("plane flipper", flipper(dir, &flipper_plane(QUICK_FLIP), QUICK_GAP, 1e-3)),
        ("mesh flipper", flipper(dir, &flipper_mesh(dir, QUICK_FLIP), QUICK_GAP, 1e-3)),
        ("mesh drum", scene(dir, &faceted_drum(dir), DVec3::new(DRUM - R, 0.0, 0.0), DVec3::new(G, 0.0, 0.0), 5e-4)),
    ]
}

/// The GPU turns the walls and meets the grain as its CPU f32 twin does, bitwise on a
/// software adapter (the grain, the walls' normals and rotations, the work booked); the GPU,
/// which keeps no candidates for wall contacts, thereby also checks the CPU's choice of them
/// while a wall sweeps onto a grain.
#[test]
fn turning_walls_run_on_the_gpu_as_on_the_cpu() {
    const F32_TOLERANCE: f64 = 1e-5;
    let dir = tempfile::tempdir().unwrap();
    for (name, s) in turning_scenes(dir.path()) {
        let Some(mut g) = common::gpu_engine(&s) else { return };
        let exact = g.adapter().device_type == wgpu::DeviceType::Cpu;
        let mut c: CpuEngine<f32> = common::engine(&s);
        g.advance(steps(&s)).unwrap();
        c.advance(steps(&s)).unwrap();
        let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
        let (wg, wc) = (g.stats().unwrap().external_work, c.stats().unwrap().external_work);
        println!("{name}: gpu v {:?}, cpu v {:?}; work {wg:e} / {wc:e} J; walls {:?} / {:?}", fg.velocity[0], fc.velocity[0], fg.walls[0], fc.walls[0]);
        assert!(fc.velocity[0].length() > 1e-3, "{name}: the wall must have moved the grain");
        let vectors = |f: &Frame| [f.position[0], f.velocity[0], f.angular_velocity[0]];
        for (a, b) in vectors(&fg).iter().zip(vectors(&fc)) {
            if exact {
                assert_eq!(*a, b, "{name}");
            } else {
                assert!((0..3).all(|k| (a[k] - b[k]).abs() <= F32_TOLERANCE * (1.0 + b[k].abs())), "{name}: gpu {a:?} cpu {b:?}");
            }
        }
        // The CPU books the work in f64, the GPU in f32.
        assert!((wg - wc).abs() <= 1e-3 * wc.abs().max(1e-12), "{name}: work");
        if exact {
            assert_eq!(fg.walls, fc.walls, "{name}");
        }
    }
}

/// A checkpoint taken while the walls turn (the plane before it reaches the grain, the mesh
/// drum while it drags it) resumes to the uninterrupted run's bits, on the CPU and the GPU.
#[test]
fn a_run_with_turning_walls_resumes_bitwise() {
    let dir = tempfile::tempdir().unwrap();
    let makers = common::resumable_engines();
    for (label, s) in turning_scenes(dir.path()) {
        for (name, make) in &makers {
            let n = steps(&s);
            let mut whole = make(&s).unwrap();
            let mut first = make(&s).unwrap();
            whole.advance(n).unwrap();
            first.advance(n / 3).unwrap();
            let mut resumed = common::resumed(make, &s, first.as_ref(), n - n / 3);
            let (a, b) = (whole.frame(false).unwrap(), resumed.frame(false).unwrap());
            assert_eq!((&a.position, &a.velocity, &a.angular_velocity, &a.walls), (&b.position, &b.velocity, &b.angular_velocity, &b.walls), "{label} on {name}");
            assert_eq!(whole.stats().unwrap().external_work, resumed.stats().unwrap().external_work, "{label} on {name}");
        }
    }
}

/// The quick flipper named `flap`, still for 0.2 ms, then set turning by a stage.
fn staged_flipper(dir: &Path) -> Scene {
    let wall = "name = \"flap\"\ntype = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]";
    let stages = format!("[[stage]]\nkind = \"run\"\nduration = 2e-4\n\n[[stage]]\nkind = \"run\"\nduration = 1e-3\nwalls = {{ flap = {{ angular_velocity = [0.0, {:e}, 0.0] }} }}\n", -QUICK_FLIP);
    scene_staged(dir, wall, DVec3::new(GRAIN_X, 0.0, R + QUICK_GAP), DVec3::ZERO, &stages)
}

/// A plane that a stage starts turning swings onto the grain and throws it as one turning
/// from the start does: the CPU chooses its candidates for wall contacts again when the wall
/// starts turning (else the grain, at rest, would never be one, and the plane would pass
/// through it); the GPU runs it as its CPU f32 twin does.
#[test]
fn a_stage_that_starts_a_plane_turning_swings_it_onto_the_grain() {
    let dir = tempfile::tempdir().unwrap();
    let s = staged_flipper(dir.path());
    let record = || grains::output::RunRecorder::new(None, false).unwrap();
    let mut e: CpuEngine<f64> = common::engine(&s);
    grains::protocol::run(&s, &mut e, &mut record()).unwrap();
    let (_, want) = flipper_throw(QUICK_GAP, QUICK_FLIP);
    let v = e.frame(false).unwrap().velocity[0];
    println!("thrown at {v:?} m/s against {want:?}");
    assert!((v - want).length() < 1e-2 * want.length(), "{v:?} against {want:?}");
    let Some(mut g) = common::gpu_engine(&s) else { return };
    let mut c: CpuEngine<f32> = common::engine(&s);
    grains::protocol::run(&s, &mut g, &mut record()).unwrap();
    grains::protocol::run(&s, &mut c, &mut record()).unwrap();
    let (fg, fc) = (g.frame(false).unwrap(), c.frame(false).unwrap());
    println!("gpu v {:?}, cpu f32 v {:?}", fg.velocity[0], fc.velocity[0]);
    if g.adapter().device_type == wgpu::DeviceType::Cpu {
        assert_eq!((&fg.position, &fg.velocity, &fg.walls), (&fc.position, &fc.velocity, &fc.walls));
    } else {
        assert!((fg.velocity[0] - fc.velocity[0]).length() < 1e-5 * (1.0 + fc.velocity[0].length()));
    }
}
