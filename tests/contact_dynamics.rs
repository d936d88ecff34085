//! Contact dynamics (`src/cd`) against exact answers: a sphere resting on a plane carries its
//! weight, a sphere on an incline rolls or slides as rigid-body mechanics says, a column of
//! spheres carries the weight above each contact, a frictionless head-on collision rebounds at
//! `e v`; a servo box at pressure `p` around a cubic lattice comes to rest holding `p` times
//! its faces through columns in balance; and a box of colliding grains gives the same
//! bits on one and two threads.

mod common;

use grains::cd::{CdParams, ContactDynamics, Partner};
use grains::engine::Engine;
use grains::scene::Scene;

/// Relative error allowed where the answer is exact up to round-off and the solver's
/// tolerance (`PARAMS.tolerance`).
const EXACT: f64 = 1e-9;

/// Tight solver settings for exact answers.
const PARAMS: CdParams = CdParams { theta: 0.5, tolerance: 1e-13, max_iterations: 10_000, relaxation: 1.0, gap_allowance: 1e-6, wall_mass: None };

const G: f64 = 9.81;
const RADIUS: f64 = 0.5e-3;
const DENSITY: f64 = 2500.0;

fn mass() -> f64 {
    DENSITY * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3)
}

/// A scene of glass grains (`mu`, restitution `e`) at `grains` (TOML `[[grain]]` blocks), a
/// floor at z = 0 unless `floor` is false, gravity `gravity`, step `dt`.
fn scene(mu: f64, e: f64, gravity: [f64; 3], floor: bool, dt: f64, grains: &str) -> Scene {
    // Rigid grains know no Rayleigh time: the step is set after the DEM checks of the file.
    let floor = if floor { "[[wall]]\ntype = \"plane\"\nmaterial = \"glass\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n" } else { "" };
    let mut s = common::parse(&format!(
        r#"
[[material]]
name = "glass"
density = {DENSITY:e}
youngs_modulus = 7.0e10
poisson_ratio = 0.25
mu_s = {mu:e}
restitution = {e:e}

{floor}

[simulation]
gravity = [{:e}, {:e}, {:e}]
dt = "auto"

[[stage]]
kind = "run"
duration = 1.0e-3

{grains}
"#,
        gravity[0], gravity[1], gravity[2]
    ));
    s.time_step.dt = dt;
    s
}

fn grain(x: [f64; 3], v: [f64; 3]) -> String {
    format!("[[grain]]\nmaterial = \"glass\"\nradius = {RADIUS:e}\nposition = [{:e}, {:e}, {:e}]\nvelocity = [{:e}, {:e}, {:e}]\n", x[0], x[1], x[2], v[0], v[1], v[2])
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn a_sphere_resting_on_a_plane_carries_exactly_its_weight() {
    let dt = 1e-4;
    let s = scene(0.4, 0.5, [0.0, 0.0, -G], true, dt, &grain([0.0, 0.0, RADIUS], [0.0; 3]));
    let mut cd = ContactDynamics::<f64>::new(&s, PARAMS).unwrap();
    for _ in 0..100 {
        cd.step().unwrap();
    }
    let c = cd.contacts()[0];
    assert_eq!(c.b, Partner::Wall(0));
    let force = c.r.z / dt;
    // The impulse on the wall points down (into it): the wall carries the weight.
    println!("wall load {force:e} N, weight {:e} N, height {:e} m, report {:?}", -mass() * G, cd.position(0)[2], cd.report());
    assert!(relative(-force, mass() * G) < EXACT, "{force} against {}", mass() * G);
    assert!(relative(cd.position(0)[2], RADIUS) < EXACT);
    assert!(cd.report().converged && cd.report().unbalanced < EXACT);
}

/// The sphere on a floor under gravity tilted by `angle` (rad): its speed after `steps`.
fn incline(angle: f64, mu: f64, steps: u64) -> (f64, f64, f64) {
    let dt = 1e-4;
    let s = scene(mu, 0.5, [G * angle.sin(), 0.0, -G * angle.cos()], true, dt, &grain([0.0, 0.0, RADIUS], [0.0; 3]));
    let mut cd = ContactDynamics::<f64>::new(&s, PARAMS).unwrap();
    for _ in 0..steps {
        cd.step().unwrap();
    }
    let b = cd.bodies()[0];
    (b.vel.x, b.omega.y * RADIUS, steps as f64 * dt)
}

#[test]
fn a_sphere_on_an_incline_rolls_below_the_slip_angle_and_slides_above_it() {
    // A solid sphere on an incline rolls without slipping while tan(angle) <= 7/2 mu, at
    // 5/7 g sin(angle); above, it slides at g (sin - mu cos) and spins up at 5 mu g cos / (2 R).
    // (A body that cannot turn sticks below tan(angle) = mu instead.)
    let mu: f64 = 0.2;
    let slip = (3.5 * mu).atan();
    for (angle, rolls) in [(0.5 * slip, true), (0.95 * slip, true), (1.05 * slip, false), (1.3 * slip, false)] {
        let (v, w_r, t) = incline(angle, mu, 200);
        let (a, a_spin) = if rolls { (5.0 / 7.0 * G * angle.sin(), 5.0 / 7.0 * G * angle.sin()) } else { (G * (angle.sin() - mu * angle.cos()), 2.5 * mu * G * angle.cos()) };
        println!("angle {:.4} rad ({}): v {v:e} m/s, w R {w_r:e} m/s, expected {:e} and {:e}", angle, if rolls { "rolls" } else { "slides" }, a * t, a_spin * t);
        assert!(relative(v, a * t) < EXACT, "speed {v} against {}", a * t);
        // Rolling: the contact point is at rest (w R = v, w about +y for motion along +x).
        assert!(relative(w_r, a_spin * t) < EXACT, "spin {w_r} against {}", a_spin * t);
    }
}

/// Height of the centre of grain `k` of a column standing on the floor (m).
fn column_height(k: usize) -> f64 {
    RADIUS * (1.0 + 2.0 * k as f64)
}

/// A column of `n` grains of friction `mu` standing in touch on the floor under gravity, at
/// step `dt`.
fn column(n: usize, mu: f64, dt: f64) -> Scene {
    // Listed 1 um apart (the scene refuses touching grains), then put in touch.
    let grains: String = (0..n).map(|k| grain([0.0, 0.0, column_height(k) + 1e-6 * k as f64], [0.0; 3])).collect();
    let mut s = scene(mu, 0.5, [0.0, 0.0, -G], true, dt, &grains);
    for (k, x) in s.grains.position.iter_mut().enumerate() {
        x[2] = column_height(k);
    }
    s
}

#[test]
fn a_column_of_spheres_carries_the_weight_above_each_contact() {
    let n = 8;
    let dt = 1e-4;
    let s = column(n, 0.4, dt);
    let mut cd = ContactDynamics::<f64>::new(&s, PARAMS).unwrap();
    for _ in 0..20 {
        cd.step().unwrap();
    }
    let report = cd.report();
    println!("{report:?}");
    assert!(report.converged);
    for c in cd.contacts() {
        // The contact below grain k carries the n - k grains from k up.
        let k = c.a as usize + if matches!(c.b, Partner::Wall(_)) { 0 } else { 1 };
        let carried = (n - k) as f64 * mass() * G;
        let force = c.r.dot(c.n) / dt;
        println!("contact below grain {k}: {force:e} N, weight above {carried:e} N");
        assert!(relative(force, carried) < EXACT);
    }
    assert_eq!(cd.contacts().len(), n);
    for k in 0..n {
        assert!(relative(cd.position(k)[2], column_height(k)) < EXACT);
    }
}

/// Relative error of a contact's load allowed per unit of the solver's tolerance on a column:
/// the impulses' error is the residual magnified by the Delassus operator's conditioning,
/// which grows as the square of the column's length (about 1e2 for 16 grains).
const COLUMN_CONDITIONING: f64 = 1e3;

#[test]
fn a_frictionless_column_converges_to_its_unique_impulses_within_the_tolerance_at_every_relaxation() {
    // A frictionless column has one solution: each contact carries the weight above it. The
    // first step starts cold, so the sweeps must build the whole load; at tolerance t each load
    // lands within COLUMN_CONDITIONING t of the exact one, plain or over-relaxed.
    let n = 16;
    let dt = 1e-4;
    let s = column(n, 0.0, dt);
    for relaxation in [1.0, 1.5] {
        for tolerance in [1e-4, 1e-6, 1e-8] {
            let mut cd = ContactDynamics::<f64>::new(&s, CdParams { tolerance, relaxation, ..PARAMS }).unwrap();
            for _ in 0..20 {
                cd.step().unwrap();
            }
            let report = cd.report();
            let worst = cd.contacts().iter().map(|c| {
                let k = c.a as usize + if matches!(c.b, Partner::Wall(_)) { 0 } else { 1 };
                relative(c.r.dot(c.n) / dt, (n - k) as f64 * mass() * G)
            }).fold(0.0, f64::max);
            println!("relaxation {relaxation}, tolerance {tolerance:e}: {} sweeps, worst load error {worst:.2e}, residuals {:?}", report.iterations, report.residuals);
            assert!(report.converged && cd.contacts().len() == n);
            assert!(worst < COLUMN_CONDITIONING * tolerance, "load error {worst:e} at tolerance {tolerance:e}");
            assert!(report.residuals.quadratic < COLUMN_CONDITIONING * tolerance, "{:?}", report.residuals);
        }
    }
}

#[test]
fn the_residuals_fall_as_the_sweeps_run_in_a_loaded_packing() {
    // 1,000 grains landed in a box (900 loaded contacts): one step solved again and again from the same state with
    // more sweeps each time; how far the impulses end from the contact laws (the residuals,
    // measured on the final velocities) must fall with the sweeps, plain and over-relaxed.
    let s = common::cd::falling_box(1000, [12.0e-3, 12.0e-3, 16.0e-3]);
    let grains::scene::Method::ContactDynamics(params) = s.method else { panic!("falling_box is a contact-dynamics scene") };
    let mut cd = ContactDynamics::<f64>::new(&s, params).unwrap();
    for _ in 0..900 {
        cd.step().unwrap();
    }
    let state = cd.save().unwrap();
    for relaxation in [1.0, 1.5] {
        let residuals: Vec<(u32, f64, f64)> = [4, 16, 64, 256]
            .into_iter()
            .map(|sweeps| {
                let mut again = ContactDynamics::<f64>::new(&s, CdParams { tolerance: 1e-12, max_iterations: sweeps, relaxation, ..params }).unwrap();
                again.restore(&state).unwrap();
                again.step().unwrap();
                let r = again.report();
                assert_eq!(r.iterations, sweeps);
                (sweeps, r.residuals.quadratic, r.residuals.normal)
            })
            .collect();
        println!("relaxation {relaxation}, (sweeps, quadratic norm, largest normal residual m/s): {residuals:?}, {} loaded contacts", cd.report().loaded);
        assert!(residuals.windows(2).all(|w| w[1].1 < w[0].1 && w[1].2 < w[0].2), "residuals must fall: {residuals:?}");
        assert!(residuals[3].1 < 0.1 * residuals[0].1, "64 times the sweeps must cut the quadratic norm tenfold: {residuals:?}");
    }
}

#[test]
fn a_frictionless_head_on_collision_rebounds_at_e_v() {
    let v = 0.1;
    let dt = 1e-5;
    for e in [0.3, 0.8, 1.0] {
        // Each grain approaches at v; they meet after a 2.5e-6 m gap, mid-step.
        let grains = grain([-RADIUS - 1.25e-6, 0.0, 0.0], [v, 0.0, 0.0]) + &grain([RADIUS + 1.25e-6, 0.0, 0.0], [-v, 0.0, 0.0]);
        let s = scene(0.0, e, [0.0; 3], false, dt, &grains);
        let mut cd = ContactDynamics::<f64>::new(&s, PARAMS).unwrap();
        for _ in 0..10 {
            cd.step().unwrap();
        }
        let (a, b) = (cd.bodies()[0].vel.x, cd.bodies()[1].vel.x);
        println!("e = {e}: velocities {a:e}, {b:e} m/s after the impact");
        assert!((a + e * v).abs() < EXACT * v && (b - e * v).abs() < EXACT * v, "{a} {b} against -/+ {}", e * v);
        // They never pass through each other.
        assert!(cd.position(1)[0] - cd.position(0)[0] >= 2.0 * RADIUS * (1.0 - EXACT));
    }
}

#[test]
fn a_servo_box_holds_a_cubic_lattice_at_its_pressure_through_balanced_columns() {
    // n^3 frictionless equal spheres on a simple cubic lattice of spacing d, the servo box 2%
    // wider than the lattice on each axis: the walls, pushed by p over their faces, close in,
    // strike the lattice (restitution 0.1) and come to rest. Then each wall carries p times
    // its face, each column along an axis carries one force at its every contact (walls and
    // bonds), and the columns' forces sum to p A. (How p A splits among the columns is not
    // fixed: rigid grains between rigid walls are hyperstatic.)
    const N: usize = 3;
    const PRESSURE: f64 = 100.0;
    let d = 2.0 * RADIUS;
    let (side, half_gap) = (N as f64 * d * 1.02, N as f64 * d * 0.01);
    let mut grains = String::new();
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                let x = [i, j, k].map(|a| half_gap + (a as f64 + 0.5) * d);
                grains += &grain(x, [0.0; 3]);
            }
        }
    }
    let mut s = common::parse(&format!(
        r#"
[[material]]
name = "glass"
density = {DENSITY:e}
youngs_modulus = 7.0e10
poisson_ratio = 0.25
mu_s = 0.0
restitution = 0.1

[[wall]]
type = "servo_box"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [{side:e}, {side:e}, {side:e}]
pressure = {PRESSURE:e}
max_speed = 0.05

[simulation]
gravity = [0.0, 0.0, 0.0]

[[stage]]
kind = "run"
duration = 1.0e-3

{grains}
"#
    ));
    s.time_step.dt = 1e-5;
    let mut cd = ContactDynamics::<f64>::new(&s, CdParams { gap_allowance: 0.05 * d, ..PARAMS }).unwrap();
    cd.advance(3000).unwrap();
    let stats = cd.stats().unwrap();
    let frame = cd.frame(true).unwrap();
    let plane = |w: usize| match frame.walls[w] {
        grains::walls::WallGeom::Plane { point, .. } => [point.x, point.y, point.z],
        _ => unreachable!(),
    };
    let extent: Vec<f64> = (0..3).map(|a| plane(2 * a + 1)[a] - plane(2 * a)[a]).collect();
    println!("extents {extent:?} (lattice {}), KE {:e} J, {} sweeps, walls {:?}", N as f64 * d, stats.ke_translational, cd.report().iterations, stats.walls.iter().map(|w| w.force).collect::<Vec<_>>());
    assert!(stats.ke_translational < 1e-20, "the box comes to rest: KE {:e} J", stats.ke_translational);
    for (w, wall) in stats.walls.iter().enumerate() {
        let a = w / 2;
        let area = extent[(a + 1) % 3] * extent[(a + 2) % 3];
        let load = wall.force[a].abs();
        assert!(relative(load, PRESSURE * area) < EXACT, "wall {w} carries {load:e} N against p A = {:e} N", PRESSURE * area);
        assert_eq!(wall.contacts, (N * N) as u64, "wall {w} touches every column");
    }
    let pairs = frame.contacts.as_ref().unwrap();
    assert_eq!(pairs.len(), 3 * N * N * (N - 1), "every lattice bond is a loaded contact");
    // Each column along each axis: its two wall contacts and its bonds, by lattice index.
    let index = |x: f64, a: usize| ((x - plane(2 * a)[a]) / d).floor() as usize;
    let column = |g: u32, axis: usize| {
        let x = frame.position[g as usize];
        (index(x[(axis + 1) % 3], (axis + 1) % 3), index(x[(axis + 2) % 3], (axis + 2) % 3))
    };
    let mut loads = vec![vec![Vec::new(); N * N]; 3];
    for c in pairs {
        let (p, q) = (frame.position[c.i as usize], frame.position[c.j as usize]);
        let axis = (0..3).max_by(|&a, &b| (q[a] - p[a]).abs().total_cmp(&(q[b] - p[b]).abs())).unwrap();
        let (u, v) = column(c.i, axis);
        loads[axis][u * N + v].push(c.normal_force);
    }
    for c in frame.wall_contacts.as_ref().unwrap() {
        let axis = c.wall as usize / 2;
        let (u, v) = column(c.grain, axis);
        loads[axis][u * N + v].push(c.force[axis].abs());
    }
    for (axis, columns) in loads.iter().enumerate() {
        let area = extent[(axis + 1) % 3] * extent[(axis + 2) % 3];
        let mut total = 0.0;
        for (k, column) in columns.iter().enumerate() {
            assert_eq!(column.len(), N + 1, "column {k} along {axis}: two walls and {} bonds", N - 1);
            for f in column {
                assert!(relative(*f, column[0]) < EXACT, "column {k} along {axis} carries {f:e} N at one contact, {:e} N at another", column[0]);
            }
            total += column[0];
        }
        assert!(relative(total, PRESSURE * area) < EXACT, "the columns along {axis} carry {total:e} N against p A = {:e} N", PRESSURE * area);
    }
}

#[test]
fn impulses_are_bitwise_equal_on_one_and_two_threads() {
    // 5,000 grains in a box, colliding and falling: thousands of contacts per step, sticking
    // and sliding, and more grains than one chunk of the parallel pair detection takes; the
    // wide gap allowance lists enough contacts for the sweeps to be shared by the threads
    // (`step` runs them on the pool when there are several), each colour split between them.
    let s = common::cd::falling_box(5000, [20.0e-3, 20.0e-3, 26.0e-3]);
    let grains::scene::Method::ContactDynamics(params) = s.method else { panic!("falling_box is a contact-dynamics scene") };
    let run = || {
        let mut cd = ContactDynamics::<f64>::new(&s, params).unwrap();
        let mut loaded = 0;
        for _ in 0..400 {
            cd.step().unwrap();
            loaded += cd.report().loaded;
        }
        let bits: Vec<u64> = cd.bodies().iter().flat_map(|b| [b.pos.x, b.pos.y, b.pos.z, b.vel.x, b.omega.z]).map(f64::to_bits).collect();
        let impulses: Vec<u64> = cd.contacts().iter().flat_map(|c| [c.r.x, c.r.y, c.r.z]).map(f64::to_bits).collect();
        (bits, impulses, cd.report(), loaded)
    };
    let one = common::with_threads(1, run);
    let two = common::with_threads(2, run);
    println!("contacts {}, loaded contacts summed over the steps {}, last step {:?}", one.1.len() / 3, one.3, one.2);
    assert!(one.3 > 10_000, "the grains must be in contact");
    assert!(one.2.colours > 1 && one.2.contacts >= grains::cd::THREADS_MIN_CONTACTS, "enough contacts for the threads to share the sweeps: {:?}", one.2);
    assert_eq!(one, two);
}

#[test]
fn the_shipped_pile_runs_by_contact_dynamics_and_resumes_from_a_checkpoint_bit_for_bit() {
    let s = common::shipped("cd_pile.toml");
    let grains::scene::Method::ContactDynamics(params) = s.method else { panic!("cd_pile.toml is not a contact-dynamics scene") };
    assert_eq!((params.theta, params.tolerance, params.max_iterations, params.gap_allowance), (0.5, 1e-3, 500, 5e-5));
    let engine = || grains::runner::cpu_engine(&s, "f64").unwrap();
    let mut first = engine();
    first.advance(150).unwrap();
    let stats = first.stats().unwrap();
    let solver = stats.solver.expect("contact dynamics reports its solver");
    println!("after 150 steps: {} loaded contacts, {} on walls, solver {solver:?}", stats.contacts, stats.wall_contacts);
    assert_eq!(solver.steps, 150);
    assert!(stats.wall_contacts > 0, "the grains reach the floor");
    let saved = first.save().unwrap();
    first.advance(30).unwrap();
    let mut resumed = engine();
    resumed.restore(&saved).unwrap();
    resumed.advance(30).unwrap();
    let (a, b) = (first.frame(true).unwrap(), resumed.frame(true).unwrap());
    assert_eq!(a, b, "the resumed run differs from the uninterrupted one");
    let (sa, sb) = (first.stats().unwrap(), resumed.stats().unwrap());
    assert_eq!(sa, sb, "the resumed run's statistics differ");
    assert_eq!(sa.solver.unwrap().steps_total, 180);
    assert!(!a.wall_contacts.unwrap().is_empty());
}

#[test]
fn a_servo_box_resumes_from_a_checkpoint_bit_for_bit_through_a_triaxial_switch() {
    // 600 grains compacted by the servo box for 150 steps, then its z walls switched to a
    // strain rate (triaxial): a checkpoint taken after the switch carries the walls' places,
    // velocities, targets and work, so the resumed run is the uninterrupted one.
    let s = common::cd::servo_box();
    let engine = || grains::runner::cpu_engine(&s, "f64").unwrap();
    let mut first = engine();
    first.advance(150).unwrap();
    first.set_servo(None, Some(0.5));
    first.advance(20).unwrap();
    let saved = first.save().unwrap();
    first.advance(30).unwrap();
    let mut resumed = engine();
    resumed.restore(&saved).unwrap();
    resumed.advance(30).unwrap();
    let (sa, sb) = (first.stats().unwrap(), resumed.stats().unwrap());
    println!("after 200 steps: {} contacts, {} on walls, wall work {:e} J", sa.contacts, sa.wall_contacts, sa.external_work);
    assert!(sa.wall_contacts > 0 && sa.external_work > 0.0, "the walls reach the grains and work on them");
    assert_eq!(first.frame(true).unwrap(), resumed.frame(true).unwrap(), "the resumed run differs from the uninterrupted one");
    assert_eq!(sa, sb, "the resumed run's statistics differ");
}

#[test]
fn bad_contact_dynamics_input_gets_one_line_naming_the_key_and_the_fix() {
    let text = std::fs::read_to_string(common::scene_path("cd_pile.toml")).unwrap();
    for (from, to, says) in [
        ("theta = 0.5 ", "theta = 0.2 ", "contact_dynamics.theta = 0.2: must lie in [0.5, 1]; fix:"),
        ("max_iterations = 500 ", "max_iterations = 0 ", "contact_dynamics.max_iterations = 0: must be at least 1; fix:"),
        ("max_iterations = 500 ", "max_iterations = 500\nrelaxation = 2.0 ", "contact_dynamics.relaxation = 2: must lie in (0, 2); fix:"),
        ("tolerance = 1.0e-3 ", "tolerance = 0.0 ", "contact_dynamics.tolerance = 0: must lie in (0, 1); fix: give a quadratic norm"),
        ("dt = 1.0e-4 ", "dt = \"auto\" ", "simulation.dt = \"auto\": has no automatic value for rigid grains"),
        ("method = \"contact_dynamics\"", "method = \"lmgc\"", "simulation.method = \"lmgc\": unknown method; fix: use \"dem\" or \"contact_dynamics\""),
    ] {
        assert!(text.contains(from), "{from}");
        let err = grains::scene::parse(std::path::Path::new("cd.toml"), &text.replace(from, to)).unwrap_err().to_string();
        assert!(err.contains(says) && !err.contains('\n'), "{err}");
    }
    // A feature the solver does not model is refused when the engine is made.
    let periodic = text.replace("[simulation]", "[periodic]\nx = [0.0, 12.0e-3]\n\n[simulation]");
    let s = grains::scene::parse(std::path::Path::new("cd.toml"), &periodic).unwrap();
    let err = grains::runner::cpu_engine(&s, "f64").err().unwrap().to_string();
    assert!(err.contains("a periodic boundary is not modelled by contact dynamics; fix:"), "{err}");
    let driven = text.replacen("[[wall]]", "[[wall]]\nvelocity = [0.0, 0.0, 0.01]", 1);
    let s = grains::scene::parse(std::path::Path::new("cd.toml"), &driven).unwrap();
    let err = grains::runner::cpu_engine(&s, "f64").err().unwrap().to_string();
    assert!(err.contains("a wall with a prescribed velocity or spin is not modelled by contact dynamics; fix: use the DEM method"), "{err}");
}
