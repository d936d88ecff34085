//! Contact dynamics with its Gauss-Seidel sweeps on the GPU (lavapipe in CI) against its CPU
//! f32 twin, step by step from the same state: the same contacts, colours and order and the
//! same f32 arithmetic, except that the device may fuse a multiply and an add (lavapipe does),
//! which moves an impulse by an ulp now and then. Each step starts the GPU engine from the
//! CPU's state (a checkpoint), since rigid frictional packings amplify round-off from step to
//! step (their impulses are not unique); one step's difference is what the kernels answer
//! for. Without an adapter these tests skip with a message, except under CI, where they fail.

mod common;

use grains::engine::Frame;
use grains::scene::Scene;

/// Largest position difference after a step whose solves took the same sweeps, over the mean
/// diameter.
const CD_POSITION_TOLERANCE: f64 = 1e-6;
/// Largest velocity difference after a step whose solves took the same sweeps, over the
/// largest speed: round-off (about 1e-6; over-relaxed sweeps carry an ulp a little further).
const CD_ROUNDOFF_VELOCITY_TOLERANCE: f64 = 2e-5;
/// Largest velocity difference after a step whose solves stopped a sweep apart or both at the
/// sweeps' cap, over the largest speed: the solver's tolerance (1e-4 in these scenes) times
/// what the impulses' change moves (its positions follow, by the step times that velocity).
/// At the cap the impulses still move by more than the tolerance a sweep, and a stick-slip or
/// open-closed choice that round-off turns the other way moves them as far as a sweep does.
const CD_VELOCITY_TOLERANCE: f64 = 5e-4;
/// Steps whose solves took different numbers of sweeps, over the steps: a sweep's norm
/// within round-off of the tolerance may stop one backend a sweep before the other.
const CD_SWEEPS_TOLERANCE: f64 = 0.05;

/// What one step of both engines from the same state differed by.
#[derive(Debug, Default)]
struct Worst {
    position: f64,
    velocity: f64,
    /// The velocities' difference over the steps a sweep apart or both at the cap.
    velocity_apart: f64,
    /// Steps at which both solves stopped at the cap.
    capped: u64,
    sweeps_differ: u64,
    sweeps: u64,
    contacts: u64,
}

fn mean_diameter(s: &Scene) -> f64 {
    2.0 * s.grains.radius.iter().sum::<f64>() / s.grains.len() as f64
}

fn largest(a: &[glam::DVec3], b: &[glam::DVec3]) -> f64 {
    a.iter().zip(b).map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()).fold(0.0, f64::max)
}

fn top_speed(f: &Frame) -> f64 {
    f.velocity.iter().map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()).fold(0.0, f64::max)
}

/// Steps the CPU f32 engine `steps` times (`switch` steps in, the servo's z walls switched to a
/// strain rate of 0.5/s), and before each step sets the GPU engine to its state; returns the
/// largest differences of a step.
fn step_by_step(s: &Scene, steps: u64, switch: Option<u64>) -> Option<Worst> {
    let gpu = common::gpu()?;
    let (mut cpu, mut gpu) = (grains::runner::cpu_engine(s, "f32").unwrap(), grains::runner::gpu_engine(gpu, s).unwrap());
    assert_eq!((cpu.backend(), gpu.backend()), ("cpu", "gpu"));
    let d = mean_diameter(s);
    let mut worst = Worst::default();
    for step in 0..steps {
        if Some(step) == switch {
            cpu.set_servo(None, Some(0.5));
        }
        gpu.restore(&cpu.save().unwrap()).unwrap();
        cpu.advance(1).unwrap();
        gpu.advance(1).unwrap();
        let (fc, fg) = (cpu.frame(false).unwrap(), gpu.frame(false).unwrap());
        let (sc, sg) = (cpu.stats().unwrap(), gpu.stats().unwrap());
        let solver = |st: &grains::engine::Stats| *st.solver.as_ref().expect("contact dynamics reports its solver");
        let sweeps = |st: &grains::engine::Stats| solver(st).max_iterations;
        let capped = solver(&sc).unconverged_steps > 0 && solver(&sg).unconverged_steps > 0;
        worst.capped += u64::from(capped);
        let velocity = largest(&fc.velocity, &fg.velocity) / top_speed(&fc);
        if sweeps(&sc) == sweeps(&sg) && !capped {
            worst.position = worst.position.max(largest(&fc.position, &fg.position) / d);
            worst.velocity = worst.velocity.max(velocity);
        } else {
            worst.velocity_apart = worst.velocity_apart.max(velocity);
            worst.sweeps_differ += u64::from(sweeps(&sc) != sweeps(&sg));
        }
        worst.sweeps += sweeps(&sc) as u64;
        worst.contacts += sc.contacts + sc.wall_contacts;
    }
    println!("{steps} steps, {} sweeps, {} contacts touching summed over the steps: {worst:?}", worst.sweeps, worst.contacts);
    Some(worst)
}

fn assert_tracks(worst: &Worst, steps: u64) {
    assert!(worst.contacts > 20 * steps, "the grains must be in contact: {} over {steps} steps", worst.contacts);
    assert!(worst.position < CD_POSITION_TOLERANCE, "positions differ by {:e} of d after a step", worst.position);
    assert!(worst.velocity < CD_ROUNDOFF_VELOCITY_TOLERANCE, "velocities differ by {:e} of the top speed after a step", worst.velocity);
    assert!(worst.velocity_apart < CD_VELOCITY_TOLERANCE, "velocities differ by {:e} of the top speed after a step a sweep apart", worst.velocity_apart);
    assert!((worst.sweeps_differ as f64) < CD_SWEEPS_TOLERANCE * steps as f64, "{} of {steps} steps took different sweeps", worst.sweeps_differ);
}

#[test]
fn grains_falling_in_a_box_on_the_gpu_follow_the_cpu_f32_twin() {
    // At dt = 1 ms the 100 steps see the grains land and pile on the floor; the sweeps
    // over-relaxed (the servo box below runs them plain).
    let mut s = common::cd::falling_box(1000, [12.0e-3, 12.0e-3, 16.0e-3]);
    s.time_step.dt = 1e-3;
    let grains::scene::Method::ContactDynamics(params) = &mut s.method else { panic!("falling_box is a contact-dynamics scene") };
    params.relaxation = 1.5;
    let Some(worst) = step_by_step(&s, 100, None) else { return };
    assert_tracks(&worst, 100);
}

#[test]
fn a_servo_box_on_the_gpu_follows_the_cpu_f32_twin_through_a_triaxial_switch() {
    let s = common::cd::servo_box();
    let Some(worst) = step_by_step(&s, 400, Some(300)) else { return };
    assert_tracks(&worst, 400);
}
